#include "zcheck/compare.h"

#include "zcheck/camera_rays.h"
#include "zcheck/drawn_polygon.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/detail/lane_mask.h"
#include "zcheck/large_buffer.h"
#include "percentile.h"
#include "slope_table.h"

#ifdef ZCHECK_X86_AVX512
#include <immintrin.h>
#endif
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>

namespace zcheck {

std::string toString(PixelClass pixelClass)
{
    switch (pixelClass) {
    case PixelClass::BothMiss: return "both-miss";
    case PixelClass::Agree: return "agree";
    case PixelClass::EdgeSurface: return "edge-surface";
    case PixelClass::DepthError: return "depth-error";
    case PixelClass::RayOnlyEdge: return "ray-only-edge";
    case PixelClass::RasterOnlyEdge: return "raster-only-edge";
    case PixelClass::RayOnlyAtClear: return "ray-only-at-clear";
    case PixelClass::AtClipPlane: return "at-clip-plane";
    case PixelClass::RayOnly: return "ray-only";
    case PixelClass::RasterOnly: return "raster-only";
    case PixelClass::Hole: return "hole";
    }
    return "?";
}

double ToleranceModel::constantQuanta(const DepthSettings& depth)
{
    switch (depth.format) {
    case DepthFormat::Unorm16: return 1.0;
    case DepthFormat::Unorm24: return 4.0;
    case DepthFormat::Float32: return depth.reversed ? 8.0 : 4.0;
    }
    return 4.0;
}

DepthSlopeFrame::DepthSlopeFrame(const Camera& camera, SlopeCredit credit)
    // The plane n·p + d = 0 in world space maps to clip space through the transpose of
    // worldFromClip; there a·x + b·y + c·z + d·w = 0, so in NDC z = −(a·x + b·y + d)/c.
    : clipPlaneFromWorldPlane(glm::transpose(camera.worldFromClip)),
      zWindowPerZNdc(std::abs(camera.windowFromNdc[2][2])),
      ndcPerPixelX(std::abs(camera.ndcFromWindow[0][0])),
      ndcPerPixelY(std::abs(camera.ndcFromWindow[1][1])),
      credit(credit)
{
}

namespace {

// DepthSlopeFrame::slope's arithmetic, inlined where it is called: one triangle at a time, and
// over lane arrays in PixelJudge::slopes (several triangles per instruction there, so no
// branch: a plane seen edge-on selects +inf after the division by its zero).
ZCHECK_ALWAYS_INLINE inline double slopeOfTriangle(const DepthSlopeFrame& frame, const glm::dvec3& a,
                                                             const glm::dvec3& b, const glm::dvec3& c)
{
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const glm::dvec4 plane(normal, -glm::dot(normal, a));
    // The clip-space plane's x, y and z (its w is not needed): rows 0-2 of the product.
    const glm::dmat4& m = frame.clipPlaneFromWorldPlane;
    const double x = m[0][0] * plane.x + m[1][0] * plane.y + m[2][0] * plane.z + m[3][0] * plane.w;
    const double y = m[0][1] * plane.x + m[1][1] * plane.y + m[2][1] * plane.z + m[3][1] * plane.w;
    const double z = m[0][2] * plane.x + m[1][2] * plane.y + m[2][2] * plane.z + m[3][2] * plane.w;
    const double dx = std::abs(x) * frame.ndcPerPixelX, dy = std::abs(y) * frame.ndcPerPixelY;
    // A sample up to S off in x and in y moves depth by up to S·(|∂d/∂x| + |∂d/∂y|); vertices
    // snapped by up to S/2 per axis by no more than S·max (compare.h).
    const double slope =
        frame.zWindowPerZNdc * (frame.credit == SlopeCredit::SampleOffset ? dx + dy : std::max(dx, dy)) / std::abs(z);
    return z == 0 ? INFINITY : slope;
}

}  // namespace

double DepthSlopeFrame::slope(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) const
{
    return slopeOfTriangle(*this, a, b, c);
}

double windowDepthSlope(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return DepthSlopeFrame(camera).slope(a, b, c);
}

namespace {

// Slopes of up to kSlopeLanes consecutive triangles together: their corners dealt into lane
// arrays, then slopeOfTriangle lane by lane. Inlined into a baseline and an AVX-512 form
// (kernel_choice.h), both bit-identical to DepthSlopeFrame::slope of each (the same IEEE
// operations in the same order).
constexpr std::size_t kSlopeLanes = 64;

// The corners of `n` ≤ Lanes triangles dealt into lane arrays in double, for kernels that then
// work on several triangles per instruction: corner[v][axis][k] is corner v of triangle
// `triangle[k]`. The indices must be in range (validateScene). Always inlined, so that each
// form of a kernel compiles its own copy.
template <std::size_t Lanes>
ZCHECK_ALWAYS_INLINE inline void cornersInLanes(const Scene& scene, const std::uint32_t* triangle, std::size_t n,
                                                double (&corner)[3][3][Lanes])
{
    for (std::size_t k = 0; k < n; ++k) {
        const glm::uvec3& t = scene.triangles[triangle[k]];
        for (int v = 0; v < 3; ++v)
            for (int axis = 0; axis < 3; ++axis) corner[v][axis][k] = double(scene.positions[t[v]][axis]);
    }
}

ZCHECK_ALWAYS_INLINE inline void slopesTogether(const DepthSlopeFrame& frame, const Scene& scene, std::uint32_t first,
                                                std::size_t n, double* slope)
{
    std::uint32_t triangle[kSlopeLanes];
    for (std::size_t k = 0; k < n; ++k) triangle[k] = first + std::uint32_t(k);
    // Every corner asked for before the first is read (the loads then overlap, where reading
    // them in order waited on each few in turn), and the next block's index triples too: the
    // comparison often asks for blocks in order (the comparison ~5 % faster in process).
    for (std::size_t k = 0; k < n; ++k)
        for (int corner = 0; corner < 3; ++corner) __builtin_prefetch(&scene.positions[scene.triangles[first + k][corner]]);
    const std::size_t nextBlock = first + n, nextBlockEnd = std::min(scene.triangles.size(), nextBlock + kSlopeLanes);
    for (std::size_t k = nextBlock; k < nextBlockEnd; k += 64 / sizeof(glm::uvec3)) __builtin_prefetch(&scene.triangles[k]);
    alignas(64) double corner[3][3][kSlopeLanes];  // corner, axis, lane
    cornersInLanes(scene, triangle, n, corner);
    for (std::size_t k = 0; k < n; ++k)
        slope[k] = slopeOfTriangle(frame, glm::dvec3(corner[0][0][k], corner[0][1][k], corner[0][2][k]),
                                   glm::dvec3(corner[1][0][k], corner[1][1][k], corner[1][2][k]),
                                   glm::dvec3(corner[2][0][k], corner[2][1][k], corner[2][2][k]));
}

void slopesTogetherBaseline(const DepthSlopeFrame& frame, const Scene& scene, std::uint32_t first, std::size_t n,
                            double* slope)
{
    slopesTogether(frame, scene, first, n, slope);
}

#ifdef ZCHECK_X86_AVX512
ZCHECK_TARGET_AVX512 void slopesTogetherAvx512(const DepthSlopeFrame& frame, const Scene& scene, std::uint32_t first,
                                               std::size_t n, double* slope)
{
    slopesTogether(frame, scene, first, n, slope);
}
#endif

}  // namespace

PixelJudge::PixelJudge(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance, SlopeSource slopes)
    : scene_(scene),
      camera_(camera),
      tolerance_(tolerance),
      terms_{tolerance.constantFor(camera.depth()), tolerance.snapPixels(),
             16 * std::ldexp(1.0, -52) * std::max(std::abs(camera.depth().rangeMin), std::abs(camera.depth().rangeMax))},
      avx512_(useAvx512Form("ZCHECK_COMPARE_KERNEL", "baseline")),
      slopeFrame_(camera, tolerance.slopeCredit)
{
    if (slopes == SlopeSource::TableOfSeen) table_ = std::make_unique<SlopeTable>(scene_, slopeFrame_, avx512_);
}

PixelJudge::~PixelJudge() = default;

double PixelJudge::slope(std::uint32_t primitive) const
{
    if (!known(primitive)) return 0.0;
    if (table_ && table_->ready(primitive)) return table_->at(primitive);
    return computeSlope(primitive);
}

SlopeTable::SlopeTable(const Scene& scene, const DepthSlopeFrame& frame, bool avx512)
    : scene_(scene), frame_(frame), avx512_(avx512)
{
    const std::size_t n = scene.triangles.size();
    none_ = std::uint32_t(n);
    slopeOfTriangle_.resize(n + 1);  // uninitialised: an entry is read only once its block is ready
    slopeOfTriangle_[n] = 0.0;
    blockCount_ = std::uint32_t((n + kBlock - 1) / kBlock);
    blockState_ = std::make_unique<std::atomic<std::uint8_t>[]>(blockCount_);
}

bool SlopeTable::makeBlockReady(std::uint32_t block) const
{
    std::atomic<std::uint8_t>& state = blockState(block);
    std::uint8_t notComputed = 0;
    if (!state.compare_exchange_strong(notComputed, 1, std::memory_order_acquire))
        return notComputed == kReady;  // false: another thread is computing it
    static_assert(kBlock == kSlopeLanes, "a block's slopes are computed together");
    auto* together = &slopesTogetherBaseline;
#ifdef ZCHECK_X86_AVX512
    if (avx512_) together = &slopesTogetherAvx512;
#endif
    const std::size_t first = std::size_t(block) * kBlock;
    together(frame_, scene_, std::uint32_t(first), std::min<std::size_t>(kBlock, scene_.triangles.size() - first),
             slopeOfTriangle_.data() + first);
    state.store(kReady, std::memory_order_release);
    return true;
}

glm::dvec3 PixelJudge::vertex(std::uint32_t primitive, int corner) const
{
    return glm::dvec3(scene_.positions[scene_.triangles[primitive][corner]]);
}

double PixelJudge::computeSlope(std::uint32_t primitive) const
{
    return slopeFrame_.slope(vertex(primitive, 0), vertex(primitive, 1), vertex(primitive, 2));
}

double PixelJudge::surfaceTolerance(std::uint32_t primitive, double q, double allowance) const
{
    return toleranceForSlope(slope(primitive), q, allowance);
}

// Does the primitive's plane cross the pixel's ray at the near or far plane, to within
// binary32 rounding (2^-20 relative) of the distances where the routes clip?
bool PixelJudge::atClipPlane(std::uint32_t primitive, const glm::dvec2& pWindow) const
{
    if (!known(primitive)) return false;
    const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera_, pWindow);
    const glm::dvec3 a = vertex(primitive, 0);
    const glm::dvec3 normal = glm::cross(vertex(primitive, 1) - a, vertex(primitive, 2) - a);
    const double t = glm::dot(normal, a - ray.origin) / glm::dot(normal, ray.direction);
    const double epsilon = std::ldexp(1.0, -20);
    // An infinite far plane has no surface to lie on (inf <= inf must not explain anything).
    return std::isfinite(t) && (std::abs(t - ray.tNear) <= epsilon * std::abs(ray.tNear) ||
                                (std::isfinite(ray.tFar) && std::abs(t - ray.tFar) <= epsilon * ray.tFar));
}

