#pragma once
// Comparison of the two routes and the tolerance model (DESIGN.md).
//
// Per pixel, four classes by coverage: both hit, both miss, ray-only, raster-only.
//
// Both hit, on the same primitive: consistent iff |d_raster − d_ray| ≤ C·q + S·m, where
//   q = storage quantum at d_ray (1 LSB for unorm-N, 1 ulp of binary32 for float32),
//   m = the window-depth slope of the hit plane per pixel: max(|∂d/∂x|, |∂d/∂y|) for the raster
//       route (its vertices snap by at most S/2 in x and in y), |∂d/∂x| + |∂d/∂y| for a map
//       rendered elsewhere (`verify`: its depth may be sampled up to S off the centre in both),
//   S = 2^−subpixelBits (the rasterizer's vertex snapping, 2^−8 for 16.8 fixed point),
//   C = 1 (unorm16), 4 (unorm24, float32), 8 (float32 with reversed-Z).
// Both hit, on different primitives (adjacent triangles, or surfaces closer together than
// the depth buffer resolves): the raster's surface may legitimately win, so the bound is
// the sum of both surfaces' tolerances, 2·C·q + S·(m_ray + m_raster).
// Otherwise a mismatch is *explained* only when the pixel centre lies within S pixels of an
// edge of a triangle involved (as drawn: clipped to the near and far planes), i.e. where
// vertex snapping can move the edge across the sample point, or when only the ray hits a
// surface whose depth lies within its tolerance of the clear value (stored, it would equal
// the clear value and fail the strict LESS/GREATER test: the far end of a unorm16 buffer
// with a tiny near plane), or when the surface involved lies on the near or far plane to
// within 2^-20 of its distance (Embree's binary32 tNear/tFar and the rasterizer's clipping
// round differently there). Everything else is an unexplained mismatch; a half-pixel or
// one-row shift can never hide among edge pixels.
//
// Every tolerance also carries E = 16·2^-52·max(|rangeMin|, |rangeMax|), the rounding of
// the double-precision forward chain itself; it matters only where binary32 ulps are finer
// still (reversed-Z float32 at the far plane, where window depth is ~0).
//
// Systematic bias: over both-hit pixels on one triangle where quantization dominates
// (S·m ≤ 0.1·q), a correct buffer rounds to nearest, so the mean signed error is ~0 q;
// truncation (or any one-sided rounding) drifts towards ±½ q while staying inside C·q at
// every pixel. With ≥ 1000 such pixels whose exact depths fall in every quarter of the
// quantum (so a constant-depth wall cannot fake it), |mean| > ¼ q is a depth bias.
//
// Verdict: consistent ⇔ no unexplained coverage mismatch, no depth error and no bias.
#include "zcheck/camera.h"
#include "zcheck/kernel_form.h"
#include "zcheck/large_buffer.h"
#include "zcheck/render.h"
#include "zcheck/scene.h"
#include "zcheck/tile_grid.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

enum class PixelClass : std::uint8_t {
    BothMiss,            // neither route sees a surface
    Agree,               // both hit, depths agree within tolerance
    EdgeSurface,         // both hit different surfaces beyond tolerance, the pixel centre at an
                         // edge of one of them or one of them on the near/far plane: explained
    DepthError,          // both hit, depths disagree beyond tolerance, unexplained
    RayOnlyEdge,         // only the ray hits, pixel centre at an edge: explained
    RasterOnlyEdge,      // only the raster hits, pixel centre at an edge: explained
    RayOnlyAtClear,      // only the ray hits a surface whose depth is within tolerance of the clear
                         // value: quantized, it cannot pass the strict depth test (a precision
                         // limit of the camera and format, not a chain error): explained
    AtClipPlane,         // only one route hits, and the surface lies on the near or far plane
                         // within binary32 rounding of where the routes clip: explained
    RayOnly,             // only the ray hits, unexplained
    RasterOnly,          // only the raster hits, unexplained
    Hole,                // only the ray hits, and the raster side is a map that declared it leaves
                         // holes (DeclaredMap::holesAllowed): counted, explained
};
std::string toString(PixelClass pixelClass);
// DepthError, RayOnly and RasterOnly: the classes no tolerance explains.
bool isUnexplained(PixelClass pixelClass);

// What the slope credit S·m stands for (compare.h's m).
enum class SlopeCredit {
    VertexSnapping,  // the raster route: vertices snapped by at most S/2 per axis; m = max of the partials
    SampleOffset,    // a map from elsewhere: depth sampled up to S off the centre per axis; m = their sum
};

