// The ray route's camera in its fast form: the affine rays (one unit of eye-z per unit of t)
// against the per-pixel rays from the definition, and the folded depth mapping against the
// inverse-projection module's, for every projection model of the examples and every
// convention.
#include "zcheck/camera_file.h"
#include "zcheck/camera_rays.h"
#include "zcheck/inverse_projection.h"

#include <catch2/catch.hpp>

#include <string>

using namespace zcheck;

namespace {
const char* const kModels[] = {"perspective", "lens", "pinhole", "frustum", "orthographic", "oblique-cabinet",
                               "oblique-cavalier", "isometric", "infinite-far"};
const char* const kConventions[] = {"opengl", "direct3d", "vulkan", "metal", "opencv"};

// Calls visit(camera) for every example model, convention and Z direction.
template <class Visit>
void forEachExampleCamera(Visit&& visit)
{
    for (const char* model : kModels)
        for (const char* convention : kConventions)
            for (const bool reversed : {false, true}) {
                CameraSpec spec = readCameraFile(std::string(ZCHECK_TESTS_DIR) + "/../examples/" + model + ".json");
                spec.convention = Convention::preset(convention);
                spec.depth.reversed = reversed;
                INFO(model << " " << convention << (reversed ? " reversed" : ""));
                visit(Camera(spec));
            }
}
}  // namespace

TEST_CASE("affine rays are the definition's rays, with t equal to eye-z", "[camera_rays]")
{
    forEachExampleCamera([](const Camera& camera) {
        const CameraRays rays(camera);
        const auto affine = rays.affine();
        REQUIRE(affine.has_value());
        for (const glm::dvec2 pImage : {glm::dvec2(0.5, 0.5), glm::dvec2(camera.width() - 0.5, 0.5),
                                        glm::dvec2(17.25, camera.height() - 3.75),
                                        glm::dvec2(camera.width() / 2.0, camera.height() / 2.0)}) {
            const EyePlaneRay r = rays.worldRay(pImage);
            const glm::dvec3 origin = affine->originAt(pImage), direction = affine->directionAt(pImage);
            const double scale = 1.0 + glm::length(r.origin);
            REQUIRE(glm::length(origin - r.origin) <= 1e-12 * scale);
            REQUIRE(glm::length(glm::normalize(direction) - r.direction) <= 1e-13);
            // t along the affine direction is eye-z: the near plane at t = near, any point's
            // eye-z equal to its t.
            for (const double t : {camera.nearDistance(), 1.7 * camera.nearDistance() + 0.3}) {
                const glm::dvec3 pWorld = origin + t * direction;
                REQUIRE(rays.eyeZ(pWorld) == Approx(t).epsilon(1e-12));
            }
            REQUIRE(r.tNear * glm::dot(r.direction, direction) / glm::dot(direction, direction) ==
                    Approx(camera.nearDistance()).epsilon(1e-12));
        }
    });
}

TEST_CASE("the folded depth mapping is the inverse-projection module's, and its inverse round-trips", "[camera_rays]")
{
    forEachExampleCamera([](const Camera& camera) {
        const CameraRays rays(camera);
        const glm::dvec2 pImage(11.5, 7.5);
        const glm::dvec2 pWindow(pImage.x, camera.windowYFromImageY(pImage.y));
        const double n = camera.nearDistance();
        const double far = std::isinf(camera.farDistance()) ? 1000 * n : camera.farDistance();
        for (const double eyeZ : {n, 1.5 * n, 0.5 * (n + far), far}) {
            const double window = rays.windowDepth(pImage, eyeZ);
            // The matrices' route (clip_from_eye, viewport), an independent evaluation.
            REQUIRE(window == Approx(windowDepthFromEyeZ(camera, pWindow, eyeZ)).margin(1e-12));
            REQUIRE(rays.eyeZFromWindowDepth(pImage, window) == Approx(eyeZ).epsilon(1e-9));
            // The relative eye-z difference of a depth one part in 10^4 of the range away.
            const double other = window + 1e-4 * (camera.depth().rangeMax - camera.depth().rangeMin);
            const double zOther = rays.eyeZFromWindowDepth(pImage, other);
            REQUIRE(rays.relativeEyeZDifference(pImage, window, other) ==
                    Approx(std::abs(zOther - eyeZ) / eyeZ).epsilon(1e-6));
        }
        REQUIRE(rays.windowDepth(pImage, n) == Approx(camera.windowDepthNear()).margin(1e-14));
    });
}
