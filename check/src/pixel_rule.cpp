// The per-pixel rule (compare.h): PixelJudge, the tolerance model's constants, the pixel
// classes, and the slope m of a triangle's plane, one at a time (DepthSlopeFrame) or a block of
// 64 at a time for the judge's table (slope_table.h), in each kernel form. The
// comparison's row pass (compare_rows.cpp) and its tile driver (compare.cpp) apply this rule.
#include "zcheck/compare.h"

#include "zcheck/drawn_polygon.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/detail/lanes.h"
#include "slope_table.h"

#include <algorithm>
#include <cmath>
#include <memory>

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

// DepthSlopeFrame::slope's arithmetic, written once for one triangle (Real: double, Ops:
// ScalarOps) and for a lane type's eight (Real: L::Real, Ops: L), inlined where it is called;
// each form's lanes compute the bits the scalar form does (the same IEEE operations in the same
// order). Corners a, b and c as x, y, z. No branch: a plane seen edge-on selects +inf after the
// division by its zero.
struct ScalarOps {
    static double abs(double x) { return std::abs(x); }
    static double max(double a, double b) { return a > b ? a : b; }  // as the lane types' max
    static double select(bool m, double ifTrue, double ifFalse) { return m ? ifTrue : ifFalse; }
    static double set1(double x) { return x; }
};

template <class Ops, class Real>
ZCHECK_ALWAYS_INLINE inline Real slopeOfCorners(const DepthSlopeFrame& frame, const Real (&a)[3], const Real (&b)[3],
                                                const Real (&c)[3])
{
    // The plane (normal, −normal·a): glm::cross(b − a, c − a) and glm::dot's order.
    const Real e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Real normal[3] = {e1[1] * e2[2] - e2[1] * e1[2], e1[2] * e2[0] - e2[2] * e1[0], e1[0] * e2[1] - e2[0] * e1[1]};
    const Real offset = normal[0] * a[0] + normal[1] * a[1] + normal[2] * a[2];  // the plane's w is −offset
    // The clip-space plane's x, y and z (its w is not needed): rows 0-2 of the product, its last
    // term m·(−offset) as − m·offset (the same bits).
    const glm::dmat4& m = frame.clipPlaneFromWorldPlane;
    const auto row = [&](int r) ZCHECK_ALWAYS_INLINE {
        return m[0][r] * normal[0] + m[1][r] * normal[1] + m[2][r] * normal[2] - m[3][r] * offset;
    };
    const Real x = row(0), y = row(1), z = row(2);
    const Real dx = frame.ndcPerPixelX * Ops::abs(x), dy = frame.ndcPerPixelY * Ops::abs(y);
    // A sample up to S off in x and in y moves depth by up to S·(|∂d/∂x| + |∂d/∂y|); vertices
    // snapped by up to S/2 per axis by no more than S·max (compare.h). (std::max(dx, dy) is
    // max(dy, dx) here: dx where either is NaN or they are equal.)
    const Real perPixel = frame.credit == SlopeCredit::SampleOffset ? dx + dy : Ops::max(dy, dx);
    const Real absZ = Ops::abs(z);
    return Ops::select(absZ <= Ops::set1(0.0), Ops::set1(INFINITY), frame.zWindowPerZNdc * perPixel / absZ);
}

}  // namespace

double DepthSlopeFrame::slope(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) const
{
    const double corners[3][3] = {{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}};
    return slopeOfCorners<ScalarOps>(*this, corners[0], corners[1], corners[2]);
}

double windowDepthSlope(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return DepthSlopeFrame(camera).slope(a, b, c);
}