struct ToleranceModel {
    int subpixelBits = 8;  // S = 2^−subpixelBits pixels
    SlopeCredit slopeCredit = SlopeCredit::VertexSnapping;
    // C, in storage quanta, when the compared side's own storage states it (a map of eye-z or
    // distance: its file's, never the camera's depth buffer's); 0: the camera's depth format's.
    double storageConstant = 0;

    double snapPixels() const { return 1.0 / double(1 << subpixelBits); }
    // C, in storage quanta, for a depth buffer of these settings.
    static double constantQuanta(const DepthSettings& depth);
    // C as this model applies it to a camera of these settings.
    double constantFor(const DepthSettings& depth) const
    {
        return storageConstant > 0 ? storageConstant : constantQuanta(depth);
    }

    bool operator==(const ToleranceModel& other) const
    {
        return subpixelBits == other.subpixelBits && slopeCredit == other.slopeCredit &&
               storageConstant == other.storageConstant;
    }
    bool operator!=(const ToleranceModel& other) const { return !(*this == other); }
};

// One pixel as the report shows it.
struct PixelFinding {
    int col = 0, row = 0;       // row 0 at the top
    PixelClass pixelClass = PixelClass::BothMiss;
    double rayWindowDepth = 0;      // d_ray (exact, or the clear value on a miss)
    double rasterWindowDepth = 0;   // d_raster (stored value, or the clear value on a miss)
    double errorQuanta = 0;         // |d_raster − d_ray| / q (both hit only)
    double toleranceQuanta = 0;     // the pixel's tolerance / q (both hit only)
    std::uint32_t rayPrimitive = kNoPrimitive;
    std::uint32_t rasterPrimitive = kNoPrimitive;
};

struct ComparisonReport {
    int width = 0, height = 0;
    // Coverage classes; bothHit + bothMiss + rayOnly + rasterOnly = width·height.
    std::int64_t bothHit = 0;       // both routes see a surface
    std::int64_t bothMiss = 0;      // neither does
    std::int64_t rayOnly = 0;       // the ray hits, the raster does not
    std::int64_t rasterOnly = 0;    // the raster hits, the ray does not
    // Both-hit pixels split by outcome; agree + edgeSurface + depthErrors = bothHit.
    std::int64_t agree = 0;         // depths within tolerance
    std::int64_t edgeSurface = 0;   // different surfaces beyond tolerance at an edge or clip plane (explained)
    std::int64_t depthErrors = 0;   // beyond tolerance, unexplained
    // Coverage mismatches split; explained + unexplained = rayOnly + rasterOnly.
    std::int64_t coverageExplained = 0;    // pixel centre within S of an edge, or depth at the clear value
    std::int64_t lostAtClearValue = 0;     // of those: ray-only surfaces whose depth quantizes to the clear value
    std::int64_t atClipPlane = 0;          // of those: a surface on the near or far plane
    std::int64_t holes = 0;                // of those: holes of a map that declared it leaves them
    std::int64_t coverageUnexplained = 0;  // anything else
    // Over the both-hit pixels compared on depth (agree + depthErrors):
    double maxErrorQuanta = 0;      // max |d_raster − d_ray| / q
    double p99ErrorQuanta = 0;      // its 99th percentile
    double maxErrorOverTolerance = 0;  // max |d_raster − d_ray| / tolerance; ≤ 1 means within
    double maxRelativeEyeZError = 0;   // max |z_eye(d_raster) − z_eye(d_ray)| / z_eye(d_ray)
    double p99RelativeEyeZError = 0;   // its 99th percentile
    PixelFinding worst;             // the pixel with the largest error / tolerance
    // Up to 20 unexplained pixels, in scan order, and the bounding box of all of them
    // (inclusive; empty when there are none).
    std::vector<PixelFinding> unexplainedSamples;
    int unexplainedMinCol = 0, unexplainedMinRow = 0, unexplainedMaxCol = -1, unexplainedMaxRow = -1;

    // The bias test (see above):
    std::int64_t biasSamples = 0;          // pixels where quantization dominates
    double meanSignedErrorQuanta = 0;      // mean of (d_raster − d_ray) / q over them
    bool depthBias = false;                // a systematic rounding bias was found

