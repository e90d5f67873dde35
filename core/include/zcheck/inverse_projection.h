#pragma once
// The inverse-projection module: from window coordinates back into eye and world space.
//
// One rule serves every projective camera (perspective, orthographic, off-axis frustum,
// oblique, raw matrices): the ray through a window point (x, y) is obtained by unprojecting
// (x, y) at the window depths of the near and far planes through eyeFromClip =
// inverse(clipFromEye) and dividing by w. A far point with w = 0 (infinite far plane) is a
// direction. Everything is computed in double. It is what `unproject`, `verify` and depth
// conversions use; the ray route of a check builds its rays from the camera's definition
// instead (camera_rays.h), except for raw-matrix cameras.
//
// Consumes window coordinates (see camera.h; pixel centres at +0.5) and depth values as
// stored in the depth buffer (window depth); produces eye- or world-space points and rays.
// Pure functions of the camera: thread-safe.
//
//   const glm::dvec2 pWindow = zcheck::windowFromPixelCentre(camera, col, row);
//   const auto pEye = zcheck::eyePointFromDepth(camera, pWindow, depth, zcheck::DepthQuantity::EyeZ);
#include "zcheck/camera.h"
#include "zcheck/quantity.h"

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace zcheck {

// Points origin + t·direction for t ∈ [0, tMax]. origin lies on the near plane; direction
// is (far point − near point) with tMax = 1, or, when the far plane is at infinity, a unit
// direction with tMax = +inf.
struct Ray {
    glm::dvec3 origin;
    glm::dvec3 direction;
    double tMax;
};

// Window coordinates of the centre of pixel (col, row); row 0 is the top row of the image.
inline glm::dvec2 windowFromPixelCentre(const Camera& camera, int col, int row)
{
    return {col + 0.5, camera.windowYFromImageY(row + 0.5)};
}

// Pixel (col, row) of the camera's image, whole numbers as the caller read them; throws Error
// "<what> is outside the WxH image" for one outside [0, width) × [0, height). `what` names the
// pixel as the caller was given it ("--pixel 3,4", "pixel (3, 4)").
glm::ivec2 pixelInImage(const Camera& camera, double col, double row, const std::string& what);

// The viewing ray through a window point, between the near and far planes.
Ray eyeRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow);
Ray worldRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow);

// The same viewing ray parametrized from the eye plane: origin where the ray crosses
// z_eye = 0 (the centre of projection for a perspective camera), unit direction, and the
// interval [tNear, tFar] between the near and far planes (tFar = +inf for an infinite far
// plane). t is then the `distance` quantity. Tracers want this form: an origin on the near
// plane, close to the eye, would lose the ray's angle to float rounding.
struct EyePlaneRay {
    glm::dvec3 origin;
    glm::dvec3 direction;  // unit length
    double tNear;
    double tFar;
};
EyePlaneRay eyePlaneRayFrom(const Ray& ray);
// In world space, for the tracer.
EyePlaneRay worldEyePlaneRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow);

// The unit viewing direction through a window point, eye space (for a parallel projection, the
// rays' common direction); empty only outside a lens model's field.
std::optional<glm::dvec3> eyeDirectionThroughWindow(const Camera& camera, const glm::dvec2& pWindow);
// Throws Error "image point (x, y) is outside the lens model's field (...)" for a window point of
// a lens camera that has no ray; nothing for every other point and camera.
void requireRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow);
// The viewing ray through a window point parametrized from the eye plane (eyePlaneRayFrom of
// eyeRayThroughWindow; a lens's from its centre, t the distance); NaN outside a lens's field.
EyePlaneRay eyePlaneRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow);
// The image point (camera.h: x right, y down from the top-left corner, pixel centres at +½) where
// an eye-space point is seen, through the lens for a lens model; empty where it is not seen (at or
// behind a perspective camera's eye plane, outside a lens's field). Points beyond the image's
// edges still have image points.
std::optional<glm::dvec2> imageFromEye(const Camera& camera, const glm::dvec3& pEye);

// Window point (x, y, window depth) → eye-space point, and the forward map. (A lens model has no
// window depth: for its camera, everything below that takes a window point reads only its x and y,
// and rays come from the lens — from the near to the far distance along each.)
glm::dvec3 eyeFromWindow(const Camera& camera, const glm::dvec3& pWindow);
glm::dvec3 windowFromEye(const Camera& camera, const glm::dvec3& pEye);
glm::dvec3 windowFromWorld(const Camera& camera, const glm::dvec3& pWorld);

// Depth value conversions at window point (x, y). eye-z is planar depth (positive, along
// the viewing axis); distance is the Euclidean range from the centre of projection, or for
// parallel projections from the eye plane (z_eye = 0) along the ray.
double eyeZFromWindowDepth(const Camera& camera, const glm::dvec2& pWindow, double windowDepth);
double windowDepthFromEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ);
double distanceFromEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ);
double eyeZFromDistance(const Camera& camera, const glm::dvec2& pWindow, double distance);
// The depth value, as `quantity`, of the point at eye depth eyeZ on the ray through (x, y).
double depthValueFromEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ, DepthQuantity quantity);