bool PixelJudge::nearEdge(std::uint32_t primitive, const glm::dvec2& pWindow) const
{
    if (!known(primitive)) return false;
    return distanceToDrawnEdge(camera_, vertex(primitive, 0), vertex(primitive, 1), vertex(primitive, 2), pWindow) <= terms_.S;
}

PixelClass PixelJudge::bothHit(double rayDepth, std::uint32_t rayPrimitive, double rasterDepth,
                               std::uint32_t rasterPrimitive, double q, const glm::dvec2& pWindow, double& bound,
                               double allowance) const
{
    const double error = std::abs(rasterDepth - rayDepth);
    // Different surfaces: the raster's may legitimately win where the two lie within both
    // tolerances of each other, so the bound is their sum.
    const bool samePrimitive = rayPrimitive == rasterPrimitive;
    bound = surfaceTolerance(rayPrimitive, q, allowance) + (samePrimitive ? 0.0 : surfaceTolerance(rasterPrimitive, q));
    if (error <= bound) return PixelClass::Agree;
    if (!samePrimitive && (nearEdge(rayPrimitive, pWindow) || nearEdge(rasterPrimitive, pWindow) ||
                           atClipPlane(rayPrimitive, pWindow) || atClipPlane(rasterPrimitive, pWindow)))
        return PixelClass::EdgeSurface;
    return PixelClass::DepthError;
}

PixelClass PixelJudge::oneHit(bool rayHit, double depth, std::uint32_t primitive, double q,
                              const glm::dvec2& pWindow, bool holesAllowed) const
{
    // Explained at an edge of its triangle, (ray route only) at the clear value, or on the
    // near/far plane.
    if (nearEdge(primitive, pWindow)) return rayHit ? PixelClass::RayOnlyEdge : PixelClass::RasterOnlyEdge;
    if (rayHit && std::abs(depth - camera_.clearDepth()) <= surfaceTolerance(primitive, q)) return PixelClass::RayOnlyAtClear;
    if (atClipPlane(primitive, pWindow)) return PixelClass::AtClipPlane;
    return !rayHit ? PixelClass::RasterOnly : holesAllowed ? PixelClass::Hole : PixelClass::RayOnly;
}

bool isUnexplained(PixelClass c)
{
    return c == PixelClass::DepthError || c == PixelClass::RayOnly || c == PixelClass::RasterOnly;
}

namespace {

// What one tile contributes to the report; tiles are merged in tile order, and what depends
// on scan order (the first unexplained pixels, the worst pixel among equals) is restored.
struct TileTally {
    ComparisonReport report;  // counts, maxima, worst pixel, samples, bounding box, bias samples
    double signedErrorSum = 0;
    std::int64_t quarterCounts[4] = {0, 0, 0, 0};
};

// A float's or a double's bits, read through a pointer to it (the lane loops below stay SIMD
// where std::memcpy would not).
typedef std::uint32_t __attribute__((may_alias)) AliasedBits32;
typedef std::int64_t __attribute__((may_alias)) AliasedBits64;

constexpr std::size_t kUnexplainedSamples = 20;  // the first ones in scan order (compare.h)

bool beforeInScanOrder(const PixelFinding& a, const PixelFinding& b)
{
    return a.row != b.row ? a.row < b.row : a.col < b.col;
}

// Grows the bounding box of the unexplained pixels to hold (col, row).
void extendUnexplainedBox(ComparisonReport& r, int col, int row)
{
    if (r.unexplainedMaxCol < 0) {
        r.unexplainedMinCol = r.unexplainedMaxCol = col;
        r.unexplainedMinRow = r.unexplainedMaxRow = row;
    }
    r.unexplainedMinCol = std::min(r.unexplainedMinCol, col);
    r.unexplainedMaxCol = std::max(r.unexplainedMaxCol, col);
    r.unexplainedMinRow = std::min(r.unexplainedMinRow, row);
    r.unexplainedMaxRow = std::max(r.unexplainedMaxRow, row);
}

void noteUnexplained(ComparisonReport& r, const PixelFinding& f)
{
    if (r.unexplainedSamples.size() < kUnexplainedSamples) r.unexplainedSamples.push_back(f);
    extendUnexplainedBox(r, f.col, f.row);
}

// Adds `tile` to `total`. The worst pixel is the largest ratio, the first in scan order among
// equals; a tile's first unexplained pixels in its own scan order hold the image's first ones
// that lie in it, so all tiles' samples, sorted, hold the image's first 20.
void merge(TileTally& total, TileTally& tile)
{
    ComparisonReport& r = total.report;
    const ComparisonReport& b = tile.report;
    if (b.agree + b.depthErrors > 0) {
        const bool firstCompared = r.agree + r.depthErrors == 0;
        if (firstCompared || b.maxErrorOverTolerance > r.maxErrorOverTolerance ||
            (b.maxErrorOverTolerance == r.maxErrorOverTolerance && beforeInScanOrder(b.worst, r.worst))) {
            r.maxErrorOverTolerance = b.maxErrorOverTolerance;
            r.worst = b.worst;
        }
    }
    r.bothHit += b.bothHit, r.bothMiss += b.bothMiss, r.rayOnly += b.rayOnly, r.rasterOnly += b.rasterOnly;
    r.agree += b.agree, r.edgeSurface += b.edgeSurface, r.depthErrors += b.depthErrors;
    r.coverageExplained += b.coverageExplained, r.lostAtClearValue += b.lostAtClearValue;
    r.atClipPlane += b.atClipPlane, r.holes += b.holes, r.coverageUnexplained += b.coverageUnexplained;
    r.maxErrorQuanta = std::max(r.maxErrorQuanta, b.maxErrorQuanta);
    r.maxRelativeEyeZError = std::max(r.maxRelativeEyeZError, b.maxRelativeEyeZError);
    r.biasSamples += b.biasSamples;
    r.unexplainedSamples.insert(r.unexplainedSamples.end(), b.unexplainedSamples.begin(), b.unexplainedSamples.end());
    if (b.unexplainedMaxCol >= 0) {  // the box of all of them, not only of the samples
        extendUnexplainedBox(r, b.unexplainedMinCol, b.unexplainedMinRow);
        extendUnexplainedBox(r, b.unexplainedMaxCol, b.unexplainedMaxRow);
    }
    total.signedErrorSum += tile.signedErrorSum;
    for (int k = 0; k < 4; ++k) total.quarterCounts[k] += tile.quarterCounts[k];
}

// The 99th percentiles: each thread's largest values (what is selected does not depend on
// which thread saw which value).
struct StatisticCounts {
    LargestValues errorQuanta, relativeEyeZ;
};

// What the comparison measures at pixel (col, row), entry a of the ray's arrays and b of the
// raster's: in one place for the comparison and for the sample its keepers' floors come from.
struct PixelMeasures {
    explicit PixelMeasures(const Camera& c) : camera(c), cameraRays(c), format(c.depth().format) {}

