#pragma once
// Verifying a depth map rendered elsewhere (a GPU, an engine, Blender, a simulator) against
// the ray route's ground truth (library zcheck::diagnose): what a verification returns, the
// tolerance a map is judged with, and the pixel-by-pixel reading a verification is made of, for
// judging a sample of pixels without the whole comparison. MapVerifier (map_verifier.h) is the
// entry point; the rest of verification's steps are private to the library
// (src/verify_estimators.h).
//
// The map does not say which surface it saw: each hit takes the ground truth's surface when
// the comparison's rule (PixelJudge) accepts the map's depth on it; otherwise, among the
// triangles within 2 pixels and those sharing a vertex with them, one drawn within S of the
// pixel centre whose tolerance interval joined with the truth's holds the depth and under
// which the comparison explains the pixel — and, where no ray meets one, among the triangles
// zcheck's rasterizer draws at and around the pixel (a sliver's or a tip's snapped footprint);
// otherwise the truth's surface (a depth error) or kUnknownPrimitive. The accepted depths at a
// pixel are therefore one interval around the true depth: a map nearer the truth never fails
// where a farther one passes.
#include "zcheck/checker.h"
#include "zcheck/depth_map.h"

#include <cmath>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace zcheck {

// A map compared with the ray route's ground truth: both as render results, the comparison, and
// its report (secondRoute "map").
struct VerifyResult {
    RenderResult truth;       // the ray route
    RenderResult map;         // the map as a render result (the surface each hit saw: above)
    Comparison comparison;
    CheckReport report;
    std::vector<float> mapError;  // MapVerifier::verify: per pixel map − truth in report.mapErrors' units,
                                  // NaN where not compared on depth; empty otherwise
};

// Triangles around each vertex position (positions, not indices: loaders duplicate vertices),
// for guessing which surface a map saw, and, given the ray route, the triangles seen at points
// near a pixel centre. Holds references to the scene and the renderer. Immutable once built.
class VertexNeighbours {
public:
    explicit VertexNeighbours(const Scene& scene, const RayRenderer* rays = nullptr, const RasterRenderer* raster = nullptr);
    // The rasterizer whose drawing proposes surfaces no ray meets (a sliver or a triangle's tip
    // that snapping moves over a pixel centre); nullptr without one.
    const RasterRenderer* raster() const { return raster_; }
    // The triangles the ray route sees at the four corners of the box of half-side `reach`
    // pixels around pWindow (none without a ray renderer): surfaces a sample that close to the
    // centre may show that no neighbouring pixel shows (the far side of a ridge).
    template <class Visit>
    void forEachSeenNear(const Camera& camera, const glm::dvec2& pWindow, double reach, Visit&& visit) const
    {
        if (!rays_) return;
        for (const glm::dvec2 corner : {glm::dvec2(-reach, -reach), glm::dvec2(reach, -reach), glm::dvec2(-reach, reach),
                                        glm::dvec2(reach, reach)})
            if (const std::uint32_t seen = rays_->primitiveAt(camera, pWindow + corner); seen != kNoPrimitive) visit(seen);
    }
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
    const RayRenderer* rays_;
    const RasterRenderer* raster_;
    std::unordered_map<std::string, std::vector<std::uint32_t>> around_;
};

// The tolerance a map rendered elsewhere is judged with: the default, its slope credit for a
// depth sampled up to S off the pixel centre in each axis (compare.h), and for a map of eye-z or
// distance the constant C of its own storage — 4 for floating point (binary32 or binary16, as a
// float32 depth buffer), 1 for integers (a rounded value, as a unorm16 buffer) — never the
// camera's depth format or reversal, which concern window and NDC maps only.
inline ToleranceModel mapTolerance(const DepthMap& map)
{
    ToleranceModel model;
    model.slopeCredit = SlopeCredit::SampleOffset;
    if (map.quantity == DepthQuantity::EyeZ || map.quantity == DepthQuantity::Distance)
        model.storageConstant = map.integerStorage() ? 1.0 : 4.0;
    return model;
}

// One pixel of a map as the raster side of a comparison sees it.
struct MapPixel {
    double depth = NAN;                        // window depth, NaN for a miss
    double quantum = 0;                        // the storage step there, in window units
    double allowance = 0;                      // the declared accuracy there, in window units (DeclaredMap)
    std::uint32_t primitive = kNoPrimitive;    // the surface chosen (above); kNoPrimitive for a miss
};

// Reads a map pixel by pixel against an already rendered truth: the per-pixel rule a
// verification reads the whole map with, and the comparison's class for one pixel, so that a
// diagnosis can judge a sample of pixels without reading the whole map. Holds references;
// thread-safe.
// `judge`: made for the scene and camera with mapTolerance(map) (std::logic_error otherwise);
// SlopeSource::TableOfSeen for reading every pixel, EachCall for a sample.
class MapReader {
public:
    MapReader(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
              const VertexNeighbours& neighbours);
    // `search` false: a hit that does not agree with the truth's own surface is left as
    // kUnknownPrimitive unsearched (a cheap test of whether the pixel needs the search).
    MapPixel read(int col, int row, bool search = true) const;
    // The class compareRoutes gives the pixel (truth as the ray, the map as the raster).
    PixelClass classify(int col, int row, const MapPixel& pixel) const;

private:
    // The surfaces the rasterizer draws through the camera, drawn once on first need.
    const RenderResult& drawn() const;

    const Scene& scene_;
    const Camera& camera_;
    const DepthMap& map_;
    const RenderResult& truth_;
    const VertexNeighbours& neighbours_;
    const PixelJudge& judge_;
    mutable std::once_flag drawnOnce_;
    mutable RenderResult drawn_;
};

}  // namespace zcheck