// What a stored value is to a map of `quantity` made by `camera`. A miss: not finite, the clear
// value or the far plane's depth (window, ndc; exact, or rounded to binary32 as a float32 file
// holds it), or 0 (eye-z, distance: "no depth"). Out of range — a value the quantity
// cannot hold, an error and never a miss: window depth outside the depth range, z_ndc outside
// the convention's NDC depth range (each with one binary32 step of slack, and widened to what the
// depth buffer stores at the range's ends: a unorm code may stand for a value half a code beyond
// a narrowed range's end), a negative eye-z or distance. Otherwise a depth.
enum class DepthValueKind { Depth, Miss, OutOfRange };
DepthValueKind kindOfDepthValue(const Camera& camera, DepthQuantity quantity, double value);
// The interval a quantity's depths lie in, as text: "[0, 1], the camera's depth range", "> 0".
std::string depthValueRange(const Camera& camera, DepthQuantity quantity);

// The eye-space point at window point (x, y) whose depth, as `quantity`, is `value`
// (window: depth-buffer value; ndc: z_ndc; eye-z; distance). Empty unless kindOfDepthValue
// says Depth.
std::optional<glm::dvec3> eyePointFromDepth(const Camera& camera, const glm::dvec2& pWindow, double value,
                                            DepthQuantity quantity);

// Refuses (throws Error) a depth value the camera cannot produce: window depth outside the
// depth range, z_ndc outside the convention's NDC range, eye-z or distance not in front of
// the eye, or anything not finite (stricter than kindOfDepthValue: no slack). `name` begins the message ("--depth 2 (window) must lie in
// [0, 1], the camera's depth range").
void requireDepthValue(const Camera& camera, DepthQuantity quantity, double value, const std::string& name);
// Refuses (throws Error beginning with `name`) a quantity the camera cannot produce at all: window
// and ndc of a lens model, which has no depth buffer. requireDepthValue checks it first.
void requireQuantityOf(const Camera& camera, DepthQuantity quantity, const std::string& name);

// The point seen at window point (x, y) at depth `value` of `quantity`, in both spaces and
// both depths: what `zcheck unproject --pixel --depth` and Python's Camera.point_at give.
struct PointAtDepth {
    glm::dvec3 pEye, pWorld;
    double eyeZ = 0;      // planar depth
    double distance = 0;  // distanceOfEyePoint
};
// Refuses, naming `name` ("--depth", "depth"), a value requireDepthValue refuses and a value
// that is a miss for the quantity (eyePointFromDepth: the clear value of window and ndc).
PointAtDepth pointAtDepth(const Camera& camera, const glm::dvec2& pWindow, double value, DepthQuantity quantity,
                          const std::string& name);

// Batch unprojection of a whole map: `values` holds width·height depth values of `quantity`
// (row 0 at the top, the camera's image size); every `stride`-th pixel in x and y from (0, 0)
// becomes a point, misses (as eyePointFromDepth defines them) are skipped and counted.
//
//   const zcheck::UnprojectedMap cloud = zcheck::unprojectMap(camera, depth, zcheck::DepthQuantity::EyeZ);
//   // cloud.points[k] (world space) was seen at pixel cloud.pixels[k] = (col, row)
struct UnprojectedMap {
    std::vector<glm::dvec3> points;   // eye or world space, as asked
    std::vector<glm::ivec2> pixels;   // (col, row) of each point
    std::size_t misses = 0;
    std::size_t outOfRange = 0;       // values the quantity cannot hold (kindOfDepthValue): no point
    glm::ivec2 firstOutOfRange{-1, -1};  // the first of them in scan order, (col, row)
};
enum class PointSpace { Eye, World };
// "eye" or "world"; throws Error "<what> must be eye or world, got '<name>'".
PointSpace pointSpaceFromName(const std::string& name, const std::string& what);
// Throws Error if values.size() is not width·height or stride < 1.
UnprojectedMap unprojectMap(const Camera& camera, const std::vector<double>& values, DepthQuantity quantity,
                            PointSpace space = PointSpace::World, int stride = 1);

// How two cameras image the world differently, in one phrase ("" when alike): their image
// sizes; a point seen at a pixel of `a` seen elsewhere by `b` (pose, field of view, principal
// point, y direction), or at another eye-z; with `depthMapping`, another depth-buffer value
// (near, far, depth range, reversed-Z). Conventions that image the world alike are alike.
std::string howCamerasDiffer(const Camera& a, const Camera& b, bool depthMapping);

// Range of an eye-space point from the centre of projection (or from the eye plane, along
// the viewing ray, for parallel projections).
double distanceOfEyePoint(const Camera& camera, const glm::dvec3& pEye);

}  // namespace zcheck
