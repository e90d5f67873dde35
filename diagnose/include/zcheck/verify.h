#pragma once
// Verifying a depth map rendered elsewhere (a GPU, an engine, Blender, a simulator) against
// the ray route's ground truth (library zcheck::diagnose): the pieces MapVerifier::verify and
// MapVerifier::diagnose (map_verifier.h) are made of, and what a verification returns.
//
// The map does not say which surface it saw: each hit takes the ground truth's surface when
// the comparison's rule (PixelJudge) accepts the map's depth on it; otherwise, among the
// triangles within 2 pixels and those sharing a vertex with them, one drawn within S of the
// pixel centre whose tolerance interval joined with the truth's holds the depth and under
// which the comparison explains the pixel — and, where no ray meets one, among the triangles
// zcheck's rasterizer draws at and around the pixel (a sliver's or a tip's snapped footprint);
// otherwise the truth's surface (a depth error) or kUnknownPrimitive. The accepted depths at a pixel are therefore one interval around the
// true depth: a map nearer the truth never fails where a farther one passes.
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

// The eye-z step of a standard binary32 depth buffer (near → 0, far → 1, not reversed) of the
// camera's near and far planes at `eyeZ`: the precision of an eye-z or distance map linearized
// from a renderer's depth buffer, which such a map is allowed besides its own storage step —
// the same whatever the camera's depth format, range and reversal, which no linear map depends on.
double linearizedBufferStep(const Camera& camera, double eyeZ);

// The pixel's window depth, storage step and allowance as the comparison reads them (its
// surface left kNoPrimitive); `truthDepth` is the truth's window depth there, the reference for
// a miss. The value's step and declared accuracy are carried into window units through the
// quantity's mapping at the pixel: the larger window change of value ± step, and of value ±
// ValueAccuracy::declaredAt(value). A window map's step is the camera's depth format's unless
// the file states one (then at least binary32's spacing at the window depth); an eye-z or
// distance map's is at least linearizedBufferStep.
MapPixel mapPixelDepth(const Camera& camera, const DepthMap& map, int col, int row, double truthDepth);
// The same for one value of `quantity` judged by `accuracy` (a step of 0: binary32, or for a
// window map the camera's depth format).
MapPixel mapPixelDepth(const Camera& camera, DepthQuantity quantity, double value, const ValueAccuracy& accuracy, int col,
                       int row, double truthDepth);

// Reads a map pixel by pixel against an already rendered truth: the per-pixel rule of
// renderResultFromMap, and the comparison's class for one pixel, so that a diagnosis can
// judge a sample of pixels without reading the whole map. Holds references; thread-safe.
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

// The map as the raster side of a comparison (window depth per pixel, a hit where the value is
// not a miss, the surface chosen as above). `quantum` and `allowance` receive each pixel's
// storage step and declared accuracy in window units (allowance left empty where the map
// declares none), for the comparison's DeclaredMap. `judge` as MapReader's; the comparison of
// the result may then use it too (compareRoutes), finding the slopes it computed.
RenderResult renderResultFromMap(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                                 const VertexNeighbours& neighbours, std::vector<double>& quantum,
                                 std::vector<double>& allowance);

// Throws Error unless `map` is camera.width() × camera.height() with a value per pixel.
void requireMapFits(const Camera& camera, const DepthMap& map);
// The map's values its quantity cannot hold (kindOfDepthValue), counted into `report`
// (outOfRange, the first one and its stored value); verifyAgainst does it for every reading.
void countOutOfRange(const Camera& camera, const DepthMap& map, ComparisonReport& report);
// Refuses (Error beginning with `name`) a map whose values are all misses or out of range with
// at least one out of range: it holds nothing of its quantity (a wrong --quantity, mostly).
void requireDepthsInRange(const Camera& camera, const DepthMap& map, const std::string& name);

// Whether `map` certainly cannot be consistent with `truth`, judged on a sample: the pixels
// that do not simply agree with the truth's own surface are looked for on every fourth row
// and column, and an evenly spaced sample of at most 1024 of them is read and classified
// exactly as the full comparison would, in blocks, until 64 unexplained ones are found. An
// unexplained pixel proves the map inconsistent (a consistent map has none anywhere); the
// value returned then estimates how many pixels are unexplained, from the sample's share.
// std::nullopt: every sampled pixel is explained, or there are too few suspects to bother;
// only the full comparison can tell.
std::optional<std::int64_t> screenUnexplained(const Scene& scene, const Camera& camera, const DepthMap& map,
                                              const RenderResult& truth, const VertexNeighbours& neighbours);

