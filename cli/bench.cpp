// zcheck bench: how fast a whole check runs, phase by phase, and (--reference) how that
// compares with what the checked pipelines themselves cost: Mesa's llvmpipe drawing the same
// depth buffer, and Embree tracing the same rays at its best. Not a test: it measures.
#include "common.h"
#include "plugin.h"

#include "zcheck/camera_rays.h"
#include "zcheck/depth_map_formats.h"
#include "zcheck/detail/clock.h"
#include "zcheck/embree_reference.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/gl_reference.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_loader.h"

#include <nlohmann/json.hpp>
#include <sys/resource.h>
#include <tbb/parallel_for.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <thread>
#include <type_traits>

namespace zcheck::cli {

namespace {

// The named workloads (docs/speed.md): one million-triangle terrain, three cameras.
const char* const kWorkloadScene = "builtin:terrain?n=709&size=2";

// terrain-1M-1080p: seen from above at 1080p through a pinhole, every pixel covered.
CameraSpec terrainCamera()
{
    CameraSpec spec;
    spec.width = 1920, spec.height = 1080;
    spec.projection = Projection::perspective(60.0, 0.01, 10.0);
    spec.view = View::lookAt({0.0, 0.6, -0.15}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
    spec.depth.format = DepthFormat::Unorm24;
    return spec;
}

// A lens camera looking from `eye` towards `target`, OpenCV's convention.
CameraSpec lensCamera(int width, int height, LensSpec lens, glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up)
{
    CameraSpec spec;
    spec.convention = Convention::preset("opencv");
    spec.width = width, spec.height = height;
    spec.projection.type = ProjectionType::NonLinear;
    spec.projection.lens = std::move(lens);
    spec.projection.near = 0.001, spec.projection.far = 10.0;
    spec.view = View::lookAt(eye, target, up);
    return spec;
}

// fisheye-1M-1080p: an OpenCV (Kannala–Brandt) fisheye at 1920x1080 looking straight down from
// just above the terrain, its 180° circle as high as the image; outside it, no ray.
CameraSpec fisheyeCamera()
{
    return lensCamera(1920, 1080, {"opencv_fisheye", {340.0, 340.0, 959.5, 539.5, 0.021, -0.004, 0.0007, -0.0001}},
                      {0.0, 0.2, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0});
}

// panorama-1M-1920x960: a whole-sphere equirectangular panorama from just above the terrain's
// middle; the sky half misses.
CameraSpec panoramaCamera()
{
    return lensCamera(1920, 960, {"equirectangular", {-180.0, 180.0, -90.0, 90.0}}, {0.0, 0.2, 0.0}, {0.0, 0.2, 1.0},
                      {0.0, 1.0, 0.0});
}

struct Workload {
    const char* name;
    CameraSpec (*camera)();
};
const Workload kWorkloads[] = {
    {"terrain-1M-1080p", terrainCamera},
    {"fisheye-1M-1080p", fisheyeCamera},
    {"panorama-1M-1920x960", panoramaCamera},
};

struct Phase {
    std::vector<double> ms;
    double median() const
    {
        std::vector<double> sorted = ms;
        std::sort(sorted.begin(), sorted.end());
        return sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
    }
    double best() const { return ms.empty() ? 0.0 : *std::min_element(ms.begin(), ms.end()); }
};

double maxResidentMiB(const rusage& usage) { return double(usage.ru_maxrss) / 1024.0; }  // KiB on Linux

// The number of threads this process runs (/proc/self/status), 0 if unknown.
int threadsOfThisProcess()
{
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("Threads:", 0) == 0) return std::atoi(line.c_str() + 8);
    return 0;
}

// Runs `measure` in a child process of its own (fresh memory and page tables, nothing
// inherited from an earlier repeat's warm heap) with `threads` threads, and returns what it
// returned (a trivially copyable record) and the child's peak resident set. Throws when the
// child fails; `what` names it in the message. The fork copies this process without exec, which
// is safe only while it has one thread (a lock held by another thread would stay held in the
// child): that is checked, not assumed — TBB, Embree and OpenImageIO start nothing here before.
template <class Result, class Measure>
std::pair<Result, double> inChild(int threads, const char* what, Measure measure)
{
    static_assert(std::is_trivially_copyable_v<Result>, "the result crosses a pipe");
    if (const int running = threadsOfThisProcess(); running != 1)
        throw std::logic_error("bench: " + std::to_string(running) + " threads run before the measuring child is forked; a fork "
                               "without exec needs one");
    int channel[2];
    if (pipe(channel) != 0) throw std::runtime_error("bench: cannot create a pipe");
    const pid_t child = fork();
    if (child < 0) throw std::runtime_error("bench: cannot fork");
    if (child == 0) {
        close(channel[0]);
        try {
            const auto threadLimit = limitThreads(threads);
            const Result result = measure();
            const bool written = write(channel[1], &result, sizeof result) == ssize_t(sizeof result);
            _exit(written ? 0 : kExitInternal);
        } catch (...) {
            _exit(kExitInternal);
        }
    }
    close(channel[1]);
    Result result{};
    const bool complete = read(channel[0], &result, sizeof result) == ssize_t(sizeof result);
    close(channel[0]);
    int status = 0;
    rusage usage{};
    wait4(child, &status, 0, &usage);
    if (!complete || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw std::runtime_error(std::string("bench: ") + what + " in the child process failed");
    return {result, maxResidentMiB(usage)};
}

// One whole check as `zcheck check` runs it (tile by tile, keeping no per-pixel result; cold:
// as in a fresh `zcheck check` process), then, with the same Checker, a check that keeps
// both routes' full-frame renders (the phases the speed targets time: each route's whole
// image, its buffers new), and that one again (warm: the memory the one before freed is
// reused, as in a program that checks many cameras or maps, and as the yardsticks' repeated
// draws and traces run).
struct WholeCheck {
    double loadMs, bvhMs, tilesMs, wholeMs;  // tilesMs: the tile-by-tile pass of the whole check
    double traceMs, rasterMs, compareMs;     // the full-frame check's phases
    double warmTraceMs, warmRasterMs, warmCompareMs;
    std::size_t triangles;
    bool consistent;
    double peakMiB;  // the child's maximum resident set, after the cold check
};

WholeCheck wholeCheckInChild(const std::string& sceneName, const Camera& camera, int threads)
{
    return inChild<WholeCheck>(threads, "the check (run `zcheck check` with the same scene and camera)", [&] {
        WholeCheck w{};
        const auto start = Clock::now();
        Scene scene = loadScene(sceneName);
        w.loadMs = millisecondsSince(start);
        const Checker checker(std::move(scene));
        {
            CheckOptions asTheCommand;
            asTheCommand.keepPixels = false;
            const CheckResult run = checker.check(camera, asTheCommand);
            w.wholeMs = millisecondsSince(start);
            w.bvhMs = run.report.timings.bvhBuildMs;
            w.tilesMs = run.report.timings.traceMs + run.report.timings.rasterMs + run.report.timings.compareMs;
            w.consistent = run.report.comparison.consistent();
        }
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        w.peakMiB = maxResidentMiB(usage);
        {
            releaseCachedLargeBuffers();  // the full-frame check's buffers new, as in a fresh process
            const CheckResult fullFrame = checker.check(camera);
            w.traceMs = fullFrame.report.timings.traceMs, w.rasterMs = fullFrame.report.timings.rasterMs;
            w.compareMs = fullFrame.report.timings.compareMs;
            w.consistent = w.consistent && fullFrame.report.comparison.consistent();
        }
        const CheckResult again = checker.check(camera);
        w.warmTraceMs = again.report.timings.traceMs, w.warmRasterMs = again.report.timings.rasterMs;
        w.warmCompareMs = again.report.timings.compareMs;
        w.triangles = checker.scene().triangleCount();
        return w;
    }).first;
}

// A lens camera's own costs, in a child as the check's: its ray table built (once per
// intrinsics), every pixel's world ray made from it as the trace makes its lanes' (what each
// frame pays), the trace of the depth alone (the table built: the rays Embree's yardstick
// traces, and what a pinhole check's trace does; a lens check's trace also keeps every hit's
// eye point for its forward check), and a one-shot
// export of its distance map as `zcheck export` runs it (load, BVH, table, trace, the .npy
// written), then the same export warm (BVH and table kept: the second frame of a dataset).
struct LensCosts {
    double tableMs, raysMs, depthTraceMs;
    double exportMs, exportTraceMs, exportWriteMs, warmExportMs;
};

LensCosts lensCostsInChild(const std::string& sceneName, const Camera& camera, int threads)
{
    return inChild<LensCosts>(threads, "the lens camera's export (run `zcheck export` with the same scene and camera)", [&] {
        LensCosts c{};
        const std::filesystem::path output = std::filesystem::temp_directory_path() /
                                             ("zcheck-bench-" + std::to_string(getpid()) + ".npy");
        const auto exportOnce = [&](const Checker& checker, double& traceMs, double& writeMs) {
            auto start = Clock::now();
            const RenderResult route = checker.renderRay(camera, {}, EyePoints::Keep);
            traceMs = millisecondsSince(start);
            start = Clock::now();
            writeDepthMapFile(output.string(), {quantityImage(checker.scene(), camera, route, ExportQuantity::Distance)}, 1.0);
            writeMs = millisecondsSince(start);
        };
        const auto start = Clock::now();
        const Checker checker(loadScene(sceneName));
        const auto tableStart = Clock::now();
        camera.lens()->directionAtPixel(0, 0);  // builds the table
        c.tableMs = millisecondsSince(tableStart);
        exportOnce(checker, c.exportTraceMs, c.exportWriteMs);
        c.exportMs = millisecondsSince(start);

        const CameraRays cameraRays(camera);
        const int W = camera.width(), H = camera.height();
        std::vector<double> sums(std::size_t(H), 0.0);  // read, so that nothing is optimised away
        const auto raysStart = Clock::now();
        tbb::parallel_for(0, H, [&](int row) {
            double sum = 0;
            glm::dvec3 direction;
            for (int col = 0; col < W; ++col)  // as the trace makes each lane's ray
                if (cameraRays.lensDirectionAtPixel(col, row, direction)) sum += direction.x;
            sums[std::size_t(row)] = sum;
        });
        c.raysMs = millisecondsSince(raysStart);
        if (std::isnan(std::accumulate(sums.begin(), sums.end(), 0.0))) c.raysMs = NAN;

        c.depthTraceMs = checker.renderRay(camera).renderMilliseconds;

        const auto warmStart = Clock::now();
        double traceMs = 0, writeMs = 0;
        exportOnce(checker, traceMs, writeMs);
        c.warmExportMs = millisecondsSince(warmStart);
        std::filesystem::remove(output);
        return c;
    }).first;
}

struct BenchOptions {
    SceneAndCamera input{kWorkloadScene, {}};
    std::string workload = kWorkloads[0].name;
    ImageSize imageSize;
    int repeat = 5;
    int threads = 0;
    bool reference = false;
    bool json = false;
};

// One line a script can split on whitespace: name, median, best, an optional rate.
void printPhase(const std::string& name, const Phase& phase, const std::string& rate = "")
{
    std::printf("%-24s median %9.1f ms   best %9.1f ms   %s\n", name.c_str(), phase.median(), phase.best(), rate.c_str());
}

std::string rate(double value, const char* unit)
{
    char text[64];
    std::snprintf(text, sizeof text, "%.2f %s", value, unit);
    return text;
}

struct Ratio {
    std::string name;
    double value;
    double target;
    bool atMost;  // the target is an upper bound (else a lower bound)
    bool met() const { return atMost ? value <= target : value >= target; }
};

int runBenchCommand(const BenchOptions& o)
{
    const int threads = o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    const bool progress = isatty(STDERR_FILENO) && !o.json;
    const bool workload = o.input.scene == kWorkloadScene && o.input.camera.reference.empty();
    const Workload* named = nullptr;
    for (const Workload& w : kWorkloads)
        if (o.workload == w.name) named = &w;
    if (!named) throw Error("--workload '" + o.workload + "' is not a named workload: terrain-1M-1080p, fisheye-1M-1080p or panorama-1M-1920x960");
    if (o.workload != kWorkloads[0].name && !workload)
        throw Error("--workload " + o.workload + " names its own scene and camera: give it without --scene and --camera");

    // The camera comes from a first load (a file is read once before timing: cold-cache
    // effects are not what this measures). TBB is not started before the children fork.
    CameraSpec spec;
    {
        Scene scene = loadScene(o.input.scene);
        if (workload) scene.defaultCamera = named->camera();
        spec = cameraSpecFor(scene, o.input);
    }
    o.imageSize.apply(spec);
    const Camera camera(spec);
    const bool isFile = !isBuiltinSceneName(o.input.scene);
    const double fileMB = isFile ? double(std::filesystem::file_size(o.input.scene)) / 1e6 : 0.0;

    // The whole check, N times, each in a process of its own.
    Phase load, bvh, tiles, trace, raster, compare, whole, warmTrace, warmRaster, warmCompare;
    std::size_t triangles = 0;
    bool consistent = true;
    double peakMiB = 0;
    for (int r = 0; r < o.repeat; ++r) {
        if (progress) std::fprintf(stderr, "\rbench: whole check %d/%d", r + 1, o.repeat), std::fflush(stderr);
        const WholeCheck w = wholeCheckInChild(o.input.scene, camera, threads);
        load.ms.push_back(w.loadMs), bvh.ms.push_back(w.bvhMs), tiles.ms.push_back(w.tilesMs), trace.ms.push_back(w.traceMs);
        raster.ms.push_back(w.rasterMs), compare.ms.push_back(w.compareMs), whole.ms.push_back(w.wholeMs);
        warmTrace.ms.push_back(w.warmTraceMs), warmRaster.ms.push_back(w.warmRasterMs);
        warmCompare.ms.push_back(w.warmCompareMs);
        triangles = w.triangles;
        consistent = consistent && w.consistent;
        peakMiB = std::max(peakMiB, w.peakMiB);
    }
    // A lens camera's own costs, N times, each in a process of its own.
    const bool lens = camera.lens() != nullptr;
    Phase rayTable, rays, depthTrace, exportOneShot, exportTrace, exportWrite, warmExport;
    for (int r = 0; lens && r < o.repeat; ++r) {
        if (progress) std::fprintf(stderr, "\rbench: lens rays and export %d/%d", r + 1, o.repeat), std::fflush(stderr);
        const LensCosts c = lensCostsInChild(o.input.scene, camera, threads);
        rayTable.ms.push_back(c.tableMs), rays.ms.push_back(c.raysMs), exportOneShot.ms.push_back(c.exportMs);
        depthTrace.ms.push_back(c.depthTraceMs);
        exportTrace.ms.push_back(c.exportTraceMs), exportWrite.ms.push_back(c.exportWriteMs), warmExport.ms.push_back(c.warmExportMs);
    }
    if (progress) std::fprintf(stderr, "\r%40s\r", "");
    const auto threadLimit = limitThreads(threads);
    const double pixels = double(camera.width()) * camera.height();
    // A lens camera's check holds two arrays more, 24 bytes a pixel each: the ray table (lens.h)
    // and the trace's eye points, which its forward check projects.
    const double bytesPerPixel = lens ? 32.0 + 24.0 + 24.0 : 32.0;
    const double budgetMiB = (150.0 * double(triangles) + bytesPerPixel * pixels) / (1024.0 * 1024.0);

    // The references: Embree's builds each in a child, as the check's are; its trace and
    // llvmpipe's draws repeated in this process (their own buffers reused, at their best).
    Phase embreeBuild, embreeTrace, glDraw;
    std::string glRenderer, glSkipped;
    double glAgreement = NAN, embreeAgreement = NAN;
    if (o.reference) {
        const Scene scene = loadScene(o.input.scene);
        if (progress) std::fprintf(stderr, "\rbench: Embree reference%20s", ""), std::fflush(stderr);
        // Embree's build, like the check's, in a fresh process each time: in this process
        // its repeats ran on memory earlier builds had faulted in (and varied 142-274 ms).
        for (int r = 0; r < o.repeat; ++r)
            embreeBuild.ms.push_back(inChild<double>(threads, "Embree's reference build", [&] {
                return reference::EmbreeReference(scene).buildMilliseconds();
            }).first);
        const reference::EmbreeReference embree(scene);  // built here only to be traced
        std::vector<std::uint32_t> primitiveId;
        embree.trace(camera, primitiveId);  // warm-up
        for (int r = 0; r < o.repeat; ++r) embreeTrace.ms.push_back(embree.trace(camera, primitiveId));
        {  // The same rays? The primitive each pixel's ray hits, against the ray route's.
            const RenderResult traced = RayRenderer(scene).render(camera);
            std::size_t same = 0;
            for (std::size_t i = 0; i < primitiveId.size(); ++i) same += primitiveId[i] == traced.primitiveId[i];
            embreeAgreement = double(same) / double(primitiveId.size());
        }
        if (progress) std::fprintf(stderr, "\rbench: llvmpipe reference%20s", ""), std::fflush(stderr);
        const reference::GlYardstickFunctions* gl = nullptr;
        if (lens) glSkipped = "does not apply: a lens model has no projection matrix to draw through";
        else try {
            using Entry = const reference::GlYardstickFunctions* (*)();
            gl = reinterpret_cast<Entry>(pluginEntry("libzcheck_gl_yardstick.so", "zcheck_gl_yardstick"))();
        } catch (const std::runtime_error& e) {
            glSkipped = std::string("its plugin is missing (built only where libegl-dev is installed): ") + e.what();
        }
        if (gl) {
            reference::GlDepthInput input;
            input.positions = &scene.positions[0].x;
            input.vertexCount = scene.positions.size();
            input.indices = &scene.triangles[0].x;
            input.triangleCount = scene.triangles.size();
            for (int c = 0; c < 4; ++c)
                for (int k = 0; k < 4; ++k) input.clipFromWorld[std::size_t(4 * c + k)] = camera.clipFromWorld[c][k];
            input.width = camera.width(), input.height = camera.height();
            input.reversedZ = camera.depth().reversed;
            input.zeroToOne = camera.convention().ndcZMin() == 0.0;
            input.threads = threads;
            try {
                const reference::GlDepthTiming drawn = gl->timeDraw(input, o.repeat);
                const RenderResult lastRaster = RasterRenderer(scene).render(camera);
                glDraw.ms = drawn.drawMs;
                glRenderer = drawn.renderer;
                // The same picture? Coverage and depth per pixel. OpenGL's window has y up; the
                // camera's viewport may not (Vulkan, Direct3D, Metal): each pixel is found
                // through NDC, where both agree.
                const int W = camera.width(), H = camera.height();
                auto pixelOf = [&](int glCol, int glRowFromTop) {
                    const glm::dvec2 pNdc(2.0 * (glCol + 0.5) / W - 1.0, 1.0 - 2.0 * (glRowFromTop + 0.5) / H);
                    const glm::dvec4 pWindow = camera.windowFromNdc * glm::dvec4(pNdc, 0.0, 1.0);
                    const int col = int(std::floor(pWindow.x)), row = int(std::floor(camera.imageYFromWindowY(pWindow.y)));
                    return std::size_t(row) * W + col;
                };
                std::size_t same = 0;
                for (int row = 0; row < H && !drawn.depth.empty(); ++row)
                    for (int col = 0; col < W; ++col) {
                        const float depth = drawn.depth[std::size_t(row) * W + col];
                        const std::size_t i = pixelOf(col, row);
                        const bool glHit = depth != float(camera.clearDepth());
                        same += glHit == lastRaster.hit(i) && (!glHit || std::abs(depth - lastRaster.windowDepth.value[i]) <= 1e-5);
                    }
                glAgreement = drawn.depth.empty() ? NAN : double(same) / double(drawn.depth.size());
            } catch (const std::exception& e) {
                glSkipped = e.what();
            }
        }
        if (progress) std::fprintf(stderr, "\r%40s\r", "");
    }

    std::vector<Ratio> ratios;
    if (!lens) ratios.push_back({"compare/(trace+raster)", compare.median() / (trace.median() + raster.median()), 0.10, true});
    ratios.push_back({"peak-rss/budget", peakMiB / budgetMiB, 1.0, true});
    if (lens) {
        ratios.push_back({"rays/trace", rays.median() / depthTrace.median(), 0.10, true});
        ratios.push_back({"warm-export-seconds", warmExport.median() / 1e3, 0.5, true});
    }
    if (isFile) ratios.push_back({"load-MB/s", fileMB / (load.median() / 1e3), 150.0, false});
    if (!glDraw.ms.empty()) ratios.push_back({"raster/llvmpipe", raster.median() / glDraw.median(), 0.33, true});
    if (!embreeTrace.ms.empty()) {
        ratios.push_back({"trace-throughput/embree", embreeTrace.median() / (lens ? depthTrace : trace).median(), lens ? 0.8 : 0.9, false});
        if (!lens) ratios.push_back({"whole/(load+embree-bvh+embree-trace)",
                          whole.median() / (load.median() + embreeBuild.median() + embreeTrace.median()), 1.3, true});
    }
    // The same targets for the warm repeat (see WholeCheck): like for like with the
    // yardsticks, which repeat on buffers they have touched before.
    if (!lens) ratios.push_back({"warm-compare/(trace+raster)", warmCompare.median() / (warmTrace.median() + warmRaster.median()), 0.10, true});
    if (!glDraw.ms.empty()) ratios.push_back({"warm-raster/llvmpipe", warmRaster.median() / glDraw.median(), 0.33, true});
    if (!embreeTrace.ms.empty() && !lens)
        ratios.push_back({"warm-trace-throughput/embree", embreeTrace.median() / warmTrace.median(), 0.9, false});

    if (o.json) {
        auto phaseJson = [](const Phase& p) { return nlohmann::ordered_json{{"median_ms", p.median()}, {"best_ms", p.best()}, {"ms", p.ms}}; };
        nlohmann::ordered_json out;
        out["scene"] = o.input.scene;
        if (workload) out["workload"] = o.workload;
        if (lens) out["lens"] = camera.lens()->spec().model;
        out["triangles"] = triangles;
        out["width"] = camera.width(), out["height"] = camera.height();
        out["threads"] = threads, out["repeat"] = o.repeat;
        out["consistent"] = consistent;
        out["phases"] = {{"load", phaseJson(load)},     {"bvh", phaseJson(bvh)},         {"tiles", phaseJson(tiles)},
                         {"trace", phaseJson(trace)},
                         {"raster", phaseJson(raster)}, {"compare", phaseJson(compare)}, {"whole", phaseJson(whole)},
                         {"warm_trace", phaseJson(warmTrace)}, {"warm_raster", phaseJson(warmRaster)},
                         {"warm_compare", phaseJson(warmCompare)}};
        if (lens)
            out["lens_phases"] = {{"ray_table", phaseJson(rayTable)},         {"rays", phaseJson(rays)},
                                  {"depth_trace", phaseJson(depthTrace)},
                                  {"export", phaseJson(exportOneShot)},       {"export_trace", phaseJson(exportTrace)},
                                  {"export_write", phaseJson(exportWrite)},   {"warm_export", phaseJson(warmExport)}};
        out["mrays_per_s"] = pixels / trace.median() / 1e3;
        out["mtris_per_s"] = double(triangles) / raster.median() / 1e3;
        out["peak_rss_mib"] = peakMiB;
        out["memory_budget_mib"] = budgetMiB;
        if (isFile) out["load_mb_per_s"] = fileMB / (load.median() / 1e3);
        if (o.reference) {
            auto& ref = out["reference"];
            ref["embree_bvh"] = phaseJson(embreeBuild);
            ref["embree_trace"] = phaseJson(embreeTrace);
            ref["embree_mrays_per_s"] = pixels / embreeTrace.median() / 1e3;
            ref["embree_agreement"] = embreeAgreement;
            if (!glDraw.ms.empty()) {
                ref["llvmpipe_draw"] = phaseJson(glDraw);
                ref["llvmpipe_renderer"] = glRenderer;
                ref["llvmpipe_agreement"] = glAgreement;
            } else {
                ref["llvmpipe_skipped"] = glSkipped;
            }
        }
        for (const Ratio& r : ratios)
            out["ratios"][r.name] = {{"value", r.value}, {"target", r.target}, {"bound", r.atMost ? "at most" : "at least"}, {"met", r.met()}};
        std::cout << out.dump(2) << "\n";
        return kExitConsistent;
    }

    const std::string depth = lens ? "lens model " + camera.lens()->spec().model + ", distance"
                                   : toString(camera.depth().format) + (camera.depth().reversed ? " reversed-Z" : "");
    std::printf("zcheck bench: %s%s, %zu triangles, %dx%d, %s, %d threads, %d repeats, %s\n",
                workload ? (o.workload + ": ").c_str() : "", o.input.scene.c_str(), triangles, camera.width(), camera.height(),
                depth.c_str(), threads, o.repeat, consistent ? "consistent" : "INCONSISTENT");
    printPhase("load", load, isFile ? rate(fileMB / (load.median() / 1e3), "MB/s") : "(built in)");
    printPhase("bvh build", bvh);
    if (lens) printPhase("ray table", rayTable, rate(pixels / rayTable.median() / 1e3, "Mrays/s") + " (built once per intrinsics)");
    printPhase("trace", trace, rate(pixels / trace.median() / 1e3, "Mrays/s") + (lens ? " (the table built; eye points kept)" : ""));
    if (lens) {
        printPhase("depth trace", depthTrace, rate(pixels / depthTrace.median() / 1e3, "Mrays/s") + " (the depth alone)");
        printPhase("rays", rays, rate(pixels / rays.median() / 1e3, "Mrays/s") + " (every pixel's world ray from the table)");
        std::printf("%-24s does not apply: a lens model has no projection matrix to rasterize through\n", "raster");
        printPhase("lens check", compare, rate(pixels / compare.median() / 1e3, "Mpixels/s") + " (round trip and forward)");
    } else {
        printPhase("raster", raster, rate(double(triangles) / raster.median() / 1e3, "Mtris/s"));
        printPhase("compare", compare);
    }
    printPhase("whole check", whole, "as zcheck check: load + bvh + tile by tile");
    printPhase("tile by tile", tiles, "trace, raster and compare interleaved, nothing kept per pixel");
    printPhase("warm trace", warmTrace, rate(pixels / warmTrace.median() / 1e3, "Mrays/s (the check repeated)"));
    if (lens) {
        printPhase("warm lens check", warmCompare);
        printPhase("export", exportOneShot, "distance to .npy, one-shot: load + bvh + ray table + trace + write");
        printPhase("export trace", exportTrace);
        printPhase("export write", exportWrite);
        printPhase("warm export", warmExport, "trace + write again, the BVH and the ray table kept");
    } else {
        printPhase("warm raster", warmRaster, rate(double(triangles) / warmRaster.median() / 1e3, "Mtris/s"));
        printPhase("warm compare", warmCompare);
    }
    std::printf("%-24s %.1f MiB   budget %.1f MiB (150 B/triangle + %.0f B/pixel%s)\n", "peak RSS", peakMiB, budgetMiB,
                bytesPerPixel, lens ? ": 32, 24 for the ray table, 24 for the eye points" : "");
    if (o.reference) {
        printPhase("reference embree-bvh", embreeBuild);
        printPhase("reference embree-trace", embreeTrace,
                   rate(pixels / embreeTrace.median() / 1e3, "Mrays/s") +
                       (lens ? " (rtcIntersect16, the rays from a table made before timing), " : " (rtcIntersect16), ") +
                       rate(100.0 * embreeAgreement, "%") + " pixels hit the ray route's primitive");
        if (!glDraw.ms.empty())
            printPhase("reference llvmpipe", glDraw, glRenderer + ", LP_NUM_THREADS=" + std::to_string(threads) + ", " +
                                                         rate(100.0 * glAgreement, "% pixels as zcheck's raster"));
        else
            std::printf("%-24s skipped: %s\n", "reference llvmpipe", glSkipped.c_str());
    }
    for (const Ratio& r : ratios)
        std::printf("ratio %-34s %8.3f   target %s %.2f   %s\n", r.name.c_str(), r.value, r.atMost ? "<=" : ">=", r.target,
                    r.met() ? "met" : "NOT met");
    return kExitConsistent;
}

}  // namespace

Command addBenchCommand(CLI::App& app)
{
    auto o = std::make_shared<BenchOptions>();
    CLI::App* command = app.add_subcommand(
        "bench", "Measure a whole check phase by phase (load, BVH build, trace, raster, compare) and its\n"
                 "peak memory; with --reference, side by side with Embree's best trace and Mesa's llvmpipe.");
    addSceneAndCameraOptions(command, o->input);
    addImageSizeOptions(command, o->imageSize);
    command->add_option("--repeat", o->repeat, "whole checks to time (median and best are reported), 1..1000")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    command->add_option("--threads", o->threads,
                        "worker threads, 1..1024, also llvmpipe's LP_NUM_THREADS (default: all cores)")
        ->check(kThreadRange);
    command->add_flag("--reference", o->reference,
                      "also time Embree's own BVH build and best packet trace (rtcIntersect16, 8x8 tiles) and\n"
                      "a depth-only OpenGL draw on Mesa llvmpipe through EGL, and print the ratios to the targets");
    command->add_flag("--json", o->json, "print the measurements as JSON");
    command->add_option("--workload", o->workload,
                        "a named workload, without --scene and --camera: terrain-1M-1080p, fisheye-1M-1080p,\n"
                        "panorama-1M-1920x960")
        ->capture_default_str();
    command->footer(
        "Without --scene and --camera the workload is terrain-1M-1080p: builtin:terrain?n=709&size=2\n"
        "(1,002,528 triangles) at 1920x1080, unorm24, OpenGL perspective fovy 60, near 0.01, far 10,\n"
        "eye (0, 0.6, -0.15) looking at the origin: every pixel covered. --workload fisheye-1M-1080p:\n"
        "the same terrain through an OpenCV fisheye (opencv_fisheye fx = fy = 340, k1..k4 0.021,\n"
        "-0.004, 0.0007, -0.0001) at 1920x1080 from (0, 0.2, 0) looking straight down, its 180° circle as\n"
        "high as the image; panorama-1M-1920x960: a whole-sphere equirectangular panorama at\n"
        "1920x960 from (0, 0.2, 0), the sky half missing. For a lens camera there is no raster route:\n"
        "'compare' is the lens check (every pixel's round trip, every hit projected forward), and\n"
        "bench also times the ray table's build, every pixel's world ray made from it (rays: what\n"
        "each frame pays, target <= 10 % of the depth trace), the trace of the depth alone (the\n"
        "check's trace also keeps every hit's eye point for its forward check), and an export of the\n"
        "distance map to .npy, one-shot and warm (target <= 0.5 s); --reference times Embree on the\n"
        "same rays (target: the depth trace >= 0.8x its throughput).\n"
        "Each repeat is a whole check in a child process of its own, as `zcheck check` runs it: the\n"
        "scene is loaded, the BVH built, both routes drawn and compared tile by tile ('whole check').\n"
        "The child then checks again with the same BVH keeping both routes' full-frame renders, whose\n"
        "trace, raster and compare are the phases timed (their buffers new), and once more ('warm':\n"
        "memory the check before freed is reused, as when a program checks many cameras). Peak RSS\n"
        "is the largest child's, after the first check. Embree's reference builds run in children too;\n"
        "its trace and llvmpipe's draws repeat in this process (llvmpipe's from the plugin\n"
        "libzcheck_gl_yardstick.so, loaded only here). Lines are\n"
        "'<phase> median <ms> ms best <ms> ms <rate>' and 'ratio <name> <value> target <bound>'.\n"
        "Examples:\n"
        "  zcheck bench --reference                         terrain-1M-1080p, with both references\n"
        "  zcheck bench --scene terrain.obj --camera cam.json --threads 1 --json\n"
        "  zcheck bench --scene 'builtin:terrain?n=1416&size=2' --width 3840 --height 2160");
    return {command, [o] { return runBenchCommand(*o); }};
}

}  // namespace zcheck::cli
