#include "zcheck/inverse_projection.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace zcheck {

namespace {

glm::dvec4 clipFromWindow(const Camera& camera, const glm::dvec3& pWindow)
{
    return glm::dvec4(glm::dvec3(camera.ndcFromWindow * glm::dvec4(pWindow, 1.0)), 1.0);
}

// A lens camera's unit direction through a window point, eye space; NaN outside the field.
glm::dvec3 lensEyeDirection(const Camera& camera, const glm::dvec2& pWindow)
{
    const std::optional<glm::dvec3> dLens = camera.lens()->directionThrough({pWindow.x, camera.imageYFromWindowY(pWindow.y)});
    return dLens ? camera.eyeFromLensFrame(*dLens) : glm::dvec3(NAN);
}

}  // namespace

std::optional<glm::dvec3> eyeDirectionThroughWindow(const Camera& camera, const glm::dvec2& pWindow)
{
    if (camera.lens()) {
        const glm::dvec3 d = lensEyeDirection(camera, pWindow);
        return std::isnan(d.x) ? std::nullopt : std::optional<glm::dvec3>(d);
    }
    return eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow)).direction;
}

void requireRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow)
{
    if (!camera.lens() || eyeDirectionThroughWindow(camera, pWindow)) return;
    char where[96];
    std::snprintf(where, sizeof where, "image point (%.6g, %.6g)", pWindow.x, camera.imageYFromWindowY(pWindow.y));
    throw Error(std::string(where) + " is outside the lens model's field (" + camera.lens()->spec().model + ", up to " +
                fourSignificantDigits(camera.lens()->fieldAngle() * 180 / 3.14159265358979323846) +
                "° from the axis, where it is one-to-one): it has no ray");
}

EyePlaneRay eyePlaneRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow)
{
    if (camera.lens())
        return {glm::dvec3(0.0), lensEyeDirection(camera, pWindow), camera.nearDistance(), camera.farDistance()};
    return eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow));
}

std::optional<glm::dvec2> imageFromEye(const Camera& camera, const glm::dvec3& pEye)
{
    if (const LensModel* lens = camera.lens()) return lens->imageFromDirection(camera.lensFrameFromEye(pEye));
    const glm::dvec4 pClip = camera.clipFromEye * glm::dvec4(pEye, 1.0);
    if (!(pClip.w > 0)) return std::nullopt;  // at or behind the eye plane of a perspective camera
    const glm::dvec3 pWindow = windowFromEye(camera, pEye);
    return glm::dvec2(pWindow.x, camera.imageYFromWindowY(pWindow.y));
}

EyePlaneRay eyePlaneRayFrom(const Ray& rayEye)
{
    // Where the ray crosses the eye plane z = 0: the centre of projection for a perspective
    // camera, the foot of the ray on the eye plane for a parallel one.
    const double tEyePlane = -rayEye.origin.z / rayEye.direction.z;
    const double length = glm::length(rayEye.direction);
    EyePlaneRay out;
    out.origin = rayEye.origin + tEyePlane * rayEye.direction;
    out.direction = rayEye.direction / length;
    out.tNear = -tEyePlane * length;
    out.tFar = std::isinf(rayEye.tMax) ? INFINITY : (rayEye.tMax - tEyePlane) * length;
    return out;
}

EyePlaneRay worldEyePlaneRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow)
{
    EyePlaneRay ray = camera.lens() ? EyePlaneRay{glm::dvec3(0.0), lensEyeDirection(camera, pWindow), camera.nearDistance(),
                                                  camera.farDistance()}
                                    : eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow));
    ray.origin = glm::dvec3(camera.worldFromEye * glm::dvec4(ray.origin, 1.0));
    ray.direction = glm::dvec3(camera.worldFromEye * glm::dvec4(ray.direction, 0.0));
    return ray;
}

