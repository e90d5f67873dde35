// zcheck — the command line. Thin: parse, call the libraries, print.
// Exit status: 0 consistent, 1 inconsistent, 2 usage or input error, 3 internal failure (out
// of memory, a library error); errors are one line on stderr.
#include "check.h"
#include "suite.h"
#include "verify.h"

#include "zcheck/atomic_file.h"
#include "zcheck/camera_file.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/image_io.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/point_cloud.h"
#include "zcheck/precision.h"

#include <CLI/CLI.hpp>
#include <unistd.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <iostream>
#include <memory>
#include <optional>

namespace {

using namespace zcheck;

constexpr int kExitConsistent = 0;
constexpr int kExitInconsistent = 1;
constexpr int kExitUsage = 2;     // bad input: a file, key, option or value (one line names it)
constexpr int kExitInternal = 3;  // zcheck itself failed: out of memory, a library or internal error

// Option validators, the same in every subcommand.
// An option whose value may not be empty; `what` names it in the message ("the path is empty").
CLI::Validator nonEmpty(const std::string& what, const std::string& description)
{
    return CLI::Validator(
        [what](std::string& value) { return value.empty() ? "the " + what + " is empty" : std::string(); }, description);
}
const CLI::Validator kNonEmptyPath = nonEmpty("path", "PATH");
const CLI::Validator kPositiveFinite(
    [](std::string& value) {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (value.empty() || *end != '\0') return "'" + value + "' is not a number";
        if (!std::isfinite(v) || !(v > 0)) return "must be a positive finite number, got '" + value + "'";
        return std::string();
    },
    "NUMBER > 0");
const CLI::Validator kNonEmptyList = nonEmpty("list", "LIST");
const auto kThreadRange = CLI::Range(1, 1024);
const auto kImageSideRange = CLI::Range(1, 16384);

// At most `threads` worker threads (0: all cores) for the lifetime of the object.
std::unique_ptr<tbb::global_control> limitThreads(int threads)
{
    if (threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
}

// Refuses a comparison with nothing in it: a camera that sees no geometry proves nothing,
// and must not be reported CONSISTENT.
void requireSomethingCompared(const ComparisonReport& report, const std::string& scene)
{
    if (report.bothHit + report.rayOnly + report.rasterOnly == 0)
        throw Error("nothing to compare: neither route sees any surface of '" + scene +
                    "' through this camera (is it pointing away, or are near/far wrong?)");
}

struct CheckOptions {
    std::string scene = "builtin:default";
    std::string cameraFile;
    std::string convention;
    std::optional<int> width, height;
    std::string depthFormat;
    bool reversedZ = false;
    std::string outDir;
    bool json = false;
    int threads = 0;
};

// The camera a command uses: the camera file, or the scene's own camera; then --convention.
CameraSpec cameraSpecFor(const Scene& scene, const std::string& cameraFile, const std::string& convention)
{
    CameraSpec spec = cameraFile.empty() ? scene.defaultCamera : readCameraFile(cameraFile);
    if (!convention.empty()) spec.convention = Convention::preset(convention);
    return spec;
}

// --scene, --camera and --convention, as check, export and verify take them.
void addSceneAndCameraOptions(CLI::App* command, std::string& scene, std::string& cameraFile, std::string& convention)
{
    command->add_option("--scene", scene,
                        "builtin:default | builtin:terrain[?n=N] | builtin:near-crossing | a mesh file (OBJ, PLY, STL, glTF/glb)")
        ->capture_default_str()
        ->check(kNonEmptyPath);
    command->add_option("--camera", cameraFile, "camera file (JSON, see README); default: the scene's own camera")
        ->check(kNonEmptyPath);
    command->add_option("--convention", convention, "override the convention: opengl | direct3d | vulkan | metal | opencv");
}

std::vector<float> asFloats(const DepthImage& image)
{
    return std::vector<float>(image.value.begin(), image.value.end());
}

// check --out / verify --out: the images and report.json of one run, registered before it.
struct RunFolder {
    std::string dir, rasterName;
    std::string path(const char* name) const { return (std::filesystem::path(dir) / name).string(); }
    std::vector<std::string> files() const
    {
        return {path("ray_depth.exr"), path(rasterName.c_str()), path("error_heatmap.png"), path("coverage_classes.png"),
                path("report.json")};
    }
    void plan(OutputFiles& outputs) const
    {
        outputs.addFolder(dir, "--out");
        for (const std::string& file : files()) outputs.add(file, "--out");
    }
    void write(OutputFiles& outputs, const CheckRun& run, const nlohmann::json& report) const
    {
        const int W = run.comparison.report.width, H = run.comparison.report.height;
        outputs.write(path("ray_depth.exr"), [&](const std::string& t) { writeExr(t, W, H, {"window"}, asFloats(run.ray.windowDepth)); });
        outputs.write(path(rasterName.c_str()),
                      [&](const std::string& t) { writeExr(t, W, H, {"window"}, asFloats(run.raster.windowDepth)); });
        outputs.write(path("error_heatmap.png"), [&](const std::string& t) { writePng8(t, W, H, errorHeatmapRgb(run.comparison)); });
        outputs.write(path("coverage_classes.png"), [&](const std::string& t) { writePng8(t, W, H, pixelClassRgb(run.comparison)); });
        outputs.writeText(path("report.json"), prettyJson(report) + "\n");
    }
};

int runCheckCommand(const CheckOptions& options)
{
    const auto threadLimit = limitThreads(options.threads);
    OutputFiles outputs;
    outputs.addInput(options.scene);
    outputs.addInput(options.cameraFile);
    const RunFolder folder{options.outDir, "raster_depth.exr"};
    if (!options.outDir.empty()) folder.plan(outputs);
    const Scene scene = loadScene(options.scene);
    CameraSpec spec = cameraSpecFor(scene, options.cameraFile, options.convention);
    if (options.width) spec.width = *options.width;
    if (options.height) spec.height = *options.height;
    if (!options.depthFormat.empty()) spec.depth.format = depthFormatFromName(options.depthFormat);
    if (options.reversedZ) spec.depth.reversed = true;
    const Camera camera(spec);

    const RayRenderer rays(scene);
    const RasterRenderer raster(scene);
    const CheckRun run = runCheck(scene, camera, rays, raster);
    requireSomethingCompared(run.report.comparison, scene.name);
    if (!options.outDir.empty()) {
        folder.write(outputs, run, toJson(run.report));
        outputs.commit();
    }
    if (options.json)
        std::cout << prettyJson(toJson(run.report)) << "\n";
    else
        std::cout << formatSummary(run.report);
    return run.report.comparison.consistent() ? kExitConsistent : kExitInconsistent;
}

CameraSpec cameraSpecFrom(const std::string& cameraFile, const std::string& convention)
{
    CameraSpec spec = readCameraFile(cameraFile);
    if (!convention.empty()) spec.convention = Convention::preset(convention);
    return spec;
}

int runMatricesCommand(const std::string& cameraFile, const std::string& convention)
{
    const Camera camera(cameraSpecFrom(cameraFile, convention));
    std::cout << prettyJson(matricesJson(camera)) << "\n";
    return kExitConsistent;
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

int runPrecisionCommand(const std::string& cameraFile, const std::string& convention, const std::string& at, bool json)
{
    const CameraSpec spec = cameraSpecFrom(cameraFile, convention);
    const PrecisionTable table = depthPrecision(spec, parseNumberList(at, "--at"));
    if (json) {
        nlohmann::json layouts = nlohmann::json::array();
        for (std::size_t k = 0; k < table.layouts.size(); ++k) {
            nlohmann::json steps = nlohmann::json::array();
            for (double step : table.step[k]) steps.push_back(std::isfinite(step) ? nlohmann::json(step) : nlohmann::json(nullptr));
            layouts.push_back({{"format", toString(table.layouts[k].format)},
                               {"mapping", toString(table.layouts[k].mapping)},
                               {"eye_z_step", steps}});
        }
        const PrecisionLayout& best = table.layouts[table.best];
        std::cout << prettyJson({{"camera", toJson(spec)},
                                 {"distances", table.distances},
                                 {"definition", "eye_z_step: eye-z between the stored value at that distance and the next "
                                                "representable value farther away; null: unresolvable"},
                                 {"layouts", layouts},
                                 {"best", {{"format", toString(best.format)}, {"mapping", toString(best.mapping)},
                                           {"worst_relative_step", table.bestWorstRelativeStep}}}})
                  << "\n";
        return kExitConsistent;
    }
    const Camera camera(spec);
    std::printf("depth precision: %s camera, near %g, far %g, %s convention\n", toString(spec.projection.type).c_str(),
                camera.nearDistance(), camera.farDistance(), spec.convention.name.c_str());
    std::printf("smallest resolvable eye-z step at eye-z d (scene units; '-' = cannot be told from the far end)\n");
    for (DepthFormat format : {DepthFormat::Unorm16, DepthFormat::Unorm24, DepthFormat::Float32}) {
        std::printf("\n%-8s %12s", toString(format).c_str(), "eye-z d");
        for (const auto& layout : table.layouts)
            if (layout.format == format) std::printf(" %24s", toString(layout.mapping).c_str());
        std::printf("\n");
        for (std::size_t i = 0; i < table.distances.size(); ++i) {
            std::printf("%-8s %12.6g", "", table.distances[i]);
            for (std::size_t k = 0; k < table.layouts.size(); ++k)
                if (table.layouts[k].format == format) {
                    const double step = table.step[k][i];
                    if (std::isfinite(step))
                        std::printf(" %13.3g (%8.2g%%)", step, 100 * step / table.distances[i]);
                    else
                        std::printf(" %24s", "-");
                }
            std::printf("\n");
        }
    }
    const PrecisionLayout& best = table.layouts[table.best];
    std::printf("\nbest for this camera: %s, %s (worst relative step %.3g over these distances)\n",
                toString(best.format).c_str(), toString(best.mapping).c_str(), table.bestWorstRelativeStep);
    return kExitConsistent;
}

struct UnprojectOptions {
    std::string cameraFile, convention, pixel, depthMap, quantity = "window", output, space = "world";
    std::optional<double> depth;
    double scale = 0;
    int stride = 1;
    bool ascii = false;
};

glm::ivec2 parsePixel(const std::string& text, const Camera& camera)
{
    const std::vector<double> v = parseNumberList(text, "--pixel");
    if (v.size() != 2 || v[0] != std::floor(v[0]) || v[1] != std::floor(v[1]))
        throw Error("--pixel: expected COL,ROW as two whole numbers, got '" + text + "'");
    if (v[0] < 0 || v[0] >= camera.width() || v[1] < 0 || v[1] >= camera.height())
        throw Error("--pixel " + text + " is outside the " + std::to_string(camera.width()) + "x" +
                    std::to_string(camera.height()) + " image");
    return {int(v[0]), int(v[1])};
}

// A depth value the camera can produce: window depth within the depth range, z_ndc within the
// convention's NDC range, eye-z and distance in front of the eye.
void requireDepthValueInRange(const Camera& camera, DepthQuantity quantity, double value)
{
    const std::string given = "--depth " + formatNumber(value) + " (" + toString(quantity) + ")";
    if (!std::isfinite(value)) throw Error(given + " must be a finite number");
    const double lo = quantity == DepthQuantity::Window ? camera.depth().rangeMin
                      : quantity == DepthQuantity::Ndc  ? camera.convention().ndcZMin()
                                                        : 0.0;
    const double hi = quantity == DepthQuantity::Window ? camera.depth().rangeMax : quantity == DepthQuantity::Ndc ? 1.0 : INFINITY;
    const bool inside = quantity == DepthQuantity::Window || quantity == DepthQuantity::Ndc ? value >= lo && value <= hi : value > 0;
    if (!inside)
        throw Error(given + (quantity == DepthQuantity::EyeZ || quantity == DepthQuantity::Distance
                                 ? " must be > 0: the point must lie in front of the eye"
                                 : " must lie in [" + formatNumber(lo) + ", " + formatNumber(hi) + "], the camera's " +
                                       (quantity == DepthQuantity::Window ? "depth range" : "NDC depth range")));
}

nlohmann::json vec3Json(const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

int runUnprojectCommand(const UnprojectOptions& o)
{
    if (o.space != "eye" && o.space != "world") throw Error("--space must be eye or world, got '" + o.space + "'");
    const DepthQuantity quantity = depthQuantityFromName(o.quantity);
    const Camera camera(cameraSpecFrom(o.cameraFile, o.convention));
    auto toWorld = [&](const glm::dvec3& pEye) { return glm::dvec3(camera.worldFromEye * glm::dvec4(pEye, 1.0)); };

    if (!o.pixel.empty() && (!o.depthMap.empty() || !o.output.empty()))
        throw Error("--pixel and --depth-map/-o are alternatives: one pixel's ray or point, or a whole map as a point cloud");
    if (o.pixel.empty() && o.depth)
        throw Error("--depth " + formatNumber(*o.depth) + " needs --pixel COL,ROW (a --depth-map holds its own depths)");
    if (!o.pixel.empty()) {
        const glm::ivec2 pixel = parsePixel(o.pixel, camera);
        const glm::dvec2 pWindow = windowFromPixelCentre(camera, pixel.x, pixel.y);
        nlohmann::json out = {{"pixel", {pixel.x, pixel.y}}, {"window", {pWindow.x, pWindow.y}}};
        if (!o.depth) {
            const EyePlaneRay rayEye = eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow));
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
            requireDepthValueInRange(camera, quantity, *o.depth);
            const auto pEye = eyePointFromDepth(camera, pWindow, *o.depth, quantity);
            if (!pEye) throw Error("--depth " + formatNumber(*o.depth) + " is a miss for quantity " + o.quantity);
            out["point"] = {{"eye", vec3Json(*pEye)}, {"world", vec3Json(toWorld(*pEye))},
                            {"eye_z", camera.eyeZOf(*pEye)}, {"distance", distanceOfEyePoint(camera, *pEye)}};
        }
        std::cout << prettyJson(out) << "\n";
        return kExitConsistent;
    }

    if (o.depthMap.empty()) throw Error("unproject needs --pixel COL,ROW or --depth-map FILE");
    if (o.output.empty()) throw Error("--depth-map needs -o FILE.ply");
    OutputFiles outputs;
    outputs.addInput(o.cameraFile);
    outputs.addInput(o.depthMap);
    outputs.add(o.output, "-o");
    const DepthMapFile map = readDepthMap(o.depthMap, channelNameOf(exportQuantitiesFromList(o.quantity).front()), o.scale,
                                          camera.width(), camera.height());
    std::vector<glm::dvec3> points;
    std::size_t misses = 0;
    for (int row = 0; row < map.height; row += o.stride)
        for (int col = 0; col < map.width; col += o.stride) {
            const double value = map.value[std::size_t(row) * map.width + col];
            const auto pEye = eyePointFromDepth(camera, windowFromPixelCentre(camera, col, row), value, quantity);
            if (!pEye) {
                ++misses;
                continue;
            }
            points.push_back(o.space == "eye" ? *pEye : toWorld(*pEye));
        }
    outputs.write(o.output, [&](const std::string& temporary) {
        writePointCloudPly(temporary, points, !o.ascii,
                           {"zcheck unproject of " + std::filesystem::path(o.depthMap).filename().string() + " (" +
                                o.quantity + ", channel " + map.channel + ")",
                            std::string("space ") + o.space +
                                (o.space == "eye" ? " (" + camera.convention().name + " eye axes)" : "")});
    });
    outputs.commit();
    std::cout << prettyJson({{"points", points.size()}, {"misses", misses}, {"channel", map.channel},
                             {"quantity", o.quantity}, {"space", o.space}, {"output", o.output}})
              << "\n";
    return kExitConsistent;
}

struct ExportOptions {
    std::string backend = "ray", quantities = "eye-z", scene = "builtin:default", cameraFile, convention, output,
                preview;
    double scale = 0;
    int threads = 0;
};

nlohmann::json numberOrName(double v)
{
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return v;
}

int runExportCommand(const ExportOptions& o)
{
    if (o.backend != "ray" && o.backend != "raster") throw Error("--backend must be ray or raster, got '" + o.backend + "'");
    if (o.output.empty()) throw Error("export needs -o FILE (.exr, .pfm, .tif or .png)");
    const std::vector<ExportQuantity> quantities = exportQuantitiesFromList(o.quantities);
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;
    outputs.addInput(o.scene);
    outputs.addInput(o.cameraFile);
    outputs.add(o.output, "-o");
    outputs.add(o.output + ".json", "the sidecar of -o");
    if (!o.preview.empty()) outputs.add(o.preview, "--preview");
    const Scene scene = loadScene(o.scene);
    CameraSpec spec = cameraSpecFor(scene, o.cameraFile, o.convention);
    const Camera camera(spec);
    const RenderResult route = o.backend == "ray" ? RayRenderer(scene).render(camera) : RasterRenderer(scene).render(camera);
    std::vector<QuantityImage> images;
    for (ExportQuantity q : quantities) images.push_back(quantityImage(scene, camera, route, q));
    std::string format;
    outputs.write(o.output, [&](const std::string& temporary) { format = writeQuantityFile(temporary, images, o.scale); });

    nlohmann::json channels = nlohmann::json::array();
    for (const auto& image : images)
        for (const auto& name : image.channels) {
            nlohmann::json channel = {{"name", name},
                                      {"quantity", toString(image.quantity)},
                                      {"unit", image.unit},
                                      {"type", format == "png" ? "uint16" : image.quantity == ExportQuantity::PrimitiveId ? "uint32" : "float32"},
                                      {"miss_value", format == "png" ? nlohmann::json(0) : numberOrName(image.missValue)}};
            if (format == "png") channel["stored_as"] = "round(value * scale); 0 = miss";
            channels.push_back(channel);
        }
    const std::string orientation =
        format == "pfm" ? "row 0 is the top row of the picture as a standard reader returns it; the file stores rows "
                          "bottom to top, as the PFM specification says"
                        : "row 0 (the first row stored and read) is the top row of the picture";
    nlohmann::json sidecar = {
        {"zcheck_version", ZCHECK_VERSION},
        {"file", std::filesystem::path(o.output).filename().string()},
        {"format", format},
        {"width", camera.width()},
        {"height", camera.height()},
        {"orientation", orientation},
        {"pixel_centres", "pixel (col,row) samples window point (col + 0.5, row + 0.5) from the top-left corner"},
        {"channels", channels},
        {"scale", format == "png" ? nlohmann::json(o.scale) : nlohmann::json(nullptr)},
        {"backend", o.backend},
        {"scene", scene.name},
        {"convention", spec.convention.name},
        {"depth", {{"format", toString(spec.depth.format)}, {"reversed", spec.depth.reversed},
                   {"range", {spec.depth.rangeMin, spec.depth.rangeMax}}, {"clear_value", camera.clearDepth()}}},
        {"camera", toJson(spec)},
        {"matrices", matricesJson(camera)},
    };
    outputs.writeText(o.output + ".json", prettyJson(sidecar) + "\n");
    if (!o.preview.empty())
        outputs.write(o.preview, [&](const std::string& temporary) {
            writePng8(temporary, camera.width(), camera.height(), previewRgb(images.front()));
        });
    outputs.commit();
    std::size_t hits = 0;
    for (std::size_t i = 0; i < route.primitiveId.size(); ++i) hits += route.hit(i) ? 1 : 0;
    std::cout << prettyJson({{"output", o.output}, {"sidecar", o.output + ".json"}, {"format", format},
                             {"quantities", o.quantities}, {"backend", o.backend}, {"covered_pixels", hits},
                             {"pixels", route.primitiveId.size()}})
              << "\n";
    return kExitConsistent;
}

struct VerifyOptions {
    std::string scene = "builtin:default", cameraFile, convention, depthMap, quantity = "window", outDir;
    double scale = 0;
    bool diagnose = false, json = false;
    int threads = 0;
};

int runVerifyCommand(const VerifyOptions& o)
{
    const DepthQuantity quantity = depthQuantityFromName(o.quantity);
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;
    outputs.addInput(o.scene);
    outputs.addInput(o.cameraFile);
    outputs.addInput(o.depthMap);
    const RunFolder folder{o.outDir, "map_depth.exr"};
    if (!o.outDir.empty()) folder.plan(outputs);
    const Scene scene = loadScene(o.scene);
    CameraSpec spec = cameraSpecFor(scene, o.cameraFile, o.convention);
    const Camera camera(spec);
    const DepthMapFile file = readDepthMap(o.depthMap, channelNameOf(exportQuantitiesFromList(o.quantity).front()), o.scale,
                                           camera.width(), camera.height());
    ExternalDepthMap map{file.width, file.height, quantity, file.value, o.scale > 0 ? 1.0 / o.scale : 0.0};
    RayRenderer rays(scene);
    const VerifyRun run = verifyDepthMap(scene, camera, map, rays);
    requireSomethingCompared(run.comparison.report, scene.name);
    nlohmann::json report = toJson(run.report);
    report["depth_map"] = {{"file", o.depthMap}, {"quantity", o.quantity}, {"channel", file.channel}, {"scale", o.scale}};
    std::vector<Hypothesis> hypotheses;
    if (o.diagnose && !run.comparison.report.consistent()) {
        hypotheses = diagnoseDepthMap(scene, camera, map, rays);
        nlohmann::json list = nlohmann::json::array();
        for (const auto& h : hypotheses)
            list.push_back({{"hypothesis", h.name}, {"explanation", h.explanation}, {"consistent", h.consistent},
                            {"unexplained", h.unexplained}});
        report["diagnosis"] = list;
    }
    if (!o.outDir.empty()) {
        CheckRun asCheck;
        asCheck.ray = run.truth, asCheck.raster = run.map, asCheck.comparison = run.comparison, asCheck.report = run.report;
        folder.write(outputs, asCheck, report);
        outputs.commit();
    }
    if (o.json) {
        std::cout << prettyJson(report) << "\n";
    } else {
        std::cout << formatSummary(run.report, "ground truth (Embree) vs depth map '" + o.depthMap + "' (" + o.quantity + ")");
        if (o.diagnose && !run.comparison.report.consistent()) {
            const Hypothesis* best = nullptr;
            for (const auto& h : hypotheses)
                if (h.consistent) {
                    best = &h;
                    break;
                }
            std::cout << "\ndiagnosis  ";
            if (best) {
                std::cout << best->explanation << "\n";
            } else {
                const Hypothesis* closest = &hypotheses.front();
                for (const auto& h : hypotheses)
                    if (h.unexplained < closest->unexplained) closest = &h;
                std::cout << "none of the " << hypotheses.size() << " hypotheses makes the map consistent (closest: "
                          << closest->name << ", " << closest->unexplained << " unexplained pixels)\n";
            }
        }
    }
    return run.comparison.report.consistent() ? kExitConsistent : kExitInconsistent;
}

struct SuiteOptions {
    bool quick = false;
    std::string filter, jsonFile, htmlFile, modelsDir = ZCHECK_MODELS_DIR;
    int threads = 0;
};

std::string htmlEscape(const std::string& text)
{
    std::string out;
    for (char c : text) out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
    return out;
}

// Detected / applicable per fault over the whole run.
struct FaultTally {
    int detected = 0, missed = 0, notApplicable = 0, meaningless = 0;
};

std::vector<FaultTally> tallyFaults(const SuiteResult& result)
{
    std::vector<FaultTally> tally(faultCatalogue().size());
    for (const auto& outcome : result.outcomes)
        for (std::size_t k = 0; k < outcome.faults.size(); ++k) switch (outcome.faults[k]) {
            case FaultResult::Detected: ++tally[k].detected; break;
            case FaultResult::Missed: ++tally[k].missed; break;
            case FaultResult::NotApplicable: ++tally[k].notApplicable; break;
            case FaultResult::Meaningless: ++tally[k].meaningless; break;
            }
    return tally;
}

std::string suiteTable(const SuiteResult& result)
{
    std::ostringstream out;
    const auto tally = tallyFaults(result);
    const int clean = int(result.outcomes.size());
    char line[256];
    std::snprintf(line, sizeof line, "clean configurations: %d consistent of %d (false positives: %d)\n\n",
                  clean - result.falsePositives, clean, result.falsePositives);
    out << line;
    std::snprintf(line, sizeof line, "%-22s %-7s %10s %14s %9s  %s\n", "fault", "route", "detected", "not applicable",
                  "n/a", "");
    out << line;
    for (std::size_t k = 0; k < tally.size(); ++k) {
        const Fault& fault = faultCatalogue()[k];
        const int applicable = tally[k].detected + tally[k].missed;
        std::snprintf(line, sizeof line, "%-22s %-7s %4d / %-4d %14d %9d  %s\n", fault.name.c_str(), fault.route.c_str(),
                      tally[k].detected, applicable, tally[k].notApplicable, tally[k].meaningless,
                      tally[k].missed ? "<- MISSED" : "");
        out << line;
    }
    out << "\n(detected / applicable. Not applicable: the fault leaves that picture visibly unchanged - the same\n"
           " coverage, depth within twice the snapping noise - e.g. no near clipping where nothing crosses the near\n"
           " plane. n/a: the mistake has no meaning there, e.g. a field-of-view mistake on an orthographic camera.)\n";
    return out.str();
}

int runSuiteCommand(const SuiteOptions& o)
{
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;  // validated now, not after a long run
    if (!o.jsonFile.empty()) outputs.add(o.jsonFile, "--json");
    if (!o.htmlFile.empty()) outputs.add(o.htmlFile, "--html");
    std::vector<SuiteConfig> configs;
    for (auto& config : suiteConfigurations(o.quick, o.modelsDir))
        if (o.filter.empty() || config.label().find(o.filter) != std::string::npos) configs.push_back(config);
    if (configs.empty()) throw Error("--filter '" + o.filter + "' matches no configuration");
    const bool terminal = ::isatty(2);
    const auto start = std::chrono::steady_clock::now();
    int failuresSoFar = 0;
    const SuiteResult result = runSuite(configs, [&](std::size_t done, std::size_t total, const ConfigOutcome& outcome) {
        for (FaultResult r : outcome.faults) failuresSoFar += r == FaultResult::Missed ? 1 : 0;
        failuresSoFar += outcome.clean.consistent() ? 0 : 1;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (terminal || done == total || done % 25 == 0)
            std::fprintf(stderr, "%s[%zu/%zu] %.0f s, failures %d: %-70.70s%s", terminal ? "\r" : "", done, total,
                         seconds, failuresSoFar, outcome.config.label().c_str(), terminal && done < total ? "" : "\n");
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "zcheck suite" << (o.quick ? " --quick" : "") << ": " << configs.size() << " configurations x "
              << faultCatalogue().size() << " faults in " << std::lround(seconds) << " s\n\n"
              << suiteTable(result) << "\nverdict    " << (result.passed() ? "PASSED" : "FAILED") << "\n";

    if (!o.jsonFile.empty()) {
        nlohmann::json configsJson = nlohmann::json::array();
        for (const auto& outcome : result.outcomes) {
            nlohmann::json faults;
            for (std::size_t k = 0; k < outcome.faults.size(); ++k) faults[faultCatalogue()[k].name] = toString(outcome.faults[k]);
            configsJson.push_back({{"label", outcome.config.label()},
                                   {"scene", outcome.config.scene},
                                   {"model", outcome.config.model},
                                   {"camera", toJson(outcome.config.spec)},
                                   {"clean", {{"consistent", outcome.clean.consistent()},
                                              {"unexplained", outcome.clean.unexplained()},
                                              {"max_over_tolerance", outcome.clean.maxErrorOverTolerance},
                                              {"mean_signed_error_quanta", outcome.clean.meanSignedErrorQuanta}}},
                                   {"faults", faults},
                                   {"milliseconds", outcome.milliseconds}});
        }
        nlohmann::json table = nlohmann::json::object();
        const auto tally = tallyFaults(result);
        for (std::size_t k = 0; k < tally.size(); ++k)
            table[faultCatalogue()[k].name] = {{"description", faultCatalogue()[k].description},
                                               {"route", faultCatalogue()[k].route},
                                               {"detected", tally[k].detected},
                                               {"applicable", tally[k].detected + tally[k].missed},
                                               {"not_applicable", tally[k].notApplicable},
                                               {"meaningless", tally[k].meaningless}};
        outputs.writeText(o.jsonFile, prettyJson({{"zcheck_version", ZCHECK_VERSION},
                                                        {"quick", o.quick},
                                                        {"configurations", configsJson},
                                                        {"detection", table},
                                                        {"false_positives", result.falsePositives},
                                                        {"missed_faults", result.missedFaults},
                                                        {"passed", result.passed()},
                                                        {"seconds", seconds}}) + "\n");
    }
    if (!o.htmlFile.empty()) {
        std::ostringstream html;
        html << "<!doctype html><html><head><meta charset=\"utf-8\"><title>zcheck suite</title><style>"
                "body{font-family:sans-serif;margin:2em}pre{background:#f4f4f4;padding:1em}"
                "img{image-rendering:pixelated;width:320px;margin-right:8px;border:1px solid #ccc}"
                ".failure{margin-bottom:2em}</style></head><body>"
             << "<h1>zcheck suite: " << (result.passed() ? "PASSED" : "FAILED") << "</h1><p>" << configs.size()
             << " configurations &times; " << faultCatalogue().size() << " faults, " << std::lround(seconds)
             << " s.</p><pre>" << htmlEscape(suiteTable(result)) << "</pre>";
        const int allFailures = result.falsePositives + result.missedFaults;
        html << "<h2>Failures" << (allFailures == 0 ? ": none" : "") << "</h2>";
        if (allFailures > int(result.failures.size()))
            html << "<p>Showing the first " << result.failures.size() << " of " << allFailures
                 << " failures with images; the JSON report lists every configuration.</p>";
        for (const auto& failure : result.failures) {
            const Comparison& c = failure.run.comparison;
            QuantityImage depth;
            depth.quantity = ExportQuantity::Window, depth.width = c.report.width, depth.height = c.report.height;
            depth.channels = {"window"}, depth.value = failure.run.raster.windowDepth.value;
            depth.missValue = failure.run.raster.windowDepth.value.empty() ? 0 : NAN;
            html << "<div class=\"failure\"><h3>" << htmlEscape(failure.label) << "</h3><p>" << htmlEscape(failure.what)
                 << "</p><img title=\"raster depth\" src=\"" << pngDataUri(depth.width, depth.height, previewRgb(depth))
                 << "\"><img title=\"error heatmap\" src=\"" << pngDataUri(depth.width, depth.height, errorHeatmapRgb(c))
                 << "\"><img title=\"coverage classes\" src=\"" << pngDataUri(depth.width, depth.height, pixelClassRgb(c))
                 << "\"><pre>" << htmlEscape(formatSummary(failure.run.report)) << "</pre></div>";
        }
        html << "</body></html>\n";
        outputs.writeText(o.htmlFile, html.str());
    }
    outputs.commit();
    return result.passed() ? kExitConsistent : kExitInconsistent;
}

}  // namespace

int main(int argc, char** argv)
{
    CLI::App app{"zcheck proves a graphics transform chain correct by computing every pixel's depth twice —\n"
                 "by ray casting through the inverse projection (Embree) and by rasterizing forward through\n"
                 "view, projection, clipping, divide and viewport — and demanding agreement.",
                 "zcheck"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(ZCHECK_VERSION));

    CheckOptions check;
    CLI::App* checkCommand = app.add_subcommand(
        "check", "Check one scene through one camera: ray route vs raster route, per pixel.\n"
                 "Exit status 0 consistent, 1 inconsistent, 2 usage or input error.");
    addSceneAndCameraOptions(checkCommand, check.scene, check.cameraFile, check.convention);
    checkCommand->add_option("--width", check.width, "override the image width in pixels (1..16384)")->check(kImageSideRange);
    checkCommand->add_option("--height", check.height, "override the image height in pixels (1..16384)")->check(kImageSideRange);
    checkCommand->add_option("--depth-format", check.depthFormat, "override the depth format: float32 | unorm24 | unorm16");
    checkCommand->add_flag("--reversed-z", check.reversedZ, "use reversed-Z (near -> far end of the range, test GREATER)");
    checkCommand->add_option("--out", check.outDir,
                             "write ray_depth.exr, raster_depth.exr, error_heatmap.png, coverage_classes.png "
                             "and report.json into this directory (all or none of them: see README)")
        ->check(kNonEmptyPath);
    checkCommand->add_flag("--json", check.json, "print the report as JSON instead of the summary");
    checkCommand->footer(
        "Examples:\n"
        "  zcheck check                                      the built-in default scene, its own camera\n"
        "  zcheck check --scene bunny.obj --convention direct3d --reversed-z --depth-format unorm24\n"
        "  zcheck check --camera examples/frustum.json --out results/   camera file; images + report.json\n"
        "  zcheck check --scene 'builtin:terrain?n=708' --width 1920 --height 1080 --json\n"
        "Depths are compared as window depth (the depth-buffer value) per pixel; the tolerance is\n"
        "C*q + S*m (q: storage quantum, m: depth slope per pixel, S = 2^-8 px). See README.md.");
    checkCommand->add_option("--threads", check.threads, "worker threads, 1..1024 (default: all cores)")->check(kThreadRange);

    std::string matricesCamera, matricesConvention;
    CLI::App* matricesCommand = app.add_subcommand(
        "matrices", "Print a camera's transforms as JSON: eye_from_world, world_from_eye, clip_from_eye,\n"
                    "eye_from_clip, clip_from_world, window_from_ndc, ndc_from_window (4 rows of 4, column\n"
                    "vectors p' = M·p), and a 'native' block in the convention's own form (row vectors for\n"
                    "direct3d).");
    matricesCommand->add_option("--camera", matricesCamera, "camera file (JSON, see README)")->required()->check(kNonEmptyPath);
    matricesCommand->add_option("--convention", matricesConvention, "override the convention");

    std::string precisionCamera, precisionConvention, precisionAt;
    bool precisionJson = false;
    CLI::App* precisionCommand = app.add_subcommand(
        "precision", "How finely each depth layout (unorm16, unorm24, float32 x standard, reversed, infinite far)\n"
                     "resolves eye depth for a camera's near/far: the eye-z step between neighbouring stored\n"
                     "values at each distance, and which layout is best.");
    precisionCommand->add_option("--camera", precisionCamera, "camera file (JSON, see README)")->required()->check(kNonEmptyPath);
    precisionCommand->add_option("--at", precisionAt, "eye-z distances, comma-separated (default: 9 log-spaced from near to far)")
        ->check(kNonEmptyList);
    precisionCommand->add_option("--convention", precisionConvention, "override the convention");
    precisionCommand->add_flag("--json", precisionJson, "print JSON instead of tables");

    UnprojectOptions unproject;
    CLI::App* unprojectCommand = app.add_subcommand(
        "unproject", "The inverse projection: the ray through a pixel centre, the point at a depth value, or a\n"
                     "whole depth map (EXR, PFM, TIFF, 16-bit PNG with --scale) as a PLY point cloud, misses skipped.");
    unprojectCommand->add_option("--camera", unproject.cameraFile, "camera file (JSON, see README)")->required()->check(kNonEmptyPath);
    unprojectCommand->add_option("--convention", unproject.convention, "override the convention");
    unprojectCommand->add_option("--pixel", unproject.pixel, "COL,ROW (row 0 at the top): print the ray through its centre");
    unprojectCommand->add_option("--depth", unproject.depth, "with --pixel: print the point at this depth value");
    unprojectCommand->add_option("--quantity", unproject.quantity, "what --depth / the map holds: window | ndc | eye-z | distance")
        ->capture_default_str();
    unprojectCommand->add_option("--depth-map", unproject.depthMap, "a depth map to turn into a point cloud")->check(kNonEmptyPath);
    unprojectCommand->add_option("--scale", unproject.scale, "stored value = depth x scale (required for 16-bit PNG)")
        ->check(kPositiveFinite);
    unprojectCommand->add_option("-o,--output", unproject.output, "the PLY file to write (atomically)")->check(kNonEmptyPath);
    unprojectCommand->add_option("--space", unproject.space, "eye | world coordinates for points")->capture_default_str();
    unprojectCommand->add_option("--stride", unproject.stride, "use every K-th pixel in x and y, 1..16384")
        ->capture_default_str()
        ->check(kImageSideRange);
    unprojectCommand->add_flag("--ascii", unproject.ascii, "write ASCII PLY instead of binary little-endian");

    ExportOptions exportOptions;
    CLI::App* exportCommand = app.add_subcommand(
        "export", "Render depth with one route and write it as EXR, PFM, TIFF or 16-bit PNG, with a JSON sidecar\n"
                  "(FILE.json) that says everything needed to read it: quantity, unit, miss value, orientation,\n"
                  "camera and matrices.");
    exportCommand->add_option("--backend", exportOptions.backend, "ray | raster")->capture_default_str();
    exportCommand->add_option("--quantity", exportOptions.quantities,
                              "comma-separated: window, ndc, eye-z, distance, position-eye, position-world, normal, "
                              "primitive-id (several only into .exr)")
        ->capture_default_str();
    addSceneAndCameraOptions(exportCommand, exportOptions.scene, exportOptions.cameraFile, exportOptions.convention);
    exportCommand->add_option("-o,--output", exportOptions.output, "FILE.exr | .pfm | .tif | .png (written atomically)")
        ->check(kNonEmptyPath);
    exportCommand->add_option("--scale", exportOptions.scale, "16-bit PNG: stored = value x scale (e.g. 1000 = millimetres)")
        ->check(kPositiveFinite);
    exportCommand->add_option("--preview", exportOptions.preview, "also write an 8-bit colour-mapped PNG of the first quantity")
        ->check(kNonEmptyPath);
    exportCommand->add_option("--threads", exportOptions.threads, "worker threads, 1..1024 (default: all cores)")
        ->check(kThreadRange);

    VerifyOptions verify;
    CLI::App* verifyCommand = app.add_subcommand(
        "verify", "Compare a depth map rendered elsewhere (a GPU, an engine, Blender, a simulator) against Embree's\n"
                  "ground truth for the same scene and camera, with the same tolerance model, report and exit codes\n"
                  "as check; --diagnose names the classic mistake that explains an inconsistent map.");
    addSceneAndCameraOptions(verifyCommand, verify.scene, verify.cameraFile, verify.convention);
    verifyCommand->add_option("--depth-map", verify.depthMap, "EXR, PFM, TIFF, or 16-bit PNG with --scale")
        ->required()
        ->check(kNonEmptyPath);
    verifyCommand->add_option("--quantity", verify.quantity, "what the map holds: window | ndc | eye-z | distance")
        ->capture_default_str();
    verifyCommand->add_option("--scale", verify.scale, "stored value = depth x scale (required for integer files)")
        ->check(kPositiveFinite);
    verifyCommand->add_flag("--diagnose", verify.diagnose, "when inconsistent, test the classic hypotheses and name the one that fits");
    verifyCommand->add_option("--out", verify.outDir, "write truth and map depth EXRs, heatmap, classes and report.json")
        ->check(kNonEmptyPath);
    verifyCommand->add_option("--threads", verify.threads, "worker threads, 1..1024 (default: all cores)")->check(kThreadRange);
    verifyCommand->add_flag("--json", verify.json, "print the report as JSON");

    SuiteOptions suite;
    CLI::App* suiteCommand = app.add_subcommand(
        "suite", "Run the consistency suite: every configuration clean (no false positive allowed) and with each\n"
                 "fault of the catalogue injected into one route (each applicable fault must be detected).\n"
                 "Exit status 0 only when both hold.");
    suiteCommand->add_flag("--quick", suite.quick, "a representative subset (what CTest runs)");
    suiteCommand->add_option("--filter", suite.filter, "only configurations whose label contains TEXT");
    suiteCommand->add_option("--json", suite.jsonFile, "write the results as JSON")->check(kNonEmptyPath);
    suiteCommand->add_option("--html", suite.htmlFile, "write a self-contained HTML report with images of every failure")
        ->check(kNonEmptyPath);
    suiteCommand->add_option("--models", suite.modelsDir, "folder of the shared meshes")->capture_default_str()->check(kNonEmptyPath);
    suiteCommand->add_option("--threads", suite.threads, "worker threads, 1..1024 (default: all cores)")->check(kThreadRange);

    // CLI11 says only "a subcommand is required" for a misspelt one: name it.
    if (argc > 1 && argv[1][0] != '-') {
        std::string names;
        bool found = false;
        for (const CLI::App* command : app.get_subcommands({})) {
            found = found || command->get_name() == argv[1];
            names += (names.empty() ? "" : ", ") + command->get_name();
        }
        if (!found) {
            std::cerr << "zcheck: error: unknown command '" << argv[1] << "' (expected one of: " << names
                      << "; see 'zcheck --help')\n";
            return kExitUsage;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "zcheck: error: " << e.what() << " (see 'zcheck --help')\n";
        return kExitUsage;
    }

    try {
        if (checkCommand->parsed()) return runCheckCommand(check);
        if (matricesCommand->parsed()) return runMatricesCommand(matricesCamera, matricesConvention);
        if (unprojectCommand->parsed()) return runUnprojectCommand(unproject);
        if (exportCommand->parsed()) return runExportCommand(exportOptions);
        if (suiteCommand->parsed()) return runSuiteCommand(suite);
        if (verifyCommand->parsed()) return runVerifyCommand(verify);
        if (precisionCommand->parsed())
            return runPrecisionCommand(precisionCamera, precisionConvention, precisionAt, precisionJson);
    } catch (const zcheck::Error& e) {
        std::cerr << "zcheck: error: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::bad_alloc&) {
        std::cerr << "zcheck: internal error: out of memory (the mesh or the image is too large for this machine)\n";
        return kExitInternal;
    } catch (const std::exception& e) {
        std::string what = e.what();
        for (char& c : what)
            if (c == '\n' || c == '\r') c = ' ';
        std::cerr << "zcheck: internal error: " << what << "\n";
        return kExitInternal;
    }
    return kExitInternal;
}
