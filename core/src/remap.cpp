#include "zcheck/remap.h"

#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

namespace zcheck {

RemapSampling remapSamplingFromName(const std::string& name, const std::string& what)
{
    if (name == "nearest") return RemapSampling::Nearest;
    if (name == "plane") return RemapSampling::Plane;
    throw Error(what + " must be nearest or plane, got '" + name + "'");
}

namespace {

// The source's sample at pixel (col, row) as an eye-space point of the source; NaN for a miss.
glm::dvec3 samplePoint(const Camera& from, const std::vector<double>& values, DepthQuantity quantity, int col, int row)
{
    const double value = values[std::size_t(row) * from.width() + col];
    const std::optional<glm::dvec3> pEye = eyePointFromDepth(from, windowFromPixelCentre(from, col, row), value, quantity);
    return pEye ? *pEye : glm::dvec3(NAN);
}

// The distance along the unit source-eye ray `ray` where it meets the plane of the 2×2 samples
// around image point p, or NaN where they are not one plane (or not all hits, or at the border).
double planeDistanceAt(const Camera& from, const std::vector<double>& values, DepthQuantity quantity,
                       const glm::dvec2& p, const glm::dvec3& ray)
{
    const int col0 = int(std::floor(p.x - 0.5)), row0 = int(std::floor(p.y - 0.5));
    if (col0 < 0 || row0 < 0 || col0 + 1 >= from.width() || row0 + 1 >= from.height()) return NAN;
    const glm::dvec3 a = samplePoint(from, values, quantity, col0, row0), b = samplePoint(from, values, quantity, col0 + 1, row0),
                     c = samplePoint(from, values, quantity, col0, row0 + 1), d = samplePoint(from, values, quantity, col0 + 1, row0 + 1);
    if (std::isnan(a.x + b.x + c.x + d.x)) return NAN;
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const double length = glm::length(normal);
    if (!(length > 0)) return NAN;
    const glm::dvec3 n = normal / length;
    if (!(std::abs(glm::dot(n, d - a)) <= 1e-4 * glm::length(d))) return NAN;  // an edge: not one plane
    const double t = glm::dot(n, a) / glm::dot(n, ray);
    return t > 0 && std::isfinite(t) ? t : NAN;
}

double missValue(const Camera& to, DepthQuantity quantity)
{
    switch (quantity) {
    case DepthQuantity::Window: return to.clearDepth();
    case DepthQuantity::Ndc: return to.ndcZFar();
    case DepthQuantity::EyeZ:
    case DepthQuantity::Distance: break;
    }
    return INFINITY;
}

void requireSharedCentre(const Camera& from, const Camera& to)
{
    const glm::dvec3 a(from.worldFromEye[3]), b(to.worldFromEye[3]);
    const double scale = std::max({1.0, glm::length(a), glm::length(b)});
    const auto point = [](const glm::dvec3& p) {  // to 6 digits: the centres are where the views were placed
        char text[96];
        std::snprintf(text, sizeof text, "%.6g, %.6g, %.6g", p.x, p.y, p.z);
        return std::string(text);
    };
    if (!(glm::length(a - b) <= 1e-9 * scale))
        throw Error("the two cameras' centres differ (" + point(a) + " and " + point(b) + "): a depth map moves between cameras with one centre of projection only (other views need the scene: "
                    "render them with export)");
}

}  // namespace

CameraSpec undistortedCameraSpec(const Camera& camera, double alpha)
{
    const LensModel* lens = camera.lens();
    if (!lens) throw Error("the camera has no lens to undistort (its projection is " + toString(camera.spec().projection.type) + ")");
    if (!(alpha >= 0 && alpha <= 1)) throw Error("alpha must lie in [0, 1], got " + formatNumber(alpha));
    const int W = camera.width(), H = camera.height();
    constexpr int kGrid = 9;
    glm::dvec2 plane[kGrid][kGrid];
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            // OpenCV's points (i·W/8, j·H/8) in its pixel coordinates (calib3d's icvGetRectangles: from
            // the top-left pixel's centre to a pixel past the last one's); zcheck's image point is +½.
            const glm::dvec2 pImage(i * double(W) / (kGrid - 1) + 0.5, j * double(H) / (kGrid - 1) + 0.5);
            const std::optional<glm::dvec3> ray = lens->directionFromImage(pImage);
            if (!ray || !(ray->z > 1e-9))
                throw Error("lens model " + lens->spec().model + ": pixel (" + formatNumber(pImage.x - 0.5) + ", " +
                            formatNumber(pImage.y - 0.5) + ") has " + (ray ? "a ray 90° or more off the axis" : "no ray") +
                            ", which no pinhole image holds: undistort to a camera of your own (--to-camera)");
            plane[j][i] = glm::dvec2(*ray) / ray->z;
        }
    double outerX0 = INFINITY, outerX1 = -INFINITY, outerY0 = INFINITY, outerY1 = -INFINITY;
    double innerX0 = -INFINITY, innerX1 = INFINITY, innerY0 = -INFINITY, innerY1 = INFINITY;
    for (int j = 0; j < kGrid; ++j)
        for (int i = 0; i < kGrid; ++i) {
            const glm::dvec2 p = plane[j][i];
            outerX0 = std::min(outerX0, p.x), outerX1 = std::max(outerX1, p.x);
            outerY0 = std::min(outerY0, p.y), outerY1 = std::max(outerY1, p.y);
            if (i == 0) innerX0 = std::max(innerX0, p.x);
            if (i == kGrid - 1) innerX1 = std::min(innerX1, p.x);
            if (j == 0) innerY0 = std::max(innerY0, p.y);
            if (j == kGrid - 1) innerY1 = std::min(innerY1, p.y);
        }
    if (!(innerX1 > innerX0 && innerY1 > innerY0))
        throw Error("lens model " + lens->spec().model + ": its undistorted border holds no rectangle");
    const double fx0 = (W - 1) / (innerX1 - innerX0), fy0 = (H - 1) / (innerY1 - innerY0);
    const double fx1 = (W - 1) / (outerX1 - outerX0), fy1 = (H - 1) / (outerY1 - outerY0);
    const double fx = fx0 * (1 - alpha) + fx1 * alpha, fy = fy0 * (1 - alpha) + fy1 * alpha;
    const double cx = -fx0 * innerX0 * (1 - alpha) - fx1 * outerX0 * alpha;
    const double cy = -fy0 * innerY0 * (1 - alpha) - fy1 * outerY0 * alpha;
    CameraSpec spec = camera.spec();
    spec.projection = Projection{};
    spec.projection.type = ProjectionType::Pinhole;
    spec.projection.fx = fx, spec.projection.fy = fy, spec.projection.cx = cx, spec.projection.cy = cy;
    spec.projection.near = camera.nearDistance(), spec.projection.far = camera.farDistance();
    return spec;
}