Ray eyeRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow)
{
    if (camera.lens()) {  // from the near sphere to the far one
        const glm::dvec3 d = lensEyeDirection(camera, pWindow);
        if (camera.farIsInfinite()) return {camera.nearDistance() * d, d, INFINITY};
        return {camera.nearDistance() * d, (camera.farDistance() - camera.nearDistance()) * d, 1.0};
    }
    const glm::dvec4 nearEye = camera.eyeFromClip * clipFromWindow(camera, {pWindow, camera.windowDepthNear()});
    const glm::dvec4 farEye = camera.eyeFromClip * clipFromWindow(camera, {pWindow, camera.windowDepthFar()});
    Ray ray;
    ray.origin = glm::dvec3(nearEye) / nearEye.w;
    // With an infinite far plane the far point has w = 0 (up to rounding): a direction.
    if (camera.farIsInfinite()) {
        const glm::dvec3 direction = glm::normalize(glm::dvec3(farEye));
        // The direction of the point at infinity is fixed up to sign: it points away from the eye.
        ray.direction = camera.eyeZOf(direction) > 0 ? direction : -direction;
        ray.tMax = INFINITY;
    } else {
        ray.direction = glm::dvec3(farEye) / farEye.w - ray.origin;
        ray.tMax = 1.0;
    }
    return ray;
}

Ray worldRayThroughWindow(const Camera& camera, const glm::dvec2& pWindow)
{
    const Ray rayEye = eyeRayThroughWindow(camera, pWindow);
    return {glm::dvec3(camera.worldFromEye * glm::dvec4(rayEye.origin, 1.0)),
            glm::dvec3(camera.worldFromEye * glm::dvec4(rayEye.direction, 0.0)), rayEye.tMax};
}

glm::dvec3 eyeFromWindow(const Camera& camera, const glm::dvec3& pWindow)
{
    const glm::dvec4 pEye = camera.eyeFromClip * clipFromWindow(camera, pWindow);
    return glm::dvec3(pEye) / pEye.w;
}

glm::dvec3 windowFromEye(const Camera& camera, const glm::dvec3& pEye)
{
    const glm::dvec4 pClip = camera.clipFromEye * glm::dvec4(pEye, 1.0);
    return glm::dvec3(camera.windowFromNdc * glm::dvec4(glm::dvec3(pClip) / pClip.w, 1.0));
}

glm::dvec3 windowFromWorld(const Camera& camera, const glm::dvec3& pWorld)
{
    return windowFromEye(camera, glm::dvec3(camera.eyeFromWorld * glm::dvec4(pWorld, 1.0)));
}

double eyeZFromWindowDepth(const Camera& camera, const glm::dvec2& pWindow, double windowDepth)
{
    return camera.eyeZOf(eyeFromWindow(camera, {pWindow, windowDepth}));
}

namespace {
// The eye point on the ray through pWindow at planar depth eyeZ.
glm::dvec3 eyePointAtEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ)
{
    const Ray ray = eyeRayThroughWindow(camera, pWindow);
    // A lens's ray 90° or more off the axis has no eye-z.
    if (camera.lens() && !(camera.eyeZOf(ray.direction) > 0)) return glm::dvec3(NAN);
    const double t = (eyeZ - camera.eyeZOf(ray.origin)) / camera.eyeZOf(ray.direction);
    return ray.origin + t * ray.direction;
}
}  // namespace

double windowDepthFromEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ)
{
    return windowFromEye(camera, eyePointAtEyeZ(camera, pWindow, eyeZ)).z;
}

double distanceFromEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ)
{
    return distanceOfEyePoint(camera, eyePointAtEyeZ(camera, pWindow, eyeZ));
}

double depthValueFromEyeZ(const Camera& camera, const glm::dvec2& pWindow, double eyeZ, DepthQuantity quantity)
{
    switch (quantity) {
    case DepthQuantity::Window: return windowDepthFromEyeZ(camera, pWindow, eyeZ);
    case DepthQuantity::Ndc: return camera.ndcZFromWindowDepth(windowDepthFromEyeZ(camera, pWindow, eyeZ));
    case DepthQuantity::EyeZ: return eyeZ;
    case DepthQuantity::Distance: return distanceFromEyeZ(camera, pWindow, eyeZ);
    }
    return NAN;
}

