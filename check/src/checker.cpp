#include "zcheck/checker.h"

#include "zcheck/detail/clock.h"

#include "zcheck/pose.h"

#include "zcheck/error.h"
#include "zcheck/export.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>

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

Checker::Checker(Scene scene, BvhBuild build) : scene_(std::move(scene)), rays_(scene_, build), raster_(scene_) {}

namespace {

}  // namespace

// Tile by tile: each worker traces a tile's rays, draws the same tile of the raster and
// compares them while both are in its cache; no full-frame buffer is made.
CheckResult Checker::checkTileByTile(const Camera& camera, const CheckOptions& options) const
{
    constexpr int kTile = TileComparison::kTileSize;
    static_assert(kTile == RasterRenderer::kTileSize, "the raster's tiles are the comparison's");
    CheckResult run;
    Timings& timings = run.report.timings;
    const auto start = Clock::now();
    const RasterFrame frame = raster_.prepare(camera, options.faults.raster);
    const double setUpMs = millisecondsSince(start);
    const auto comparisonStart = Clock::now();
    TileComparison tiles(scene_, camera, options.tolerance, nullptr);  // (its slopes are computed as the tiles ask)
    const double comparisonSetUpMs = millisecondsSince(comparisonStart);

    struct Worker {
        double ray[kTile * kTile], raster[kTile * kTile];
        std::uint32_t rayPrimitive[kTile * kTile], rasterPrimitive[kTile * kTile];
        double traceMs = 0, rasterMs = 0, compareMs = 0;
    };
    tbb::enumerable_thread_specific<std::unique_ptr<Worker>> workers([] { return std::make_unique<Worker>(); });
    const auto passStart = Clock::now();
    tbb::parallel_for(0, tiles.tiles().count(), [&](int tile) {
        Worker& w = *workers.local();
        const PixelRect rect = tiles.tiles().rect(tile);
        const auto t0 = Clock::now();
        rays_.traceRect(camera, rect, w.ray, w.rayPrimitive, kTile, options.faults.ray);
        const auto t1 = Clock::now();
        frame.drawTile(tile, w.raster, w.rasterPrimitive, kTile);
        const auto t2 = Clock::now();
        RoutePixels ray, raster;
        ray.windowDepth = w.ray, ray.primitive = w.rayPrimitive;
        raster.windowDepth = w.raster, raster.primitive = w.rasterPrimitive;
        ray.col0 = raster.col0 = rect.col0, ray.row0 = raster.row0 = rect.row0;
        ray.stride = raster.stride = kTile;
        tiles.compareTile(tile, ray, raster);
        const auto t3 = Clock::now();
        w.traceMs += std::chrono::duration<double, std::milli>(t1 - t0).count();
        w.rasterMs += std::chrono::duration<double, std::milli>(t2 - t1).count();
        w.compareMs += std::chrono::duration<double, std::milli>(t3 - t2).count();
    });
    std::optional<ComparisonReport> report = tiles.finish();  // no floors: always an answer
    if (!report) throw std::logic_error("comparison: the percentiles' keepers kept too few values");
    const double passMs = millisecondsSince(passStart);
    double traceMs = 0, rasterMs = 0, compareMs = 0;
    for (const auto& w : workers) traceMs += w->traceMs, rasterMs += w->rasterMs, compareMs += w->compareMs;
    const double busyMs = std::max(traceMs + rasterMs + compareMs, 1e-9);
    timings.tileByTile = true;
    timings.traceMs = passMs * traceMs / busyMs;
    timings.rasterMs = setUpMs + passMs * rasterMs / busyMs;
    timings.compareMs = comparisonSetUpMs + passMs * compareMs / busyMs;
    timings.bvhBuildMs = rays_.buildMilliseconds();
    run.comparison.report = std::move(*report);
    run.report.describeInputs(scene_, camera, options.tolerance);
    run.report.comparison = run.comparison.report;
    return run;
}

CheckResult Checker::check(const Camera& camera, const CheckOptions& options) const
{
    if (camera.lens()) return checkLens(camera, options);
    if (!options.keepPixels) return checkTileByTile(camera, options);
    CheckResult run;
    run.ray = rays_.render(camera, options.faults.ray);
    run.raster = raster_.render(camera, options.faults.raster);
    const auto start = Clock::now();
    run.comparison = compareRoutes(scene_, camera, run.ray, run.raster, options.tolerance);
    run.report.timings.compareMs =
        millisecondsSince(start);
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
    for (const std::string& w : {checked.planarity.warning(checked.name), checked.rounding.warning(checked.name, checked.origin)})
        if (!w.empty()) warnings.push_back(w);
    for (const std::string& note : cameraNotes(used.spec())) warnings.push_back(note);
    camera = used.spec();
    tolerance = model;
}

RenderResult Checker::renderRay(const Camera& camera, const RayFaults& faults, EyePoints eyePoints) const
{
    return rays_.render(camera, faults, eyePoints);
}

RenderResult Checker::renderRaster(const Camera& camera, const RasterFaults& faults) const
{
    if (const LensModel* lens = camera.lens())
        throw Error("the raster route does not apply to a lens model (" + lens->spec().model +
                    "): it has no projection matrix to rasterize through; use the ray route");
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

}  // namespace zcheck