    // The storage quantum q.
    double quantum(const RoutePixels& ray, const RoutePixels& raster, std::size_t a, std::size_t b) const
    {
        return raster.quantum ? raster.quantum[b] : storageQuantum(format, ray.windowDepth[a]);
    }
    // (d_raster − d_ray)/q, of which the statistics take the absolute value.
    static double signedErrorQuanta(double rayDepth, double rasterDepth, double q) { return (rasterDepth - rayDepth) / q; }
    // quantum() of n pixels of a row, entries a0.. and b0.., into q: several per instruction
    // where the format's quantum is one constant or comes from the raster's own array.
    void quanta(const RoutePixels& ray, const RoutePixels& raster, std::size_t a0, std::size_t b0, std::size_t n,
                double* q) const
    {
        if (raster.quantum) {
            std::copy(raster.quantum + b0, raster.quantum + b0 + n, q);
        } else if (const std::optional<double> constant = constantQuantum(raster)) {
            std::fill(q, q + n, *constant);
        } else {
            for (std::size_t j = 0; j < n; ++j) q[j] = storageQuantum(format, ray.windowDepth[a0 + j]);
        }
    }
    // The quantum of every pixel, where the format gives one for all and the raster no own ones.
    std::optional<double> constantQuantum(const RoutePixels& raster) const
    {
        if (raster.quantum || format == DepthFormat::Float32) return std::nullopt;
        return storageQuantum(format, 0.0);  // 1/(2^N − 1) at every depth
    }
    // The closed form relativeEyeZErrors takes, where it takes one (no eye points, not a raw matrix).
    std::optional<CameraRays::RelativeForm> relativeForm(const RoutePixels& ray) const
    {
        if (ray.pEye) return std::nullopt;
        return cameraRays.relativeForm();
    }
    // relativeEyeZError of n pixels of a row from (col0, row), entries a0.. and b0.., into
    // `relative`: several per instruction where the closed form applies.
    void relativeEyeZErrors(const RoutePixels& ray, const RoutePixels& raster, std::size_t a0, std::size_t b0, int col0,
                            int row, std::size_t n, double* relative) const
    {
        if (!ray.pEye && cameraRays.relativeEyeZDifferences(ray.windowDepth + a0, raster.windowDepth + b0, n, relative))
            return;
        for (std::size_t j = 0; j < n; ++j)
            relative[j] = relativeEyeZError(ray, raster, a0 + j, b0 + j, col0 + int(j), row);
    }
    // The relative eye-z error of a pixel compared on depth.
    double relativeEyeZError(const RoutePixels& ray, const RoutePixels& raster, std::size_t a, std::size_t b, int col,
                             int row) const
    {
        const glm::dvec2 pImage(col + 0.5, row + 0.5);
        const double rayDepth = ray.windowDepth[a], rasterDepth = raster.windowDepth[b];
        if (!ray.pEye) return cameraRays.relativeEyeZDifference(pImage, rayDepth, rasterDepth);
        const double eyeZ = camera.eyeZOf(ray.pEye[a]);
        return std::abs(cameraRays.eyeZFromWindowDepth(pImage, rasterDepth) - eyeZ) / std::abs(eyeZ);
    }

