#include "common.h"

#include "zcheck/camera_file.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/version.h"
#include "zcheck/camera_sources.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace zcheck::cli {

namespace {

// An option whose value may not be empty; `what` names it in the message ("the path is empty").
CLI::Validator nonEmpty(const std::string& what, const std::string& description)
{
    return CLI::Validator(
        [what](std::string& value) { return value.empty() ? "the " + what + " is empty" : std::string(); }, description);
}

// A number (all of the text) for which `holds` is true; else "'x' is not a number" or
// "must be <rule>, got 'x'".
CLI::Validator number(bool (*holds)(double), const std::string& rule, const std::string& description)
{
    return CLI::Validator(
        [holds, rule](std::string& value) {
            char* end = nullptr;
            const double v = std::strtod(value.c_str(), &end);
            if (value.empty() || *end != '\0') return "'" + value + "' is not a number";
            if (!holds(v)) return "must be " + rule + ", got '" + value + "'";
            return std::string();
        },
        description);
}

}  // namespace

const CLI::Validator kNonEmptyPath = nonEmpty("path", "PATH");
const CLI::Validator kNonEmptyList = nonEmpty("list", "LIST");
const CLI::Validator kMissRule(
    [](std::string& value) {
        try {
            MissRule::parse(value);
            return std::string();
        } catch (const Error& e) {
            return std::string(e.what());
        }
    },
    "RULE");
const CLI::Validator kPositiveFinite = number([](double v) { return std::isfinite(v) && v > 0; },
                                               "a positive finite number", "NUMBER > 0");
const CLI::Validator kBelowOne = number([](double v) { return v > 0 && v < 1; }, "a number in (0, 1)", "0 < NUMBER < 1");
const CLI::Range kThreadRange(1, 1024);
const CLI::Range kImageSideRange(1, Camera::kMaxImageSide);

std::unique_ptr<tbb::global_control> limitThreads(int threads)
{
    if (threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
}

void addThreadsOption(CLI::App* command, int& threads)
{
    command->add_option("--threads", threads, "worker threads, 1..1024 (default: all cores)")->check(kThreadRange);
}

void addCameraOptions(CLI::App* command, CameraOptions& options, const std::string& cameraHelp)
{
    command->add_option("--camera", options.reference, cameraHelp)->check(kNonEmptyPath);
    command->add_option("--camera-format", options.format,
                        "the camera file's format when its content should not decide:\n" +
                            cameraFormatChoices(CameraFormatsWith::Reader));
    command->add_option("--near", options.near, "near plane distance (eye-z > 0); default: the camera file's, else\n"
                                                "the scene's nearest point as the camera sees it, less 1 %")
        ->check(kPositiveFinite);
    command->add_option("--far", options.far, "far plane distance; default: the camera file's, else the scene's\n"
                                              "farthest point as the camera sees it, plus 1 %")
        ->check(kPositiveFinite);
    command->add_option("--convention", options.convention,
                        "override the convention: opengl | direct3d | vulkan | metal | opencv");
}

void addSceneAndCameraOptions(CLI::App* command, SceneAndCamera& options)
{
    command->add_option("--scene", options.scene,
                        "builtin:default | builtin:terrain[?n=N] | builtin:near-crossing | a mesh file (OBJ, PLY, STL, glTF/glb)")
        ->capture_default_str()
        ->check(kNonEmptyPath);
    addCameraOptions(command, options.camera,
                     cameraFileHelp("(#FRAME: an index, an image name, a path or its stem); default: the scene's own camera"));
}

void addImageSizeOptions(CLI::App* command, ImageSize& size)
{
    command->add_option("--width", size.width, "override the image width in pixels (1..16384)")->check(kImageSideRange);
    command->add_option("--height", size.height, "override the image height in pixels (1..16384)")->check(kImageSideRange);
}

namespace {

const CameraFormat* formatOption(const CameraOptions& options)
{
    if (options.format.empty()) return nullptr;
    return &cameraFormatNamed(options.format);
}

CameraSpec withConvention(CameraSpec spec, const std::string& convention)
{
    if (!convention.empty()) spec.convention = Convention::preset(convention);
    return spec;
}

CameraCompletion completionOf(const CameraOptions& o, std::optional<std::pair<int, int>> size)
{
    CameraCompletion given;
    given.near = o.near, given.far = o.far;
    if (size) given.width = size->first, given.height = size->second;
    return given;
}

}  // namespace

std::string cameraFileHelp(const std::string& tail)
{
    std::string out = "FILE or FILE#FRAME, its format told by content:";
    for (const CameraFormat* format : cameraFormats()) out += "\n  " + format->title + " (" + format->example + ")";
    return out + "\n" + tail;
}

std::string cameraInputPath(const CameraOptions& options) { return splitCameraReference(options.reference).first; }

CameraForMap cameraAndMapFor(const Scene* scene, const SceneAndCamera& options, DepthQuantity quantity,
                             const std::function<DepthMapFile(int width, int height)>& read)
{
    const CameraOptions& o = options.camera;
    if (o.reference.empty() && scene && scene->cameras.empty()) {  // the scene's own framing camera
        CameraForMap out;
        out.spec = cameraSpecFor(*scene, options);
        out.map = read(out.spec.width, out.spec.height);
        return out;
    }
    const ImportedCamera camera = o.reference.empty() ? scene->cameras.front() : importCamera(o.reference, formatOption(o));
    CameraForMap out = completeCameraForMap(camera, scene, completionOf(o, std::nullopt), quantity, read);
    out.spec = withConvention(out.spec, o.convention);
    return out;
}

CameraSpec cameraSpecFor(const Scene& scene, const SceneAndCamera& options, std::optional<std::pair<int, int>> size)
{
    const CameraOptions& o = options.camera;
    if (o.reference.empty() && scene.cameras.empty()) {  // the scene's own framing camera
        CameraSpec spec = scene.defaultCamera;
        if (o.near) spec.projection.near = *o.near;
        if (o.far) spec.projection.far = *o.far;
        return withConvention(spec, o.convention);
    }
    const ImportedCamera camera = o.reference.empty() ? scene.cameras.front() : importCamera(o.reference, formatOption(o));
    return withConvention(completeCamera(camera, &scene, completionOf(o, size)), o.convention);
}

CameraSpec cameraSpecFrom(const CameraOptions& options, std::optional<std::pair<int, int>> size,
                          std::optional<std::pair<double, double>> eyeZRange)
{
    const ImportedCamera camera = importCamera(options.reference, formatOption(options));
    CameraCompletion given = completionOf(options, size);
    given.mapEyeZ = eyeZRange;
    return withConvention(completeCamera(camera, nullptr, given), options.convention);
}

std::vector<double> parseNumberList(const std::string& text, const std::string& option)
{
    std::vector<double> values;
    std::size_t start = 0;
    while (start <= text.size() && !text.empty()) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        const std::string item = text.substr(start, end - start);
        char* stop = nullptr;
        const double value = std::strtod(item.c_str(), &stop);
        if (item.empty() || *stop != '\0' || !std::isfinite(value))
            throw Error(option + ": '" + item + "' is not a number (expected a comma-separated list)");
        values.push_back(value);
        start = end + 1;
    }
    return values;
}

