// zcheck unproject: the inverse projection — a pixel's ray, the point at a depth value, or a
// whole depth map as a PLY point cloud.
#include "common.h"
#include "image_plugin.h"

#include "zcheck/atomic_file.h"
#include "zcheck/detail/json.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/point_cloud.h"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

namespace zcheck::cli {

namespace {

struct UnprojectOptions {
    CameraOptions camera;
    std::string pixel, depthMap, quantity, output, space = "world";  // quantity "": the sidecar's, else window
    std::optional<double> depth;
    DepthMapOptions reading;
    int stride = 1;
    bool ascii = false;
};

glm::ivec2 parsePixel(const std::string& text, const Camera& camera)
{
    const std::vector<double> v = parseNumberList(text, "--pixel");
    if (v.size() != 2 || v[0] != std::floor(v[0]) || v[1] != std::floor(v[1]))
        throw Error("--pixel: expected COL,ROW as two whole numbers, got '" + text + "'");
    return pixelInImage(camera, v[0], v[1], "--pixel " + text);
}

nlohmann::json vec3Json(const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

int runUnprojectCommand(const UnprojectOptions& o)
{
    const PointSpace space = pointSpaceFromName(o.space, "--space");
    CameraOptions cameraOptions = o.camera;
    std::string quantityName = o.quantity;
    const std::string compareWith = takeFromSidecar(o.reading, cameraOptions, quantityName);
    const DepthQuantity quantity = depthQuantityFromName(quantityName);
    if (cameraOptions.reference.empty())
        throw Error("unproject needs --camera FILE (or the --sidecar zcheck's export wrote, which names the camera)");
    // With a map: the camera and the map made together (a camera file without an image size takes
    // the map's; near and far, when the file has none, cover the map's depths).
    std::optional<DepthMapFile> sized;
    CameraSpec spec;
    if (!o.depthMap.empty()) {
        SceneAndCamera input;
        input.camera = cameraOptions;
        CameraForMap made = cameraAndMapFor(nullptr, input, quantity, [&](int width, int height) {
            return readDepthMapFile(o.depthMap, o.reading.reading(quantityName), width, height);
        });
        requireSidecarCameraAgrees(made.spec, cameraOptions, compareWith, quantity);
        spec = made.spec;
        sized = std::move(made.map);
    } else {
        // One eye-z or distance value needs no near and far: a camera file without them takes
        // planes around it (eye-z ≤ distance, so a distance's eye-z lies below it).
        std::optional<std::pair<double, double>> eyeZRange;
        if (o.depth && *o.depth > 0 && std::isfinite(*o.depth)) {
            if (quantity == DepthQuantity::EyeZ) eyeZRange = std::pair{*o.depth, *o.depth};
            if (quantity == DepthQuantity::Distance) eyeZRange = std::pair{*o.depth * 1e-3, *o.depth};
        }
        spec = cameraSpecFrom(cameraOptions, {}, eyeZRange);
    }
    const Camera camera(spec);

    if (!o.pixel.empty() && (!o.depthMap.empty() || !o.output.empty()))
        throw Error("--pixel and --depth-map/-o are alternatives: one pixel's ray or point, or a whole map as a point cloud");
    if (o.pixel.empty() && o.depth)
        throw Error("--depth " + formatNumber(*o.depth) + " needs --pixel COL,ROW (a --depth-map holds its own depths)");
    if (!o.pixel.empty()) {
        const glm::ivec2 pixel = parsePixel(o.pixel, camera);
        const glm::dvec2 pWindow = windowFromPixelCentre(camera, pixel.x, pixel.y);
        nlohmann::json out = {{"pixel", {pixel.x, pixel.y}}, {"window", {pWindow.x, pWindow.y}}};
        requireRayThroughWindow(camera, pWindow);
        if (!o.depth) {
            const EyePlaneRay rayEye = eyePlaneRayThroughWindow(camera, pWindow);
            const EyePlaneRay rayWorld = worldEyePlaneRayThroughWindow(camera, pWindow);
            auto rayJson = [](const EyePlaneRay& r) {
                return nlohmann::json{{"origin", vec3Json(r.origin)},
                                      {"direction", vec3Json(r.direction)},
                                      {"t_near", r.tNear},
                                      {"t_far", std::isinf(r.tFar) ? nlohmann::json("inf") : nlohmann::json(r.tFar)}};
            };
            out["ray"] = {{"definition", "points origin + t·direction, t in [t_near, t_far] between the near and far "
                                         "planes; origin on the eye plane (the centre of projection for perspective)"}};
            if (o.space == "eye") out["ray"]["eye"] = rayJson(rayEye);
            out["ray"]["world"] = rayJson(rayWorld);
            out["ray"]["eye"] = rayJson(rayEye);
        } else {
            const PointAtDepth point = pointAtDepth(camera, pWindow, *o.depth, quantity, "--depth");
            out["point"] = {{"eye", vec3Json(point.pEye)}, {"world", vec3Json(point.pWorld)},
                            {"eye_z", point.eyeZ}, {"distance", point.distance}};
        }
        std::cout << prettyJson(out) << "\n";
        return kExitConsistent;
    }

    if (o.depthMap.empty()) throw Error("unproject needs --pixel COL,ROW or --depth-map FILE");
    if (o.output.empty()) throw Error("--depth-map needs -o FILE.ply");
    OutputFiles outputs;
    outputs.addInput(cameraInputPath(cameraOptions));
    outputs.addInput(o.depthMap);
    outputs.addInput(o.reading.sidecar);
    outputs.add(o.output, "-o");
    const DepthMapFile map =
        sized ? std::move(*sized) : readDepthMapFile(o.depthMap, o.reading.reading(quantityName), camera.width(), camera.height());
    const UnprojectedMap cloud =
        unprojectMap(camera, map.value, quantity, space, o.stride);
    std::string outOfRange;  // values the quantity cannot hold: never dropped silently
    if (cloud.outOfRange > 0) {
        const glm::ivec2 at = cloud.firstOutOfRange;
        outOfRange = std::to_string(cloud.outOfRange) + " value" + (cloud.outOfRange == 1 ? "" : "s") + " of '" +
                     o.depthMap + "' lie outside what a " + quantityName + " map holds, " +
                     depthValueRange(camera, quantity) + " (e.g. " +
                     formatNumber(map.value[std::size_t(at.y) * camera.width() + at.x]) + " at pixel (" +
                     std::to_string(at.x) + ", " + std::to_string(at.y) + "))";
        if (cloud.points.empty()) throw Error(outOfRange + ", and the rest are misses: is --quantity right?");
    }
    outputs.write(o.output, [&](const std::string& temporary) {
        writePointCloudPly(temporary, cloud.points, !o.ascii,
                           {"zcheck unproject of " + std::filesystem::path(o.depthMap).filename().string() + " (" +
                                quantityName + ", channel " + map.channel + ")",
                            std::string("space ") + o.space +
                                (o.space == "eye" ? " (" + camera.convention().name + " eye axes)" : "")});
    });
    outputs.commit();
    if (!outOfRange.empty()) std::cerr << "zcheck: warning: " << outOfRange << ": no point written for them\n";
    std::cout << prettyJson({{"points", cloud.points.size()}, {"misses", cloud.misses},
                             {"out_of_range", cloud.outOfRange}, {"channel", map.channel},
                             {"quantity", quantityName}, {"space", o.space}, {"output", o.output}})
              << "\n";
    return kExitConsistent;
}

}  // namespace

Command addUnprojectCommand(CLI::App& app)
{
    auto o = std::make_shared<UnprojectOptions>();
    CLI::App* command = app.add_subcommand(
        "unproject", "The inverse projection: the ray through a pixel centre, the point at a depth value, or a\n"
                     "whole depth map (EXR, PFM, TIFF, 16-bit PNG with --scale) as a PLY point cloud, misses skipped.");
    addCameraOptions(command, o->camera, cameraFileHelp());
    command->add_option("--pixel", o->pixel, "COL,ROW (row 0 at the top): print the ray through its centre");
    command->add_option("--depth", o->depth, "with --pixel: print the point at this depth value");
    command->add_option("--quantity", o->quantity,
                        "what --depth / the map holds: window | ndc | eye-z | distance (default: as zcheck's export\n"
                        "sidecar given with --sidecar says, else window)");
    command->add_option("--depth-map", o->depthMap, "a depth map to turn into a point cloud (any format `zcheck formats` lists)")->check(kNonEmptyPath);
    addDepthMapOptions(command, o->reading);
    command->add_option("-o,--output", o->output, "the PLY file to write (atomically)")
        ->type_name("FILE")->check(kNonEmptyPath);
    command->add_option("--space", o->space, "eye | world coordinates for points")->capture_default_str();
    command->add_option("--stride", o->stride, "use every K-th pixel in x and y, 1..16384")
        ->capture_default_str()
        ->check(kImageSideRange);
    command->add_flag("--ascii", o->ascii, "write ASCII PLY instead of binary little-endian");

    return {command, [o] { return runUnprojectCommand(*o); }};
}

}  // namespace zcheck::cli