    const Camera& camera;
    const CameraRays cameraRays;  // eye-z of a window depth in closed form
    const DepthFormat format;
};

// A tile's row, as its lane pass (rowLanesBaseline, rowLanesAvx512) reads it: n ≤ kLanes
// pixels, pixel j at entry j of each array.
constexpr int kLanes = TileComparison::kTileSize;
struct RowInputs {
    const std::uint32_t* rayPrimitive = nullptr;
    const std::uint32_t* rasterPrimitive = nullptr;
    const std::uint32_t* surface = nullptr;  // the triangle both routes hit (the common case), else kNoPrimitive
    const double* rayDepth = nullptr;
    const double* rasterDepth = nullptr;
    const double* slope = nullptr;     // of the triangle both routes hit (where they hit one)
    const double* quantum = nullptr;   // q
    const double* allowance = nullptr; // a (RoutePixels::allowance; kNoAllowance where it has none)
    const double* relative = nullptr;  // the relative eye-z error
    int n = 0;
    // rowLanesAvx512 only: where these are given, it computes the three arrays above itself
    // (which are then not read): the slopes from PixelJudge::slopeTableFor, the quantum one for
    // all, the relative error in closed form.
    const double* slopeTable = nullptr;  // SlopeTable::tableFor (where gatherable())
    std::uint32_t slopeTableNone = 0;
    std::optional<double> constantQuantum;
    std::optional<CameraRays::RelativeForm> relativeForm;
    PixelClass* pixelClass = nullptr;  // the row's per-pixel results, or null (none kept)
    float* errorOverTolerance = nullptr;
};

// A row's allowances where the raster side declares none.
alignas(64) constexpr double kNoAllowance[kLanes] = {};

// What a row's lane pass gives the rest of its tally: the common case's measures (both routes
// on one triangle: PixelJudge::bothHit's rule for a single surface, one slope, no edge or
// clip-plane question), computed for every lane and used for the common ones, and the lanes'
// masks as bits (lane j: bit j).
struct RowLanes {
    alignas(64) double bound[kLanes], signedErrorQuanta[kLanes], errorQuanta[kLanes], ratio[kLanes];
    std::uint64_t common;  // both routes hit one triangle
    std::uint64_t agree;   // |Δ| <= bound
    std::uint64_t hit;     // either route hit
    std::uint64_t bias;    // common, and quantization dominates: it feeds the bias test
    // The largest |Δ|/q, relative error and ratio of the common lanes, as the bits of a double:
    // for values ≥ +0 or NaN (NaN left out, as std::max leaves it), the largest bit pattern is
    // the largest value; -1 where no lane counts.
    std::int64_t largest[3];
};

// |Δ| / tolerance, as the report and the heatmap give it.
// (The division and both comparisons are made whatever the bound, so that a loop of these
// needs no branch: a compiler may not make a trapping operation the code skipped.)
ZCHECK_ALWAYS_INLINE inline double ratioOf(double error, double bound)
{
    const double quotient = error / bound;
    const bool boundPositive = bound > 0, errorPositive = error > 0;
    const double unbounded = errorPositive ? INFINITY : 0.0;
    return boundPositive ? quotient : unbounded;
}

// A row's lane pass, lane by lane: the measures and masks above; each pixel's class and ratio
// as the common case or a miss has them (the scan-order pass rewrites the others); the common
// lanes' |Δ|/q and relative errors given to the keepers. Auto-vectorised where it is compiled
// for (several pixels per instruction with AVX-512).
ZCHECK_ALWAYS_INLINE inline void rowLanesBaseline(const RowInputs& in, const PixelJudge::ToleranceTerms& terms,
                                                  StatisticCounts& counts, RowLanes& out)
{
    const int n = in.n;
    alignas(64) std::uint8_t common[kLanes], agree[kLanes], hit[kLanes], bias[kLanes];
    alignas(64) float errorQuantaOfLane[kLanes], relativeOfLane[kLanes];
    for (int j = 0; j < n; ++j) {
        common[j] = in.surface[j] != kNoPrimitive;
        hit[j] = (in.rayPrimitive[j] != kNoPrimitive) | (in.rasterPrimitive[j] != kNoPrimitive);
    }
    for (int j = 0; j < n; ++j) {
        const double q = in.quantum[j], m = in.slope[j], a = in.allowance[j];
        out.bound[j] = terms.of(m, q, a);
        const double error = std::abs(in.rasterDepth[j] - in.rayDepth[j]);
        out.signedErrorQuanta[j] = PixelMeasures::signedErrorQuanta(in.rayDepth[j], in.rasterDepth[j], q);
        out.ratio[j] = ratioOf(error, out.bound[j]);
        agree[j] = error <= out.bound[j];
        bool dominates;
        terms.quantizationDominates(m, q, a, dominates);
        bias[j] = common[j] & dominates;
    }
    if (in.pixelClass) {
        // Without a branch, so that the loop stays SIMD: the class as arithmetic, the ratio's
        // bits masked (0.0f where not common).
        static_assert(int(PixelClass::BothMiss) == 0 && int(PixelClass::Agree) == 1 && int(PixelClass::DepthError) == 3,
                      "the class arithmetic below");
        std::uint8_t* classBytes = reinterpret_cast<std::uint8_t*>(in.pixelClass);
        AliasedBits32* ratioBits = reinterpret_cast<AliasedBits32*>(in.errorOverTolerance);
        for (int j = 0; j < n; ++j) {
            classBytes[j] = std::uint8_t(common[j] + 2 * (common[j] & (agree[j] ^ 1)));
            const float ratioOfLane = static_cast<float>(out.ratio[j]);
            ratioBits[j] = *reinterpret_cast<const AliasedBits32*>(&ratioOfLane) & (0u - std::uint32_t(common[j]));
        }
    }
    for (int j = 0; j < n; ++j) {
        out.errorQuanta[j] = std::abs(out.signedErrorQuanta[j]);
        errorQuantaOfLane[j] = float(out.errorQuanta[j]);
        relativeOfLane[j] = float(in.relative[j]);
    }
    // The three maxima in one loop (its mask widened once: three loops measured slower).
    {
        const AliasedBits64* bitsQ = reinterpret_cast<const AliasedBits64*>(out.errorQuanta);
        const AliasedBits64* bitsE = reinterpret_cast<const AliasedBits64*>(in.relative);
        const AliasedBits64* bitsR = reinterpret_cast<const AliasedBits64*>(out.ratio);
        std::int64_t lq = -1, le = -1, lr = -1;
        for (int j = 0; j < n; ++j) {
            const std::int64_t keep = -std::int64_t(common[j]);  // all ones where common
            const std::int64_t q = (out.errorQuanta[j] == out.errorQuanta[j]) ? (bitsQ[j] & keep) | ~keep : -1;
            const std::int64_t e = (in.relative[j] == in.relative[j]) ? (bitsE[j] & keep) | ~keep : -1;
            const std::int64_t t = (out.ratio[j] == out.ratio[j]) ? (bitsR[j] & keep) | ~keep : -1;
            lq = lq < q ? q : lq;
            le = le < e ? e : le;
            lr = lr < t ? t : lr;
        }
        out.largest[0] = lq, out.largest[1] = le, out.largest[2] = lr;
    }
    counts.errorQuanta.add(errorQuantaOfLane, common, std::size_t(n));
    counts.relativeEyeZ.add(relativeOfLane, common, std::size_t(n));
    out.common = laneBits(common, std::size_t(n)), out.agree = laneBits(agree, std::size_t(n));
    out.hit = laneBits(hit, std::size_t(n)), out.bias = laneBits(bias, std::size_t(n));
}

// Whether rowLanesAvx512 can look up slopes in a table whose largest index (SlopeTable::none())
// is this itself: its gathers take signed 32-bit indices (so not for 2^31 triangles or more,
// beyond any scene a machine of today holds; the lane loops then look them up).
inline bool gatherable(std::uint32_t largestIndex) { return largestIndex < (1u << 31); }

#ifdef ZCHECK_X86_AVX512
ZCHECK_INTRINSICS_BEGIN
// A row's surface (the triangle both routes hit, else kNoPrimitive) into `surface`, sixteen
// lanes at a time, and, as bits, the lanes that begin a run in one slope block of the scene's
// (SlopeTable::tableForRuns): found from the lanes in registers, each one's left
// neighbour's block shifted in, where reading the stored surface back one lane off waited on
// the stores (~10 % of the row pass's samples).
static_assert(kLanes <= 64, "a row's run starts fit one word");
ZCHECK_TARGET_AVX512 std::uint64_t surfaceAndBlockRunsAvx512(const std::uint32_t* rayPrimitive,
                                                             const std::uint32_t* rasterPrimitive, int n,
                                                             std::uint32_t blocks, std::uint32_t* surface)
{
    static_assert(SlopeTable::kBlock == 64, "a block is a shift by 6");
    const __m512i none = _mm512_set1_epi32(int(kNoPrimitive)), blockCount = _mm512_set1_epi32(int(blocks));
    __m512i previousBlocks = _mm512_set1_epi32(-1);  // lane 15: the block left of lane 0, none of the scene's
    std::uint64_t runStarts = 0;
    for (int j = 0; j < n; j += 16) {
        const __mmask16 lanes = n - j >= 16 ? __mmask16(0xFFFF) : __mmask16((1u << (n - j)) - 1);
        const __m512i ray = _mm512_maskz_loadu_epi32(lanes, rayPrimitive + j);
        const __m512i raster = _mm512_maskz_loadu_epi32(lanes, rasterPrimitive + j);
        const __mmask16 common = _mm512_mask_cmpeq_epu32_mask(_mm512_mask_cmpneq_epu32_mask(lanes, ray, none), ray, raster);
        const __m512i row = _mm512_mask_blend_epi32(common, none, ray);
        _mm512_mask_storeu_epi32(surface + j, lanes, row);
        const __m512i block = _mm512_srli_epi32(row, 6);
        const __m512i leftBlock = _mm512_alignr_epi32(block, previousBlocks, 15);  // lane k: block of lane k − 1
        const __mmask16 starts =
            _mm512_mask_cmpneq_epu32_mask(_mm512_mask_cmplt_epu32_mask(lanes, block, blockCount), block, leftBlock);
        runStarts |= std::uint64_t(starts) << j;
        previousBlocks = block;
    }
    return runStarts;
}

// rowLanesBaseline's results, written out eight lanes at a time for AVX-512: the same IEEE
// operations lane for lane (bit-identical), its masks in mask registers and the keepers'
// candidates found among them, a row in one pass. (The lane loops above compiled for AVX-512,
// each through arrays of bytes, made the whole comparison ~1.3× as long; bench/speed-log.md.)
ZCHECK_TARGET_AVX512 void rowLanesAvx512(const RowInputs& in, const PixelJudge::ToleranceTerms& termsOfJudge,
                                         StatisticCounts& counts, RowLanes& out)
{
    const PixelJudge::ToleranceTerms terms = termsOfJudge;  // its C, S and E in registers for the row
    alignas(64) float errorQuantaOfLane[kLanes], relativeOfLane[kLanes];
    const __m256i none = _mm256_set1_epi32(int(kNoPrimitive));
    const __m512d zero = _mm512_setzero_pd(), infinity = _mm512_set1_pd(INFINITY);
    const __m512i magnitude = _mm512_set1_epi64(0x7fffffffffffffff);  // std::abs: the sign bit cleared
    // A keeper's candidates: the common lanes at or above its leastKeepable() (none at 2^32).
    const std::uint64_t leastQ = counts.errorQuanta.leastKeepable(), leastE = counts.relativeEyeZ.leastKeepable();
    const __mmask8 keepsQ = leastQ >> 32 ? 0 : 0xFF, keepsE = leastE >> 32 ? 0 : 0xFF;
    const __m256i leastQBits = _mm256_set1_epi32(int(std::uint32_t(leastQ)));
    const __m256i leastEBits = _mm256_set1_epi32(int(std::uint32_t(leastE)));
    const __m256i slopeTableNone = _mm256_set1_epi32(int(in.slopeTableNone));
    const __m512d constantQuantum = _mm512_set1_pd(in.constantQuantum.value_or(0.0));
    const __m512d relativeA = _mm512_set1_pd(in.relativeForm ? in.relativeForm->A : 0.0);
    const bool parallel = in.relativeForm && in.relativeForm->parallel;
    __m512i largestQ = _mm512_set1_epi64(-1), largestE = largestQ, largestR = largestQ;
    std::uint64_t common = 0, agree = 0, hit = 0, bias = 0, candidateQ = 0, candidateE = 0;
    for (int j = 0; j < in.n; j += 8) {
        const __mmask8 lanes = in.n - j >= 8 ? __mmask8(0xFF) : __mmask8((1u << (in.n - j)) - 1);
        const __m256i rayPrimitive = _mm256_maskz_loadu_epi32(lanes, in.rayPrimitive + j);
        const __m256i rasterPrimitive = _mm256_maskz_loadu_epi32(lanes, in.rasterPrimitive + j);
        const __mmask8 rayHit = _mm256_mask_cmpneq_epu32_mask(lanes, rayPrimitive, none);
        const __mmask8 c = _mm256_mask_cmpeq_epu32_mask(rayHit, rayPrimitive, rasterPrimitive);
        const __mmask8 h = rayHit | _mm256_mask_cmpneq_epu32_mask(lanes, rasterPrimitive, none);
        const __m512d rayDepth = _mm512_maskz_loadu_pd(lanes, in.rayDepth + j);
        const __m512d rasterDepth = _mm512_maskz_loadu_pd(lanes, in.rasterDepth + j);
        // The slope of a common lane's triangle (0 elsewhere, as table[slopeTableNone] is).
        const __m512d m = in.slopeTable ? _mm512_mask_i32gather_pd(zero, c, _mm256_min_epu32(rayPrimitive, slopeTableNone),
                                                                   in.slopeTable, sizeof(double))
                                        : _mm512_maskz_loadu_pd(lanes, in.slope + j);
        const __m512d q = in.constantQuantum ? constantQuantum : _mm512_maskz_loadu_pd(lanes, in.quantum + j);
        // CameraRays::relativeEyeZDifferences (reference: the ray's depth, other: the raster's).
        __m512d relative;
        if (!in.relativeForm)
            relative = _mm512_maskz_loadu_pd(lanes, in.relative + j);
        else if (parallel)
            relative = _mm512_div_pd(_mm512_sub_pd(rasterDepth, rayDepth), _mm512_sub_pd(rayDepth, relativeA));
        else
            relative = _mm512_div_pd(_mm512_sub_pd(rayDepth, rasterDepth), _mm512_sub_pd(rasterDepth, relativeA));
        if (in.relativeForm) relative = _mm512_castsi512_pd(_mm512_and_si512(_mm512_castpd_si512(relative), magnitude));
        const __m512d allowance = in.allowance == kNoAllowance ? zero : _mm512_maskz_loadu_pd(lanes, in.allowance + j);
        // The tolerance model's rules, as the baseline form and PixelJudge apply them (compare.h).
        __m512d bound;
        terms.bound(m, q, allowance, bound);
        const __m512d difference = _mm512_sub_pd(rasterDepth, rayDepth);
        const __m512d error = _mm512_castsi512_pd(_mm512_and_si512(_mm512_castpd_si512(difference), magnitude));
        const __m512d signedErrorQuanta = _mm512_div_pd(difference, q);
        const __m512d errorQuanta =
            _mm512_castsi512_pd(_mm512_and_si512(_mm512_castpd_si512(signedErrorQuanta), magnitude));
        // ratioOf(error, bound).
        const __m512d unbounded = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(error, zero, _CMP_GT_OQ), infinity);
        const __m512d ratio =
            _mm512_mask_blend_pd(_mm512_cmp_pd_mask(bound, zero, _CMP_GT_OQ), unbounded, _mm512_div_pd(error, bound));
        const __mmask8 a = _mm512_mask_cmp_pd_mask(lanes, error, bound, _CMP_LE_OQ);
        decltype(m <= m) dominates;
        terms.quantizationDominates(m, q, allowance, dominates);
        const __mmask8 b = c & _mm512_movepi64_mask(__m512i(dominates));
        _mm512_store_pd(out.bound + j, bound);
        _mm512_store_pd(out.signedErrorQuanta + j, signedErrorQuanta);
        _mm512_store_pd(out.errorQuanta + j, errorQuanta);
        _mm512_store_pd(out.ratio + j, ratio);
        const __m256 errorQuantaOfLanes = _mm512_cvtpd_ps(errorQuanta), relativeOfLanes = _mm512_cvtpd_ps(relative);
        if (in.pixelClass) {
            const __m256i pixelClass = _mm256_mask_set1_epi32(
                _mm256_maskz_set1_epi32(__mmask8(c & a), int(PixelClass::Agree)), __mmask8(c & ~a), int(PixelClass::DepthError));
            _mm256_mask_cvtepi32_storeu_epi8(reinterpret_cast<std::uint8_t*>(in.pixelClass) + j, lanes, pixelClass);
            _mm256_mask_storeu_ps(in.errorOverTolerance + j, lanes, _mm256_maskz_mov_ps(c, _mm512_cvtpd_ps(ratio)));
        }
        largestQ = _mm512_mask_max_epi64(largestQ, _mm512_mask_cmp_pd_mask(c, errorQuanta, errorQuanta, _CMP_ORD_Q),
                                         largestQ, _mm512_castpd_si512(errorQuanta));
        largestE = _mm512_mask_max_epi64(largestE, _mm512_mask_cmp_pd_mask(c, relative, relative, _CMP_ORD_Q), largestE,
                                         _mm512_castpd_si512(relative));
        largestR = _mm512_mask_max_epi64(largestR, _mm512_mask_cmp_pd_mask(c, ratio, ratio, _CMP_ORD_Q), largestR,
                                         _mm512_castpd_si512(ratio));
        _mm256_store_ps(errorQuantaOfLane + j, errorQuantaOfLanes);
        _mm256_store_ps(relativeOfLane + j, relativeOfLanes);
        const __mmask8 keptQ = _mm256_mask_cmpge_epu32_mask(__mmask8(c & keepsQ), _mm256_castps_si256(errorQuantaOfLanes), leastQBits);
        const __mmask8 keptE = _mm256_mask_cmpge_epu32_mask(__mmask8(c & keepsE), _mm256_castps_si256(relativeOfLanes), leastEBits);
        common |= std::uint64_t(c) << j, agree |= std::uint64_t(a) << j, hit |= std::uint64_t(h) << j;
        bias |= std::uint64_t(b) << j, candidateQ |= std::uint64_t(keptQ) << j, candidateE |= std::uint64_t(keptE) << j;
    }
    out.common = common, out.agree = agree, out.hit = hit, out.bias = bias;
    out.largest[0] = _mm512_reduce_max_epi64(largestQ);
    out.largest[1] = _mm512_reduce_max_epi64(largestE);
    out.largest[2] = _mm512_reduce_max_epi64(largestR);
    const std::size_t commons = std::size_t(__builtin_popcountll(common));
    counts.errorQuanta.addCandidates(errorQuantaOfLane, candidateQ, commons);
    counts.relativeEyeZ.addCandidates(relativeOfLane, candidateE, commons);
}
ZCHECK_INTRINSICS_END
#endif

}  // namespace

