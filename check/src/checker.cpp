#include "zcheck/checker.h"

#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/verify.h"

#include <chrono>

namespace zcheck {

std::string toString(Route route) { return route == Route::Ray ? "ray" : "raster"; }

Route routeFromName(const std::string& name)
{
    if (name == "ray") return Route::Ray;
    if (name == "raster") return Route::Raster;
    throw Error("unknown route '" + name + "' (expected ray or raster)");
}

void requireSomethingCompared(const ComparisonReport& report, const std::string& scene)
{
    if (report.bothHit + report.rayOnly + report.rasterOnly == 0)
        throw Error("nothing to compare: neither route sees any surface of '" + scene +
                    "' through this camera (is it pointing away, or are near/far wrong?)");
}

Checker::Checker(Scene scene) : scene_(std::move(scene)), rays_(scene_), raster_(scene_) {}

Checker::~Checker() = default;

CheckResult Checker::check(const Camera& camera, const CheckOptions& options) const
{
    CheckResult run;
    run.ray = rays_.render(camera, options.faults.ray);
    run.raster = raster_.render(camera, options.faults.raster);
    const auto start = std::chrono::steady_clock::now();
    run.comparison = compareRoutes(scene_, camera, run.ray, run.raster, options.tolerance);
    run.report.timings.compareMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    run.report.timings.bvhBuildMs = rays_.buildMilliseconds();
    run.report.timings.traceMs = run.ray.renderMilliseconds;
    run.report.timings.rasterMs = run.raster.renderMilliseconds;
    run.report.describeInputs(scene_, camera, options.tolerance);
    run.report.comparison = run.comparison.report;
    return run;
}

void CheckReport::describeInputs(const Scene& checked, const Camera& used, const ToleranceModel& model)
{
    scene = checked.name;
    triangles = checked.triangleCount();
    warnings.clear();
    if (const std::string w = checked.planarity.warning(checked.name); !w.empty()) warnings.push_back(w);
    camera = used.spec();
    tolerance = model;
}

RenderResult Checker::renderRay(const Camera& camera, const RayFaults& faults, EyePoints eyePoints) const
{
    return rays_.render(camera, faults, eyePoints);
}

RenderResult Checker::renderRaster(const Camera& camera, const RasterFaults& faults) const
{
    return raster_.render(camera, faults);
}

RenderResult Checker::render(const Camera& camera, Route route, const RouteFaults& faults) const
{
    return route == Route::Ray ? renderRay(camera, faults.ray) : renderRaster(camera, faults.raster);
}

QuantityImage Checker::render(const Camera& camera, ExportQuantity quantity, Route route) const
{
    // The ray route's eye-space points are exact: exports of eye-z, distance and positions read them.
    const RenderResult drawn = route == Route::Ray ? renderRay(camera, {}, EyePoints::Keep) : renderRaster(camera);
    return quantityImage(scene_, camera, drawn, quantity);
}

const VertexNeighbours& Checker::neighbours() const
{
    std::call_once(neighboursOnce_, [&] { neighbours_ = std::make_unique<VertexNeighbours>(scene_, &rays_); });
    return *neighbours_;
}

}  // namespace zcheck
