#pragma once
// The report of one consistency check: what was compared, how long it took, what was found.
#include "zcheck/camera.h"
#include "zcheck/compare.h"

#include <nlohmann/json.hpp>

#include <string>

namespace zcheck {

struct Timings {
    double bvhBuildMs = 0;   // Embree scene build (BVH), wall time
    double traceMs = 0;      // ray generation + tracing + depth in double, wall time
    double rasterMs = 0;     // transform, clip, bin, rasterize, wall time
    double compareMs = 0;    // per-pixel comparison and classification, wall time
};

struct CheckReport {
    std::string scene;              // scene name as addressed
    std::size_t triangles = 0;      // triangles in the scene
    CameraSpec camera;              // the camera both routes used
    ToleranceModel tolerance;
    ComparisonReport comparison;
    Timings timings;
};

nlohmann::json toJson(const CheckReport& report);
// JSON indented for people: arrays of numbers (matrix rows, vectors) stay on one line.
// Invalid UTF-8 in strings (file names) is replaced, never thrown over.
std::string prettyJson(const nlohmann::json& document);

// The human-readable summary `zcheck check` prints; `comparing` names the two sides.
std::string formatSummary(const CheckReport& report,
                          const std::string& comparing = "ray route (Embree) vs raster route (z-buffer)");

}  // namespace zcheck