RoutePixels RoutePixels::of(const RenderResult& render)
{
    RoutePixels p;
    p.windowDepth = render.windowDepth.value.data();
    p.primitive = render.primitiveId.data();
    p.pEye = render.pEye.empty() ? nullptr : render.pEye.data();
    p.stride = std::size_t(render.windowDepth.width);
    return p;
}

struct TileComparison::Impl {
    // `ownJudge` empty: `judge` is the caller's.
    Impl(std::unique_ptr<const PixelJudge> ownJudge, const PixelJudge* callersJudge, Comparison* perPixel,
         float errorQuantaFloor, float relativeEyeZFloor)
        : ownJudge(std::move(ownJudge)),
          judge(callersJudge ? *callersJudge : *this->ownJudge),
          camera(judge.camera()),
          perPixel(perPixel),
          measures(camera),
          W(camera.width()),
          H(camera.height()),
          grid(W, H, kTileSize),
          tallies(std::size_t(grid.count())),
          statisticCounts([keep = std::size_t(W) * std::size_t(H) / 100 + 2, errorQuantaFloor, relativeEyeZFloor] {
              // keep ≥ n/100 + 1 for any n ≤ W·H
              return StatisticCounts{LargestValues(keep, errorQuantaFloor), LargestValues(keep, relativeEyeZFloor)};
          })
    {
    }