namespace {

// Slopes of up to kSlopeLanes consecutive triangles together: their corners dealt into lane
// arrays, then slopeOfCorners over them, one triangle at a time in the baseline form (which the
// compiler vectorises as it can) and eight at a time over a lane type in the vector forms (which
// GCC left scalar for AVX2); in the AVX-512 form a whole block's corners are gathered instead
// (slopesOfWholeBlockGathered). Inlined into one function per form (kernel_choice.h).
constexpr std::size_t kSlopeLanes = 64;

// Asks for the index triples of the block after the one ending before triangle `next`: the
// comparison often asks for blocks in order (the comparison ~5 % faster in process).
ZCHECK_ALWAYS_INLINE inline void prefetchNextBlock(const Scene& scene, std::size_t next)
{
    const std::size_t end = std::min(scene.triangles.size(), next + kSlopeLanes);
    for (std::size_t k = next; k < end; k += 64 / sizeof(glm::uvec3)) __builtin_prefetch(&scene.triangles[k]);
}

// Asks for every corner of triangles first .. first + n − 1 (first + n ≤ the scene's triangle
// count, their indices in range: validateScene), and the next block's index triples: the loads of
// a block's corners then overlap, where reading them in order waited on each few in turn (the
// scene's vertices are out of the caches after both routes rendered). Before the gathered form did
// this too, its slopes were a third of an AVX-512 comparison, mostly waiting on its gathers; with
// it the comparison (`bench/zcheck_bench --phase compare`) took 4.3-4.6 ms instead of 4.8-5.0 in
// six pairs (Zen 5).
ZCHECK_ALWAYS_INLINE inline void prefetchCorners(const Scene& scene, std::uint32_t first, std::size_t n)
{
    for (std::size_t k = 0; k < n; ++k)
        for (int v = 0; v < 3; ++v) __builtin_prefetch(&scene.positions[scene.triangles[first + k][v]]);
    prefetchNextBlock(scene, first + n);
}

// The corners of triangles first .. first + n − 1 (n ≤ kSlopeLanes) dealt into lane arrays in
// double, for kernels that then work on several triangles per instruction: corner[v][axis][k] is
// corner v of triangle first + k. The indices must be in range (validateScene). Always inlined,
// so that each form of a kernel compiles its own copy.
ZCHECK_ALWAYS_INLINE inline void cornersOfBlock(const Scene& scene, std::uint32_t first, std::size_t n,
                                                double (&corner)[3][3][kSlopeLanes])
{
    prefetchCorners(scene, first, n);
    for (std::size_t k = 0; k < n; ++k) {
        const glm::uvec3& t = scene.triangles[first + k];
        for (int v = 0; v < 3; ++v)
            for (int axis = 0; axis < 3; ++axis) corner[v][axis][k] = double(scene.positions[t[v]][axis]);
    }
}

void slopesTogetherBaseline(const DepthSlopeFrame& frame, const Scene& scene, std::uint32_t first, std::size_t n,
                            double* slope)
{
    alignas(64) double corner[3][3][kSlopeLanes];  // corner, axis, lane
    cornersOfBlock(scene, first, n, corner);
    for (std::size_t k = 0; k < n; ++k) {
        const double a[3] = {corner[0][0][k], corner[0][1][k], corner[0][2][k]};
        const double b[3] = {corner[1][0][k], corner[1][1][k], corner[1][2][k]};
        const double c[3] = {corner[2][0][k], corner[2][1][k], corner[2][2][k]};
        slope[k] = slopeOfCorners<ScalarOps>(frame, a, b, c);
    }
}

#ifdef ZCHECK_X86_FORMS
// A whole block's slopes with its corners gathered eight triangles at a time (L::kFastGathers),
// where the indices allow it (cornersGatherable): each triangle's three indices read as a
// stream, each corner's x, y and z eight at a time; no array in between. The same floats, made
// doubles, as cornersOfBlock's.
template <class L>
ZCHECK_ALWAYS_INLINE inline void slopesOfWholeBlockGathered(const DepthSlopeFrame& frame, const Scene& scene,
                                                            std::uint32_t first, double* slope)
{
    using Real = typename L::Real;
    using Int32 = typename L::Int32;
    prefetchCorners(scene, first, kSlopeLanes);
    const float* positions = &scene.positions[0].x;
    for (std::size_t k = 0; k < kSlopeLanes; k += L::kLanes) {
        Int32 index[3];
        L::loadTriples(&scene.triangles[first + k].x, index);
        Real c[3][3];
        for (int v = 0; v < 3; ++v) {
            const Int32 at = index[v] + index[v] + index[v];  // of the vertex's x among the floats
            for (int axis = 0; axis < 3; ++axis) c[v][axis] = L::toReal(L::gatherFloats(positions + axis, at));
        }
        L::store(slope + k, slopeOfCorners<L>(frame, c[0], c[1], c[2]));
    }
}

// Whether slopesOfWholeBlockGathered reaches every vertex: its offsets among the floats (3 per
// vertex) are lanes of non-negative 32-bit integers.
bool cornersGatherable(const Scene& scene) { return scene.positions.size() <= std::size_t(INT32_MAX) / 3; }

template <class L>
ZCHECK_ALWAYS_INLINE inline void slopesTogetherLanes(const DepthSlopeFrame& frame, const Scene& scene,
                                                     std::uint32_t first, std::size_t n, double* slope)
{
    using Real = typename L::Real;
    if constexpr (L::kFastGathers)
        if (n == kSlopeLanes && cornersGatherable(scene)) return slopesOfWholeBlockGathered<L>(frame, scene, first, slope);
    alignas(64) double corner[3][3][kSlopeLanes];  // corner, axis, lane
    cornersOfBlock(scene, first, n, corner);
    for (std::size_t k = n; k % L::kLanes != 0; ++k)  // the last group's lanes past n: zeros, not stored
        for (int v = 0; v < 3; ++v)
            for (int axis = 0; axis < 3; ++axis) corner[v][axis][k] = 0.0;
    for (std::size_t k = 0; k < n; k += L::kLanes) {
        Real c[3][3];
        for (int v = 0; v < 3; ++v)
            for (int axis = 0; axis < 3; ++axis) c[v][axis] = L::load(&corner[v][axis][k]);
        const Real slopes = slopeOfCorners<L>(frame, c[0], c[1], c[2]);
        if (k + L::kLanes <= n)
            L::store(slope + k, slopes);
        else
            L::maskedStore(L::firstLanes(int(n - k)), slope + k, slopes);
    }
}

ZCHECK_KERNEL_ENTRY_AVX2 void slopesTogetherAvx2(const DepthSlopeFrame& frame, const Scene& scene, std::uint32_t first,
                                                 std::size_t n, double* slope)
{
    slopesTogetherLanes<Avx2Lanes>(frame, scene, first, n, slope);
}

ZCHECK_KERNEL_ENTRY_AVX512 void slopesTogetherAvx512(const DepthSlopeFrame& frame, const Scene& scene,
                                                     std::uint32_t first, std::size_t n, double* slope)
{
    slopesTogetherLanes<Avx512Lanes>(frame, scene, first, n, slope);
}
#endif

}  // namespace

