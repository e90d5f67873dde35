#pragma once
// check --out / verify --out: the depth images, pictures and report.json of one run, all
// registered with OutputFiles before the run and written together after it.
#include "zcheck/atomic_file.h"
#include "zcheck/checker.h"

#include <string>
#include <vector>

namespace zcheck::cli {

struct RunFolder {
    std::string dir;          // empty: no --out
    std::string secondName;   // "raster_depth.exr" (check) or "map_depth.exr" (verify)
    bool mapError = false;    // verify: map_error.exr too

    void plan(OutputFiles& outputs) const;
    // ray_depth.exr, the second route's depth, error_heatmap.png, coverage_classes.png, report.json;
    // with mapError, map_error.exr: channel "error", map − truth per pixel in the map's units (eye-z
    // in scene units for window and ndc maps; VerifyResult::mapError), NaN where not compared.
    void write(OutputFiles& outputs, const RenderResult& ray, const RenderResult& second, const Comparison& comparison,
               const std::string& reportJson, const std::vector<float>& error = {}) const;

private:
    std::string path(const std::string& name) const;
};

}  // namespace zcheck::cli