double eyeZFromDistance(const Camera& camera, const glm::dvec2& pWindow, double distance)
{
    if (camera.lens()) return camera.eyeZOf(distance * lensEyeDirection(camera, pWindow));
    const EyePlaneRay ray = eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow));
    return camera.eyeZOf(ray.origin + distance * ray.direction);
}

namespace {
// The closed interval of window or NDC depths: the camera's depth range (its NDC range), and
// what its depth buffer stores at the range's ends, where that lies outside. A unorm code stands
// for a multiple of 1/(2^N − 1), which may lie up to half a code beyond the ends of a narrowed
// range: [0.11498, 0.28484] in unorm16 stores its far end as 18667/65535 = 0.2848402, above
// 0.2848395. Eye-z and distance: [0, inf].
std::pair<double, double> depthValueBounds(const Camera& camera, DepthQuantity quantity)
{
    const DepthSettings& depth = camera.depth();
    const double lo = std::min(depth.rangeMin, quantizeDepth(depth.format, depth.rangeMin));
    const double hi = std::max(depth.rangeMax, quantizeDepth(depth.format, depth.rangeMax));
    switch (quantity) {
    case DepthQuantity::Window: return {lo, hi};
    case DepthQuantity::Ndc:  // the viewport's map from NDC to window depth increases
        return {std::min(camera.convention().ndcZMin(), camera.ndcZFromWindowDepth(lo)),
                std::max(1.0, camera.ndcZFromWindowDepth(hi))};
    case DepthQuantity::EyeZ:
    case DepthQuantity::Distance: break;
    }
    return {0.0, INFINITY};
}
}  // namespace

DepthValueKind kindOfDepthValue(const Camera& camera, DepthQuantity quantity, double value)
{
    if (!std::isfinite(value)) return DepthValueKind::Miss;
    const bool linear = quantity == DepthQuantity::EyeZ || quantity == DepthQuantity::Distance;
    if (linear) return value > 0 ? DepthValueKind::Depth : value == 0 ? DepthValueKind::Miss : DepthValueKind::OutOfRange;
    if (camera.lens()) return DepthValueKind::OutOfRange;  // no depth buffer: no window or NDC depth
    const auto [lo, hi] = depthValueBounds(camera, quantity);
    const double slack = 0x1p-23 * std::max({1.0, std::abs(lo), std::abs(hi)});  // one binary32 step
    if (!(value >= lo - slack && value <= hi + slack)) return DepthValueKind::OutOfRange;
    // The clear value (or the far plane's depth) marks a miss, as the map holds it: exact, or
    // rounded to binary32 (a float32 file of a unorm buffer whose clear value no float holds).
    const bool ndc = quantity == DepthQuantity::Ndc;
    const double window = ndc ? camera.windowDepthFromNdcZ(value) : value;
    for (const double missWindow : {camera.clearDepth(), camera.windowDepthFar()}) {
        const double miss = ndc ? camera.ndcZFromWindowDepth(missWindow) : missWindow;
        if (window == missWindow || value == miss || value == roundedToBinary32(miss)) return DepthValueKind::Miss;
    }
    return DepthValueKind::Depth;
}

std::string depthValueRange(const Camera& camera, DepthQuantity quantity)
{
    if (quantity == DepthQuantity::EyeZ || quantity == DepthQuantity::Distance) return "> 0 (0 means no depth)";
    if (camera.lens()) return "nothing: a lens model has no depth buffer (use eye-z or distance)";
    const auto [lo, hi] = depthValueBounds(camera, quantity);
    const DepthSettings& depth = camera.depth();
    const auto [windowLo, windowHi] = depthValueBounds(camera, DepthQuantity::Window);
    const bool widened = windowLo < depth.rangeMin || windowHi > depth.rangeMax;
    return "[" + formatNumber(lo) + ", " + formatNumber(hi) + "], the camera's " +
           (quantity == DepthQuantity::Window ? "depth range" : "NDC depth range") +
           (widened ? " as its " + toString(depth.format) + " buffer stores its ends" : "");
}

