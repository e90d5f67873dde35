#include "zcheck/suite.h"

#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/mesh_loader.h"

#include <cmath>
#include <filesystem>
#include <memory>

namespace zcheck {

std::vector<NamedCamera> cameraModels(const Scene& scene, int width, int height)
{
    CameraSpec base = scene.defaultCamera;
    base.width = width, base.height = height;
    const Camera reference(base);
    const double n = base.projection.near;
    const double distance = glm::length(base.view.target - base.view.eye);
    const double tanHalf = std::tan(glm::radians(base.projection.fovyDeg) / 2), aspect = double(width) / height;
    std::vector<NamedCamera> out;
    auto add = [&](const std::string& name, const CameraSpec& spec) { out.push_back({name, spec}); };

    add("perspective", base);
    CameraSpec infinite = base;
    infinite.projection.far = INFINITY;
    add("perspective far=inf", infinite);

    CameraSpec frustum = base;
    frustum.projection.type = ProjectionType::Frustum;
    frustum.projection.left = -0.6 * n * tanHalf * aspect, frustum.projection.right = 1.1 * n * tanHalf * aspect;
    frustum.projection.bottom = -0.9 * n * tanHalf, frustum.projection.top = 0.7 * n * tanHalf;
    add("frustum", frustum);

    CameraSpec pinhole = base;
    pinhole.projection.type = ProjectionType::Pinhole;
    pinhole.projection.fx = height / 2.0 / tanHalf * 1.02, pinhole.projection.fy = height / 2.0 / tanHalf;
    pinhole.projection.cx = (width - 1) / 2.0 + width / 24.0, pinhole.projection.cy = (height - 1) / 2.0 - height / 33.0;
    add("pinhole", pinhole);

    CameraSpec lens = base;
    lens.projection.type = ProjectionType::Lens;
    lens.projection.focalMm = 18.0 / (tanHalf * aspect);
    add("lens", lens);

    CameraSpec ortho = base;
    ortho.projection.type = ProjectionType::Orthographic;
    const double halfHeight = distance * tanHalf;
    ortho.projection.left = -halfHeight * aspect, ortho.projection.right = halfHeight * aspect * 0.9;
    ortho.projection.bottom = -halfHeight * 1.1, ortho.projection.top = halfHeight;
    add("orthographic", ortho);

    for (auto [name, lambda, angle] : {std::tuple{"oblique cavalier", 1.0, 45.0}, std::tuple{"oblique cabinet", 0.5, 63.4}}) {
        CameraSpec oblique = ortho;
        oblique.projection.type = ProjectionType::Oblique;
        oblique.projection.foreshortening = lambda, oblique.projection.angleDeg = angle;
        // Keep the sheared depth range short so that the scene stays in view.
        oblique.projection.near = std::max(n, distance * 0.5), oblique.projection.far = distance * 1.6;
        add(name, oblique);
    }
    for (auto [kind, azimuth, elevation] : {std::tuple{"isometric", 45.0, 35.2643896827547}, std::tuple{"dimetric", 45.0, 30.0},
                                            std::tuple{"trimetric", 25.0, 20.0}}) {
        CameraSpec axonometric = ortho;
        axonometric.view = View::axonometricView(kind, base.view.target, distance, azimuth, elevation);
        axonometric.projection.near = distance * 0.05, axonometric.projection.far = distance * 3;
        add(std::string("axonometric ") + kind, axonometric);
    }

    CameraSpec matrix = base;  // the perspective camera's own matrices, pasted raw
    matrix.projection.type = ProjectionType::Matrix;
    matrix.projection.clipFromEye = reference.clipFromEye;
    matrix.view.hasMatrix = true;
    matrix.view.eyeFromWorld = reference.eyeFromWorld;
    add("matrix", matrix);
    return out;
}

// A raw-matrix camera's matrices must belong to its convention and depth mapping.
CameraSpec withDepthAndConvention(CameraSpec spec, const Scene& scene, const Convention& convention, DepthSettings depth)
{
    spec.convention = convention;
    spec.depth = depth;
    if (isRawMatrix(spec.projection)) {
        CameraSpec perspective = scene.defaultCamera;
        perspective.width = spec.width, perspective.height = spec.height;
        perspective.convention = convention, perspective.depth = depth;
        const Camera source(perspective);
        spec.projection.clipFromEye = source.clipFromEye;
        spec.view.eyeFromWorld = source.eyeFromWorld;
    }
    return spec;
}

std::string SuiteConfig::label() const
{
    return scene + " | " + model + " | " + spec.convention.name + " " + toString(spec.depth.format) +
           (spec.depth.reversed ? " reversed" : "") + " | " + std::to_string(spec.width) + "x" +
           std::to_string(spec.height) + (!isRawMatrix(spec.projection) && !std::isinf(spec.projection.far) &&
                                                  spec.projection.far / spec.projection.near > 1e6
                                              ? " | near/far " + formatNumber(spec.projection.far / spec.projection.near)
                                              : "");
}

std::vector<std::string> suiteScenes(bool quick, const std::string& modelsDir)
{
    std::vector<std::string> scenes = quick ? std::vector<std::string>{"builtin:default", "builtin:near-crossing"}
                                            : std::vector<std::string>{"builtin:default", "builtin:terrain?n=96",
                                                                       "builtin:near-crossing"};
    if (!modelsDir.empty())
        for (const char* model : {"stanford-bunny.obj", "spot.obj", "teapot.obj", "suzanne.obj"}) {
            scenes.push_back((std::filesystem::path(modelsDir) / model).string());
            if (quick) break;
        }
    return scenes;
}

std::string suiteSceneLabel(const std::string& scenePath)
{
    return isBuiltinSceneName(scenePath) ? scenePath : std::filesystem::path(scenePath).filename().string();
}

std::vector<SuiteConfig> suiteConfigurations(bool quick, const std::string& modelsDir)
{
    const std::vector<std::string> scenes = suiteScenes(quick, modelsDir);
    const std::vector<std::pair<int, int>> sizes = {{320, 240}, {333, 257}, {256, 256}, {160, 300}};
    const std::vector<std::string>& conventions = Convention::presetNames();
    const DepthFormat formats[] = {DepthFormat::Float32, DepthFormat::Unorm24, DepthFormat::Unorm16};
    const int variants = quick ? 1 : 4;
    std::vector<SuiteConfig> configs;
    for (std::size_t si = 0; si < scenes.size(); ++si) {
        const Scene scene = loadScene(scenes[si]);
        const std::string sceneLabel = suiteSceneLabel(scenes[si]);
        for (int v = 0; v < variants; ++v) {
            const auto [width, height] = sizes[(si + std::size_t(v)) % sizes.size()];
            const std::vector<NamedCamera> models = cameraModels(scene, width, height);
            for (std::size_t mi = 0; mi < models.size(); ++mi) {
                if (quick && mi % 3 != 0) continue;  // perspective, pinhole, oblique cavalier, dimetric
                const std::size_t k = si * 7 + mi * 3 + std::size_t(v) * 5;
                DepthSettings depth;
                depth.format = formats[(si + mi + std::size_t(v)) % 3];
                depth.reversed = (mi + std::size_t(v) + si) % 2 == 1;
                const Convention convention = Convention::preset(conventions[k % conventions.size()]);
                configs.push_back({scenes[si], sceneLabel, models[mi].name,
                                   withDepthAndConvention(models[mi].spec, scene, convention, depth)});
            }
        }
        // Extreme near/far ratios: a tiny near plane, a far plane 1e7 times farther.
        for (bool reversed : {false, true}) {
            CameraSpec spec = scene.defaultCamera;
            spec.width = 320, spec.height = 240;
            spec.projection.near *= 1e-3;
            spec.projection.far = spec.projection.near * 1e7;
            spec.depth.format = reversed ? DepthFormat::Float32 : DepthFormat::Unorm24;
            spec.depth.reversed = reversed;
            spec.convention = Convention::preset(conventions[(si + (reversed ? 2 : 0)) % conventions.size()]);
            if (!quick || si == 0) configs.push_back({scenes[si], sceneLabel, "perspective", spec});
        }
    }
    return configs;
}

// Does `faulty` differ visibly from its clean twin? See suite.h: coverage compared raw, depth
// beyond twice the snapping noise of the clean twin's triangle (4 q + 2·S·m); none of the
// checker's explanations (edges, clip planes, clear value) are used.
bool differsVisibly(const Scene& scene, const Camera& camera, const RenderResult& clean, const RenderResult& faulty)
{
    const double S = ToleranceModel{}.snapPixels();
    std::size_t different = 0;
    for (std::size_t i = 0; i < clean.primitiveId.size(); ++i) {
        if (clean.hit(i) != faulty.hit(i)) {
            ++different;
        } else if (clean.hit(i)) {
            const glm::uvec3 t = scene.triangles[clean.primitiveId[i]];
            const double m = windowDepthSlope(camera, scene.worldPosition(t[0]), scene.worldPosition(t[1]),
                                              scene.worldPosition(t[2]));
            const double q = storageQuantum(camera.depth().format, clean.windowDepth.value[i]);
            if (!(std::abs(faulty.windowDepth.value[i] - clean.windowDepth.value[i]) <= 4 * q + 2 * S * m)) ++different;
        }
    }
    return different >= std::max<std::size_t>(10, clean.primitiveId.size() / 1000);
}

std::string toString(FaultResult result)
{
    switch (result) {
    case FaultResult::Detected: return "detected";
    case FaultResult::Missed: return "MISSED";
    case FaultResult::NotApplicable: return "not applicable";
    case FaultResult::Meaningless: return "-";
    }
    return "?";
}

std::vector<FaultTally> tallyFaults(const SuiteResult& result)
{
    std::vector<FaultTally> tally(injectableMistakes().size());
    for (const auto& outcome : result.outcomes)
        for (std::size_t k = 0; k < outcome.faults.size(); ++k) switch (outcome.faults[k]) {
            case FaultResult::Detected: ++tally[k].detected; break;
            case FaultResult::Missed: ++tally[k].missed; break;
            case FaultResult::NotApplicable: ++tally[k].notApplicable; break;
            case FaultResult::Meaningless: ++tally[k].meaningless; break;
            }
    return tally;
}

SuiteResult runSuite(const std::vector<SuiteConfig>& configs,
                     const std::function<void(std::size_t, std::size_t, const ConfigOutcome&)>& progress)
{
    constexpr std::size_t kKeptFailures = 24;  // with their images, for the HTML report
    SuiteResult result;
    const std::vector<const Mistake*> mistakes = injectableMistakes();
    std::string loadedPath;
    std::unique_ptr<Checker> checker;
    auto keep = [&](const SuiteConfig& config, const std::string& what, CheckResult run) {
        if (result.failures.size() < kKeptFailures) result.failures.push_back({config.label(), what, std::move(run)});
    };
    for (std::size_t index = 0; index < configs.size(); ++index) {
        const SuiteConfig& config = configs[index];
        const auto start = Clock::now();
        if (config.scenePath != loadedPath) {  // configurations come grouped by scene: build each once
            checker.reset();
            checker = std::make_unique<Checker>(loadScene(config.scenePath));
            loadedPath = config.scenePath;
        }
        const Scene& scene = checker->scene();
        const Camera camera(config.spec);
        CheckResult clean = checker->check(camera);
        ConfigOutcome outcome{config, clean.report.comparison, {}, 0};
        if (!outcome.clean.consistent()) {
            ++result.falsePositives;
            keep(config, "clean chain reported inconsistent (a false positive)", clean);
        }
        for (const Mistake* mistake : mistakes) {
            RouteFaults faults;
            if (!mistake->inject(camera, faults)) {
                outcome.faults.push_back(FaultResult::Meaningless);
                continue;
            }
            // The faulty route, its clean twin, and the route it is checked against.
            CheckResult faulty = clean;
            bool applicable;
            if (mistake->route == Route::Ray) {
                faulty.ray = checker->renderRay(camera, faults.ray);
                applicable = differsVisibly(scene, camera, clean.ray, faulty.ray);
            } else {
                faulty.raster = checker->renderRaster(camera, faults.raster);
                applicable = differsVisibly(scene, camera, clean.raster, faulty.raster);
            }
            faulty.comparison = compareRoutes(scene, camera, faulty.ray, faulty.raster);
            faulty.report.comparison = faulty.comparison.report;
            const bool detected = !faulty.comparison.report.consistent();
            const FaultResult r = detected ? FaultResult::Detected : applicable ? FaultResult::Missed : FaultResult::NotApplicable;
            outcome.faults.push_back(r);
            if (r == FaultResult::Missed) {
                ++result.missedFaults;
                keep(config, "fault '" + mistake->name + "' (" + mistake->description + ") not detected", std::move(faulty));
            }
        }
        outcome.milliseconds = millisecondsSince(start);
        result.outcomes.push_back(outcome);
        progress(index + 1, configs.size(), result.outcomes.back());
    }
    return result;
}

}  // namespace zcheck