    // A verified map's pixels whose values its quantity cannot hold (kindOfDepthValue: window 2,
    // a negative eye-z): errors whatever the classes above say of them; the first in scan order
    // and its value as stored. A route's render has none.
    std::int64_t outOfRange = 0;
    int outOfRangeCol = -1, outOfRangeRow = -1;
    double outOfRangeValue = 0;

    // A verified map's declared accuracy judged as a whole (diagnose/verify.h,
    // judgeDeclaredAccuracy): why it cannot stand — a bias it would absorb, a grid the values do
    // not lie on, an accuracy as coarse as the depths — or "" when it stands (or none was declared).
    std::string declaredAccuracyRefused;

    std::int64_t unexplained() const { return depthErrors + coverageUnexplained; }
    bool consistent() const
    {
        return unexplained() == 0 && !depthBias && outOfRange == 0 && declaredAccuracyRefused.empty();
    }
};

struct Comparison {
    ComparisonReport report;
    LargeVector<PixelClass> pixelClass;      // per pixel
    LargeVector<float> errorOverTolerance;   // per pixel: |Δ| / tolerance for both-hit, 0 elsewhere
};

// Window-depth slope m of a world-space triangle's plane, per pixel (may be +inf for a plane
// seen edge-on), with what it needs of the camera computed once.
struct DepthSlopeFrame {
    explicit DepthSlopeFrame(const Camera& camera, SlopeCredit credit = SlopeCredit::VertexSnapping);
    double slope(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) const;

    glm::dmat4 clipPlaneFromWorldPlane;  // transpose(worldFromClip)
    double zWindowPerZNdc, ndcPerPixelX, ndcPerPixelY;
    SlopeCredit credit;
};

// The per-pixel rule above, in one place: the comparison applies it to the raster's surface,
// and `verify` (which must guess the surface a map saw) applies it to every candidate surface,
// so that which surfaces a pixel may show and whether its depth agrees are one decision.
// Thread-safe: const calls may run from several threads at once.
//
// Where a judge finds a triangle's slope m (SlopeSource), the same value either way:
// - TableOfSeen, for judging whole images: the slopes of the triangles asked about are computed
//   once, a block of consecutive triangles at a time, into a table the comparison's kernels read
//   with one load (check/src/slope_table.h).
// - EachCall, for a judge asked about a few thousand pixels or fewer (verify's probes of a
//   camera, a fit's samples): m computed from the triangle at every call; making it costs
//   nothing per triangle.
enum class SlopeSource { TableOfSeen, EachCall };

class SlopeTable;

class PixelJudge {
public:
    // Reads ZCHECK_KERNELS (zcheck/kernel_form.h: the form its comparisons run in) and throws Error
    // for a value it refuses; so do compareRoutes and TileComparison, which make one.
    PixelJudge(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance = {},
               SlopeSource slopes = SlopeSource::TableOfSeen);
    ~PixelJudge();
    PixelJudge(const PixelJudge&) = delete;
    PixelJudge& operator=(const PixelJudge&) = delete;

