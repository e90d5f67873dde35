// The suite's lens part (suite.h): lens cameras clean, and each mistake of the lens family
// (lens_mistakes.h) injected by rendering the map the mistaken renderer delivers.
#include "zcheck/suite.h"

#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/lens_mistakes.h"
#include "zcheck/map_verifier.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/verify_map.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

namespace zcheck {

namespace {

constexpr double kDegree = 3.14159265358979323846 / 180;
// Small images: every mistake of a configuration is verified and diagnosed in full.
constexpr int kLensSuiteWidth = 128, kLensSuiteHeight = 96;

// A lens camera at the scene camera's eye, looking where it looks.
CameraSpec lensCamera(const CameraSpec& base, int width, int height, LensSpec lens, const std::string& convention)
{
    CameraSpec spec;
    spec.convention = Convention::preset(convention);
    spec.width = width, spec.height = height;
    spec.projection.type = ProjectionType::NonLinear;
    spec.projection.lens = std::move(lens);
    spec.projection.near = base.projection.near;
    spec.projection.far = std::isfinite(base.projection.far) ? base.projection.far : 1e4 * base.projection.near;
    spec.view = View::lookAt(base.view.eye, base.view.target, base.view.up);
    return spec;
}

// Double sphere's image radius (fx = 1) of a direction θ off the axis (Usenko et al. 2018).
double doubleSphereRadius(double xi, double alpha, double theta)
{
    const double x = std::sin(theta), z = std::cos(theta);
    const double d2 = std::sqrt(x * x + (xi + z) * (xi + z));
    return x / (alpha * d2 + (1 - alpha) * (xi + z));
}

}  // namespace

std::string LensSuiteConfig::label() const
{
    return scene + " | " + model + " " + magnitude + " | " + toString(quantity) + " | " + spec.convention.name + " | " +
           std::to_string(spec.width) + "x" + std::to_string(spec.height);
}

std::vector<LensSuiteConfig> lensCameras(const Scene& scene, const std::string& scenePath, const std::string& sceneLabel,
                                         int width, int height)
{
    const CameraSpec& base = scene.defaultCamera;
    const double halfFovy = base.projection.fovyDeg * kDegree / 2;
    const double halfFovx = std::atan(std::tan(halfFovy) * width / height);
    // The principal point a little off the centre: a flipped picture and cx, cy exchanged differ.
    const double cx = (width - 1) / 2.0 + width / 40.0, cy = (height - 1) / 2.0 - height / 50.0;
    // A perspective lens frames the scene camera's vertical field; Kannala–Brandt spans it as an
    // equidistant fisheye (θ = r/f) one and a half times over.
    const double f = height / 2.0 / std::tan(halfFovy), fFisheye = height / 2.0 / (1.5 * halfFovy);
    const auto withK = [&](double focal, std::initializer_list<double> coefficients) {
        std::vector<double> params = {focal, focal, cx, cy};
        params.insert(params.end(), coefficients);
        return params;
    };
    struct Row {
        const char* model;
        const char* magnitude;
        LensSpec lens;
        DepthQuantity quantity;
    };
    std::vector<Row> rows = {
        // k1 k2 p1 p2 k3: a mild barrel, and a strong one (a wide-angle action camera's).
        {"opencv", "mild", {"opencv", withK(f, {-0.06, 0.015, 6e-4, -4e-4, -0.002})}, DepthQuantity::EyeZ},
        {"opencv", "strong", {"opencv", withK(f, {-0.28, 0.09, 2.2e-3, -1.6e-3, -0.015})}, DepthQuantity::Distance},
        // k1 k2 p1 p2 k3 k4 k5 k6: the rational model as calibrations return it, numerator and
        // denominator both large.
        {"opencv rational", "mild", {"opencv", withK(f, {0.35, -0.02, 5e-4, 3e-4, 0.001, 0.42, 0.01, 0.002})}, DepthQuantity::Distance},
        {"opencv rational", "strong", {"opencv", withK(f, {1.2, 0.5, 1.5e-3, -1e-3, 0.02, 1.5, 0.9, 0.08})}, DepthQuantity::EyeZ},
        // k1 k2 k3 k4 of cv::fisheye.
        {"opencv_fisheye", "mild", {"opencv_fisheye", withK(fFisheye, {0.012, -0.003, 5e-4, -1e-4})}, DepthQuantity::EyeZ},
        {"opencv_fisheye", "strong", {"opencv_fisheye", withK(fFisheye, {0.09, -0.035, 0.008, -0.001})}, DepthQuantity::Distance},
    };
    // Double sphere (ξ, α) seeing 110° off the axis at the image's corners: the object in the
    // middle, the corners behind the camera's plane — distance maps only.
    const double halfDiagonal = std::hypot(width / 2.0, height / 2.0);
    for (const auto& [magnitude, xi, alpha] : {std::tuple{"mild", -0.15, 0.55}, std::tuple{"strong", 0.25, 0.62}}) {
        const double focal = halfDiagonal / doubleSphereRadius(xi, alpha, 110 * kDegree);
        std::vector<double> params = {focal, focal, cx, cy, xi, alpha};
        rows.push_back({"double_sphere", magnitude, {"double_sphere", params}, DepthQuantity::Distance});
    }
    // A panorama: the part of the sphere around the scene's view (1.3 times its field), and the whole sphere.
    const double lon = 1.3 * halfFovx / kDegree, lat = 1.3 * halfFovy / kDegree;
    rows.push_back({"equirectangular", "part", {"equirectangular", {-lon, lon, -lat, lat}}, DepthQuantity::EyeZ});
    rows.push_back({"equirectangular", "sphere", {"equirectangular", {-180, 180, -90, 90}}, DepthQuantity::Distance});

    const std::vector<std::string>& conventions = Convention::presetNames();
    std::vector<LensSuiteConfig> out;
    for (std::size_t k = 0; k < rows.size(); ++k) {
        const std::string& convention = conventions[(k + sceneLabel.size()) % conventions.size()];
        out.push_back({scenePath, sceneLabel, rows[k].model, rows[k].magnitude,
                       lensCamera(base, width, height, rows[k].lens, convention), rows[k].quantity});
    }
    return out;
}

std::vector<LensSuiteConfig> lensSuiteConfigurations(bool quick, const std::string& modelsDir)
{
    std::vector<LensSuiteConfig> out;
    for (const std::string& path : suiteScenes(false, modelsDir)) {
        const Scene scene = loadScene(path);
        std::vector<LensSuiteConfig> cameras = lensCameras(scene, path, suiteSceneLabel(path), kLensSuiteWidth, kLensSuiteHeight);
        if (quick) {
            // builtin:default alone, one magnitude of each model (the strong ones where there are
            // two); between them every mistake of the family and both quantities.
            for (const std::size_t k : {1, 3, 5, 6, 8}) out.push_back(cameras[k]);
            break;
        }
        if (isBuiltinSceneName(path)) {  // the built-ins at both magnitudes
            out.insert(out.end(), cameras.begin(), cameras.end());
        } else {  // a shared mesh at one magnitude of each model, alternating from mesh to mesh
            const std::size_t meshes = out.size();
            for (std::size_t k = 0; k < cameras.size(); k += 2) out.push_back(cameras[k + (k / 2 + meshes) % 2]);
        }
    }
    return out;
}

namespace {

// Does `wrong` differ visibly from `clean` (suite.h): coverage, or the value beyond 4 q + 2·S·m,
// judged from the two maps alone.
bool mapsDifferVisibly(const Camera& camera, const DepthMap& clean, const DepthMap& wrong)
{
    constexpr double kSnap = 1.0 / 256;
    const int W = clean.width, H = clean.height;
    const auto depth = [&](const DepthMap& map, int col, int row) -> std::optional<double> {
        if (col < 0 || row < 0 || col >= W || row >= H) return std::nullopt;
        const double v = map.value[std::size_t(row) * W + col];
        if (kindOfDepthValue(camera, map.quantity, v) != DepthValueKind::Depth) return std::nullopt;
        return v;
    };
    std::size_t different = 0;
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::optional<double> a = depth(clean, col, row), b = depth(wrong, col, row);
            if (a.has_value() != b.has_value()) {
                ++different;
                continue;
            }
            if (!a) continue;
            double slope = 0;
            for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
                double steepest = 0;
                for (const int sign : {-1, 1})
                    if (const std::optional<double> n = depth(clean, col + sign * dx, row + sign * dy))
                        steepest = std::max(steepest, std::abs(*n - *a));
                slope += steepest;
            }
            const double q = storageQuantum(DepthFormat::Float32, *a);
            if (!(std::abs(*b - *a) <= 4 * q + 2 * kSnap * slope)) ++different;
        }
    return different >= std::max<std::size_t>(10, std::size_t(W) * H / 1000);
}

