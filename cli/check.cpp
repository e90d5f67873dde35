#include "check.h"

#include <chrono>

namespace zcheck {

CheckRun runCheck(const Scene& scene, const Camera& camera, const RayRenderer& rays, const RasterRenderer& raster,
                  const ToleranceModel& tolerance)
{
    CheckRun run;
    run.ray = rays.render(camera);
    run.raster = raster.render(camera);
    const auto start = std::chrono::steady_clock::now();
    run.comparison = compareRoutes(scene, camera, run.ray, run.raster, tolerance);
    run.report.timings.compareMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    run.report.timings.bvhBuildMs = rays.buildMilliseconds();
    run.report.timings.traceMs = run.ray.renderMilliseconds;
    run.report.timings.rasterMs = run.raster.renderMilliseconds;
    run.report.scene = scene.name;
    run.report.triangles = scene.triangleCount();
    run.report.camera = camera.spec();
    run.report.tolerance = tolerance;
    run.report.comparison = run.comparison.report;
    return run;
}

CheckRun runCheck(const Scene& scene, const Camera& camera)
{
    const RayRenderer rays(scene);
    const RasterRenderer raster(scene);
    return runCheck(scene, camera, rays, raster);
}

}  // namespace zcheck
