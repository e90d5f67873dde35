// zcheck check: one scene through one camera, ray route vs raster route, per pixel.
#include "common.h"
#include "run_folder.h"

#include "zcheck/mesh_loader.h"
#include "zcheck/report.h"

#include <iostream>

namespace zcheck::cli {

namespace {

struct CheckCommandOptions {
    SceneAndCamera input;
    ImageSize imageSize;
    std::string depthFormat;
    bool reversedZ = false;
    std::string outDir;
    bool json = false;
    int threads = 0;
};

int runCheckCommand(const CheckCommandOptions& o)
{
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;
    outputs.addInput(o.input.scene);
    outputs.addInput(cameraInputPath(o.input.camera));
    const RunFolder folder{o.outDir, "raster_depth.exr"};
    if (!o.outDir.empty()) folder.plan(outputs);
    Scene scene = loadScene(o.input.scene);
    CameraSpec spec = cameraSpecFor(scene, o.input);
    o.imageSize.apply(spec);
    if (!o.depthFormat.empty()) spec.depth.format = depthFormatFromName(o.depthFormat);
    if (o.reversedZ) spec.depth.reversed = true;
    const Camera camera(spec);  // validated before the BVH is built

    // One frame's rays: a huge mesh is checked soonest over a BVH built quickly (ray_renderer.h).
    const BvhBuild build = bvhBuildFor(double(camera.width()) * camera.height(), scene.triangleCount());
    const Checker checker(std::move(scene), build);
    CheckOptions options;
    options.keepPixels = !o.outDir.empty();  // pictures and maps need them; the report does not
    const CheckResult run = checker.check(camera, options);
    requireSomethingCompared(run.report.comparison, checker.scene().name);
    const std::string reportJson = checkReportJson(run.report);
    if (!o.outDir.empty()) {
        folder.write(outputs, run.ray, run.raster, run.comparison, reportJson);
        outputs.commit();
    }
    std::cout << (o.json ? reportJson + "\n" : formatSummary(run.report));
    return run.report.comparison.consistent() ? kExitConsistent : kExitInconsistent;
}

}  // namespace

Command addCheckCommand(CLI::App& app)
{
    auto o = std::make_shared<CheckCommandOptions>();
    CLI::App* command = app.add_subcommand(
        "check", "Check one scene through one camera: ray route vs raster route, per pixel.\n"
                 "Exit status 0 consistent, 1 inconsistent, 2 usage or input error.");
    addSceneAndCameraOptions(command, o->input);
    addImageSizeOptions(command, o->imageSize);
    command->add_option("--depth-format", o->depthFormat, "override the depth format: float32 | unorm24 | unorm16");
    command->add_flag("--reversed-z", o->reversedZ, "use reversed-Z (near -> far end of the range, test GREATER)");
    command->add_option("--out", o->outDir,
                        "write ray_depth.exr, raster_depth.exr, error_heatmap.png, coverage_classes.png "
                        "and report.json into this folder (all or none of them)")->type_name("DIR")
        ->check(kNonEmptyPath);
    command->add_flag("--json", o->json, "print the report as JSON instead of the summary");
    command->footer(
        "Examples:\n"
        "  zcheck check                                      the built-in default scene, its own camera\n"
        "  zcheck check --scene bunny.obj --convention direct3d --reversed-z --depth-format unorm24\n"
        "  zcheck check --camera examples/frustum.json --out results/   camera file; images + report.json\n"
        "  zcheck check --scene 'builtin:terrain?n=708' --width 1920 --height 1080 --json\n"
        "Depths are compared as window depth (the depth-buffer value) per pixel; the tolerance is\n"
        "C*q + S*m (q: storage quantum, m: depth slope per pixel, S = 2^-8 px). See docs/tolerance.md.");
    addThreadsOption(command, o->threads);
    return {command, [o] { return runCheckCommand(*o); }};
}

}  // namespace zcheck::cli
