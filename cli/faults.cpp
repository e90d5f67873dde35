#include "faults.h"

#include <cmath>

namespace zcheck {

namespace {

// A wrong projection: draw with `clipFromEye` instead of the camera's.
bool wrongProjection(const Camera& camera, const glm::dmat4& clipFromEye, FaultInjection& injection)
{
    injection.raster.overrideClipFromWorld = true;
    injection.raster.clipFromWorld = clipFromEye * camera.eyeFromWorld;
    return true;
}

bool hasFovy(const Camera& camera) { return camera.spec().projection.type == ProjectionType::Perspective; }

// The projection's x and y rows scaled by (kx, ky): field-of-view and aspect mistakes.
glm::dmat4 scaledRows(const Camera& camera, double kx, double ky)
{
    glm::dmat4 m = camera.clipFromEye;
    for (int c = 0; c < 4; ++c) m[c][0] *= kx, m[c][1] *= ky;
    return m;
}

// The z row rebuilt with near and far exchanged (the mapping's formula, see camera.cpp).
glm::dmat4 nearFarSwapped(const Camera& camera)
{
    const double a = camera.ndcZNear(), b = camera.ndcZFar();
    const double n = camera.farDistance(), f = camera.nearDistance();  // swapped
    const double towardsEye = -camera.convention().eyeForwardZ;       // z_gl = towardsEye·z_eye
    double P, Q;
    if (camera.spec().projection.isPerspective()) {
        P = (a - b) * n / (f - n) - b, Q = (a - b) * n * f / (f - n);
    } else {
        P = -(b - a) / (f - n), Q = a - (b - a) * n / (f - n);
    }
    glm::dmat4 m = camera.clipFromEye;
    m[2][2] = P * towardsEye, m[3][2] = Q;
    return m;
}

}  // namespace

const std::vector<Fault>& faultCatalogue()
{
    static const std::vector<Fault> catalogue = {
        {"y-flip", "the window's y axis flipped (bottom-left vs top-left origin mixed up)", "ray",
         [](const Camera&, FaultInjection& f) { return f.ray.flipRows = true; }},
        {"half-pixel", "pixel centres at integer coordinates: the +0.5 offset forgotten", "ray",
         [](const Camera&, FaultInjection& f) {
             f.ray.shiftPixels = {-0.5, -0.5};
             return true;
         }},
        {"ndc-range", "a [-1,1] depth matrix used with a [0,1] convention, or the reverse", "raster",
         [](const Camera& camera, FaultInjection& f) {
             CameraSpec other = camera.spec();
             if (other.projection.type == ProjectionType::Matrix) return false;
             other.convention.ndcDepth = other.convention.ndcDepth == NdcDepthRange::ZeroToOne ? NdcDepthRange::MinusOneToOne
                                                                                                : NdcDepthRange::ZeroToOne;
             return wrongProjection(camera, Camera(other).clipFromEye, f);
         }},
        {"reversed-as-standard", "a reversed-Z projection's values read as standard (or the reverse)", "raster",
         [](const Camera& camera, FaultInjection& f) {
             CameraSpec other = camera.spec();
             if (other.projection.type == ProjectionType::Matrix) return false;
             other.depth.reversed = !other.depth.reversed;
             return wrongProjection(camera, Camera(other).clipFromEye, f);
         }},
        {"handedness", "a left-handed view used in a right-handed pipeline: the eye's x axis mirrored", "raster",
         [](const Camera& camera, FaultInjection& f) {
             glm::dmat4 mirror(1.0);
             mirror[0][0] = -1;
             return wrongProjection(camera, camera.clipFromEye * mirror, f);
         }},
        {"transposed", "the projection matrix transposed (row- vs column-major confusion)", "raster",
         [](const Camera& camera, FaultInjection& f) { return wrongProjection(camera, glm::transpose(camera.clipFromEye), f); }},
        {"aspect-inverted", "height/width used where width/height belongs", "raster",
         [](const Camera& camera, FaultInjection& f) {
             const double aspect = double(camera.width()) / camera.height();
             return camera.width() != camera.height() && wrongProjection(camera, scaledRows(camera, aspect * aspect, 1.0), f);
         }},
        {"fovy-radians", "the vertical field of view in degrees passed where radians are expected", "raster",
         [](const Camera& camera, FaultInjection& f) {
             if (!hasFovy(camera)) return false;
             const double fovy = camera.spec().projection.fovyDeg;
             const double k = std::tan(glm::radians(fovy) / 2) / std::tan(fovy / 2);
             return wrongProjection(camera, scaledRows(camera, k, k), f);
         }},
        {"half-fov", "tan(fovy) used where tan(fovy/2) belongs (full vs half field of view)", "raster",
         [](const Camera& camera, FaultInjection& f) {
             if (!hasFovy(camera)) return false;
             const double half = glm::radians(camera.spec().projection.fovyDeg) / 2;
             const double k = std::tan(half) / std::tan(2 * half);
             return std::isfinite(k) && wrongProjection(camera, scaledRows(camera, k, k), f);
         }},
        {"near-far-swapped", "near and far exchanged in the projection", "raster",
         [](const Camera& camera, FaultInjection& f) {
             if (camera.farIsInfinite() || camera.spec().projection.type == ProjectionType::Matrix) return false;
             return wrongProjection(camera, nearFarSwapped(camera), f);
         }},
        {"linear-depth", "linear eye depth (z − n)/(f − n) stored as the window depth", "raster",
         [](const Camera& camera, FaultInjection& f) { return !camera.farIsInfinite() && (f.raster.storeLinearEyeZ = true); }},
        {"distance-as-eye-z", "ray distance taken as planar depth (eye-z)", "ray",
         [](const Camera&, FaultInjection& f) { return f.ray.distanceAsEyeZ = true; }},
        {"no-near-clip", "no clipping at the near plane (geometry behind the eye wraps around)", "raster",
         [](const Camera&, FaultInjection& f) { return f.raster.noNearClip = true; }},
        {"screen-linear-eye-z", "eye depth interpolated linearly in screen space instead of perspective-correctly", "raster",
         [](const Camera&, FaultInjection& f) { return f.raster.screenLinearEyeZ = true; }},
        {"viewport-minus-one", "the viewport scaled by width − 1 and height − 1", "raster",
         [](const Camera&, FaultInjection& f) { return f.raster.viewportMinusOne = true; }},
        {"unorm-truncation", "unorm depth quantized by truncation instead of rounding", "raster",
         [](const Camera& camera, FaultInjection& f) {
             return camera.depth().format != DepthFormat::Float32 && (f.raster.truncateUnorm = true);
         }},
    };
    return catalogue;
}

}  // namespace zcheck
