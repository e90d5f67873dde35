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

RemappedMap remapDepthMap(const Camera& from, const std::vector<double>& values, DepthQuantity fromQuantity,
                          const Camera& to, DepthQuantity toQuantity, RemapSampling sampling)
{
    if (values.size() != std::size_t(from.width()) * from.height())
        throw Error("the map holds " + std::to_string(values.size()) + " values for a " + std::to_string(from.width()) +
                    "x" + std::to_string(from.height()) + " camera");
    requireSharedCentre(from, to);
    for (const auto& [camera, quantity, role] : {std::tuple{&from, fromQuantity, "source"}, std::tuple{&to, toQuantity, "target"}})
        if (camera->lens() && (quantity == DepthQuantity::Window || quantity == DepthQuantity::Ndc))
            requireDepthValue(*camera, quantity, 0.5, std::string("the ") + role + " quantity");  // refused: no depth buffer
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