// How near a hypothesis comes, before a truth is rendered for it: at a 16×16 grid of pixel
// centres, one ray each (RayRenderer::primitiveAt), whether `map`, read through `camera`,
// agrees with the surface the ray meets by the comparison's rule (PixelJudge). `agreeing`:
// the share of the grid's pixels where the map or the truth sees a surface at which they agree
// (0 where none does); `seen`: that share of the whole grid. A consistent reading fails only at
// edges and where the map shows a neighbouring surface, which a coarse grid seldom meets: an
// `agreeing` under 3/4 rules it out.
struct Probe {
    double agreeing = 0, seen = 0;
    bool rulesOut() const { return agreeing < 0.75; }
    // The unexplained pixels of `pixels` the probe's share stands for.
    std::int64_t unexplainedOf(double pixels) const { return std::llround((1 - agreeing) * seen * pixels); }
};
Probe probeAgreement(const Scene& scene, const RayRenderer& rays, const Camera& camera, const DepthMap& map);

// Whether the truth around pixel (col, row) is one smooth surface: its 3×3 neighbourhood
// (clamped at the image's border) all hit or all miss, and, where hit, window depth nearly
// affine in x and y (a plane's is): second differences across the pixel in x, y and both
// diagonals within a tenth of the rise plus 1e-12. False at silhouettes and occlusion edges
// (there the second difference is as large as the rise) and at sharp creases; true on a
// finely tessellated curved surface, whose gentle creases bend depth far less.
bool onePlaneAround(const RenderResult& truth, int width, int height, int col, int row);

// Of a comparison's unexplained pixels, those at edges of the truth (a 3×3 neighbourhood that
// is not one plane, or a coverage change), and of those the ones whose map depth lies between
// the truth's depths around them (the clear value standing for a miss): a blend of the
// surfaces either side, as anti-aliased or resolved multisample depth holds.
struct EdgeTally {
    std::int64_t atEdges = 0, blends = 0;
};
EdgeTally tallyEdges(const Camera& camera, const RenderResult& truth, const RenderResult& map, const Comparison& comparison);

// A map's declarations (MapAccuracy) judged as a whole, over the pixels a
// comparison compared on depth (Agree, DepthError), in the map's own units (`mapRender`: the
// map as renderResultFromMap read it, the surface each pixel saw): what no pixel's
// tolerance can see. Sets report.declaredAccuracyRefused, which makes the map inconsistent:
//   holes   where holes are allowed, they are at most half the pixels where the truth sees a surface;
//   coarse  the declared accuracy at the median pixel is under a tenth of its depth (in eye-z):
//           a grid or tolerance as coarse as the depths accepts any map of the right order;
//   grid    a declared quantum Q is the grid the values were rounded to: ≥ 99 % of them (less
//           the offset) lie within 1/1000 of Q (or four binary32 spacings) of a multiple of Q;
//   bias    rounding and noise are unbiased: over the pixels where the map shows the truth's own
//           surface (256 or more), |mean(map − truth)| — the truth rounded to the declared grid,
//           if any, so that a rounding's own error is no bias — is within the median of C·q + S·m
//           + E (the tolerance of a map declaring nothing) plus six times the mean's sampling
//           error (the spread of the means of 16 interleaved samples, over 4). A declared
//           tolerance or noise absorbs no bias: a map 4·10⁻⁴ short everywhere is a scale mistake
//           whatever --rel-tolerance says, and one a centimetre far is an offset under any grid.
// A map declaring no accuracy is left as it is: its per-pixel tolerance bounds its median.
void judgeDeclaredAccuracy(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                           const RenderResult& mapRender, const std::vector<double>& quantum, Comparison& comparison);

// The map's errors in its own units (report.mapErrors, mapError per pixel), from a comparison
// of it: MapVerifier::verify's last step (a diagnosis's readings skip it).
void measureMapErrors(const Camera& camera, const DepthMap& map, VerifyResult& run);

// The comparison of `map` against an already rendered ground truth `truth` (one BVH, one
// truth render, many readings of the map).
VerifyResult verifyAgainst(const Scene& scene, const Camera& camera, const DepthMap& map, RenderResult truth,
                           const VertexNeighbours& neighbours);

}  // namespace zcheck
