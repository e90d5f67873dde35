// The inverse projection applied to whole depth maps: points land on the surface they came from.
#include "zcheck/checker.h"

#include "zcheck/inverse_projection.h"
#include "zcheck/mesh_loader.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <utility>

using namespace zcheck;

namespace {

struct Plane {
    glm::dvec3 normal;  // unit
    double offset;
    double distance(const glm::dvec3& p) const { return std::abs(glm::dot(normal, p) + offset); }
};

Plane planeOf(const Scene& scene, std::uint32_t primitive)
{
    const glm::uvec3 t = scene.triangles[primitive];
    const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    return {n, -glm::dot(n, a)};
}

}  // namespace

TEST_CASE("depth from either route, unprojected, lands on the surface it came from", "[unproject]")
{
    for (const std::string& name : {std::string("builtin:default"), std::string(ZCHECK_MODELS_DIR) + "/stanford-bunny.obj"})
        for (const auto& convention : Convention::presetNames())
            for (bool reversed : {false, true}) {
                const Scene scene = loadScene(name);
                CameraSpec spec = scene.defaultCamera;
                spec.width = 200, spec.height = 150;
                spec.convention = Convention::preset(convention);
                spec.depth.reversed = reversed;
                const Camera camera(spec);
                const Checker checker(scene);
                const CheckResult run = checker.check(camera);
                const RenderResult ray = checker.renderRay(camera, {}, EyePoints::Keep);  // with its eye points
                const double C = ToleranceModel::constantQuanta(spec.depth), S = ToleranceModel{}.snapPixels();
                std::size_t rayHits = 0, rasterHits = 0, rayPoints = 0, rasterPoints = 0;
                for (int row = 0; row < camera.height(); ++row)
                    for (int col = 0; col < camera.width(); ++col) {
                        const std::size_t i = std::size_t(row) * camera.width() + col;
                        const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
                        INFO(name << " " << convention << (reversed ? " reversed" : "") << " pixel " << col << "," << row);
                        // Ray route: exact window depth, and its eye-z and distance.
                        const auto fromWindow = eyePointFromDepth(camera, pWindow, ray.windowDepth.value[i], DepthQuantity::Window);
                        REQUIRE(fromWindow.has_value() == ray.hit(i));
                        if (ray.hit(i)) {
                            ++rayHits, ++rayPoints;
                            const glm::dvec3 pEye = ray.pEye[i];
                            const double scale = 1e-9 * (1 + glm::length(pEye));
                            REQUIRE(glm::length(*fromWindow - pEye) <= 1e-6 * glm::length(pEye));
                            const auto fromEyeZ = eyePointFromDepth(camera, pWindow, camera.eyeZOf(pEye), DepthQuantity::EyeZ);
                            const auto fromDistance =
                                eyePointFromDepth(camera, pWindow, distanceOfEyePoint(camera, pEye), DepthQuantity::Distance);
                            REQUIRE(glm::length(*fromEyeZ - pEye) <= scale);
                            REQUIRE(glm::length(*fromDistance - pEye) <= scale);
                            const glm::dvec3 pWorld(camera.worldFromEye * glm::dvec4(*fromEyeZ, 1.0));
                            REQUIRE(planeOf(scene, ray.primitiveId[i]).distance(pWorld) <= scale);
                        }
                        // Raster route: the stored (quantized) value, within the tolerance model
                        // turned into a distance along the ray.
                        const double stored = run.raster.windowDepth.value[i];
                        const auto fromRaster = eyePointFromDepth(camera, pWindow, stored, DepthQuantity::Window);
                        REQUIRE(fromRaster.has_value() == run.raster.hit(i));
                        if (!run.raster.hit(i)) continue;
                        ++rasterHits, ++rasterPoints;
                        const std::uint32_t primitive = run.raster.primitiveId[i];
                        const glm::uvec3 t = scene.triangles[primitive];
                        const double m = windowDepthSlope(camera, glm::dvec3(scene.positions[t[0]]), glm::dvec3(scene.positions[t[1]]),
                                                          glm::dvec3(scene.positions[t[2]]));
                        const double tolerance = C * storageQuantum(spec.depth.format, stored) + S * m;
                        const double d0 = distanceOfEyePoint(camera, *fromRaster);
                        double alongRay = 0;
                        for (double sign : {-1.0, 1.0}) {
                            const auto p = eyePointFromDepth(camera, pWindow, stored + sign * tolerance, DepthQuantity::Window);
                            alongRay = std::max(alongRay, p ? std::abs(distanceOfEyePoint(camera, *p) - d0) : INFINITY);
                        }
                        const glm::dvec3 pWorld(camera.worldFromEye * glm::dvec4(*fromRaster, 1.0));
                        REQUIRE(planeOf(scene, primitive).distance(pWorld) <= alongRay * 1.0001 + 1e-12);
                    }
                REQUIRE(rayPoints == rayHits);
                REQUIRE(rasterPoints == rasterHits);
                REQUIRE(rayHits > 1000);
            }
}