PixelJudge::PixelJudge(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance, SlopeSource slopes)
    : scene_(scene),
      camera_(camera),
      local_(scene, camera),
      tolerance_(tolerance),
      terms_{tolerance.constantFor(camera.depth()), tolerance.snapPixels(),
             16 * std::ldexp(1.0, -52) * std::max(std::abs(camera.depth().rangeMin), std::abs(camera.depth().rangeMax))},
      form_(kernelForm()),
      slopeFrame_(local_.get(), tolerance.slopeCredit)
{
    if (slopes == SlopeSource::TableOfSeen) table_ = std::make_unique<SlopeTable>(scene_, slopeFrame_, form_);
}

PixelJudge::~PixelJudge() = default;

double PixelJudge::slope(std::uint32_t primitive) const
{
    if (!known(primitive)) return 0.0;
    if (table_ && table_->ready(primitive)) return table_->at(primitive);
    return computeSlope(primitive);
}

SlopeTable::SlopeTable(const Scene& scene, const DepthSlopeFrame& frame, KernelForm form)
    : scene_(scene), frame_(frame), form_(form)
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
#ifdef ZCHECK_X86_FORMS
    together = formOf(form_, together, &slopesTogetherAvx2, &slopesTogetherAvx512);
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
    const EyePlaneRay ray = worldEyePlaneRayThroughWindow(local_.get(), pWindow);
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
    return distanceToDrawnEdge(local_.get(), vertex(primitive, 0), vertex(primitive, 1), vertex(primitive, 2), pWindow) <= terms_.S;
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

}  // namespace zcheck
