// zcheck verify: a depth map rendered elsewhere against the ground truth, and its diagnosis.
#include "common.h"
#include "image_plugin.h"
#include "run_folder.h"

#include "zcheck/mesh_loader.h"
#include "zcheck/report.h"
#include "zcheck/verify_map.h"

#include <iostream>

namespace zcheck::cli {

namespace {

struct VerifyOptions {
    SceneAndCamera input;
    std::string depthMap, quantity, outDir;  // quantity "": the sidecar's, else window
    DepthMapOptions reading;
    bool diagnose = false, json = false;
    int threads = 0;
};

int runVerifyCommand(const VerifyOptions& o)
{
    SceneAndCamera input = o.input;
    std::string quantityName = o.quantity;
    const std::string compareWith = takeFromSidecar(o.reading, input.camera, quantityName);
    const DepthQuantity quantity = depthQuantityFromName(quantityName);
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;
    outputs.addInput(input.scene);
    outputs.addInput(cameraInputPath(input.camera));
    outputs.addInput(o.depthMap);
    outputs.addInput(o.reading.sidecar);
    const RunFolder folder{o.outDir, "map_depth.exr", true};
    if (!o.outDir.empty()) folder.plan(outputs);
    Scene scene = loadScene(o.input.scene);
    const DepthMapReading reading = o.reading.reading(quantityName);
    CameraForMap made = cameraAndMapFor(&scene, input, quantity, [&](int width, int height) {
        return readDepthMapFile(o.depthMap, reading, width, height);
    });
    requireSidecarCameraAgrees(made.spec, input.camera, compareWith, quantity);
    const Camera camera(made.spec);
    DepthMapFile& file = made.map;
    const DepthMap map = DepthMap::of(file, quantity, reading);
    // One frame's rays, or (--diagnose) one per hypothesis tried: the BVH built for them (ray_renderer.h).
    const BvhBuild build = o.diagnose ? BvhBuild::Thorough
                                      : bvhBuildFor(double(camera.width()) * camera.height(), scene.triangleCount());
    const Checker checker(std::move(scene), build);
    const MapVerifier verifier(checker);
    const DepthMapSource source{o.depthMap, quantityName, file.channel, reading};
    const VerifiedMap verified = verifyMap(verifier, camera, map, o.diagnose, source.name());
    const VerificationReport report = formatVerification(verified, source);
    const VerifyResult& run = verified.run;
    if (!o.outDir.empty()) {
        folder.write(outputs, run.truth, run.map, run.comparison, report.json, run.mapError);
        outputs.commit();
    }
    std::cout << (o.json ? report.json : report.summary) << (o.json ? "\n" : "");
    return run.comparison.report.consistent() ? kExitConsistent : kExitInconsistent;
}

}  // namespace

Command addVerifyCommand(CLI::App& app)
{
    auto o = std::make_shared<VerifyOptions>();
    CLI::App* command = app.add_subcommand(
        "verify", "Compare a depth map rendered elsewhere (a GPU, an engine, Blender, a simulator) against Embree's\n"
                  "ground truth for the same scene and camera, with the same tolerance model, report and exit codes\n"
                  "as check; --diagnose names the classic mistake that explains an inconsistent map.");
    addSceneAndCameraOptions(command, o->input);
    command->add_option("--depth-map", o->depthMap, "the depth map: any format `zcheck formats` lists, told by its first bytes (integers need --scale)")
        ->required()
        ->check(kNonEmptyPath);
    command->add_option("--quantity", o->quantity,
                        "what the map holds: window | ndc | eye-z | distance (default: as zcheck's export sidecar\n"
                        "given with --sidecar says, else window)");
    addDepthMapOptions(command, o->reading);
    command->add_flag("--diagnose", o->diagnose, "when inconsistent, test the classic hypotheses and name the one that fits");
    command->add_option("--out", o->outDir, "write ray_depth.exr, map_depth.exr, map_error.exr, error_heatmap.png, coverage_classes.png and "
                        "report.json into this folder (all or none of them)")->type_name("DIR")
        ->check(kNonEmptyPath);
    addThreadsOption(command, o->threads);
    command->add_flag("--json", o->json, "print the report as JSON");

    return {command, [o] { return runVerifyCommand(*o); }};
}

}  // namespace zcheck::cli