TEST_CASE("pointAtDepth: one pixel's point in both spaces, a miss or an impossible value refused by name", "[unproject]")
{
    const Camera camera{CameraSpec{}};  // opengl, 640x480, perspective, looking at the origin
    const glm::dvec2 pWindow = windowFromPixelCentre(camera, 100, 200);
    const PointAtDepth p = pointAtDepth(camera, pWindow, 2.5, DepthQuantity::EyeZ, "depth");
    REQUIRE(p.eyeZ == Approx(2.5));
    REQUIRE(p.distance == Approx(glm::length(p.pEye)));  // from the centre of projection
    const glm::dvec3 pBack = windowFromWorld(camera, p.pWorld);
    REQUIRE(pBack.x == Approx(pWindow.x));
    REQUIRE(pBack.y == Approx(pWindow.y));
    // The same point given by its distance, and by its window depth.
    for (const auto& [value, quantity] : {std::pair{p.distance, DepthQuantity::Distance},
                                          std::pair{pBack.z, DepthQuantity::Window}}) {
        const PointAtDepth q = pointAtDepth(camera, pWindow, value, quantity, "depth");
        for (int k = 0; k < 3; ++k) REQUIRE(q.pWorld[k] == Approx(p.pWorld[k]).epsilon(1e-9));
    }
    REQUIRE_THROWS_WITH(pointAtDepth(camera, pWindow, camera.clearDepth(), DepthQuantity::Window, "--depth"),
                        "--depth 1 is a miss for quantity window");
    REQUIRE_THROWS_WITH(pointAtDepth(camera, pWindow, -1, DepthQuantity::EyeZ, "depth"),
                        Catch::StartsWith("depth -1 (eye-z) must be > 0"));

    REQUIRE(pixelInImage(camera, 639, 479, "pixel (639, 479)") == glm::ivec2(639, 479));
    REQUIRE_THROWS_WITH(pixelInImage(camera, 640, 0, "pixel (640, 0)"), "pixel (640, 0) is outside the 640x480 image");
    REQUIRE_THROWS_WITH(pixelInImage(camera, 0, -1, "--pixel 0,-1"), "--pixel 0,-1 is outside the 640x480 image");
    REQUIRE(pointSpaceFromName("eye", "space") == PointSpace::Eye);
    REQUIRE(pointSpaceFromName("world", "space") == PointSpace::World);
    REQUIRE_THROWS_WITH(pointSpaceFromName("camera", "--space"), "--space must be eye or world, got 'camera'");
}

TEST_CASE("misses in every quantity are skipped", "[unproject]")
{
    CameraSpec spec;
    spec.depth.reversed = true;
    const Camera camera(spec);
    const glm::dvec2 centre(320, 240);
    REQUIRE_FALSE(eyePointFromDepth(camera, centre, camera.clearDepth(), DepthQuantity::Window));
    REQUIRE_FALSE(eyePointFromDepth(camera, centre, camera.ndcZFar(), DepthQuantity::Ndc));
    REQUIRE_FALSE(eyePointFromDepth(camera, centre, INFINITY, DepthQuantity::EyeZ));
    REQUIRE_FALSE(eyePointFromDepth(camera, centre, 0.0, DepthQuantity::Distance));
    REQUIRE_FALSE(eyePointFromDepth(camera, centre, NAN, DepthQuantity::Window));
    REQUIRE(eyePointFromDepth(camera, centre, 0.5, DepthQuantity::Window));
}
