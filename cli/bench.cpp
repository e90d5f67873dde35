// zcheck bench: how fast a whole check runs, phase by phase, in one kernel form or several side by
// side (--kernels), and (--reference) how that compares with what the checked pipelines
// themselves cost: Mesa's llvmpipe drawing the same depth buffer, and Embree tracing the same
// rays at its best. Not a test: it measures.
#include "common.h"
#include "plugin.h"

#include "zcheck/camera_rays.h"
#include "zcheck/depth_map_formats.h"
#include "zcheck/detail/clock.h"
#include "zcheck/embree_reference.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/gl_reference.h"
#include "zcheck/kernel_form.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/ray_renderer.h"

#include <nlohmann/json.hpp>
#include <sys/resource.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <optional>
#include <thread>
#include <type_traits>

namespace zcheck::cli {

namespace {

// The named workloads (docs/speed.md): a million-triangle terrain through three cameras, and a
// ten-million-triangle one at 4K.
const char* const kWorkloadScene = "builtin:terrain?n=709&size=2";
const char* const kHugeWorkloadScene = "builtin:terrain?n=2237&size=2";

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

// terrain-10M-4K: the same view of a terrain ten times as fine (9,999,392 triangles) at
// 3840x2160: 0.83 rays per triangle, a check whose BVH build is most of it.
CameraSpec hugeTerrainCamera()
{
    CameraSpec spec = terrainCamera();
    spec.width = 3840, spec.height = 2160;
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
    const char* scene;
    CameraSpec (*camera)();
};
const Workload kWorkloads[] = {
    {"terrain-1M-1080p", kWorkloadScene, terrainCamera},
    {"fisheye-1M-1080p", kWorkloadScene, fisheyeCamera},
    {"panorama-1M-1920x960", kWorkloadScene, panoramaCamera},
    {"terrain-10M-4K", kHugeWorkloadScene, hugeTerrainCamera},
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

// loadScene on the calling thread alone: TBB starts no worker (as a parallel loop, or a
// global_control, would), so that this process can still fork the measuring children (inChild).
Scene loadSceneOnThisThread(const std::string& name)
{
    Scene scene;
    tbb::task_arena callingThreadOnly(1);
    callingThreadOnly.execute([&] { scene = loadScene(name); });
    return scene;
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

// One whole check as `zcheck check` runs it (its BVH built for one frame's rays, bvhBuildFor;
// tile by tile, keeping no per-pixel result; cold: as in a fresh `zcheck check` process),
// then, over a BVH built for many frames (the same one where that was the one-frame choice too),
// checks that keep both routes' full-frame renders, each after the kept buffers and the C
// library's free memory are given back but the last: the process's first ('first'), one more
// right after it (the phases the speed targets time: each route's whole image into new buffers,
// following a frame of its own as each of the yardsticks' cold repeats follows the one before),
// and that one again (warm: the memory the one before freed is reused, as in a program that
// checks many cameras or maps, and as the yardsticks' warm repeats run, over Embree's own
// thorough build). Where a host takes back the memory its guest freed, memory freed seconds
// before may cost more to touch than memory freed a moment before: the first frame and the cold
// one would differ by that (on docs/speed.md's machine they did not).
struct WholeCheck {
    struct FrameMs {  // a full-frame check's phases
        double trace, raster, compare;
    };
    BvhBuild build;                          // the whole check's
    double loadMs, bvhMs, tilesMs, wholeMs;  // tilesMs: the tile-by-tile pass of the whole check
    FrameMs first, cold, warm;               // the process's first full frame, the cold one, the warm one
    std::size_t triangles;
    bool consistent;
    double peakMiB;  // the child's maximum resident set, after the cold check
};

// `checker` as a program checking many frames builds it (BvhBuild::Thorough): itself where it
// was, else one over a copy of its scene. (A copy's arrays lie on huge pages, as a loaded
// scene's: on small pages the comparison's slopes, which read them all over, ran ~1.8× as long.)
void buildThorough(std::unique_ptr<const Checker>& checker)
{
    if (checker->rayRenderer().bvhBuild() == BvhBuild::Thorough) return;
    Scene scene = checker->scene();
    checker.reset();
    checker = std::make_unique<const Checker>(std::move(scene), BvhBuild::Thorough);
}

WholeCheck wholeCheckInChild(const std::string& sceneName, const Camera& camera, int threads)
{
    return inChild<WholeCheck>(threads, "the check (run `zcheck check` with the same scene and camera)", [&] {
        WholeCheck w{};
        const auto start = Clock::now();
        Scene scene = loadScene(sceneName);
        w.loadMs = millisecondsSince(start);
        w.build = bvhBuildFor(double(camera.width()) * camera.height(), scene.triangleCount());
        auto checker = std::make_unique<const Checker>(std::move(scene), w.build);
        {
            CheckOptions asTheCommand;
            asTheCommand.keepPixels = false;
            const CheckResult run = checker->check(camera, asTheCommand);
            w.wholeMs = millisecondsSince(start);
            w.bvhMs = run.report.timings.bvhBuildMs;
            w.tilesMs = run.report.timings.traceMs + run.report.timings.rasterMs + run.report.timings.compareMs;
            w.consistent = run.report.comparison.consistent();
        }
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        w.peakMiB = maxResidentMiB(usage);
        buildThorough(checker);  // the phases over the many-frame BVH
        // A full-frame check's phases, into (first, cold) new buffers or (warm) kept ones.
        const auto fullFrame = [&] {
            const CheckResult run = checker->check(camera);
            w.consistent = w.consistent && run.report.comparison.consistent();
            return WholeCheck::FrameMs{run.report.timings.traceMs, run.report.timings.rasterMs,
                                       run.report.timings.compareMs};
        };
        releaseCachedLargeBuffers();
        w.first = fullFrame();
        releaseCachedLargeBuffers();
        w.cold = fullFrame();
        w.warm = fullFrame();
        w.triangles = checker->scene().triangleCount();
        return w;
    }).first;
}

// A lens camera's own costs, in a child as the check's: its ray table built (once per
// intrinsics), every pixel's world ray made from it as the trace makes its lanes' (what each
// frame pays), the trace of the depth alone (the table built: the rays Embree's yardstick
// traces, and what a pinhole check's trace does; a lens check's trace also keeps every hit's
// eye point for its forward check), and a one-shot
// export of its distance map as `zcheck export` runs it (load, BVH, table, trace, the .npy
// written; its BVH built for one frame's rays, bvhBuildFor), then the same export warm (the
// table kept, the BVH built for many frames: the second frame of a dataset).
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
        auto checker = [&] {  // as `zcheck export` builds it: for one frame's rays
            Scene scene = loadScene(sceneName);
            const BvhBuild build = bvhBuildFor(double(camera.width()) * camera.height(), scene.triangleCount());
            return std::make_unique<const Checker>(std::move(scene), build);
        }();
        const auto tableStart = Clock::now();
        camera.lens()->directionAtPixel(0, 0);  // builds the table
        c.tableMs = millisecondsSince(tableStart);
        exportOnce(*checker, c.exportTraceMs, c.exportWriteMs);
        c.exportMs = millisecondsSince(start);
        buildThorough(checker);  // the rest over the many-frame BVH

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

        c.depthTraceMs = checker->renderRay(camera).renderMilliseconds;

        const auto warmStart = Clock::now();
        double traceMs = 0, writeMs = 0;
        exportOnce(*checker, traceMs, writeMs);
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
    std::string kernels = "auto";
    bool reference = false;
    bool json = false;
};

constexpr KernelForm kAllForms[] = {KernelForm::Baseline, KernelForm::Avx2, KernelForm::Avx512};

// The forms --kernels names, in its order: `auto` the one kernelForm() gives (ZCHECK_KERNELS or
// the processor; a bad ZCHECK_KERNELS throws its Error), `all` every form this processor has
// (baseline, avx2, avx512), else a comma-separated list of forms, each once and each one this
// processor has. Throws Error naming the value otherwise.
std::vector<KernelForm> kernelFormsOf(const std::string& kernels)
{
    if (kernels == "auto") return {kernelForm()};
    std::vector<KernelForm> forms;
    std::string supported;
    for (KernelForm form : kAllForms)
        if (kernelFormSupported(form)) forms.push_back(form), supported += (supported.empty() ? "" : ", ") + std::string(nameOf(form));
    if (kernels == "all") return forms;
    forms.clear();
    for (std::size_t begin = 0; begin <= kernels.size();) {
        const std::size_t end = std::min(kernels.find(',', begin), kernels.size());
        const std::string name = kernels.substr(begin, end - begin);
        begin = end + 1;
        const KernelForm* form = std::find_if(std::begin(kAllForms), std::end(kAllForms),
                                              [&](KernelForm f) { return name == nameOf(f); });
        if (form == std::end(kAllForms))
            throw Error("--kernels '" + kernels + "': '" + name + "' is not a kernel form: give auto, all, or a " +
                        "comma-separated list of baseline, avx2 and avx512");
        if (!kernelFormSupported(*form))
            throw Error("--kernels '" + kernels + "': this processor cannot run the " + name + " form; it has " + supported);
        if (std::find(forms.begin(), forms.end(), *form) != forms.end())
            throw Error("--kernels '" + kernels + "' names " + name + " twice: give each form once");
        forms.push_back(*form);
    }
    return forms;
}

// "avx2", or the forms joined as --kernels takes them: "baseline,avx2,avx512".
std::string namesOf(const std::vector<KernelForm>& forms)
{
    std::string names;
    for (KernelForm form : forms) names += (names.empty() ? "" : ",") + std::string(nameOf(form));
    return names;
}

// ZCHECK_KERNELS set to `form` for this object's lifetime (kernel_form.h: read when a renderer,
// frame or comparison is made, so a child forked meanwhile runs in that form), then restored as
// it was (unset if it was). setenv is not thread-safe: made and ended only where no other thread
// can read the environment (before TBB starts, or with its workers idle).
class KernelsEnvironment {
public:
    explicit KernelsEnvironment(KernelForm form)
    {
        if (const char* was = std::getenv("ZCHECK_KERNELS")) previous_ = was;
        setenv("ZCHECK_KERNELS", nameOf(form), 1);
    }
    ~KernelsEnvironment()
    {
        if (previous_) setenv("ZCHECK_KERNELS", previous_->c_str(), 1);
        else unsetenv("ZCHECK_KERNELS");
    }
    KernelsEnvironment(const KernelsEnvironment&) = delete;
    KernelsEnvironment& operator=(const KernelsEnvironment&) = delete;

private:
    std::optional<std::string> previous_;
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

// What every form's figures share: the scene and camera measured, and the memory budget.
struct BenchSetting {
    int threads;
    bool lens;         // a lens camera: no raster route, its own costs measured (LensCosts)
    bool isFile;       // the scene is a file (else built in), fileMB its size
    double fileMB;
    double pixels;
    double bytesPerPixel, budgetMiB;
    bool huge = false;  // terrain-10M-4K: its own targets, the whole check's seconds and memory
};

// One kernel form's measurements: every repeat's whole check (WholeCheck) and, for a lens
// camera, its own costs (LensCosts), each in a child that ran in this form.
struct FormPhases {
    KernelForm form = KernelForm::Baseline;
    BvhBuild build = BvhBuild::Thorough;  // the whole check's (WholeCheck)
    Phase load, bvh, tiles, firstTrace, firstRaster, firstCompare, trace, raster, compare, whole;
    Phase warmTrace, warmRaster, warmCompare;
    Phase rayTable, rays, depthTrace, exportOneShot, exportTrace, exportWrite, warmExport;
    std::size_t triangles = 0;
    bool consistent = true;  // every repeat's check
    double peakMiB = 0;      // the largest child's
};

// One more whole check into `f`, its child forked with ZCHECK_KERNELS = f's form.
void addWholeCheck(FormPhases& f, const std::string& sceneName, const Camera& camera, int threads)
{
    const WholeCheck w = [&] {
        const KernelsEnvironment inForm(f.form);
        return wholeCheckInChild(sceneName, camera, threads);
    }();
    f.build = w.build;
    f.load.ms.push_back(w.loadMs), f.bvh.ms.push_back(w.bvhMs), f.tiles.ms.push_back(w.tilesMs);
    f.whole.ms.push_back(w.wholeMs);
    const auto add = [](Phase& trace, Phase& raster, Phase& compare, const WholeCheck::FrameMs& frame) {
        trace.ms.push_back(frame.trace), raster.ms.push_back(frame.raster), compare.ms.push_back(frame.compare);
    };
    add(f.firstTrace, f.firstRaster, f.firstCompare, w.first);
    add(f.trace, f.raster, f.compare, w.cold);
    add(f.warmTrace, f.warmRaster, f.warmCompare, w.warm);
    f.triangles = w.triangles;
    f.consistent = f.consistent && w.consistent;
    f.peakMiB = std::max(f.peakMiB, w.peakMiB);
}

// One more measure of a lens camera's own costs into `f`, its child forked in f's form.
void addLensCosts(FormPhases& f, const std::string& sceneName, const Camera& camera, int threads)
{
    const LensCosts c = [&] {
        const KernelsEnvironment inForm(f.form);
        return lensCostsInChild(sceneName, camera, threads);
    }();
    f.rayTable.ms.push_back(c.tableMs), f.rays.ms.push_back(c.raysMs), f.exportOneShot.ms.push_back(c.exportMs);
    f.depthTrace.ms.push_back(c.depthTraceMs);
    f.exportTrace.ms.push_back(c.exportTraceMs), f.exportWrite.ms.push_back(c.exportWriteMs);
    f.warmExport.ms.push_back(c.warmExportMs);
}

// The yardsticks (--reference), measured once for every form: Embree's build and trace, and
// llvmpipe's draw, each with the share of pixels that agree with zcheck's route.
struct References {
    Phase embreeBuild, embreeTrace, glDraw;
    Phase embreeColdTrace, glColdDraw;  // the same into output memory never touched before
    std::string glRenderer, glSkipped;
    double glAgreement = NAN, embreeAgreement = NAN;
};

// The references: Embree's builds each in a child, as the check's are; its trace and
// llvmpipe's draws repeated in this process, warm (their own buffers reused, at their best,
// as the warm phases), then cold: each into output memory never touched before, after the
// kept buffers and the C library's free memory are given back, as before the cold phases (a
// new primitive-id buffer for Embree, a new depth buffer made and drawn for llvmpipe; their
// code, BVH, shaders and mesh stay warm, as zcheck's code and BVH do). The routes they are
// compared with run in `form` (every form draws the same pixels).
References measureReferences(const std::string& sceneName, const Camera& camera, int threads, int repeat, KernelForm form,
                             bool progress)
{
    References ref;
    const KernelsEnvironment inForm(form);  // before TBB starts here
    const bool lens = camera.lens() != nullptr;
    const Scene scene = loadSceneOnThisThread(sceneName);  // Embree's builds below fork
    if (progress) std::fprintf(stderr, "\rbench: Embree reference%20s", ""), std::fflush(stderr);
    // Embree's build, like the check's, in a fresh process each time: in this process
    // its repeats ran on memory earlier builds had faulted in (and varied 142-274 ms).
    for (int r = 0; r < repeat; ++r)
        ref.embreeBuild.ms.push_back(inChild<double>(threads, "Embree's reference build", [&] {
            return reference::EmbreeReference(scene).buildMilliseconds();
        }).first);
    const reference::EmbreeReference embree(scene);  // built here only to be traced
    std::vector<std::uint32_t> primitiveId;
    embree.trace(camera, primitiveId);  // warm-up
    for (int r = 0; r < repeat; ++r) ref.embreeTrace.ms.push_back(embree.trace(camera, primitiveId));
    for (int r = 0; r < repeat; ++r) {
        releaseCachedLargeBuffers();
        LargeVector<std::uint32_t> fresh;
        fresh.resize(primitiveId.size());  // uninitialised: the trace touches it first
        ref.embreeColdTrace.ms.push_back(embree.trace(camera, fresh.data()));
    }
    {  // The same rays? The primitive each pixel's ray hits, against the ray route's.
        const RenderResult traced = RayRenderer(scene).render(camera);
        std::size_t same = 0;
        for (std::size_t i = 0; i < primitiveId.size(); ++i) same += primitiveId[i] == traced.primitiveId[i];
        ref.embreeAgreement = double(same) / double(primitiveId.size());
    }
    if (progress) std::fprintf(stderr, "\rbench: llvmpipe reference%20s", ""), std::fflush(stderr);
    const reference::GlYardstickFunctions* gl = nullptr;
    if (lens) ref.glSkipped = "does not apply: a lens model has no projection matrix to draw through";
    else try {
        using Entry = const reference::GlYardstickFunctions* (*)();
        gl = reinterpret_cast<Entry>(pluginEntry("libzcheck_gl_yardstick.so", "zcheck_gl_yardstick"))();
    } catch (const std::runtime_error& e) {
        ref.glSkipped = std::string("its plugin is missing (built only where libegl-dev is installed): ") + e.what();
    }
    if (gl) {
        reference::GlDepthInput input;
        input.positions = &scene.positions[0].x;
        input.vertexCount = scene.positions.size();
        input.indices = &scene.triangles[0].x;
        input.triangleCount = scene.triangles.size();
        const CameraInSceneFrame local(scene, camera);  // the positions are the scene's frame
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k) input.clipFromWorld[std::size_t(4 * c + k)] = local.get().clipFromWorld[c][k];
        input.width = camera.width(), input.height = camera.height();
        input.reversedZ = camera.depth().reversed;
        input.zeroToOne = camera.convention().ndcZMin() == 0.0;
        input.threads = threads;
        try {
            const reference::GlDepthTiming drawn = gl->timeDraw(input, repeat);
            const RenderResult lastRaster = RasterRenderer(scene).render(camera);
            ref.glDraw.ms = drawn.drawMs;
            ref.glColdDraw.ms = drawn.coldDrawMs;
            ref.glRenderer = drawn.renderer;
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
            ref.glAgreement = drawn.depth.empty() ? NAN : double(same) / double(drawn.depth.size());
        } catch (const std::exception& e) {
            ref.glSkipped = e.what();
        }
    }
    if (progress) std::fprintf(stderr, "\r%50s\r", "");
    return ref;
}

// A form's ratios to the targets (docs/speed.md), against the references measured (none
// without --reference); every form has the same ones, in the same order. terrain-10M-4K's are
// its own two (the others, set for terrain-1M-1080p, would only read as missed there).
std::vector<Ratio> ratiosOf(const FormPhases& f, const BenchSetting& s, const References& ref)
{
    const bool lens = s.lens;
    std::vector<Ratio> ratios;
    if (s.huge)  // the one-shot huge mesh has targets of its own; the others are terrain-1M-1080p's
        return {{"whole-check-seconds", f.whole.median() / 1e3, 2.0, true},
                {"peak-rss-GB", f.peakMiB * 1024.0 * 1024.0 / 1e9, 1.4, true}};
    if (!lens) ratios.push_back({"compare/(trace+raster)", f.compare.median() / (f.trace.median() + f.raster.median()), 0.10, true});
    ratios.push_back({"peak-rss/budget", f.peakMiB / s.budgetMiB, 1.0, true});
    if (lens) {
        ratios.push_back({"rays/trace", f.rays.median() / f.depthTrace.median(), 0.10, true});
        ratios.push_back({"warm-export-seconds", f.warmExport.median() / 1e3, 0.5, true});
    }
    if (s.isFile) ratios.push_back({"load-MB/s", s.fileMB / (f.load.median() / 1e3), 150.0, false});
    // The phases into new buffers against the yardsticks' cold repeats (a lens's depth trace, a
    // repeat into kept buffers, against Embree's warm ones).
    if (!ref.glColdDraw.ms.empty()) ratios.push_back({"raster/llvmpipe", f.raster.median() / ref.glColdDraw.median(), 0.33, true});
    if (!ref.embreeTrace.ms.empty()) {
        ratios.push_back({"trace-throughput/embree",
                          lens ? ref.embreeTrace.median() / f.depthTrace.median() : ref.embreeColdTrace.median() / f.trace.median(),
                          lens ? 0.8 : 0.9, false});
        if (!lens)  // a new process's check against Embree's build (a child each) and its trace into new memory
            ratios.push_back({"whole/(load+embree-bvh+embree-trace)",
                              f.whole.median() / (f.load.median() + ref.embreeBuild.median() + ref.embreeColdTrace.median()),
                              1.3, true});
    }
    // The same targets for the warm repeat (see WholeCheck): like for like with the
    // yardsticks, which repeat on buffers they have touched before.
    if (!lens)
        ratios.push_back({"warm-compare/(trace+raster)", f.warmCompare.median() / (f.warmTrace.median() + f.warmRaster.median()),
                          0.10, true});
    if (!ref.glDraw.ms.empty()) ratios.push_back({"warm-raster/llvmpipe", f.warmRaster.median() / ref.glDraw.median(), 0.33, true});
    if (!ref.embreeTrace.ms.empty() && !lens)
        ratios.push_back({"warm-trace-throughput/embree", ref.embreeTrace.median() / f.warmTrace.median(), 0.9, false});
    return ratios;
}

nlohmann::ordered_json phaseJson(const Phase& p)
{
    return nlohmann::ordered_json{{"median_ms", p.median()}, {"best_ms", p.best()}, {"ms", p.ms}};
}

// A form's own keys in --json: consistent, its phases, rates, peak RSS and ratios.
nlohmann::ordered_json formJson(const FormPhases& f, const BenchSetting& s, const References& ref)
{
    nlohmann::ordered_json out;
    out["consistent"] = f.consistent;
    out["bvh_build"] = nameOf(f.build);  // the whole check's; the other phases' is thorough
    out["phases"] = {{"load", phaseJson(f.load)},     {"bvh", phaseJson(f.bvh)},         {"tiles", phaseJson(f.tiles)},
                     {"trace", phaseJson(f.trace)},
                     {"raster", phaseJson(f.raster)}, {"compare", phaseJson(f.compare)}, {"whole", phaseJson(f.whole)},
                     {"first_trace", phaseJson(f.firstTrace)}, {"first_raster", phaseJson(f.firstRaster)},
                     {"first_compare", phaseJson(f.firstCompare)},
                     {"warm_trace", phaseJson(f.warmTrace)}, {"warm_raster", phaseJson(f.warmRaster)},
                     {"warm_compare", phaseJson(f.warmCompare)}};
    if (s.lens)
        out["lens_phases"] = {{"ray_table", phaseJson(f.rayTable)},         {"rays", phaseJson(f.rays)},
                              {"depth_trace", phaseJson(f.depthTrace)},
                              {"export", phaseJson(f.exportOneShot)},       {"export_trace", phaseJson(f.exportTrace)},
                              {"export_write", phaseJson(f.exportWrite)},   {"warm_export", phaseJson(f.warmExport)}};
    out["mrays_per_s"] = s.pixels / f.trace.median() / 1e3;
    out["mtris_per_s"] = double(f.triangles) / f.raster.median() / 1e3;
    out["peak_rss_mib"] = f.peakMiB;
    if (s.isFile) out["load_mb_per_s"] = s.fileMB / (f.load.median() / 1e3);
    out["ratios"] = nlohmann::ordered_json::object();
    for (const Ratio& r : ratiosOf(f, s, ref))
        out["ratios"][r.name] = {{"value", r.value}, {"target", r.target}, {"bound", r.atMost ? "at most" : "at least"}, {"met", r.met()}};
    return out;
}

// A form's block of lines, from load to peak RSS.
void printPhases(const FormPhases& f, const BenchSetting& s)
{
    const bool lens = s.lens;
    const double pixels = s.pixels;
    printPhase("load", f.load, s.isFile ? rate(s.fileMB / (f.load.median() / 1e3), "MB/s") : "(built in)");
    char perTriangle[32];
    std::snprintf(perTriangle, sizeof perTriangle, "%.2f", pixels / double(f.triangles));
    printPhase("bvh build", f.bvh,
               std::string(nameOf(f.build)) + " (" + perTriangle + " rays per triangle; the phases below: thorough)");
    if (lens) printPhase("ray table", f.rayTable, rate(pixels / f.rayTable.median() / 1e3, "Mrays/s") + " (built once per intrinsics)");
    printPhase("trace", f.trace, rate(pixels / f.trace.median() / 1e3, "Mrays/s") + (lens ? " (the table built; eye points kept)" : ""));
    if (lens) {
        printPhase("depth trace", f.depthTrace, rate(pixels / f.depthTrace.median() / 1e3, "Mrays/s") + " (the depth alone)");
        printPhase("rays", f.rays, rate(pixels / f.rays.median() / 1e3, "Mrays/s") + " (every pixel's world ray from the table)");
        std::printf("%-24s does not apply: a lens model has no projection matrix to rasterize through\n", "raster");
        printPhase("lens check", f.compare, rate(pixels / f.compare.median() / 1e3, "Mpixels/s") + " (round trip and forward)");
    } else {
        printPhase("raster", f.raster, rate(double(f.triangles) / f.raster.median() / 1e3, "Mtris/s"));
        printPhase("compare", f.compare);
    }
    printPhase("first trace", f.firstTrace, "the process's first full frame, its buffers new as the cold one's (no target)");
    if (!lens) printPhase("first raster", f.firstRaster);
    printPhase(lens ? "first lens check" : "first compare", f.firstCompare);
    printPhase("whole check", f.whole, "as zcheck check: load + bvh + tile by tile");
    printPhase("tile by tile", f.tiles, "trace, raster and compare interleaved, nothing kept per pixel");
    printPhase("warm trace", f.warmTrace, rate(pixels / f.warmTrace.median() / 1e3, "Mrays/s (the check repeated)"));
    if (lens) {
        printPhase("warm lens check", f.warmCompare);
        printPhase("export", f.exportOneShot, "distance to .npy, one-shot: load + bvh + ray table + trace + write");
        printPhase("export trace", f.exportTrace);
        printPhase("export write", f.exportWrite);
        printPhase("warm export", f.warmExport, "trace + write again, the BVH and the ray table kept");
    } else {
        printPhase("warm raster", f.warmRaster, rate(double(f.triangles) / f.warmRaster.median() / 1e3, "Mtris/s"));
        printPhase("warm compare", f.warmCompare);
    }
    std::printf("%-24s %.1f MiB   budget %.1f MiB (150 B/triangle + %.0f B/pixel%s)\n", "peak RSS", f.peakMiB, s.budgetMiB,
                s.bytesPerPixel, lens ? ": 32, 24 for the ray table, 24 for the eye points" : "");
}

void printReferences(const References& ref, const BenchSetting& s)
{
    printPhase("reference embree-bvh", ref.embreeBuild);
    printPhase("reference embree-trace", ref.embreeTrace,
               rate(s.pixels / ref.embreeTrace.median() / 1e3, "Mrays/s") +
                   (s.lens ? " (rtcIntersect16, the rays from a table made before timing), " : " (rtcIntersect16), ") +
                   rate(100.0 * ref.embreeAgreement, "%") + " pixels hit the ray route's primitive");
    printPhase("reference embree-cold", ref.embreeColdTrace,
               rate(s.pixels / ref.embreeColdTrace.median() / 1e3, "Mrays/s") + " (the same into a new buffer)");
    if (!ref.glDraw.ms.empty()) {
        printPhase("reference llvmpipe", ref.glDraw, ref.glRenderer + ", LP_NUM_THREADS=" + std::to_string(s.threads) + ", " +
                                                         rate(100.0 * ref.glAgreement, "% pixels as zcheck's raster"));
        printPhase("reference llvmpipe-cold", ref.glColdDraw, "the same into a new depth buffer, made for the draw");
    } else
        std::printf("%-24s skipped: %s\n", "reference llvmpipe", ref.glSkipped.c_str());
}

// The ratios of several forms as a table, a column per form and a * after each value that
// misses its target: 'ratio  baseline  avx2  avx512  target', then '<name> <value>[*]... <bound>'.
void printRatioTable(const std::vector<FormPhases>& forms, const BenchSetting& s, const References& ref)
{
    std::vector<std::vector<Ratio>> ratios;
    for (const FormPhases& f : forms) ratios.push_back(ratiosOf(f, s, ref));
    std::printf("%-36s", "ratio");
    for (const FormPhases& f : forms) std::printf(" %9s ", nameOf(f.form));
    std::printf("  target\n");
    bool missed = false;
    for (std::size_t i = 0; i < ratios.front().size(); ++i) {
        std::printf("%-36s", ratios.front()[i].name.c_str());
        for (const std::vector<Ratio>& form : ratios) {
            std::printf(" %9.3f%c", form[i].value, form[i].met() ? ' ' : '*');
            missed = missed || !form[i].met();
        }
        std::printf("  %s %.2f\n", ratios.front()[i].atMost ? "<=" : ">=", ratios.front()[i].target);
    }
    std::printf("%s\n", missed ? "* NOT met: the value misses its target" : "every target met");
}

int runBenchCommand(const BenchOptions& o)
{
    const int threads = o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
    const bool progress = isatty(STDERR_FILENO) && !o.json;
    const bool workload = o.input.scene == kWorkloadScene && o.input.camera.reference.empty();
    const Workload* named = nullptr;
    for (const Workload& w : kWorkloads)
        if (o.workload == w.name) named = &w;
    if (!named) throw Error("--workload '" + o.workload + "' is not a named workload: terrain-1M-1080p, fisheye-1M-1080p, panorama-1M-1920x960 or terrain-10M-4K");
    if (o.workload != kWorkloads[0].name && !workload)
        throw Error("--workload " + o.workload + " names its own scene and camera: give it without --scene and --camera");
    const std::string sceneName = workload ? named->scene : o.input.scene;
    std::vector<FormPhases> forms;
    for (KernelForm form : kernelFormsOf(o.kernels)) forms.emplace_back().form = form;
    // Embree's set (ZCHECK_EMBREE_ISA), for the header: a bad value refused before any child runs;
    // auto with the set it runs, "auto (avx512)".
    const std::string embreeSet = embreeIsa();
    const std::string embreeRuns = embreeSet == "auto" ? embreeAutoIsa() : embreeSet;
    const std::string embreeNamed = embreeSet == "auto" && !embreeRuns.empty() ? "auto (" + embreeRuns + ")" : embreeSet;

    // The camera comes from a first load (a file is read once before timing: cold-cache
    // effects are not what this measures). TBB is not started before the children fork.
    CameraSpec spec;
    {
        Scene scene = loadSceneOnThisThread(sceneName);
        if (workload) scene.defaultCamera = named->camera();
        spec = cameraSpecFor(scene, o.input);
    }
    o.imageSize.apply(spec);
    const Camera camera(spec);
    const bool lens = camera.lens() != nullptr;
    const bool isFile = !isBuiltinSceneName(sceneName);
    const double fileMB = isFile ? double(std::filesystem::file_size(sceneName)) / 1e6 : 0.0;

    // The whole check, N times per form, each in a process of its own; the forms in turn within
    // each repeat, so that a slower spell of a shared machine falls on every form alike.
    const auto formSuffix = [&](const FormPhases& f) {
        return forms.size() > 1 ? std::string(" (") + nameOf(f.form) + ")" : std::string();
    };
    for (int r = 0; r < o.repeat; ++r)
        for (FormPhases& f : forms) {
            if (progress)
                std::fprintf(stderr, "\rbench: whole check %d/%d%s ", r + 1, o.repeat, formSuffix(f).c_str()), std::fflush(stderr);
            addWholeCheck(f, sceneName, camera, threads);
        }
    // A lens camera's own costs, as many times, likewise.
    for (int r = 0; lens && r < o.repeat; ++r)
        for (FormPhases& f : forms) {
            if (progress)
                std::fprintf(stderr, "\rbench: lens rays and export %d/%d%s ", r + 1, o.repeat, formSuffix(f).c_str()),
                    std::fflush(stderr);
            addLensCosts(f, sceneName, camera, threads);
        }
    if (progress) std::fprintf(stderr, "\r%50s\r", "");
    const std::size_t triangles = forms.front().triangles;
    const bool consistent = std::all_of(forms.begin(), forms.end(), [](const FormPhases& f) { return f.consistent; });
    BenchSetting s{threads, lens, isFile, fileMB, double(camera.width()) * camera.height(), 0, 0};
    s.huge = workload && named->scene == kHugeWorkloadScene;
    // A lens camera's check holds two arrays more, 24 bytes a pixel each: the ray table (lens.h)
    // and the trace's eye points, which its forward check projects.
    s.bytesPerPixel = lens ? 32.0 + 24.0 + 24.0 : 32.0;
    s.budgetMiB = (150.0 * double(triangles) + s.bytesPerPixel * s.pixels) / (1024.0 * 1024.0);

    const auto threadLimit = limitThreads(threads);
    References ref;
    if (o.reference) ref = measureReferences(sceneName, camera, threads, o.repeat, forms.front().form, progress);
    std::vector<KernelForm> formList;
    for (const FormPhases& f : forms) formList.push_back(f.form);

    if (o.json) {
        nlohmann::ordered_json out;
        out["scene"] = sceneName;
        if (workload) out["workload"] = o.workload;
        if (lens) out["lens"] = camera.lens()->spec().model;
        out["triangles"] = triangles;
        out["width"] = camera.width(), out["height"] = camera.height();
        out["threads"] = threads, out["repeat"] = o.repeat;
        out["kernels"] = namesOf(formList);
        out["embree_isa"] = embreeSet;
        out["embree_runs"] = embreeRuns;
        // The first form's keys, as with one form; "consistent" is every form's.
        const nlohmann::ordered_json first = formJson(forms.front(), s, ref);
        for (const auto& item : first.items()) out[item.key()] = item.value();
        out["consistent"] = consistent;
        out["memory_budget_mib"] = s.budgetMiB;
        if (o.reference) {
            auto& json = out["reference"];
            json["embree_bvh"] = phaseJson(ref.embreeBuild);
            json["embree_trace"] = phaseJson(ref.embreeTrace);
            json["embree_cold_trace"] = phaseJson(ref.embreeColdTrace);
            json["embree_mrays_per_s"] = s.pixels / ref.embreeTrace.median() / 1e3;
            json["embree_agreement"] = ref.embreeAgreement;
            if (!ref.glDraw.ms.empty()) {
                json["llvmpipe_draw"] = phaseJson(ref.glDraw);
                json["llvmpipe_cold_draw"] = phaseJson(ref.glColdDraw);
                json["llvmpipe_renderer"] = ref.glRenderer;
                json["llvmpipe_agreement"] = ref.glAgreement;
            } else {
                json["llvmpipe_skipped"] = ref.glSkipped;
            }
        }
        if (forms.size() > 1)
            for (const FormPhases& f : forms) out["forms"][nameOf(f.form)] = formJson(f, s, ref);
        std::cout << out.dump(2) << "\n";
        return kExitConsistent;
    }

    const std::string depth = lens ? "lens model " + camera.lens()->spec().model + ", distance"
                                   : toString(camera.depth().format) + (camera.depth().reversed ? " reversed-Z" : "");
    std::printf("zcheck bench: %s%s, %zu triangles, %dx%d, %s, kernels %s, embree %s, %d threads, %d repeats, %s\n",
                workload ? (o.workload + ": ").c_str() : "", sceneName.c_str(), triangles, camera.width(), camera.height(),
                depth.c_str(), namesOf(formList).c_str(), embreeNamed.c_str(), threads, o.repeat,
                consistent ? "consistent" : "INCONSISTENT");
    for (const FormPhases& f : forms) {
        if (forms.size() > 1) std::printf("kernels %s\n", nameOf(f.form));
        printPhases(f, s);
    }
    if (o.reference) printReferences(ref, s);
    if (forms.size() > 1) {
        printRatioTable(forms, s, ref);
        return kExitConsistent;
    }
    for (const Ratio& r : ratiosOf(forms.front(), s, ref))
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
    command->add_option("--kernels", o->kernels,
                        "the kernel forms to time: auto (the one ZCHECK_KERNELS or the processor gives), all\n"
                        "(every form this processor has), or a comma-separated list of baseline, avx2, avx512")
        ->capture_default_str();
    command->add_flag("--reference", o->reference,
                      "also time Embree's own BVH build and best packet trace (rtcIntersect16, 8x8 tiles) and\n"
                      "a depth-only OpenGL draw on Mesa llvmpipe through EGL, and print the ratios to the targets");
    command->add_flag("--json", o->json, "print the measurements as JSON");
    command->add_option("--workload", o->workload,
                        "a named workload, without --scene and --camera: terrain-1M-1080p, fisheye-1M-1080p,\n"
                        "panorama-1M-1920x960, terrain-10M-4K")
        ->capture_default_str();
    command->footer(
        "Without --scene and --camera the workload is terrain-1M-1080p: builtin:terrain?n=709&size=2\n"
        "(1,002,528 triangles) at 1920x1080, unorm24, OpenGL perspective fovy 60, near 0.01, far 10,\n"
        "eye (0, 0.6, -0.15) looking at the origin: every pixel covered. --workload fisheye-1M-1080p:\n"
        "the same terrain through an OpenCV fisheye (opencv_fisheye fx = fy = 340, k1..k4 0.021,\n"
        "-0.004, 0.0007, -0.0001) at 1920x1080 from (0, 0.2, 0) looking straight down, its 180° circle as\n"
        "high as the image; panorama-1M-1920x960: a whole-sphere equirectangular panorama at\n"
        "1920x960 from (0, 0.2, 0), the sky half missing; terrain-10M-4K: builtin:terrain?n=2237&size=2\n"
        "(9,999,392 triangles) seen as terrain-1M-1080p at 3840x2160, 0.83 rays per triangle (its\n"
        "targets, the only ratios it prints: whole check <= 2 s, peak RSS <= 1.4 GB). For a lens\n"
        "camera there is no raster route:\n"
        "'compare' is the lens check (every pixel's round trip, every hit projected forward), and\n"
        "bench also times the ray table's build, every pixel's world ray made from it (rays: what\n"
        "each frame pays, target <= 10 % of the depth trace), the trace of the depth alone (the\n"
        "check's trace also keeps every hit's eye point for its forward check), and an export of the\n"
        "distance map to .npy, one-shot and warm (target <= 0.5 s); --reference times Embree on the\n"
        "same rays (target: the depth trace >= 0.8x its throughput).\n"
        "Each repeat is a whole check in a child process of its own, as `zcheck check` runs it: the\n"
        "scene is loaded, the BVH built for one frame's rays (quick below 10 rays per triangle,\n"
        "else thorough), both routes drawn and compared tile by tile ('whole check').\n"
        "The child then checks over a thorough BVH (as for many frames; Embree's reference is built so\n"
        "too), keeping both routes' full-frame renders: its first full frame ('first', no target), then\n"
        "the kept buffers and the C library's free memory given back as before each of the yardsticks'\n"
        "cold repeats, a frame whose trace, raster and compare are the phases timed (their buffers\n"
        "new), and once more ('warm': memory the check before freed is reused, as when a program\n"
        "checks many cameras). The first frame's buffers are new too (the same giving back before it).\n"
        "Peak RSS is the largest child's, after the first check. Embree's reference builds run in\n"
        "children too; its trace and llvmpipe's draws repeat in this process (llvmpipe's from the\n"
        "plugin libzcheck_gl_yardstick.so, loaded only here), into the buffers they used before, then\n"
        "each into output memory never touched ('-cold': a new buffer, llvmpipe's made in the timing):\n"
        "the phases' ratios take the cold ones, the warm phases' the warm ones. Lines are\n"
        "'<phase> median <ms> ms best <ms> ms <rate>' and 'ratio <name> <value> target <bound>'.\n"
        "The header names the kernel forms timed (--kernels; each bit-identical to the baseline's, only\n"
        "speed differs): every child runs with ZCHECK_KERNELS set to its form. With several forms they\n"
        "take turns within each repeat (their medians paired on a busy machine), each form's phases\n"
        "follow a line 'kernels <form>', the references are measured once for all, and the ratios make\n"
        "a table, a column per form, '*' after a value that misses its target. 'embree' names the\n"
        "instruction set of Embree's own kernels, in the check's trace and the yardstick alike: auto, the\n"
        "widest the processor has (named after it), unless ZCHECK_EMBREE_ISA forces one; ZCHECK_EMBREE_ISA=avx2 with\n"
        "--kernels avx2 measures on an AVX-512 machine what an AVX2-only one runs.\n"
        "Examples:\n"
        "  zcheck bench --reference                         terrain-1M-1080p, with both references\n"
        "  zcheck bench --kernels all --reference           the same, every form this processor has\n"
        "  ZCHECK_EMBREE_ISA=avx2 zcheck bench --kernels avx2 --reference   as on an AVX2-only processor\n"
        "  zcheck bench --scene terrain.obj --camera cam.json --threads 1 --json\n"
        "  zcheck bench --scene 'builtin:terrain?n=1416&size=2' --width 3840 --height 2160");
    return {command, [o] { return runBenchCommand(*o); }};
}

}  // namespace zcheck::cli
