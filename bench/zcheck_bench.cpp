// zcheck_bench — reproducible speed and memory measurements of both routes (not a test).
//
// For each named workload: scene load, BVH build, trace (ray generation + Embree + depth
// in double), raster (transform, clip, bin, scan), compare; each render repeated and the
// median and best reported. Peak memory is the process's maximum resident set size.
#include "zcheck/camera_file.h"
#include "zcheck/checker.h"

#include "zcheck/detail/clock.h"
#include "zcheck/embree_reference.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_loader.h"

#include <CLI/CLI.hpp>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>

using namespace zcheck;

namespace {

double peakResidentMiB()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

long minorFaults()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

struct Stats {
    double median, best;
};

template <class F>
Stats timeRepeated(int repeats, F&& run)
{
    std::vector<double> ms;
    for (int k = 0; k < repeats; ++k) ms.push_back(run());
    std::sort(ms.begin(), ms.end());
    return {ms[ms.size() / 2], ms.front()};
}

// `phase` other than "all" times one phase alone, for A/B comparisons of its code: "raster"
// (no BVH is built), "trace", "raster-cold" and "trace-cold" (each render into fresh buffers,
// the kept ones given back first), "compare" (both routes rendered once, the comparison repeated),
// "compare-cold" (before each comparison, both routes rendered into fresh buffers),
// "floor" (what the comparison costs at least: its arrays read and written, nothing computed),
// or "tiles" (the whole check drawn, traced and compared tile by tile, as `zcheck check` runs).
void runPhase(const std::string& phase, const Scene& scene, const Camera& camera, int repeats)
{
    if (phase == "tiles") {  // a whole check drawn, traced and compared tile by tile
        const Checker checker(scene);
        CheckOptions options;
        options.keepPixels = false;
        std::vector<double> compareMs;  // the comparison's share of each pass (Timings)
        const Stats ms = timeRepeated(repeats, [&] {
            const auto start = Clock::now();
            const CheckResult run = checker.check(camera, options);
            compareMs.push_back(run.report.timings.compareMs);
            return millisecondsSince(start);
        });
        std::sort(compareMs.begin(), compareMs.end());
        std::printf("check tile by tile %7.1f ms (best %7.1f), compare's share %5.1f ms | peak RSS %6.0f MiB\n", ms.median,
                    ms.best, compareMs[compareMs.size() / 2], peakResidentMiB());
        return;
    }
    if (phase == "embree") {  // the yardstick of the trace: Embree's own best packet trace
        const reference::EmbreeReference embree(scene);
        std::vector<std::uint32_t> primitiveId;
        const Stats ms = timeRepeated(repeats, [&] { return embree.trace(camera, primitiveId); });
        std::printf("embree trace %7.1f ms (best %7.1f) %6.2f Mrays/s | peak RSS %6.0f MiB\n", ms.median, ms.best,
                    double(camera.width()) * camera.height() / ms.median / 1e3, peakResidentMiB());
        return;
    }
    const RasterRenderer raster(scene);
    if (phase == "raster" || phase == "raster-cold") {
        RenderResult last;
        const Stats ms = timeRepeated(repeats, [&] {
            if (phase == "raster-cold") last = RenderResult(), releaseCachedLargeBuffers();  // fresh buffers, as a new process's
            last = raster.render(camera);
            return last.renderMilliseconds;
        });
        std::printf("%s %7.1f ms (best %7.1f) %6.2f Mtris/s", phase == "raster-cold" ? "raster cold" : "raster", ms.median,
                    ms.best, double(scene.triangleCount()) / ms.median / 1e3);
    } else {
        const RayRenderer rays(scene);
        RenderResult ray = rays.render(camera);
        if (phase == "trace" || phase == "trace-cold") {
            const Stats ms = timeRepeated(repeats, [&] {
                if (phase == "trace-cold") ray = RenderResult(), releaseCachedLargeBuffers();  // fresh buffers
                ray = rays.render(camera);
                return ray.renderMilliseconds;
            });
            std::printf("%s %7.1f ms (best %7.1f) %6.2f Mrays/s", phase == "trace-cold" ? "trace cold" : "trace", ms.median,
                        ms.best, double(camera.width()) * camera.height() / ms.median / 1e3);
        } else if (phase == "floor") {
            // What any comparison of these renders costs at least: the same four arrays read and
            // two per-pixel arrays written (LargeVectors, as Comparison's: fresh memory only for
            // the first repeat of the tiles pass, whose `first` figure shows it; every later
            // repeat, and the rows pass, reuses the buffers kept from it), one subtraction per
            // pixel and nothing else; by 64×64 tiles in parallel, as the comparison's tile-by-tile
            // form goes, and by whole rows, a stream the processor prefetches.
            const RenderResult drawn = raster.render(camera);
            const std::size_t W = std::size_t(camera.width());
            auto pass = [&](int parts, auto rectOf) {
                double first = 0;
                const Stats ms = timeRepeated(repeats, [&] {
                    const auto start = Clock::now();
                    LargeVector<std::uint8_t> classes;
                    LargeVector<float> ratios;
                    classes.resize(ray.primitiveId.size()), ratios.resize(ray.primitiveId.size());
                    tbb::parallel_for(0, parts, [&](int part) {
                        const PixelRect rect = rectOf(part);
                        for (int row = rect.row0; row < rect.row1; ++row)
                            for (std::size_t i = row * W + std::size_t(rect.col0); i < row * W + std::size_t(rect.col1); ++i) {
                                classes[i] = std::uint8_t(ray.primitiveId[i] == drawn.primitiveId[i]);
                                ratios[i] = float(std::abs(drawn.windowDepth.value[i] - ray.windowDepth.value[i]));
                            }
                    });
                    const double elapsed =
                        millisecondsSince(start);
                    if (first == 0) first = elapsed;
                    return elapsed;
                });
                std::printf(" %7.1f ms (best %7.1f, first %7.1f)", ms.median, ms.best, first);
            };
            const TileGrid tiles(camera.width(), camera.height(), TileComparison::kTileSize);
            std::printf("compare floor: by tiles");
            pass(tiles.count(), [&](int tile) { return tiles.rect(tile); });
            constexpr int kRows = 16;  // blocks of whole rows
            std::printf(", by rows");
            pass((camera.height() + kRows - 1) / kRows, [&](int block) {
                return PixelRect{0, block * kRows, camera.width(), std::min(camera.height(), (block + 1) * kRows)};
            });
        } else if (phase == "compare-cold") {
            // As in `zcheck bench`'s cold full-frame check: the kept buffers given back, both
            // routes rendered into fresh ones (not timed), then the comparison, timed with the
            // page faults it takes (getrusage: every thread's, 4 KiB and huge pages alike).
            std::vector<double> faults;
            const Stats ms = timeRepeated(repeats, [&] {
                releaseCachedLargeBuffers();
                ray = rays.render(camera);
                const RenderResult drawn = raster.render(camera);
                const long faultsBefore = minorFaults();
                const auto start = Clock::now();
                const Comparison c = compareRoutes(scene, camera, ray, drawn);
                const double elapsed = millisecondsSince(start);
                faults.push_back(double(minorFaults() - faultsBefore));
                return elapsed;
            });
            std::sort(faults.begin(), faults.end());
            std::printf("compare cold %7.1f ms (best %7.1f), %5.0f page faults (fewest %5.0f)", ms.median, ms.best,
                        faults[faults.size() / 2], faults.front());
        } else {
            const RenderResult drawn = raster.render(camera);
            const Stats ms = timeRepeated(repeats, [&] {
                const auto start = Clock::now();
                const Comparison c = compareRoutes(scene, camera, ray, drawn);
                return millisecondsSince(start);
            });
            std::printf("compare %7.1f ms (best %7.1f)", ms.median, ms.best);
        }
    }
    std::printf(" | peak RSS %6.0f MiB\n", peakResidentMiB());
}

void runWorkload(const std::string& label, const std::string& sceneName, const std::string& cameraFile, int width,
                 int height, int repeats, const std::string& phase)
{
    const auto loadStart = Clock::now();
    const Scene scene = loadScene(sceneName);
    const double loadMs = millisecondsSince(loadStart);
    CameraSpec spec = cameraFile.empty() ? scene.defaultCamera : readCameraFile(cameraFile);
    if (cameraFile.empty()) spec.width = width, spec.height = height;
    const Camera camera(spec);
    if (phase != "all") return runPhase(phase, scene, camera, repeats);

    const RayRenderer rays(scene);
    const RasterRenderer raster(scene);
    RenderResult lastRay, lastRaster;
    const Stats trace = timeRepeated(repeats, [&] {
        lastRay = rays.render(camera);
        return lastRay.renderMilliseconds;
    });
    const Stats rasterMs = timeRepeated(repeats, [&] {
        lastRaster = raster.render(camera);
        return lastRaster.renderMilliseconds;
    });
    bool consistent = false;
    const Stats compare = timeRepeated(repeats, [&] {
        const auto start = Clock::now();
        consistent = compareRoutes(scene, camera, lastRay, lastRaster).report.consistent();
        return millisecondsSince(start);
    });

    const double pixels = double(width) * height, triangles = double(scene.triangleCount());
    std::printf("%-16s %9.0f tris %4dx%-4d load %7.1f ms | BVH %7.1f ms | trace %7.1f ms (best %7.1f) %6.2f Mrays/s"
                " | raster %7.1f ms (best %7.1f) %6.2f Mtris/s | compare %6.1f ms | peak RSS %6.0f MiB | %s\n",
                label.c_str(), triangles, width, height, loadMs, rays.buildMilliseconds(), trace.median, trace.best,
                pixels / trace.median / 1e3, rasterMs.median, rasterMs.best, triangles / rasterMs.median / 1e3,
                compare.median, peakResidentMiB(), consistent ? "consistent" : "INCONSISTENT");
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv)
{
    CLI::App app{"zcheck_bench: throughput of the ray and raster routes on named workloads"};
    int width = 1920, height = 1080, repeats = 5, threads = 0;
    std::string only, sceneName, cameraFile, phase = "all";
    app.add_option("--width", width, "image width")->capture_default_str();
    app.add_option("--height", height, "image height")->capture_default_str();
    app.add_option("--repeat", repeats, "renders per measurement (median and best reported)")->capture_default_str();
    app.add_option("--threads", threads, "worker threads (default: all cores)");
    app.add_option("--only", only, "run only workloads whose label contains this text");
    app.add_option("--scene", sceneName, "one workload: this scene (a built-in name or a mesh file) instead of the named ones");
    app.add_option("--camera", cameraFile, "with --scene: a camera file (its size overrides --width/--height)");
    app.add_option("--phase", phase, "all, or one phase alone: raster (no BVH built), trace, raster-cold and trace-cold (each render into fresh buffers), compare, compare-cold (each comparison after renders into fresh buffers, with its page faults), floor (what any comparison costs at least: its arrays read and written, nothing computed), tiles (a check tile by tile), "
                   "or embree (the trace's yardstick: Embree's own best packet trace)")
        ->check(CLI::IsMember({"all", "raster", "raster-cold", "trace", "trace-cold", "compare", "compare-cold", "floor", "tiles", "embree"}))
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));

    const std::pair<std::string, std::string> workloads[] = {
        {"terrain-708", "builtin:terrain?n=708"},
        {"bunny", std::string(ZCHECK_MODELS_DIR) + "/stanford-bunny.obj"},
        {"default", "builtin:default"},
    };
    try {
        if (!sceneName.empty()) runWorkload("scene", sceneName, cameraFile, width, height, std::max(1, repeats), phase);
        for (const auto& [label, scene] : workloads)
            if (sceneName.empty() && (only.empty() || label.find(only) != std::string::npos))
                runWorkload(label, scene, "", width, height, std::max(1, repeats), phase);
    } catch (const Error& e) {
        std::fprintf(stderr, "zcheck_bench: error: %s\n", e.what());
        return 2;
    }
    return 0;
}
