#pragma once
// One consistency check: both routes through one camera, then the comparison.
#include "zcheck/compare.h"
#include "zcheck/raster_renderer.h"
#include "zcheck/ray_renderer.h"
#include "zcheck/report.h"

namespace zcheck {

struct CheckRun {
    RenderResult ray;
    RenderResult raster;
    Comparison comparison;
    CheckReport report;
};

// `rays` and `raster` must have been built from `scene`.
CheckRun runCheck(const Scene& scene, const Camera& camera, const RayRenderer& rays, const RasterRenderer& raster,
                  const ToleranceModel& tolerance = {});

// Builds both routes for `scene` and runs one check (BVH build time included in the report).
CheckRun runCheck(const Scene& scene, const Camera& camera);

}  // namespace zcheck