void addDepthMapOptions(CLI::App* command, DepthMapOptions& options)
{
    command->add_option("--channel", options.channel,
                        "the channel to read (default: the only one, else the one named as depth: Z, depth,\n"
                        "*.Z as in Blender's ViewLayer.Depth.Z, *.depth; several or none is an error that lists them)");
    command->add_option("--scale", options.scale,
                        "stored value = (depth - offset) x scale: required for integer files (1000 for millimetres,\n"
                        "5000 for many RGB-D sets, 256 for KITTI); float files are divided by it")
        ->check(kPositiveFinite);
    command->add_option("--offset", options.offset, "added to every depth after --scale (default 0)");
    command->add_option("--miss", options.miss,
                        "the stored value that means 'no surface', or a comparison: 0, 65535, 1e10, nan, inf, '>=1e9'\n"
                        "(default: 0 in integer files; NaN is always a miss)")
        ->check(kMissRule);
    addAccuracyOptions(command, options.accuracy);
    command->add_option("--sidecar", options.sidecar,
                        "a JSON file describing the map: {\"miss\": 65535 or \">=1e9\", \"scale\": 1000, \"offset\": 0,\n"
                        "\"channel\": \"Z\", \"quantum\": 0.001, \"rel_tolerance\": 0, \"abs_tolerance\": 0, \"noise_model\": \"kinect\",\n"
                        "\"allow_holes\": false};\n"
                        "other keys are ignored; the options above win over it")
        ->check(kNonEmptyPath);
}