LensFaultOutcome injected(const MapVerifier& verifier, const Camera& camera, DepthQuantity quantity, const DepthMap& clean,
                          const LensMistake& mistake)
{
    LensFaultOutcome out{mistake.name, mistake.variant, FaultResult::Meaningless, false, ""};
    DepthMap wrong;
    try {
        wrong = mistakenMap(verifier.checker(), camera, quantity, mistake);
    } catch (const Error&) {  // the mistaken camera is no camera: no renderer made that map
        return out;
    }
    // Detection is verify's verdict alone (a refusal counts: the map is not taken); the
    // diagnosis only names what was detected.
    bool detected;
    VerifiedMap verified;
    try {
        verified = verifyMap(verifier, camera, wrong, true);
        detected = !verified.run.comparison.report.consistent();
    } catch (const Error& e) {
        detected = true;
        out.diagnosedAs = std::string("refused: ") + e.what();
    }
    out.result = detected ? FaultResult::Detected
                 : mapsDifferVisibly(camera, clean, wrong) ? FaultResult::Missed
                                                             : FaultResult::NotApplicable;
    if (detected && verified.diagnosed) {
        const std::vector<Hypothesis>& d = verified.diagnosis;
        if (d.empty() || !d.front().explains()) {
            out.diagnosedAs = "none";
        } else {
            out.diagnosedAs = d.front().name + (d.front().variant.empty() ? "" : " (" + d.front().variant + ")");
            out.named = d.front().name == mistake.name;
        }
    }
    return out;
}

}  // namespace