RemappedMap remapDepthMap(const Camera& from, const std::vector<double>& values, DepthQuantity fromQuantity,
                          const Camera& to, DepthQuantity toQuantity, RemapSampling sampling)
{
    if (values.size() != std::size_t(from.width()) * from.height())
        throw Error("the map holds " + std::to_string(values.size()) + " values for a " + std::to_string(from.width()) +
                    "x" + std::to_string(from.height()) + " camera");
    requireSharedCentre(from, to);
    for (const auto& [camera, quantity, role] : {std::tuple{&from, fromQuantity, "source"}, std::tuple{&to, toQuantity, "target"}})
        requireQuantityOf(*camera, quantity, std::string("the ") + role + " quantity " + toString(quantity));
    const glm::dmat3 fromEyeFromToEye = glm::dmat3(from.eyeFromWorld) * glm::dmat3(to.worldFromEye);  // rotations
    RemappedMap out;
    out.values.assign(std::size_t(to.width()) * to.height(), missValue(to, toQuantity));
    for (int row = 0; row < to.height(); ++row)
        for (int col = 0; col < to.width(); ++col) {
            const glm::dvec2 pWindowTo = windowFromPixelCentre(to, col, row);
            const std::optional<glm::dvec3> rayTo = eyeDirectionThroughWindow(to, pWindowTo);
            if (!rayTo) continue;  // outside the target lens's own field: nothing there to fill
            const glm::dvec3 rayFrom = glm::normalize(fromEyeFromToEye * *rayTo);
            const std::optional<glm::dvec2> p = imageFromEye(from, rayFrom);
            if (!p || !(p->x >= 0 && p->x < from.width() && p->y >= 0 && p->y < from.height())) {
                ++out.unseen;
                continue;
            }
            double distance = NAN;
            if (sampling == RemapSampling::Plane) {
                distance = planeDistanceAt(from, values, fromQuantity, *p, rayFrom);
                out.nearestAtEdges += std::isnan(distance);
            }
            if (std::isnan(distance)) {
                const glm::dvec3 sample = samplePoint(from, values, fromQuantity, int(p->x), int(p->y));
                distance = std::isnan(sample.x) ? NAN : distanceOfEyePoint(from, sample);
            }
            if (std::isnan(distance)) {
                ++out.misses;
                continue;
            }
            // The target's quantity on its own ray.
            const double eyeZ = to.eyeZOf(distance * *rayTo);
            double value = distance;
            if (toQuantity != DepthQuantity::Distance) {
                if (!(eyeZ > 0)) {  // 90° or more off the target's axis: no eye-z, no window depth
                    ++out.misses;
                    continue;
                }
                value = depthValueFromEyeZ(to, pWindowTo, eyeZ, toQuantity);
            }
            out.values[std::size_t(row) * to.width() + col] = value;
        }
    return out;
}

}  // namespace zcheck
