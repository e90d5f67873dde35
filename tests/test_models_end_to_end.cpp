// Every projection model and view is consistent through both routes, in every convention,
// float32 and unorm24, standard and reversed (and with an infinite far plane where it
// applies), on built-in scenes and the shared meshes.
#include "check.h"

#include "zcheck/mesh_loader.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace zcheck;

namespace {

const std::string kModels = ZCHECK_MODELS_DIR;

struct NamedCamera {
    std::string name;
    CameraSpec spec;
};

// The models, all framing what the scene's own (perspective) camera frames.
std::vector<NamedCamera> cameraModels(const Scene& scene)
{
    CameraSpec base = scene.defaultCamera;
    base.width = 320, base.height = 240;
    const Camera reference(base);
    const double n = base.projection.near, f = base.projection.far;
    const double distance = glm::length(base.view.target - base.view.eye);
    const double tanHalf = std::tan(glm::radians(base.projection.fovyDeg) / 2), aspect = 320.0 / 240.0;
    std::vector<NamedCamera> out;
    auto add = [&](const std::string& name, CameraSpec spec) { out.push_back({name, spec}); };

    add("perspective", base);
    CameraSpec infinite = base;
    infinite.projection.far = INFINITY;
    add("perspective far=inf", infinite);

    CameraSpec frustum = base;
    frustum.projection.type = ProjectionType::Frustum;
    frustum.projection.left = -0.6 * n * tanHalf * aspect, frustum.projection.right = 1.1 * n * tanHalf * aspect;
    frustum.projection.bottom = -0.9 * n * tanHalf, frustum.projection.top = 0.7 * n * tanHalf;
    add("frustum (off-axis)", frustum);

    CameraSpec pinhole = base;
    pinhole.projection.type = ProjectionType::Pinhole;
    pinhole.projection.fx = 120.0 / tanHalf * 1.02, pinhole.projection.fy = 120.0 / tanHalf;
    pinhole.projection.cx = (320 - 1) / 2.0 + 13.5, pinhole.projection.cy = (240 - 1) / 2.0 - 7.25;
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
    (void)f;
    return out;
}

void requireEveryModelConsistent(const std::string& sceneName)
{
    const Scene scene = loadScene(sceneName);
    const RayRenderer rays(scene);
    const RasterRenderer raster(scene);
    for (const NamedCamera& model : cameraModels(scene))
        for (const auto& convention : Convention::presetNames())
            for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24})
                for (bool reversed : {false, true}) {
                    CameraSpec spec = model.spec;
                    spec.convention = Convention::preset(convention);
                    spec.depth.format = format;
                    spec.depth.reversed = reversed;
                    if (spec.projection.type == ProjectionType::Matrix) {
                        // The raw matrices must be the ones of this convention and depth mapping.
                        CameraSpec perspective = scene.defaultCamera;
                        perspective.width = 320, perspective.height = 240;
                        perspective.convention = spec.convention, perspective.depth = spec.depth;
                        const Camera source(perspective);
                        spec.projection.clipFromEye = source.clipFromEye;
                        spec.view.eyeFromWorld = source.eyeFromWorld;
                    }
                    const ComparisonReport r = runCheck(scene, Camera(spec), rays, raster).report.comparison;
                    INFO(sceneName << ": " << model.name << ", " << convention << ", " << toString(format)
                                   << (reversed ? ", reversed" : "") << ": both hit " << r.bothHit << ", depth errors "
                                   << r.depthErrors << ", unexplained coverage " << r.coverageUnexplained
                                   << ", max/tol " << r.maxErrorOverTolerance);
                    REQUIRE(r.bothHit > 300);  // the model sees the scene
                    REQUIRE(r.consistent());
                }
}

}  // namespace

TEST_CASE("every model is consistent on builtin:default", "[e2e][models]") { requireEveryModelConsistent("builtin:default"); }
TEST_CASE("every model is consistent on builtin:terrain", "[e2e][models]") { requireEveryModelConsistent("builtin:terrain?n=96"); }
TEST_CASE("every model is consistent on builtin:near-crossing", "[e2e][models]") { requireEveryModelConsistent("builtin:near-crossing"); }
TEST_CASE("every model is consistent on stanford-bunny.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/stanford-bunny.obj"); }
TEST_CASE("every model is consistent on nefertiti.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/nefertiti.obj"); }
TEST_CASE("every model is consistent on fandisk.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/fandisk.obj"); }
TEST_CASE("every model is consistent on spot.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/spot.obj"); }
TEST_CASE("every model is consistent on cow.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/cow.obj"); }
TEST_CASE("every model is consistent on teapot.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/teapot.obj"); }
TEST_CASE("every model is consistent on suzanne.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/suzanne.obj"); }
TEST_CASE("every model is consistent on beast.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/beast.obj"); }
TEST_CASE("every model is consistent on igea.ply", "[e2e][models]") { requireEveryModelConsistent(kModels + "/igea.ply"); }