    // One surface's tolerance at depth-storage quantum q, in window-depth units:
    // C·q + S·m + E + a (m = 0 for kUnknownPrimitive, which earns no slope credit; a, the
    // allowance, is what a map rendered elsewhere declares of its accuracy — DeclaredMap — and
    // 0 for zcheck's own routes).
    double surfaceTolerance(std::uint32_t primitive, double q, double allowance = 0) const;
    // The same for a surface whose slope m = slope(primitive) is known already.
    double toleranceForSlope(double m, double q, double allowance = 0) const { return terms_.of(m, q, allowance); }
    // The tolerance model's terms and its two rules, written once for every form of the
    // comparison: `Real` is double for one pixel, or a vector of doubles with + * and <= (GCC's
    // vector extensions: the AVX-512 row pass's eight lanes), computed with the same operations
    // in the same order, so the forms agree bit for bit. (Always inlined: into the AVX-512 form
    // as eight lanes, never called as a function of the baseline target.)
    struct ToleranceTerms {
        double C, S, E;
        // The tolerance C·q + S·m + E + a, into `bound`.
        template <class Real>
        __attribute__((always_inline)) void bound(const Real& m, const Real& q, const Real& a, Real& bound) const
        {
            bound = C * q + S * m + E + a;
        }
        double of(double m, double q, double a = 0) const
        {
            double b;
            bound(m, q, a, b);
            return b;
        }
        // Whether quantization dominates the tolerance, S·m + a ≤ q/10, into `dominates` (bool,
        // or a vector of lane masks): the pixels the bias test counts (above).
        template <class Real, class Mask>
        __attribute__((always_inline)) void quantizationDominates(const Real& m, const Real& q, const Real& a,
                                                                  Mask& dominates) const
        {
            dominates = S * m + a <= 0.1 * q;
        }
    };
    const ToleranceTerms& toleranceTerms() const { return terms_; }
    // Both routes hit: d_ray on `rayPrimitive`, d_raster on `rasterPrimitive`, at window point
    // pWindow. Returns Agree, EdgeSurface or DepthError; `bound` receives the tolerance used.
    // `allowance`: the raster side's declared accuracy there (surfaceTolerance), added once.
    PixelClass bothHit(double rayDepth, std::uint32_t rayPrimitive, double rasterDepth,
                       std::uint32_t rasterPrimitive, double q, const glm::dvec2& pWindow, double& bound,
                       double allowance = 0) const;
    // Only one route hits, on `primitive` (`rayHit`: the ray's hit, at window depth `depth`):
    // RayOnlyEdge/RasterOnlyEdge, RayOnlyAtClear, AtClipPlane, or RayOnly/RasterOnly — or Hole
    // for a ray-only pixel none of those explains when the raster side allows holes (DeclaredMap).
    PixelClass oneHit(bool rayHit, double depth, std::uint32_t primitive, double q, const glm::dvec2& pWindow,
                      bool holesAllowed = false) const;
    // Whether pWindow lies within S pixels of the primitive's edge as drawn.
    bool nearEdge(std::uint32_t primitive, const glm::dvec2& pWindow) const;
    // Whether the primitive's plane meets the pixel's ray on the near or far plane.
    bool atClipPlane(std::uint32_t primitive, const glm::dvec2& pWindow) const;
    // m of the primitive's plane (DepthSlopeFrame::slope), 0 for one not of the scene.
    double slope(std::uint32_t primitive) const;
    // TableOfSeen: the table the comparison's kernels read slopes from (check/src/slope_table.h,
    // private to zcheck_check); null for EachCall.
    const SlopeTable* slopeTable() const { return table_.get(); }
    // The form the comparison's kernels run in (ZCHECK_KERNELS, read when the judge was made).
    KernelForm form() const { return form_; }
    double snapPixels() const { return terms_.S; }
    // What it was made for.
    const Scene& scene() const { return scene_; }
    const Camera& camera() const { return camera_; }
    // The camera in the scene's frame (CameraInSceneFrame): what meets scene().positions.
    const Camera& cameraInSceneFrame() const { return local_.get(); }
    const ToleranceModel& tolerance() const { return tolerance_; }

private:
    bool known(std::uint32_t primitive) const { return primitive < scene_.triangles.size(); }
    glm::dvec3 vertex(std::uint32_t primitive, int corner) const;
    double computeSlope(std::uint32_t primitive) const;  // DepthSlopeFrame::slope of its corners

    const Scene& scene_;
    const Camera& camera_;
    CameraInSceneFrame local_;  // cameraInSceneFrame()
    ToleranceModel tolerance_;
    ToleranceTerms terms_;
    KernelForm form_;  // form()
    DepthSlopeFrame slopeFrame_;
    std::unique_ptr<SlopeTable> table_;  // TableOfSeen's; null for EachCall
};

// One route's results over a rectangle of the image, as the comparison reads them: pixel
// (col, row) is entry at(col, row) of each array. A whole render is the rectangle at (0, 0)
// with the image's width as stride (of()); a check that draws tile by tile passes its tile.
struct RoutePixels {
    const double* windowDepth = nullptr;
    const std::uint32_t* primitive = nullptr;  // kNoPrimitive where nothing was hit
    const glm::dvec3* pEye = nullptr;          // ray route, optional: exact hit points in eye space
    const double* quantum = nullptr;           // optional: each pixel's storage quantum (compareRoutes)
    const double* allowance = nullptr;         // optional: each pixel's declared allowance (DeclaredMap)
    bool holesAllowed = false;                 // DeclaredMap::holesAllowed
    int col0 = 0, row0 = 0;                    // the rectangle's first pixel
    std::size_t stride = 0;                    // entries from one row to the next

    std::size_t at(int col, int row) const { return std::size_t(row - row0) * stride + std::size_t(col - col0); }
    static RoutePixels of(const RenderResult& render);
};

