#include "zcheck/clip.h"

namespace zcheck {

ClipPlanes depthClipPlanes(double ndcZMin)
{
    ClipPlanes planes;
    planes.plane[planes.size++] = {0.0, 0.0, 1.0, -ndcZMin};  // z ≥ ndcZMin·w
    planes.plane[planes.size++] = {0.0, 0.0, -1.0, 1.0};      // z ≤ w
    return planes;
}

void addGuardBandPlanes(ClipPlanes& planes, double guard)
{
    planes.plane[planes.size++] = {1.0, 0.0, 0.0, guard};   //  x ≥ −guard·w
    planes.plane[planes.size++] = {-1.0, 0.0, 0.0, guard};  //  x ≤  guard·w
    planes.plane[planes.size++] = {0.0, 1.0, 0.0, guard};
    planes.plane[planes.size++] = {0.0, -1.0, 0.0, guard};
}

ClipPolygon clipTriangle(const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c, const ClipPlanes& planes)
{
    ClipPolygon polygon;
    polygon.pClip[0] = a, polygon.pClip[1] = b, polygon.pClip[2] = c;
    polygon.size = 3;
    for (int p = 0; p < planes.size && polygon.size > 0; ++p) {
        const glm::dvec4& plane = planes.plane[p];
        ClipPolygon out;
        // Exactly, each plane adds at most one vertex; rounding with vertices on several
        // planes at once could add more. Never write past the array: drop such a sliver.
        if (polygon.size + 1 > ClipPolygon::kMaxVertices) return ClipPolygon{};
        for (int i = 0; i < polygon.size; ++i) {
            const glm::dvec4& current = polygon.pClip[i];
            const glm::dvec4& next = polygon.pClip[(i + 1) % polygon.size];
            const double dCurrent = glm::dot(plane, current);
            const double dNext = glm::dot(plane, next);
            if (dCurrent >= 0) out.pClip[out.size++] = current;
            if ((dCurrent >= 0) != (dNext >= 0)) {
                // Interpolate from the inside vertex so that an edge clipped from either
                // side yields the same point: shared edges stay watertight.
                const bool currentInside = dCurrent >= 0;
                const glm::dvec4& in = currentInside ? current : next;
                const glm::dvec4& outside = currentInside ? next : current;
                const double dIn = currentInside ? dCurrent : dNext;
                const double dOut = currentInside ? dNext : dCurrent;
                const double t = dIn / (dIn - dOut);
                out.pClip[out.size++] = in + t * (outside - in);
            }
        }
        polygon = out;
    }
    if (polygon.size < 3) polygon.size = 0;
    return polygon;
}

}  // namespace zcheck