    // Rows [rowBegin, rowEnd) of tiles [tileBegin, tileEnd), consecutive tiles of one band,
    // image row by image row across them (TileComparison::compareTileRows, compareBandRows).
    void compare(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray, const RoutePixels& raster);
    template <bool kAvx512>
    void compareBody(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                     const RoutePixels& raster);
    void compareBaseline(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                         const RoutePixels& raster);
#ifdef ZCHECK_X86_AVX512
    ZCHECK_TARGET_AVX512 void compareAvx512(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                                            const RoutePixels& raster);
#endif

    const std::unique_ptr<const PixelJudge> ownJudge;
    const PixelJudge& judge;
    const Camera& camera;
    Comparison* perPixel;
    const PixelMeasures measures;
    const int W, H;
    const TileGrid grid;
    std::vector<TileTally> tallies;  // one per tile
    tbb::enumerable_thread_specific<StatisticCounts> statisticCounts;
};

// Impl::compare's work, inlined into a baseline and an AVX-512 form (compareBaseline,
// compareAvx512; kernel_choice.h), bit-identical to each other and to the pixel-by-pixel
// tally they replaced: the same IEEE operations in the same order wherever the order can change
// a result. Row by row: first the common case's measures for the whole row, lane by lane
// (several pixels per instruction), and their tally where the order cannot matter (counts,
// maxima, the keepers: the row's lane pass, each form's own); then the bias sum in scan order;
// then, in scan order, the pixels off the common case and those of it that may be the worst
// (noteWorst).
// A tile's rows may come in several calls, in order: all that carries from one row to the next
// is in the tile's tally (comparedBefore is derived from its counts). A call takes a row of
// each of its tiles in turn, so that what does not depend on the tile (the thread's keepers,
// the quantum's and the relative error's forms) is found once per call, not once per 64 pixels.
template <bool kAvx512>
ZCHECK_ALWAYS_INLINE inline void TileComparison::Impl::compareBody(int tileBegin, int tileEnd, int rowBegin,
                                                                   int rowEnd, const RoutePixels& ray,
                                                                   const RoutePixels& raster)
{
    StatisticCounts& counts = statisticCounts.local();
    const PixelRect band = grid.rect(tileBegin);  // the rows of every tile of the call
    const int row0 = std::max(band.row0, rowBegin), row1 = std::min(band.row1, rowEnd);

    // Pixel (col, row): a in the ray's arrays, b in the raster's, i in the image.
    auto quantumAt = [&](std::size_t a, std::size_t b) ZCHECK_ALWAYS_INLINE { return measures.quantum(ray, raster, a, b); };
    auto signedErrorQuantaAt = [&](std::size_t a, std::size_t b, double q) ZCHECK_ALWAYS_INLINE {
        return PixelMeasures::signedErrorQuanta(ray.windowDepth[a], raster.windowDepth[b], q);
    };
    auto setClass = [&](std::size_t i, PixelClass c) ZCHECK_ALWAYS_INLINE {
        if (perPixel) perPixel->pixelClass[i] = c;
    };

    const std::optional<double> constantQuantum = measures.constantQuantum(raster);
    const std::optional<CameraRays::RelativeForm> relativeForm = measures.relativeForm(ray);

    constexpr int kRowsAhead = 2;
    alignas(64) std::uint32_t surface[kLanes];  // the triangle both routes hit, else kNoPrimitive
    alignas(64) double slope[kLanes], quantum[kLanes], relative[kLanes];
    auto quantumOfLane = [&](std::size_t j) ZCHECK_ALWAYS_INLINE { return constantQuantum ? *constantQuantum : quantum[j]; };
    RowLanes lanes;

    for (int row = row0; row < row1; ++row) {
        for (int tile = tileBegin; tile < tileEnd; ++tile) {
            TileTally& tally = tallies[std::size_t(tile)];
            ComparisonReport& r = tally.report;
            const PixelRect rect = grid.rect(tile);
            const int col0 = rect.col0, col1 = rect.col1;
            // A pixel compared on depth (agree or depth error), in scan order: whether it is the worst so
            // far (its finding is then r.worst): the first compared, or a ratio above every one before.
            // So the worst is the first pixel in scan order with the largest ratio (NaN ratios aside), and
            // a row's common-case pixels that are neither its first compared one nor the first with its
            // largest ratio can be left out without changing it.
            bool comparedBefore = r.agree + r.depthErrors > 0;
            auto noteWorst = [&](double ratio) ZCHECK_ALWAYS_INLINE {
                const bool worst = ratio > r.maxErrorOverTolerance || !comparedBefore;
                comparedBefore = true;
                if (worst) r.maxErrorOverTolerance = std::max(r.maxErrorOverTolerance, ratio);
                return worst;
            };
            // A pixel compared on depth off the common case: its count, the statistics, noteWorst.
            auto noteCompared = [&](bool agree, double ratio, double errorQuanta, double relative) ZCHECK_ALWAYS_INLINE {
                agree ? ++r.agree : ++r.depthErrors;
                counts.errorQuanta.add(float(errorQuanta));
                counts.relativeEyeZ.add(float(relative));
                r.maxRelativeEyeZError = std::max(r.maxRelativeEyeZError, relative);
                r.maxErrorQuanta = std::max(r.maxErrorQuanta, errorQuanta);
                return noteWorst(ratio);
            };

            const std::size_t a0 = ray.at(col0, row), b0 = raster.at(col0, row);
            const int n = col1 - col0;
            // A later row's pixels asked for now, for a tile alone: its row of a full-frame image
            // is a few cache lines, too short for the hardware to see a stream, and each row began
            // with misses. (Across a band's tiles a row is one stream.)
            if (tileEnd - tileBegin == 1 && row + kRowsAhead < row1) {
                const std::size_t aAhead = ray.at(col0, row + kRowsAhead), bAhead = raster.at(col0, row + kRowsAhead);
                for (int j = 0; j < n; j += 16) {
                    __builtin_prefetch(ray.primitive + aAhead + j), __builtin_prefetch(raster.primitive + bAhead + j);
                    __builtin_prefetch(ray.windowDepth + aAhead + j), __builtin_prefetch(ray.windowDepth + aAhead + j + 8);
                    __builtin_prefetch(raster.windowDepth + bAhead + j);
                    __builtin_prefetch(raster.windowDepth + bAhead + j + 8);
                }
            }
            const std::uint32_t* rayPrimitives = ray.primitive + a0;
            const std::uint32_t* rasterPrimitives = raster.primitive + b0;
            const double* rayDepths = ray.windowDepth + a0;
            const double* rasterDepths = raster.windowDepth + b0;
            // The row's slopes, quanta and relative errors, except those the AVX-512 form computes itself.
            RowInputs in;
            in.rayPrimitive = rayPrimitives, in.rasterPrimitive = rasterPrimitives, in.surface = surface;
            in.rayDepth = rayDepths, in.rasterDepth = rasterDepths;
            in.slope = slope, in.quantum = quantum, in.relative = relative, in.n = n;
            in.allowance = raster.allowance ? raster.allowance + b0 : kNoAllowance;
#ifdef ZCHECK_X86_AVX512
            if constexpr (kAvx512) {
                const SlopeTable* table = judge.slopeTable();
                const std::uint64_t blockRuns =
                    surfaceAndBlockRunsAvx512(rayPrimitives, rasterPrimitives, n, table ? table->blockCount() : 0, surface);
                if (table && gatherable(table->none()))
                    in.slopeTable = table->tableForRuns(surface, blockRuns), in.slopeTableNone = table->none();
                in.constantQuantum = constantQuantum, in.relativeForm = relativeForm;
            }
#endif
            if constexpr (!kAvx512)
                for (int j = 0; j < n; ++j) {
                    const bool common = rayPrimitives[j] != kNoPrimitive && rayPrimitives[j] == rasterPrimitives[j];
                    surface[j] = common ? rayPrimitives[j] : kNoPrimitive;
                }
            if (!in.slopeTable) slopesOf(judge, surface, std::size_t(n), slope);
            if (!in.constantQuantum) measures.quanta(ray, raster, a0, b0, std::size_t(n), quantum);
            if (!in.relativeForm) measures.relativeEyeZErrors(ray, raster, a0, b0, col0, row, std::size_t(n), relative);
            const std::size_t i0 = std::size_t(row) * W + col0;
            in.pixelClass = perPixel ? perPixel->pixelClass.data() + i0 : nullptr;
            in.errorOverTolerance = perPixel ? perPixel->errorOverTolerance.data() + i0 : nullptr;
#ifdef ZCHECK_X86_AVX512
            if constexpr (kAvx512) rowLanesAvx512(in, judge.toleranceTerms(), counts, lanes);
#endif
            if constexpr (!kAvx512) rowLanesBaseline(in, judge.toleranceTerms(), counts, lanes);

            const int commons = __builtin_popcountll(lanes.common), hits = __builtin_popcountll(lanes.hit);
            const int agreeing = __builtin_popcountll(lanes.common & lanes.agree);
            auto maxOfCommon = [&](double start, int k) ZCHECK_ALWAYS_INLINE {
                double largestValue;
                std::memcpy(&largestValue, &lanes.largest[k], sizeof largestValue);
                return lanes.largest[k] < 0 ? start : std::max(start, largestValue);
            };
            r.bothMiss += n - hits;  // their class and ratio are written already
            r.bothHit += commons, r.agree += agreeing, r.depthErrors += commons - agreeing;
            r.maxErrorQuanta = maxOfCommon(r.maxErrorQuanta, 0);
            r.maxRelativeEyeZError = maxOfCommon(r.maxRelativeEyeZError, 1);
            const double rowMaxRatio = maxOfCommon(-1.0, 2);
            // The bias test's sum in scan order (its rounding depends on the order): its signed
            // error, and where its exact depth falls in the quantum (a division per pixel).
            double signedErrorSum = tally.signedErrorSum;
            std::int64_t quarters[4] = {0, 0, 0, 0};
            forEachSetBit(lanes.bias, [&](std::size_t j) ZCHECK_ALWAYS_INLINE {
                signedErrorSum += lanes.signedErrorQuanta[j];
                const double position = rayDepths[j] / quantumOfLane(j);  // d/q
                ++quarters[std::clamp(int(4 * (position - std::floor(position))), 0, 3)];
            });
            tally.signedErrorSum = signedErrorSum;
            for (int k = 0; k < 4; ++k) tally.quarterCounts[k] += quarters[k];
            r.biasSamples += __builtin_popcountll(lanes.bias);

            // What is left in scan order (noteWorst): the pixels off the common case, the common
            // case's depth errors (a NaN ratio is one), its first pixel when nothing was compared
            // before, and its first with the row's largest ratio when that may be the worst.
            std::uint64_t visit = (lanes.common & ~lanes.agree) | (~lanes.common & lanes.hit);
            if (commons > 0 && !comparedBefore) visit |= lanes.common & (0 - lanes.common);
            if (commons > 0 && rowMaxRatio > r.maxErrorOverTolerance)
                for (std::uint64_t c = lanes.common; c != 0; c &= c - 1)
                    if (lanes.ratio[__builtin_ctzll(c)] == rowMaxRatio) {
                        visit |= c & (0 - c);
                        break;
                    }

            auto visitPixel = [&](int j) ZCHECK_ALWAYS_INLINE {
                const int col = col0 + j;
                const std::size_t a = a0 + std::size_t(j), b = b0 + std::size_t(j), i = i0 + std::size_t(j);
                const std::uint32_t rayPrimitive = rayPrimitives[j], rasterPrimitive = rasterPrimitives[j];
                const bool rayHit = rayPrimitive != kNoPrimitive, rasterHit = rasterPrimitive != kNoPrimitive;
                if (lanes.common >> j & 1) {  // tallied already
                    const bool agree = lanes.agree >> j & 1;
                    const PixelClass c = agree ? PixelClass::Agree : PixelClass::DepthError;  // written already
                    const bool worst = noteWorst(lanes.ratio[j]);
                    if (agree && !worst) return;  // nothing to note: no finding is built
                    PixelFinding f;
                    f.col = col, f.row = row;
                    f.rayWindowDepth = rayDepths[j], f.rasterWindowDepth = rasterDepths[j];
                    f.rayPrimitive = f.rasterPrimitive = rayPrimitive;
                    f.pixelClass = c;
                    f.errorQuanta = lanes.errorQuanta[j];
                    f.toleranceQuanta = lanes.bound[j] / quantumOfLane(j);
                    if (worst) r.worst = f;
                    if (!agree) noteUnexplained(r, f);
                    return;
                }
                const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
                PixelFinding f;
                f.col = col, f.row = row;
                f.rayWindowDepth = ray.windowDepth[a];
                f.rasterWindowDepth = raster.windowDepth[b];
                f.rayPrimitive = rayPrimitive;
                f.rasterPrimitive = rasterPrimitive;

                if (rayHit && rasterHit) {
                    // Different surfaces: the raster's may legitimately win near an edge or a clip plane.
                    ++r.bothHit;
                    const double q = quantumAt(a, b);
                    const double error = std::abs(f.rasterWindowDepth - f.rayWindowDepth);
                    double bound = 0;
                    f.pixelClass = judge.bothHit(f.rayWindowDepth, f.rayPrimitive, f.rasterWindowDepth, f.rasterPrimitive, q,
                                                 pWindow, bound, raster.allowance ? raster.allowance[b] : 0.0);
                    f.errorQuanta = std::abs(signedErrorQuantaAt(a, b, q));
                    const double ratio = ratioOf(error, bound);
                    auto withTolerance = [&](PixelFinding& finding) -> PixelFinding& {  // a finding kept
                        finding.toleranceQuanta = bound / q;
                        return finding;
                    };
                    if (f.pixelClass == PixelClass::EdgeSurface) {
                        ++r.edgeSurface;
                    } else {
                        if (perPixel) perPixel->errorOverTolerance[i] = static_cast<float>(ratio);
                        if (noteCompared(f.pixelClass == PixelClass::Agree, ratio, f.errorQuanta,
                                         measures.relativeEyeZError(ray, raster, a, b, col, row)))
                            r.worst = withTolerance(f);
                    }
                    if (f.pixelClass == PixelClass::DepthError) withTolerance(f);
                } else {
                    // Coverage mismatch: only one route sees a surface (PixelJudge::oneHit).
                    rayHit ? ++r.rayOnly : ++r.rasterOnly;
                    f.pixelClass = judge.oneHit(rayHit, rayHit ? f.rayWindowDepth : f.rasterWindowDepth,
                                                rayHit ? f.rayPrimitive : f.rasterPrimitive, quantumAt(a, b), pWindow,
                                                raster.holesAllowed);
                    if (f.pixelClass == PixelClass::RayOnlyAtClear) ++r.lostAtClearValue;
                    if (f.pixelClass == PixelClass::AtClipPlane) ++r.atClipPlane;
                    if (f.pixelClass == PixelClass::Hole) ++r.holes;
                    isUnexplained(f.pixelClass) ? ++r.coverageUnexplained : ++r.coverageExplained;
                }
                setClass(i, f.pixelClass);
                if (isUnexplained(f.pixelClass)) noteUnexplained(r, f);
            };
            // The pixels to visit (a few per row, mostly none), in scan order.
            forEachSetBit(visit, [&](std::size_t j) ZCHECK_ALWAYS_INLINE { visitPixel(int(j)); });
        }
    }
}

