#pragma once
// Homogeneous clipping of one triangle (Sutherland–Hodgman in clip space, double).
//
// The rasterizer clips with it, and the comparison uses it to find the true edges of a
// triangle as drawn (a triangle crossing the near plane gains an edge there). Clip planes
// are 4-vectors π with "inside" meaning dot(π, pClip) ≥ 0.
#include <glm/glm.hpp>

#include <array>

namespace zcheck {

// A convex polygon in clip space; a triangle clipped by k planes has at most 3 + k vertices.
struct ClipPolygon {
    static constexpr int kMaxVertices = 12;
    std::array<glm::dvec4, kMaxVertices> pClip;
    int size = 0;
};

struct ClipPlanes {
    static constexpr int kMaxPlanes = 8;
    std::array<glm::dvec4, kMaxPlanes> plane;
    int size = 0;
};

// The near and far planes of the visible volume ndcZMin·w ≤ z ≤ w. Together they imply
// w ≥ 0, so what survives them lies in front of the eye.
ClipPlanes depthClipPlanes(double ndcZMin);

// Adds |x| ≤ guard·w and |y| ≤ guard·w (a guard band of `guard` times the viewport's half-size).
void addGuardBandPlanes(ClipPlanes& planes, double guard);

// Clips triangle (a, b, c); the result keeps the triangle's winding.
ClipPolygon clipTriangle(const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c, const ClipPlanes& planes);

}  // namespace zcheck