std::vector<LensFaultTally> tallyLensFaults(const LensSuiteResult& result)
{
    std::vector<LensFaultTally> rows;
    std::map<std::pair<std::string, std::string>, std::size_t> index;
    for (const auto& outcome : result.outcomes)
        for (const LensFaultOutcome& f : outcome.faults) {
            auto [at, added] = index.try_emplace({f.name, f.variant}, rows.size());
            if (added) rows.push_back({f.name, f.variant});
            LensFaultTally& row = rows[at->second];
            if (f.result == FaultResult::Meaningless) continue;
            ++row.configurations;
            row.detected += f.result == FaultResult::Detected;
            row.missed += f.result == FaultResult::Missed;
            row.notApplicable += f.result == FaultResult::NotApplicable;
            row.named += f.named;
        }
    return rows;
}

LensSuiteResult runLensSuite(const std::vector<LensSuiteConfig>& configs,
                             const std::function<void(std::size_t, std::size_t, const LensConfigOutcome&)>& progress)
{
    LensSuiteResult result;
    std::string loadedPath;
    std::unique_ptr<MapVerifier> verifier;
    std::unique_ptr<Checker> checker;
    for (std::size_t index = 0; index < configs.size(); ++index) {
        const LensSuiteConfig& config = configs[index];
        const auto start = Clock::now();
        if (config.scenePath != loadedPath) {  // configurations come grouped by scene: build each once
            verifier.reset(), checker.reset();
            checker = std::make_unique<Checker>(loadScene(config.scenePath));
            verifier = std::make_unique<MapVerifier>(*checker);
            loadedPath = config.scenePath;
        }
        const Camera camera(config.spec);
        LensConfigOutcome outcome{config, checker->check(camera).report.comparison, {}, {}, 0};
        const DepthMap clean = renderedMap(*checker, camera, config.quantity);
        outcome.cleanMap = verifier->verify(camera, clean).comparison.report;
        result.falsePositives += outcome.clean() ? 0 : 1;
        for (const LensMistake& mistake : lensMistakes(camera, config.quantity)) {
            outcome.faults.push_back(injected(*verifier, camera, config.quantity, clean, mistake));
            const LensFaultOutcome& f = outcome.faults.back();
            result.missedFaults += f.result == FaultResult::Missed;
            result.misnamedFaults += f.result == FaultResult::Detected && !f.named;
        }
        outcome.milliseconds = millisecondsSince(start);
        result.outcomes.push_back(std::move(outcome));
        progress(index + 1, configs.size(), result.outcomes.back());
    }
    return result;
}

}  // namespace zcheck
