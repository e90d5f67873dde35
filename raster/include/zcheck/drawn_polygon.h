#pragma once
// The "drawn polygon" query: a world-space triangle as the rasterizer draws it — clipped to
// the near and far planes (clip.h), divided and put through the viewport — for the
// comparison's edge explanations. Pure functions of the camera's matrices; thread-safe.
#include "zcheck/camera.h"

#include <glm/glm.hpp>

namespace zcheck {

// Distance in pixels from window point pWindow to the boundary of the triangle as drawn
// (clipped to the near and far planes, projected to the window); +inf if nothing is drawn.
double distanceToDrawnEdge(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                           const glm::dvec2& pWindow);
// Whether window point pWindow lies inside the triangle as drawn.
bool insideDrawnTriangle(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                         const glm::dvec2& pWindow);

}  // namespace zcheck