std::optional<glm::dvec3> eyePointFromDepth(const Camera& camera, const glm::dvec2& pWindow, double value,
                                            DepthQuantity quantity)
{
    if (kindOfDepthValue(camera, quantity, value) != DepthValueKind::Depth) return std::nullopt;
    switch (quantity) {
    case DepthQuantity::Ndc: value = camera.windowDepthFromNdcZ(value); [[fallthrough]];
    case DepthQuantity::Window: return eyeFromWindow(camera, {pWindow, value});
    case DepthQuantity::EyeZ: {
        const glm::dvec3 pEye = eyePointAtEyeZ(camera, pWindow, value);  // NaN: a lens's ray with no eye-z
        return std::isnan(pEye.x) ? std::nullopt : std::optional<glm::dvec3>(pEye);
    }
    case DepthQuantity::Distance: {
        if (camera.lens()) {
            const glm::dvec3 d = lensEyeDirection(camera, pWindow);
            return std::isnan(d.x) ? std::nullopt : std::optional<glm::dvec3>(value * d);
        }
        const EyePlaneRay ray = eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow));
        return ray.origin + value * ray.direction;
    }
    }
    return std::nullopt;
}

double distanceOfEyePoint(const Camera& camera, const glm::dvec3& pEye)
{
    if (camera.lens()) return glm::length(pEye);
    const glm::dvec3 pWindow = windowFromEye(camera, pEye);
    return glm::length(pEye - eyePlaneRayFrom(eyeRayThroughWindow(camera, {pWindow.x, pWindow.y})).origin);
}

void requireQuantityOf(const Camera& camera, DepthQuantity quantity, const std::string& name)
{
    if (camera.lens() && (quantity == DepthQuantity::Window || quantity == DepthQuantity::Ndc))
        throw Error(name + ": a lens model (" + camera.lens()->spec().model +
                    ") has no depth buffer, so no window or ndc depth: give eye-z or distance");
}

void requireDepthValue(const Camera& camera, DepthQuantity quantity, double value, const std::string& name)
{
    const std::string given = name + " " + formatNumber(value) + " (" + toString(quantity) + ")";
    if (!std::isfinite(value)) throw Error(given + " must be a finite number");
    const bool linear = quantity == DepthQuantity::EyeZ || quantity == DepthQuantity::Distance;
    if (linear) {
        if (!(value > 0)) throw Error(given + " must be > 0: the point must lie in front of the eye");
        return;
    }
    requireQuantityOf(camera, quantity, given);
    const auto [lo, hi] = depthValueBounds(camera, quantity);
    if (!(value >= lo && value <= hi)) throw Error(given + " must lie in " + depthValueRange(camera, quantity));
}

PointAtDepth pointAtDepth(const Camera& camera, const glm::dvec2& pWindow, double value, DepthQuantity quantity,
                          const std::string& name)
{
    requireDepthValue(camera, quantity, value, name);
    requireRayThroughWindow(camera, pWindow);
    const std::optional<glm::dvec3> pEye = eyePointFromDepth(camera, pWindow, value, quantity);
    if (!pEye && camera.lens())  // a ray 90° or more off the axis: no eye-z there
        throw Error(name + " " + formatNumber(value) + " (" + toString(quantity) +
                    "): the ray there is 90° or more off the axis, where eye-z does not exist; give distance");
    if (!pEye) throw Error(name + " " + formatNumber(value) + " is a miss for quantity " + toString(quantity));
    return {*pEye, glm::dvec3(camera.worldFromEye * glm::dvec4(*pEye, 1.0)), camera.eyeZOf(*pEye),
            distanceOfEyePoint(camera, *pEye)};
}

glm::ivec2 pixelInImage(const Camera& camera, double col, double row, const std::string& what)
{
    if (!(col >= 0 && col < camera.width() && row >= 0 && row < camera.height()))
        throw Error(what + " is outside the " + std::to_string(camera.width()) + "x" + std::to_string(camera.height()) +
                    " image");
    return {int(col), int(row)};
}

PointSpace pointSpaceFromName(const std::string& name, const std::string& what)
{
    if (name == "eye") return PointSpace::Eye;
    if (name == "world") return PointSpace::World;
    throw Error(what + " must be eye or world, got '" + name + "'");
}

