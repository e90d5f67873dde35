#pragma once
// The "drawn polygon" query: a world-space triangle as the rasterizer draws it — clipped to
// the near and far planes (clip.h), divided and put through the viewport — for the
// comparison's edge explanations. Pure functions of the camera's matrices; thread-safe.
#include "zcheck/camera.h"

#include <glm/glm.hpp>

#include <cmath>

namespace zcheck {

// Distance in pixels from window point pWindow to the boundary of the triangle as drawn
// (clipped to the near and far planes, projected to the window); +inf if nothing is drawn.
double distanceToDrawnEdge(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                           const glm::dvec2& pWindow);
// Whether window point pWindow lies inside the triangle as drawn.
bool insideDrawnTriangle(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                         const glm::dvec2& pWindow);

// The window depths [lo, hi] the triangle as drawn takes within `radius` pixels of window point
// pWindow along x and along y; empty (lo > hi) where none of it lies there. Unlike its plane's
// depth along one ray, this holds for a triangle seen edge-on or made a line by binary32
// positions far from the origin: it projects to a segment with many depths at each point, yet
// the rasterizer, snapping its vertices, may draw a sliver of it, every depth of which the
// triangle takes within the snap's reach.
struct WindowDepthRange {
    double lo = INFINITY, hi = -INFINITY;
    bool empty() const { return !(lo <= hi); }
};
WindowDepthRange drawnDepthsNear(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                                 const glm::dvec2& pWindow, double radius);

}  // namespace zcheck
