// zcheck remap: a depth map moved exactly to another camera with the same centre of projection
// (remap.h) — fisheye to pinhole, distorted to undistorted, pinhole to equirectangular — and, with
// --scene, compared with the target camera's own render of the mesh.
#include "common.h"
#include "image_plugin.h"

#include "zcheck/atomic_file.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/detail/json.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/remap.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

namespace zcheck::cli {

namespace {

struct RemapOptions {
    CameraOptions from, to;
    std::string depthMap, quantity, toQuantity, output, sampling = "plane", scene;
    DepthMapOptions reading;
    double scale = 0;
    std::optional<double> undistort;  // alpha: the target is the source lens undistorted (remap.h)
};

// What the remapped map is against the target camera's own render: |remapped − rendered| over the
// pixels both hold a depth, and the pixels only one of them does.
nlohmann::json comparisonWithRender(const std::vector<double>& remapped, const QuantityImage& rendered,
                                    const std::string& scene)
{
    std::vector<double> absolute, relative;
    std::size_t remappedOnly = 0, renderedOnly = 0;
    double worst = -1;
    std::size_t worstPixel = 0;
    for (std::size_t i = 0; i < remapped.size(); ++i) {
        const bool mine = std::isfinite(remapped[i]), theirs = !rendered.isMiss(i) && std::isfinite(rendered.value[i]);
        remappedOnly += mine && !theirs, renderedOnly += theirs && !mine;
        if (!mine || !theirs) continue;
        const double error = std::abs(remapped[i] - rendered.value[i]);
        absolute.push_back(error), relative.push_back(error / std::abs(rendered.value[i]));
        if (error > worst) worst = error, worstPixel = i;
    }
    auto quantile = [](std::vector<double> v, double q) {
        if (v.empty()) return 0.0;
        const std::size_t k = std::min(v.size() - 1, std::size_t(std::ceil(q * double(v.size()))) - (q > 0 ? 1 : 0));
        std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
        return v[k];
    };
    return {{"scene", scene},
            {"compared", absolute.size()},
            {"remapped_only", remappedOnly},
            {"rendered_only", renderedOnly},
            {"abs_error", {{"max", quantile(absolute, 1.0)}, {"p99", quantile(absolute, 0.99)}, {"median", quantile(absolute, 0.5)}}},
            {"rel_error", {{"max", quantile(relative, 1.0)}, {"p99", quantile(relative, 0.99)}, {"median", quantile(relative, 0.5)}}},
            {"worst_pixel", {int(worstPixel % std::size_t(rendered.width)), int(worstPixel / std::size_t(rendered.width))}}};
}

int runRemapCommand(const RemapOptions& o)
{
    if (o.output.empty()) throw Error("remap needs -o FILE (.exr, .pfm, .npy, .tif, or .png with --out-scale)");
    if (o.depthMap.empty()) throw Error("remap needs --depth-map FILE, the map to move");
    if (o.to.reference.empty() == !o.undistort)
        throw Error("remap needs one of --to-camera FILE (the camera to move the map to) and --undistort ALPHA");
    const RemapSampling sampling = remapSamplingFromName(o.sampling, "--sampling");
    CameraOptions fromOptions = o.from;
    std::string quantityName = o.quantity;
    const std::string compareWith = takeFromSidecar(o.reading, fromOptions, quantityName);
    if (fromOptions.reference.empty())
        throw Error("remap needs --camera FILE, the camera the map was made with (or the --sidecar zcheck's export wrote)");
    const DepthQuantity quantity = depthQuantityFromName(quantityName);
    const DepthQuantity toQuantity = depthQuantityFromName(o.toQuantity.empty() ? quantityName : o.toQuantity);
    OutputFiles outputs;
    outputs.addInput(cameraInputPath(fromOptions));
    if (!o.to.reference.empty()) outputs.addInput(cameraInputPath(o.to));
    outputs.addInput(o.depthMap);
    outputs.addInput(o.reading.sidecar);
    if (!o.scene.empty()) outputs.addInput(o.scene);
    outputs.add(o.output, "-o");
    outputs.add(o.output + ".json", "the sidecar of -o");

    SceneAndCamera input;
    input.camera = fromOptions;
    CameraForMap made = cameraAndMapFor(nullptr, input, quantity, [&](int width, int height) {
        return readDepthMapFile(o.depthMap, o.reading.reading(quantityName), width, height);
    });
    requireSidecarCameraAgrees(made.spec, fromOptions, compareWith, quantity);
    const Camera from(made.spec);
    // The target's near and far: its file's or the options', else the source's (they matter only
    // to a window or ndc target).
    CameraOptions toOptions = o.to;
    if (!toOptions.near) toOptions.near = from.nearDistance();
    if (!toOptions.far) toOptions.far = from.farDistance();
    const Camera to(o.undistort ? undistortedCameraSpec(from, *o.undistort) : cameraSpecFrom(toOptions));
    for (const Camera* camera : {&from, &to})
        if (!camera->lens() && !camera->spec().projection.isPerspective())
            throw Error("remap needs cameras with a centre of projection; a " + toString(camera->spec().projection.type) +
                        " projection's rays are parallel");

    const RemappedMap remapped = remapDepthMap(from, made.map.value, quantity, to, toQuantity, sampling);
    QuantityImage image = quantityImageShape(to, exportQuantityOf(toQuantity));
    image.value = remapped.values;
    std::string format;
    outputs.write(o.output, [&](const std::string& temporary) { format = writeDepthMapFile(temporary, {image}, o.scale); });

    nlohmann::json summary = {{"output", o.output},
                              {"sidecar", o.output + ".json"},
                              {"quantity", toString(toQuantity)},
                              {"sampling", o.sampling},
                              {"pixels", remapped.values.size()},
                              {"unseen", remapped.unseen},
                              {"misses", remapped.misses}};
    if (sampling == RemapSampling::Plane) summary["nearest_at_edges"] = remapped.nearestAtEdges;
    if (!o.scene.empty()) {
        Scene scene = loadScene(o.scene);
        const BvhBuild build = bvhBuildFor(double(to.width()) * to.height(), scene.triangleCount());  // one render
        const Checker checker(std::move(scene), build);
        summary["against_render"] = comparisonWithRender(remapped.values, checker.render(to, image.quantity, Route::Ray), o.scene);
    }
    nlohmann::json sidecar = depthFileSidecar(o.output, format, to, {image}, o.scale);
    sidecar["remapped_from"] = {{"depth_map", o.depthMap}, {"quantity", quantityName}, {"camera", toJson(from.spec())},
                                {"sampling", o.sampling}};
    outputs.writeText(o.output + ".json", prettyJson(sidecar) + "\n");
    outputs.commit();
    std::cout << prettyJson(summary) << "\n";
    return kExitConsistent;
}

}  // namespace

Command addRemapCommand(CLI::App& app)
{
    auto o = std::make_shared<RemapOptions>();
    CLI::App* command = app.add_subcommand(
        "remap", "Move a depth map to another camera with the same centre of projection (fisheye to pinhole,\n"
                 "distorted to undistorted, pinhole to equirectangular, a turned view): each target pixel's ray\n"
                 "is projected exactly into the source image, sampled without interpolating across a depth edge,\n"
                 "and its quantity converted per ray. With --scene, also compared with the target's own render.");
    addCameraOptions(command, o->from, cameraFileHelp("the camera the map was made with"));
    command->add_option("--depth-map", o->depthMap, "the map to move (any format `zcheck formats` lists)")->check(kNonEmptyPath);
    command->add_option("--quantity", o->quantity,
                        "what the map holds: eye-z | distance | window | ndc (default: its --sidecar's, else window)");
    addDepthMapOptions(command, o->reading);
    command->add_option("--to-camera", o->to.reference, "FILE[#FRAME]: the camera to move the map to (any camera format)")
        ->check(kNonEmptyPath);
    command->add_option("--undistort", o->undistort,
                        "ALPHA in [0, 1]: the target is the source lens undistorted to a pinhole of the same size, its\n"
                        "K as OpenCV's getOptimalNewCameraMatrix chooses it (0: only pixels every edge sees; 1: all)");
    command->add_option("--to-camera-format", o->to.format, "the target camera file's format, when its content should not decide");
    command->add_option("--to-quantity", o->toQuantity, "what the new map holds (default: --quantity)");
    command->add_option("--sampling", o->sampling,
                        "plane: where the 2x2 samples around the point lie on one plane, the target ray meets it\n"
                        "(exact on facets), else nearest; nearest: the sample the point falls in")
        ->capture_default_str();
    command->add_option("-o,--output", o->output, "the new map, in its extension's format (written atomically, with FILE.json)")
        ->type_name("FILE")->check(kNonEmptyPath);
    command->add_option("--out-scale", o->scale, "a 16-bit PNG -o: stored = value x out-scale (e.g. 1000 = millimetres)")
        ->check(kPositiveFinite);
    command->add_option("--scene", o->scene, "a mesh (or builtin:NAME): also render the target camera's map from it and\n"
                                             "report how far the moved map lies from it");
    return {command, [o] { return runRemapCommand(*o); }};
}

}  // namespace zcheck::cli