void TileComparison::Impl::compareBaseline(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                                           const RoutePixels& raster)
{
    compareBody<false>(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
}

#ifdef ZCHECK_X86_AVX512
ZCHECK_TARGET_AVX512 void TileComparison::Impl::compareAvx512(int tileBegin, int tileEnd, int rowBegin, int rowEnd,
                                                              const RoutePixels& ray, const RoutePixels& raster)
{
    compareBody<true>(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
}
#endif

void TileComparison::Impl::compare(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                                   const RoutePixels& raster)
{
#ifdef ZCHECK_X86_AVX512
    if (judge.avx512Form()) return compareAvx512(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
#endif
    compareBaseline(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
}

TileComparison::TileComparison(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance,
                               Comparison* perPixel, float errorQuantaFloor, float relativeEyeZFloor)
    : impl_(std::make_unique<Impl>(std::make_unique<const PixelJudge>(scene, camera, tolerance), nullptr, perPixel,
                                   errorQuantaFloor, relativeEyeZFloor))
{
    sizePerPixel();
}

TileComparison::TileComparison(const PixelJudge& judge, Comparison* perPixel, float errorQuantaFloor,
                               float relativeEyeZFloor)
    : impl_(std::make_unique<Impl>(nullptr, &judge, perPixel, errorQuantaFloor, relativeEyeZFloor))
{
    sizePerPixel();
}

void TileComparison::sizePerPixel()
{
    if (Comparison* perPixel = impl_->perPixel) {
        const std::size_t pixels = std::size_t(impl_->W) * std::size_t(impl_->H);
        perPixel->pixelClass.resize(pixels);  // uninitialised: compareTile writes every pixel of its tile
        perPixel->errorOverTolerance.resize(pixels);
    }
}

TileComparison::~TileComparison() = default;

const TileGrid& TileComparison::tiles() const { return impl_->grid; }

void TileComparison::compareTile(int tile, const RoutePixels& ray, const RoutePixels& raster)
{
    const PixelRect rect = impl_->grid.rect(tile);
    impl_->compare(tile, tile + 1, rect.row0, rect.row1, ray, raster);
}

void TileComparison::compareTileRows(int tile, int rowBegin, int rowEnd, const RoutePixels& ray, const RoutePixels& raster)
{
    impl_->compare(tile, tile + 1, rowBegin, rowEnd, ray, raster);
}

void TileComparison::compareBandRows(int band, int rowBegin, int rowEnd, const RoutePixels& ray, const RoutePixels& raster)
{
    const int tilesX = impl_->grid.tilesX();
    impl_->compare(band * tilesX, (band + 1) * tilesX, rowBegin, rowEnd, ray, raster);
}

std::optional<ComparisonReport> TileComparison::finish()
{
    Impl& c = *impl_;
    TileTally total;
    for (TileTally& tile : c.tallies) merge(total, tile);
    std::vector<const LargestValues*> errorQuantaParts, relativeEyeZParts;
    for (const StatisticCounts& counts : c.statisticCounts) {
        errorQuantaParts.push_back(&counts.errorQuanta);
        relativeEyeZParts.push_back(&counts.relativeEyeZ);
    }
    std::optional<double> p99ErrorQuanta, p99RelativeEyeZ;
    tbb::parallel_invoke([&] { p99ErrorQuanta = LargestValues::percentile99(errorQuantaParts); },
                         [&] { p99RelativeEyeZ = LargestValues::percentile99(relativeEyeZParts); });
    if (!p99ErrorQuanta || !p99RelativeEyeZ) return std::nullopt;

    ComparisonReport r = std::move(total.report);
    std::vector<PixelFinding>& samples = r.unexplainedSamples;
    std::sort(samples.begin(), samples.end(), beforeInScanOrder);
    if (samples.size() > kUnexplainedSamples) samples.resize(kUnexplainedSamples);
    r.width = c.W, r.height = c.H;
    r.p99ErrorQuanta = *p99ErrorQuanta;
    r.p99RelativeEyeZError = *p99RelativeEyeZ;
    if (r.biasSamples > 0) r.meanSignedErrorQuanta = total.signedErrorSum / double(r.biasSamples);
    const bool spread = std::all_of(std::begin(total.quarterCounts), std::end(total.quarterCounts),
                                    [&](std::int64_t n) { return n >= r.biasSamples / 10; });
    r.depthBias = r.biasSamples >= 1000 && spread && std::abs(r.meanSignedErrorQuanta) > 0.25;
    return r;
}

Comparison compareRoutes(const Scene& scene, const Camera& camera, const RenderResult& ray,
                         const RenderResult& raster, const ToleranceModel& tolerance, const DeclaredMap& declared)
{
    return compareRoutes(PixelJudge(scene, camera, tolerance), ray, raster, declared);
}

Comparison compareRoutes(const PixelJudge& judge, const RenderResult& ray, const RenderResult& raster,
                         const DeclaredMap& declared)
{
    const Camera& camera = judge.camera();
    const int W = camera.width(), H = camera.height();
    RoutePixels rayPixels = RoutePixels::of(ray), rasterPixels = RoutePixels::of(raster);
    if (declared.quantum) rasterPixels.quantum = declared.quantum->data();
    if (declared.allowance) rasterPixels.allowance = declared.allowance->data();
    rasterPixels.holesAllowed = declared.holesAllowed;

    // The keepers' floors, from the single-surface pixels of evenly spaced rows, ~16,000 pixels
    // in all (every 126th row at 1920×1080): the values at their 97th percentile lie below the
    // 99th of all with overwhelming probability (for values in no particular order, 3 % of such
    // a sample lies above the 99th of all only some 25 standard deviations from the 1 %
    // expected), and a keeper then holds ~3 % of its values instead of rebuilding its running
    // largest as values grow down the image. A floor too high (errors in rows the sample
    // favours) is found out at the end, and the comparison run again without. One task per
    // statistic, each a row's measures at a time, lane by lane as the comparison takes them.
    // (Every 32nd row, as before, made 1080p's floors ~10 % of the comparison's time.)
    const PixelMeasures measures(camera);
    constexpr std::size_t kFloorSamplePixels = 16384;
    const int rowStep = int(std::max<std::size_t>(1, std::size_t(W) * std::size_t(H) / kFloorSamplePixels));
    auto floorFromSample = [&](auto measureRow) {
        std::vector<float> sample;
        std::vector<double> value(static_cast<std::size_t>(W));
        for (int row = 0; row < H; row += rowStep) {
            const std::size_t i0 = std::size_t(row) * W;
            measureRow(i0, row, value.data());
            for (int col = 0; col < W; ++col) {
                const std::size_t i = i0 + std::size_t(col);
                if (ray.hit(i) && ray.primitiveId[i] == raster.primitiveId[i]) sample.push_back(float(value[col]));
            }
        }
        return LargestValues::floorBelowPercentile99(sample);
    };
    float errorQuantaFloor = 0, relativeEyeZFloor = 0;
    tbb::parallel_invoke(
        [&] {
            errorQuantaFloor = floorFromSample([&](std::size_t i0, int, double* errorQuanta) {
                measures.quanta(rayPixels, rasterPixels, i0, i0, std::size_t(W), errorQuanta);  // q, then |Δ|/q
                for (std::size_t j = 0; j < std::size_t(W); ++j)
                    errorQuanta[j] =
                        std::abs(PixelMeasures::signedErrorQuanta(rayPixels.windowDepth[i0 + j], rasterPixels.windowDepth[i0 + j], errorQuanta[j]));
            });
        },
        [&] {
            relativeEyeZFloor = floorFromSample([&](std::size_t i0, int row, double* relative) {
                measures.relativeEyeZErrors(rayPixels, rasterPixels, i0, i0, 0, row, std::size_t(W), relative);
            });
        });

    Comparison out;
    for (const bool floors : {true, false}) {
        TileComparison tiles(judge, &out, floors ? errorQuantaFloor : 0.0f, floors ? relativeEyeZFloor : 0.0f);
        // A band of tiles at a time, image row by image row across the band: each row of the
        // four arrays is then read as one stream, where tile by tile it was read in 64-pixel
        // pieces 15 KB apart (a pass that only reads and writes the arrays takes ~3× as long
        // tile by tile: `bench/zcheck_bench --phase floor`). Each tile still sees its rows in order.
        const TileGrid& grid = tiles.tiles();
        tbb::parallel_for(0, grid.tilesY(), [&](int band) { tiles.compareBandRows(band, 0, H, rayPixels, rasterPixels); });
        if (std::optional<ComparisonReport> report = tiles.finish()) {
            out.report = std::move(*report);
            return out;
        }
        if (!floors) throw std::logic_error("comparison: the percentiles' keepers kept too few values");
    }
    return out;
}

}  // namespace zcheck
