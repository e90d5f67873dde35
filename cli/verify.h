#pragma once
// Verifying a depth map rendered elsewhere (a GPU, an engine, Blender, a simulator) against
// Embree's ground truth for the same scene and camera, with the same tolerance model, and
// diagnosing a failure by testing the classic hypotheses.
#include "check.h"

#include <string>
#include <unordered_map>
#include <vector>

namespace zcheck {

struct ExternalDepthMap {
    int width = 0, height = 0;
    DepthQuantity quantity = DepthQuantity::Window;
    std::vector<double> value;   // row 0 at the top; misses as eyePointFromDepth defines them
    double valueQuantum = 0;     // the storage step of `value` (1/scale for integer files); 0: binary32
};

// Triangles around each vertex position (positions, not indices: loaders duplicate vertices),
// for guessing which surface a map saw. Holds a reference to the scene.
class VertexNeighbours {
public:
    explicit VertexNeighbours(const Scene& scene);
    // `primitive` and every triangle that shares a vertex position with it.
    template <class Visit>
    void forEachNeighbour(std::uint32_t primitive, Visit&& visit) const
    {
        for (int k = 0; k < 3; ++k)
            for (std::uint32_t t : around_.at(key(scene_.positions[scene_.triangles[primitive][k]]))) visit(t);
    }

private:
    static std::string key(const glm::vec3& p);
    const Scene& scene_;
    std::unordered_map<std::string, std::vector<std::uint32_t>> around_;
};

// The map as the raster side of a comparison: window depth per pixel, a hit where the value is
// not a miss. The map does not say which surface it saw: each hit takes the ground truth's
// surface when the comparison's rule (PixelJudge) accepts the map's depth on it; otherwise,
// among the triangles within 2 pixels and those sharing a vertex with them, one drawn within S
// of the pixel centre whose tolerance interval joined with the truth's holds the depth and
// under which the comparison explains the pixel; otherwise the truth's surface (a depth error)
// or kUnknownPrimitive. `quantum` receives each pixel's storage step in window units.
RenderResult renderResultFromMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map,
                                 const RenderResult& truth, const VertexNeighbours& neighbours,
                                 std::vector<double>& quantum);

struct VerifyRun {
    RenderResult truth;       // the ray route
    RenderResult map;         // the external map as a render result
    Comparison comparison;
    CheckReport report;
};
VerifyRun verifyDepthMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map, RayRenderer& rays);
// The same with the scene's vertex index built once by the caller (for many comparisons).
VerifyRun verifyDepthMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map, RayRenderer& rays,
                         const VertexNeighbours& neighbours);

struct Hypothesis {
    std::string name;         // e.g. "distance-as-eye-z"
    std::string explanation;  // "consistent if read as ray distance instead of eye-z"
    bool consistent = false;
    std::int64_t unexplained = 0;
};

// Tests each classic hypothesis (flips, half-pixel shifts, the other NDC depth range,
// reversed, linear or eye-z depth passed as window depth, distance vs eye-z, transposed or
// other-handed matrix, small field-of-view and aspect errors) by re-reading the map or
// re-rendering the ground truth under it; returns them all, in order of simplicity.
std::vector<Hypothesis> diagnoseDepthMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map,
                                         RayRenderer& rays);

}  // namespace zcheck