UnprojectedMap unprojectMap(const Camera& camera, const std::vector<double>& values, DepthQuantity quantity,
                            PointSpace space, int stride)
{
    const int W = camera.width(), H = camera.height();
    if (values.size() != std::size_t(W) * std::size_t(H))
        throw Error("the depth map holds " + std::to_string(values.size()) + " values, but the camera's image is " +
                    std::to_string(W) + "x" + std::to_string(H));
    if (stride < 1) throw Error("the stride must be >= 1, got " + std::to_string(stride));
    UnprojectedMap out;
    for (int row = 0; row < H; row += stride)
        for (int col = 0; col < W; col += stride) {
            const double value = values[std::size_t(row) * W + col];
            const auto pEye = eyePointFromDepth(camera, windowFromPixelCentre(camera, col, row), value, quantity);
            if (!pEye) {
                if (kindOfDepthValue(camera, quantity, value) == DepthValueKind::OutOfRange) {
                    if (out.outOfRange++ == 0) out.firstOutOfRange = {col, row};
                } else {
                    ++out.misses;
                }
                continue;
            }
            out.points.push_back(space == PointSpace::Eye ? *pEye : glm::dvec3(camera.worldFromEye * glm::dvec4(*pEye, 1.0)));
            out.pixels.emplace_back(col, row);
        }
    return out;
}

std::string howCamerasDiffer(const Camera& a, const Camera& b, bool depthMapping)
{
    if (a.width() != b.width() || a.height() != b.height())
        return "image sizes " + std::to_string(a.width()) + "x" + std::to_string(a.height()) + " and " +
               std::to_string(b.width()) + "x" + std::to_string(b.height());
    // Points `a` sees at nine pixels, at two depths inside its clip range, as `b` sees them.
    const double nearZ = a.nearDistance(), farZ = std::isinf(a.farDistance()) ? nearZ * 100 : a.farDistance();
    for (const double t : {0.25, 0.75})
        for (const double u : {0.0, 0.5, 1.0})
            for (const double v : {0.0, 0.5, 1.0}) {
                const glm::dvec2 pImage{u * a.width(), v * a.height()};  // x right, y down from the top-left
                const glm::dvec2 pWindow{pImage.x, a.windowYFromImageY(pImage.y)};
                const double eyeZ = nearZ + t * (farZ - nearZ);
                const glm::dvec3 pEyeA = eyePointAtEyeZ(a, pWindow, eyeZ);
                const glm::dvec3 pWorld = glm::dvec3(a.worldFromEye * glm::dvec4(pEyeA, 1.0));
                const glm::dvec3 pEyeB = glm::dvec3(b.eyeFromWorld * glm::dvec4(pWorld, 1.0));
                const glm::dvec3 inB = windowFromEye(b, pEyeB);
                const glm::dvec2 imageB{inB.x, b.imageYFromWindowY(inB.y)};
                const double eyeZB = b.eyeZOf(pEyeB);
                if (!(std::abs(imageB.x - pImage.x) <= 1e-3 && std::abs(imageB.y - pImage.y) <= 1e-3 && eyeZB > 0))
                    return "the pose or the projection: the point the first sees at image point (" + formatNumber(pImage.x) +
                           ", " + formatNumber(pImage.y) + ") the second sees at (" + formatNumber(imageB.x) + ", " +
                           formatNumber(imageB.y) + ")";
                if (!(std::abs(eyeZB - eyeZ) <= 1e-6 * eyeZ))
                    return "the eye-z of a point: " + formatNumber(eyeZ) + " and " + formatNumber(eyeZB);
                if (depthMapping && !(std::abs(inB.z - windowDepthFromEyeZ(a, pWindow, eyeZ)) <= 1e-7))
                    return "the depth mapping (near, far, depth range or reversed-Z): window depth " +
                           formatNumber(windowDepthFromEyeZ(a, pWindow, eyeZ)) + " and " + formatNumber(inB.z);
            }
    return "";
}

}  // namespace zcheck
