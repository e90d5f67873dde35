#include "zcheck/drawn_polygon.h"

#include "zcheck/clip.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

namespace {

double distanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b)
{
    const glm::dvec2 ab = b - a;
    const double lengthSquared = glm::dot(ab, ab);
    const double t = lengthSquared > 0 ? std::clamp(glm::dot(p - a, ab) / lengthSquared, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

}  // namespace

namespace {

// The triangle clipped by `planes` (the near and far planes among them, so w > 0), its vertices
// divided and put through the viewport: window x, y and depth.
std::vector<glm::dvec3> clippedInWindow(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                                        const ClipPlanes& planes)
{
    const ClipPolygon polygon =
        clipTriangle(camera.clipFromWorld * glm::dvec4(a, 1.0), camera.clipFromWorld * glm::dvec4(b, 1.0),
                     camera.clipFromWorld * glm::dvec4(c, 1.0), planes);
    std::vector<glm::dvec3> window;
    for (int i = 0; i < polygon.size; ++i) {
        const glm::dvec4& pClip = polygon.pClip[i];
        window.emplace_back(camera.windowFromNdc * glm::dvec4(glm::dvec3(pClip) / pClip.w, 1.0));
    }
    return window;
}

// The triangle as drawn: clipped to the near and far planes, its vertices in window space.
std::vector<glm::dvec2> drawnPolygon(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    std::vector<glm::dvec2> window;
    for (const glm::dvec3& p : clippedInWindow(camera, a, b, c, depthClipPlanes(camera.convention().ndcZMin())))
        window.emplace_back(p);
    return window;
}

}  // namespace

double distanceToDrawnEdge(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                           const glm::dvec2& pWindow)
{
    const std::vector<glm::dvec2> polygon = drawnPolygon(camera, a, b, c);
    double nearest = INFINITY;
    for (std::size_t i = 0; i < polygon.size(); ++i)
        nearest = std::min(nearest, distanceToSegment(pWindow, polygon[i], polygon[(i + 1) % polygon.size()]));
    return nearest;
}

bool insideDrawnTriangle(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                         const glm::dvec2& pWindow)
{
    // Convex polygon: inside when the point is on the same side of every edge.
    const std::vector<glm::dvec2> polygon = drawnPolygon(camera, a, b, c);
    int positive = 0, negative = 0;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec2 e = polygon[(i + 1) % polygon.size()] - polygon[i], p = pWindow - polygon[i];
        const double side = e.x * p.y - e.y * p.x;
        positive += side > 0, negative += side < 0;
    }
    return polygon.size() >= 3 && (positive == 0 || negative == 0);
}

WindowDepthRange drawnDepthsNear(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                                 const glm::dvec2& pWindow, double radius)
{
    // The square around pWindow as four clip-space planes (the viewport is affine, and the near
    // and far planes keep w > 0): x_ndc ≥ lo is x − lo·w ≥ 0, and so on.
    const glm::dvec4 corner0 = camera.ndcFromWindow * glm::dvec4(pWindow - radius, 0.0, 1.0);
    const glm::dvec4 corner1 = camera.ndcFromWindow * glm::dvec4(pWindow + radius, 0.0, 1.0);
    const glm::dvec2 lo = glm::min(glm::dvec2(corner0), glm::dvec2(corner1));
    const glm::dvec2 hi = glm::max(glm::dvec2(corner0), glm::dvec2(corner1));
    ClipPlanes planes = depthClipPlanes(camera.convention().ndcZMin());
    planes.plane[planes.size++] = {1.0, 0.0, 0.0, -lo.x};
    planes.plane[planes.size++] = {-1.0, 0.0, 0.0, hi.x};
    planes.plane[planes.size++] = {0.0, 1.0, 0.0, -lo.y};
    planes.plane[planes.size++] = {0.0, -1.0, 0.0, hi.y};
    WindowDepthRange range;
    for (const glm::dvec3& p : clippedInWindow(camera, a, b, c, planes))
        range.lo = std::min(range.lo, p.z), range.hi = std::max(range.hi, p.z);
    return range;
}

}  // namespace zcheck