// The comparison tile by tile (squares of kTileSize pixels, numbered row by row): call
// compareTile for every tile, in any order and from several threads at once, then finish().
// Tiles are merged in tile order and what depends on scan order is restored (the first
// unexplained pixels, the worst pixel among equals), so the report is the same for any
// order and thread count, and the same as compareRoutes'. `perPixel`, when given, receives
// the classes and ratios (sized here, not cleared: each compareTile writes every pixel of its
// tile, so they are whole once every tile is compared); without it nothing per pixel is kept. Keepers' floors:
// see check/src/percentile.h; finish() returns nullopt when one was too high (compare again without).
class TileComparison {
public:
    static constexpr int kTileSize = 64;

    TileComparison(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance, Comparison* perPixel,
                   float errorQuantaFloor = 0.0f, float relativeEyeZFloor = 0.0f);
    // The same with a judge of the caller's (the judge's scene, camera and tolerance), which
    // must outlive this: the slopes it computed for one comparison serve the next.
    TileComparison(const PixelJudge& judge, Comparison* perPixel, float errorQuantaFloor = 0.0f,
                   float relativeEyeZFloor = 0.0f);
    ~TileComparison();
    TileComparison(const TileComparison&) = delete;
    TileComparison& operator=(const TileComparison&) = delete;

    const TileGrid& tiles() const;  // kTileSize squares over the camera's image
    // `ray` and `raster` must cover the tile (they may cover more).
    void compareTile(int tile, const RoutePixels& ray, const RoutePixels& raster);
    // The tile's rows in [rowBegin, rowEnd) only (image rows; cut to the tile). A tile may be
    // compared in several such calls, each of its rows once and in order (top to bottom, each
    // call after the one before it returned), interleaved with other tiles' calls in any way:
    // the report is the same as compareTile's.
    void compareTileRows(int tile, int rowBegin, int rowEnd, const RoutePixels& ray, const RoutePixels& raster);
    // compareTileRows for every tile of band `band` (the tiles of one row of tiles, numbered from
    // the top), image row by image row across the band: each row of the arrays is read as one
    // stream. The same rules: a band's tiles are not compared by other calls at the same time.
    void compareBandRows(int band, int rowBegin, int rowEnd, const RoutePixels& ray, const RoutePixels& raster);
    std::optional<ComparisonReport> finish();

private:
    void sizePerPixel();  // perPixel's arrays, for the camera's pixels
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Compares two renders of `scene` through `camera`, tiles in parallel (TileComparison: the
// report is the same for any number of threads). `ray` must carry exact
// depths (the ray route); `raster` holds stored depth-buffer values. `rasterQuantum`, when given, is the
// storage quantum of each raster pixel in window-depth units (a map stored as eye-z or
// distance, or as scaled integers); otherwise q comes from the camera's depth format.
// A raster primitive id that is not a triangle of the scene (kUnknownPrimitive) marks a hit
// whose surface is unknown: it earns no edge or clip-plane explanation and no slope credit.
constexpr std::uint32_t kUnknownPrimitive = 0xFFFFFFFEu;
// What a map rendered elsewhere, compared as the raster side (verify), says of itself beyond its
// depths: per pixel (width·height entries, row by row), its storage quantum in window units, and
// the allowance its declared accuracy adds to the tolerance (window units, ≥ 0); and whether a
// pixel it leaves empty where the ray hits is a hole (PixelClass::Hole, counted in
// ComparisonReport::holes, explained) rather than unexplained. Absent arrays: the camera's
// depth format's quantum, no allowance.
struct DeclaredMap {
    const std::vector<double>* quantum = nullptr;
    const std::vector<double>* allowance = nullptr;
    bool holesAllowed = false;
};

Comparison compareRoutes(const Scene& scene, const Camera& camera, const RenderResult& ray,
                         const RenderResult& raster, const ToleranceModel& tolerance = {},
                         const DeclaredMap& declared = {});
// The same through a judge of the caller's (its scene, camera and tolerance; TableOfSeen, or
// every slope is computed per pixel): `verify` reads a map with the judge it then compares with.
Comparison compareRoutes(const PixelJudge& judge, const RenderResult& ray, const RenderResult& raster,
                         const DeclaredMap& declared = {});

// The same for one triangle (DepthSlopeFrame::slope).
double windowDepthSlope(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

}  // namespace zcheck