void addAccuracyOptions(CLI::App* command, MapAccuracy& accuracy)
{
    const char* group = "What the map's producer declares (judged with, never applied to the values)";
    command->add_option("--quantum", accuracy.quantum,
                        "the map's values were rounded to multiples of Q (map units, after --scale): each pixel's\n"
                        "tolerance includes that step (0.001 for millimetres held as float metres). Half floats carry\n"
                        "their own step without it. The values must lie on that grid, and every declared accuracy\n"
                        "is judged as a whole too: it must be under a tenth of the depths, and the map's mean error\n"
                        "unbiased (within an exact map's tolerance and six sampling errors: docs/verify.md)")
        ->check(kPositiveFinite)
        ->group(group);
    command->add_option("--rel-tolerance", accuracy.relative,
                        "values are good only to this fraction of themselves (a rasterizer's reconstructed Z pass:\n"
                        "1e-3 for Blender's Eevee); added to every pixel's tolerance")
        ->check(kBelowOne)
        ->group(group);
    command->add_option("--abs-tolerance", accuracy.absolute,
                        "values are good only to this many map units (a sensor's noise: 0.01 m); added to every\n"
                        "pixel's tolerance")
        ->check(kPositiveFinite)
        ->group(group);
    command->add_option_function<std::string>(
               "--noise-model", [&accuracy](const std::string& text) { accuracy.noise = NoiseModel::parse(text); },
               "a sensor's noise σ(z) in map units, z the map's own value at the pixel (eye-z, or range for a\n"
               "distance map): kinect (0.0012+0.0019*(z-0.4)^2, metres), A+B*z^2 or A+B*(z-C)^2. Each pixel may\n"
               "be off by 6σ(z); the map's errors must still be unbiased (see --quantum)")
        ->group(group);
    command->add_flag("--allow-holes", accuracy.allowHoles,
                      "a pixel without a value where the surface is hit is a hole (counted and reported), not a\n"
                      "failure: sensors and some renderers leave them")
        ->group(group);
}

std::string takeFromSidecar(const DepthMapOptions& reading, CameraOptions& camera, std::string& quantity)
{
    std::string compareWith;
    if (!reading.sidecar.empty()) {
        const SidecarSubject subject = sidecarSubject(reading.sidecar);
        if (subject.hasCamera) {
            if (camera.reference.empty()) camera.reference = reading.sidecar;
            else compareWith = reading.sidecar;
        }
        if (quantity.empty())
            quantity = subject.quantityOf(reading.sidecar, reading.channel).value_or("");
    }
    if (quantity.empty()) quantity = "window";
    return compareWith;
}

void requireSidecarCameraAgrees(const CameraSpec& used, const CameraOptions& camera, const std::string& sidecar,
                                DepthQuantity quantity)
{
    if (sidecar.empty()) return;
    const bool depthMapping = quantity == DepthQuantity::Window || quantity == DepthQuantity::Ndc;
    const std::string difference = howCamerasDiffer(Camera(used), Camera(readCameraFile(sidecar)), depthMapping);
    if (!difference.empty())
        throw Error("--camera '" + camera.reference + "' and the camera in sidecar '" + sidecar + "' (the one that rendered "
                    "the map) differ in " + difference + ": give the map's own camera, or leave --camera out");
}

DepthMapReading DepthMapOptions::reading(const std::string& quantityName) const
{
    DepthMapReading r;
    r.channel = channel;
    r.quantityChannel = channelNameOf(exportQuantityOf(depthQuantityFromName(quantityName)));
    r.scale = scale, r.offset = offset;
    if (!miss.empty()) r.miss = MissRule::parse(miss);
    r.accuracy = accuracy;
    return sidecar.empty() ? r : withSidecar(r, sidecar);
}

nlohmann::json depthFileSidecar(const std::string& output, const std::string& format, const Camera& camera,
                                const std::vector<QuantityImage>& images, double scale, glm::dvec2 sampleOffset)
{
    const auto numberOrName = [](double v) {  // JSON has no inf or NaN
        if (std::isnan(v)) return nlohmann::json("nan");
        if (std::isinf(v)) return nlohmann::json(v > 0 ? "inf" : "-inf");
        return nlohmann::json(v);
    };
    const bool png = format == "png";
    nlohmann::json channels = nlohmann::json::array();
    for (const QuantityImage& image : images)
        for (const std::string& name : image.channels) {
            nlohmann::json channel = {{"name", name},
                                      {"quantity", toString(image.quantity)},
                                      {"unit", image.unit},
                                      {"type", png ? "uint16" : image.quantity == ExportQuantity::PrimitiveId ? "uint32" : "float32"},
                                      {"miss_value", png ? nlohmann::json(0) : numberOrName(image.missValue)}};
            if (png) channel["stored_as"] = "round(value * scale); 0 = miss";
            channels.push_back(channel);
        }
    const std::string orientation =
        format == "pfm" ? "row 0 is the top row of the picture as a standard reader returns it; the file stores rows "
                          "bottom to top, as the PFM specification says"
                        : "row 0 (the first row stored and read) is the top row of the picture";
    return {
        {"zcheck_version", kVersion},
        {"file", std::filesystem::path(output).filename().string()},
        {"format", format},
        {"width", camera.width()},
        {"height", camera.height()},
        {"orientation", orientation},
        {"pixel_centres", "pixel (col,row) samples image point (col + 0.5 + dx, row + 0.5 + dy) from the top-left "
                          "corner, x right, y down"},
        {"sample_offset", {sampleOffset.x, sampleOffset.y}},
        {"channels", channels},
        {"scale", png ? nlohmann::json(scale) : nlohmann::json(nullptr)},
        {"convention", camera.convention().name},
        {"camera", toJson(camera.spec())},
        {"matrices", matricesJson(camera)},
    };
}

}  // namespace zcheck::cli
