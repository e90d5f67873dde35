// Scan conversion after the classic half-space formulation (Pineda, "A Parallel Algorithm
// for Polygon Rasterization", SIGGRAPH 1988) with Direct3D's top-left fill convention,
// binned into tiles as in Abrash's Larrabee rasterizer.
#include "zcheck/raster_renderer.h"

#include "zcheck/detail/clock.h"
#include "zcheck/detail/streaming_stores.h"

#include "raster_testing.h"

#include "zcheck/clip.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/kernel_choice.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cmath>

#ifdef ZCHECK_X86_AVX512
#include <immintrin.h>
#endif

namespace zcheck {

namespace {

constexpr std::int64_t kSubpixel = 1 << RasterRenderer::kSubpixelBits;  // fixed-point units per pixel
constexpr std::int64_t kHalfPixel = kSubpixel / 2;
constexpr double kMaxImageCoordinate = 1 << 20;  // |window coordinate| after guard-band clipping, pixels

// The pixels whose centres a snapped triangle may cover, inclusive and inside the image.
struct PixelBox {
    int minCol, maxCol, minRow, maxRow;
};

// A triangle ready to scan: edge functions in 16.8 fixed point, depth plane in pixels.
struct TriangleSetup {
    // E_i(P) = A_i·P.x + B_i·P.y + C_i for P in fixed point; the pixel is covered iff all
    // three are ≥ 0 (the top-left rule is folded into C_i as a bias of −1 on other edges).
    std::int64_t A[3], B[3], C[3];
    // Window depth at image point (x, y): z0 + dzdx·(x − x0) + dzdy·(y − y0).
    double x0, y0, z0, dzdx, dzdy;
    PixelBox box;
    std::uint32_t primitive;
};

// A vertex after divide, viewport and snapping; `valid` is false where it cannot be snapped
// (only a fault, no near clipping, brings such vertices here).
struct SnappedVertex {
    std::int64_t X, Y;  // 16.8 fixed point, image rows top-down
    double z;           // the value interpolated: window depth (or eye-z under a fault)
    bool valid;
};

// A snapped vertex as the per-vertex array stores it, in 16 bytes instead of 32 (a million
// triangles' vertices are 8 MB less to fault in and to pull through the caches per tile).
// A valid vertex lies within 2·kMaxImageCoordinate pixels, i.e. |X|, |Y| < 2^29: int32 holds
// it exactly. X = INT32_MIN marks a vertex not snapped: Y = 0 for one inside every clip plane
// that cannot be snapped, Y = its outcode for one outside a clip plane (so that a vertex's
// outcode is read with its position, and no array of outcodes is kept beside it).
static_assert(2 * kMaxImageCoordinate * kSubpixel < 2147483648.0, "a valid snapped vertex fits int32");
struct StoredVertex {
    double z;
    std::int32_t X, Y;

    static StoredVertex from(const SnappedVertex& v)
    {
        return v.valid ? StoredVertex{v.z, std::int32_t(v.X), std::int32_t(v.Y)} : StoredVertex{0.0, INT32_MIN, 0};
    }
    static StoredVertex outside(unsigned outcode) { return {0.0, INT32_MIN, std::int32_t(outcode)}; }
    SnappedVertex snapped() const { return {X, Y, z, X != INT32_MIN}; }
    unsigned outcode() const { return X == INT32_MIN ? unsigned(Y) : 0u; }  // bit k: outside clip plane k
};

// A bin entry names a triangle of the scene whose three vertices needed no clipping (its
// set-up is recomputed from the snapped vertices when drawn), or, with kClippedBit, a set-up
// of the chunk's clipped triangles. Nothing per triangle is stored beyond these 4 bytes.
constexpr std::uint32_t kClippedBit = 0x80000000u;

struct Chunk {
    std::vector<TriangleSetup> clipped;     // set-ups of the triangles clipping produced
    std::vector<std::uint32_t> tileStart;   // CSR: entries of tile t are binned[tileStart[t] .. tileStart[t+1])
    std::vector<std::uint32_t> binned;      // bin entries, submission order per tile
};

struct Viewport {
    const Camera& camera;
    const RasterFaults& faults;
    int width, height;
    TileGrid tiles;  // kTileSize squares
    ClipPlanes planes;  // near, far, guard band
    glm::dmat4 clipFromWorld, windowFromNdc;
    bool pixelFaults;   // a fault that changes the per-pixel depth computation

    Viewport(const Camera& c, const RasterFaults& f)
        : camera(c), faults(f), width(c.width()), height(c.height()), tiles(width, height, RasterRenderer::kTileSize)
    {
        const ClipPlanes depthPlanes = depthClipPlanes(c.convention().ndcZMin());
        planes = depthPlanes;
        if (f.noNearClip) planes.size = 0, planes.plane[planes.size++] = depthPlanes.plane[1];  // far only
        // |ndc| ≤ guard keeps image coordinates within ±(guard+1)/2·size ≤ 2^20 pixels.
        addGuardBandPlanes(planes, 2.0 * kMaxImageCoordinate / std::max(width, height) - 1.0);
        clipFromWorld = f.overrideClipFromWorld ? f.clipFromWorld : c.clipFromWorld;
        windowFromNdc = c.windowFromNdc;
        if (f.viewportMinusOne) {
            windowFromNdc[0][0] *= double(width - 1) / width, windowFromNdc[3][0] *= double(width - 1) / width;
            windowFromNdc[1][1] *= double(height - 1) / height, windowFromNdc[3][1] *= double(height - 1) / height;
        }
        pixelFaults = f.screenLinearEyeZ || f.truncateUnorm || f.storeLinearEyeZ;
    }

    unsigned outcode(const glm::dvec4& pClip) const
    {
        unsigned code = 0;
        for (int p = 0; p < planes.size; ++p)
            if (glm::dot(planes.plane[p], pClip) < 0) code |= 1u << p;
        return code;
    }
};

// std::llround(x) for |x| < 2^52, inline (the library call was a tenth of the vertex work):
// the truncation t and the fraction x − t are exact, and a fraction of ±½ or more rounds
// away from zero, as llround does.
std::int64_t roundHalfAwayFromZero(double x)
{
    const auto t = static_cast<std::int64_t>(x);
    const double fraction = x - static_cast<double>(t);
    return t + (fraction >= 0.5) - (fraction <= -0.5);
}

// Perspective divide, viewport, image rows top-down, snap: one vertex, the same arithmetic
// whether the vertex is the scene's or one that clipping made.
SnappedVertex snapVertex(const Viewport& vp, const glm::dvec4& pClip)
{
    SnappedVertex v{};
    const glm::dvec3 pNdc = glm::dvec3(pClip) / pClip.w;
    const glm::dvec3 pWindow(vp.windowFromNdc * glm::dvec4(pNdc, 1.0));
    const double yImage = vp.camera.imageYFromWindowY(pWindow.y);
    // Only a fault (no near clipping) can bring w ≤ 0 here: mark what cannot be snapped.
    v.valid = std::abs(pWindow.x) < 2 * kMaxImageCoordinate && std::abs(yImage) < 2 * kMaxImageCoordinate;
    if (!v.valid) return v;
    v.X = roundHalfAwayFromZero(pWindow.x * kSubpixel);  // |X|, |Y| < 2^30 (valid)
    v.Y = roundHalfAwayFromZero(yImage * kSubpixel);
    // The fault "eye-z interpolated in screen space" interpolates eye-z instead of depth.
    if (vp.faults.screenLinearEyeZ) {
        const glm::dvec4 pEye = vp.camera.eyeFromClip * pClip;
        v.z = vp.camera.eyeZOf(glm::dvec3(pEye) / pEye.w);
    } else {
        v.z = pWindow.z;
    }
    return v;
}

// The box of a snapped triangle; false when it covers no pixel centre (zero area, outside
// the image, or a vertex that cannot be snapped). `area2` receives twice its signed area.
bool coveredBox(const Viewport& vp, const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
                PixelBox& box, std::int64_t& area2)
{
    if (!v0.valid || !v1.valid || !v2.valid) return false;
    area2 = (v1.X - v0.X) * (v2.Y - v0.Y) - (v1.Y - v0.Y) * (v2.X - v0.X);
    if (area2 == 0) return false;  // covers no sample point
    // Pixel (c, r) samples at fixed point (c·256 + 128, r·256 + 128).
    auto firstCentre = [](std::int64_t lo) { return int((lo - kHalfPixel + kSubpixel - 1) >> RasterRenderer::kSubpixelBits); };
    auto lastCentre = [](std::int64_t hi) { return int((hi - kHalfPixel) >> RasterRenderer::kSubpixelBits); };
    box.minCol = std::max(0, firstCentre(std::min({v0.X, v1.X, v2.X})));
    box.maxCol = std::min(vp.width - 1, lastCentre(std::max({v0.X, v1.X, v2.X})));
    box.minRow = std::max(0, firstCentre(std::min({v0.Y, v1.Y, v2.Y})));
    box.maxRow = std::min(vp.height - 1, lastCentre(std::max({v0.Y, v1.Y, v2.Y})));
    return box.minCol <= box.maxCol && box.minRow <= box.maxRow;
}

// Edge functions, pixel bounding box and depth plane of a snapped triangle; false when it
// covers no pixel centre (coveredBox).
bool setupFromSnapped(const Viewport& vp, const SnappedVertex& v0, const SnappedVertex& v1, const SnappedVertex& v2,
                      std::uint32_t primitive, TriangleSetup& t)
{
    PixelBox box;
    std::int64_t area2;
    if (!coveredBox(vp, v0, v1, v2, box, area2)) return false;
    t.box = box;
    std::int64_t X[3] = {v0.X, v1.X, v2.X}, Y[3] = {v0.Y, v1.Y, v2.Y};
    double z[3] = {v0.z, v1.z, v2.z};
    if (area2 < 0)  // no culling: both windings are drawn, normalised to area2 > 0
        std::swap(X[1], X[2]), std::swap(Y[1], Y[2]), std::swap(z[1], z[2]);

    for (int e = 0; e < 3; ++e) {
        const int a = e, b = (e + 1) % 3;
        const std::int64_t dx = X[b] - X[a], dy = Y[b] - Y[a];
        // Top-left rule (image y points down, area2 > 0): a top edge is horizontal with the
        // interior below it (dx > 0); a left edge goes up (dy < 0).
        const bool topLeft = dy < 0 || (dy == 0 && dx > 0);
        t.A[e] = -dy;
        t.B[e] = dx;
        t.C[e] = dy * X[a] - dx * Y[a] - (topLeft ? 0 : 1);
    }
    const double x0 = double(X[0]) / kSubpixel, y0 = double(Y[0]) / kSubpixel;
    const double dx1 = double(X[1] - X[0]) / kSubpixel, dy1 = double(Y[1] - Y[0]) / kSubpixel;
    const double dx2 = double(X[2] - X[0]) / kSubpixel, dy2 = double(Y[2] - Y[0]) / kSubpixel;
    const double dz1 = z[1] - z[0], dz2 = z[2] - z[0];
    const double det = dx1 * dy2 - dx2 * dy1;
    t.x0 = x0, t.y0 = y0, t.z0 = z[0];
    t.dzdx = (dz1 * dy2 - dz2 * dy1) / det;
    t.dzdy = (dx1 * dz2 - dx2 * dz1) / det;
    t.primitive = primitive;
    return true;
}

// Clip one world triangle that crosses a clip plane and set up what survives (a fan when
// clipping made a polygon).
void setupClippedPrimitive(const Viewport& vp, const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c,
                           std::uint32_t primitive, std::vector<TriangleSetup>& out)
{
    const ClipPolygon polygon = clipTriangle(a, b, c, vp.planes);
    for (int k = 1; k + 1 < polygon.size; ++k) {
        TriangleSetup t;
        if (setupFromSnapped(vp, snapVertex(vp, polygon.pClip[0]), snapVertex(vp, polygon.pClip[k]),
                             snapVertex(vp, polygon.pClip[k + 1]), primitive, t))
            out.push_back(t);
    }
}

// What binning needs of one entry: its pixel bounding box.
struct BinItem {
    std::uint32_t entry;
    PixelBox box;
};

void binChunk(const Viewport& vp, const std::vector<BinItem>& items, Chunk& chunk)
{
    const int tiles = vp.tiles.count();
    chunk.tileStart.assign(std::size_t(tiles) + 1, 0);
    // The tiles a box overlaps, per triangle: with the tile side a compile-time constant these
    // divisions are shifts (dividing by the TileGrid's run-time side made the raster 13 % slower).
    constexpr int T = RasterRenderer::kTileSize;
    const int tilesX = vp.tiles.tilesX();
    auto forEachTile = [&](const BinItem& item, auto&& visit) {
        const PixelBox& b = item.box;
        for (int ty = b.minRow / T; ty <= b.maxRow / T; ++ty)
            for (int tx = b.minCol / T; tx <= b.maxCol / T; ++tx) visit(ty * tilesX + tx);
    };
    for (const BinItem& item : items) forEachTile(item, [&](int tile) { ++chunk.tileStart[std::size_t(tile) + 1]; });
    for (int tile = 0; tile < tiles; ++tile) chunk.tileStart[tile + 1] += chunk.tileStart[tile];
    chunk.binned.resize(chunk.tileStart[tiles]);
    std::vector<std::uint32_t> fill(chunk.tileStart.begin(), chunk.tileStart.end() - 1);
    for (const BinItem& item : items) forEachTile(item, [&](int tile) { chunk.binned[fill[tile]++] = item.entry; });
}

// What a tile holds per pixel while it is drawn: the depth buffer's key, which orders as the
// stored values do — a unorm format's integer code (its value is code / (2^N − 1)), a float32
// buffer's value itself. The depth test compares keys, and the stored value is made from the
// key once, when the tile is copied into the frame: no division per drawn pixel.
struct DepthKeys {
    bool unorm;
    double maxCode;

    explicit DepthKeys(DepthFormat f) : unorm(f != DepthFormat::Float32), maxCode(unorm ? unormMax(f) : 1.0) {}
    // Integer codes of `codes` steps whatever the format (RasterFrameTesting's fine keys).
    static DepthKeys withCodes(double codes)
    {
        DepthKeys keys(DepthFormat::Unorm24);
        keys.maxCode = codes;
        return keys;
    }
    // The key of window depth d: value(key(d)) == quantizeDepth(format, d), bit for bit
    // (unormCode's arithmetic, with maxCode = unormMax(format)).
    double key(double windowDepth) const
    {
        return unorm ? nearbyintNonNegative(std::clamp(windowDepth, 0.0, 1.0) * maxCode) : double(float(windowDepth));
    }
    double value(double key) const { return unorm ? key / maxCode : key; }
    // The key of a value the buffer can store (code / (2^N − 1) times 2^N − 1 is the code to
    // within 1e-9, so rounding recovers it exactly).
    double keyOfStored(double stored) const { return unorm ? nearbyintNonNegative(stored * maxCode) : stored; }
};

// The stored value under the pixel faults (never called for a clean chain).
double faultyStoredDepth(const Viewport& vp, double interpolated, int col, int row)
{
    const Camera& camera = vp.camera;
    const DepthSettings& depth = camera.depth();
    const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
    double windowDepth = vp.faults.screenLinearEyeZ ? windowDepthFromEyeZ(camera, pWindow, interpolated) : interpolated;
    if (vp.faults.storeLinearEyeZ) {
        const double eyeZ = eyeZFromWindowDepth(camera, pWindow, windowDepth);
        windowDepth = depth.rangeMin + (depth.rangeMax - depth.rangeMin) * (eyeZ - camera.nearDistance()) /
                                           (camera.farDistance() - camera.nearDistance());
    }
    windowDepth = std::clamp(windowDepth, depth.rangeMin, depth.rangeMax);
    if (vp.faults.truncateUnorm && depth.format != DepthFormat::Float32) {
        const double maxCode = 1.0 / storageQuantum(depth.format, windowDepth);
        return std::floor(windowDepth * maxCode) / maxCode;
    }
    return quantizeDepth(depth.format, windowDepth);
}

// One tile's depth keys and primitive ids while it is drawn: kept in the worker's cache
// (48 KB), then copied into the frame once.
struct TileBuffer {
    static constexpr int kSide = RasterRenderer::kTileSize;
    int col0, row0;  // the tile's top-left pixel in the frame
    double key[kSide * kSide];
    std::uint32_t primitive[kSide * kSide];
};

// Scan one triangle inside one tile; `PixelFaults`: a fault changes how a pixel's stored
// depth is computed (faultyStoredDepth), the clean chain otherwise.
template <bool PixelFaults>
void drawInTile(const Viewport& vp, const DepthKeys& keys, const TriangleSetup& t, int tileCol0, int tileRow0,
                int tileCol1, int tileRow1, TileBuffer& out)
{
    const int col0 = std::max(t.box.minCol, tileCol0), col1 = std::min(t.box.maxCol, tileCol1);
    const int row0 = std::max(t.box.minRow, tileRow0), row1 = std::min(t.box.maxRow, tileRow1);
    const DepthSettings& depth = vp.camera.depth();
    const bool reversed = depth.reversed;  // the depth test: LESS, or GREATER with reversed-Z
    for (int row = row0; row <= row1; ++row) {
        const std::int64_t py = row * kSubpixel + kHalfPixel, px = col0 * kSubpixel + kHalfPixel;
        std::int64_t e0 = t.A[0] * px + t.B[0] * py + t.C[0];
        std::int64_t e1 = t.A[1] * px + t.B[1] * py + t.C[1];
        std::int64_t e2 = t.A[2] * px + t.B[2] * py + t.C[2];
        const std::int64_t step0 = t.A[0] * kSubpixel, step1 = t.A[1] * kSubpixel, step2 = t.A[2] * kSubpixel;
        const double rowDepth = t.z0 + t.dzdy * (row + 0.5 - t.y0);
        double* keyRow = out.key + (row - out.row0) * TileBuffer::kSide - out.col0;
        std::uint32_t* primitiveRow = out.primitive + (row - out.row0) * TileBuffer::kSide - out.col0;
        for (int col = col0; col <= col1; ++col, e0 += step0, e1 += step1, e2 += step2) {
            if ((e0 | e1 | e2) < 0) continue;  // some edge function negative: outside
            const double interpolated = rowDepth + t.dzdx * (col + 0.5 - t.x0);
            const double key = PixelFaults ? keys.keyOfStored(faultyStoredDepth(vp, interpolated, col, row))
                                           : keys.key(std::clamp(interpolated, depth.rangeMin, depth.rangeMax));
            if (reversed ? key > keyRow[col] : key < keyRow[col]) {
                keyRow[col] = key;
                primitiveRow[col] = t.primitive;
            }
        }
    }
}

#ifdef ZCHECK_X86_AVX512
ZCHECK_INTRINSICS_BEGIN

// std::clamp(v, lo, hi) per lane: v < lo ? lo : hi < v ? hi : v, NaN and signed zeros included.
ZCHECK_TARGET_AVX512 inline __m512d clamp(__m512d v, __m512d lo, __m512d hi)
{
    v = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(v, lo, _CMP_LT_OQ), v, lo);
    return _mm512_mask_blend_pd(_mm512_cmp_pd_mask(hi, v, _CMP_LT_OQ), v, hi);
}

// Edge function k of t at pixels (col + j, row), j = 0..7, one per lane.
ZCHECK_TARGET_AVX512 inline __m512i edgeAtLanes(const TriangleSetup& t, int k, int col, int row)
{
    const std::int64_t px = col * kSubpixel + kHalfPixel, py = row * kSubpixel + kHalfPixel;
    return _mm512_add_epi64(_mm512_set1_epi64(t.A[k] * px + t.B[k] * py + t.C[k]),
                            _mm512_mullo_epi64(_mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0), _mm512_set1_epi64(t.A[k] * kSubpixel)));
}

// drawInTile<false> with eight pixels of a row at a time: the same integer edge functions
// and the same double operations in the same order per pixel (the build forbids contracting
// them into fused multiply-adds), so its output is bit-identical to the scalar loop's. A
// triangle's pixels are distinct within a row, so lanes never depend on each other.
ZCHECK_TARGET_AVX512 void drawInTileAvx512(const DepthSettings& depth, const DepthKeys& keys, const TriangleSetup& t,
                                           int tileCol0, int tileRow0, int tileCol1, int tileRow1, TileBuffer& out)
{
    const int col0 = std::max(t.box.minCol, tileCol0), col1 = std::min(t.box.maxCol, tileCol1);
    const int row0 = std::max(t.box.minRow, tileRow0), row1 = std::min(t.box.maxRow, tileRow1);
    // Edge function k at lane j of a group: its value at the group's first pixel + j·A_k·256;
    // a group eight pixels on adds 8·A_k·256, a row down B_k·256 (exact: what the scalar loop
    // computes as A_k·px + B_k·py + C_k).
    __m512i rowE0 = edgeAtLanes(t, 0, col0, row0), rowE1 = edgeAtLanes(t, 1, col0, row0), rowE2 = edgeAtLanes(t, 2, col0, row0);
    const __m512i down0 = _mm512_set1_epi64(t.B[0] * kSubpixel), across0 = _mm512_set1_epi64(t.A[0] * kSubpixel * 8);
    const __m512i down1 = _mm512_set1_epi64(t.B[1] * kSubpixel), across1 = _mm512_set1_epi64(t.A[1] * kSubpixel * 8);
    const __m512i down2 = _mm512_set1_epi64(t.B[2] * kSubpixel), across2 = _mm512_set1_epi64(t.A[2] * kSubpixel * 8);
    // A lane's pixel centre col + 0.5 (exact in double, as are its steps of 8).
    const __m512d firstCentres = _mm512_add_pd(_mm512_set1_pd(col0), _mm512_set_pd(7.5, 6.5, 5.5, 4.5, 3.5, 2.5, 1.5, 0.5));
    const __m512d eight = _mm512_set1_pd(8.0), x0 = _mm512_set1_pd(t.x0), dzdx = _mm512_set1_pd(t.dzdx);
    const __m512d rangeMin = _mm512_set1_pd(depth.rangeMin), rangeMax = _mm512_set1_pd(depth.rangeMax);
    const __m512d maxCode = _mm512_set1_pd(keys.maxCode);
    const __m512d noFractionBits = _mm512_set1_pd(4503599627370496.0);  // nearbyintNonNegative's 2^52
    const __m256i primitive = _mm256_set1_epi32(int(t.primitive));
    // No branch on coverage: a group with no pixel covered stores nothing (its masks are
    // empty), and a branch on it was mispredicted often enough to cost 5 %.
    for (int row = row0; row <= row1; ++row) {
        const __m512d rowDepth = _mm512_set1_pd(t.z0 + t.dzdy * (row + 0.5 - t.y0));
        double* keyRow = out.key + (row - out.row0) * TileBuffer::kSide - out.col0;
        std::uint32_t* primitiveRow = out.primitive + (row - out.row0) * TileBuffer::kSide - out.col0;
        __m512i e0 = rowE0, e1 = rowE1, e2 = rowE2;
        __m512d centre = firstCentres;
        for (int col = col0; col <= col1; col += 8) {
            const __mmask8 inBox = __mmask8((1u << std::min(8, col1 - col + 1)) - 1);
            const __mmask8 covered = _mm512_mask_cmpge_epi64_mask(
                inBox, _mm512_or_si512(_mm512_or_si512(e0, e1), e2), _mm512_setzero_si512());
            const __m512d interpolated = _mm512_add_pd(rowDepth, _mm512_mul_pd(dzdx, _mm512_sub_pd(centre, x0)));
            const __m512d windowDepth = clamp(interpolated, rangeMin, rangeMax);
            // unormCode's own clamp to [0, 1] is left out: the camera holds 0 ≤ rangeMin < rangeMax ≤ 1,
            // so it returns every clamped value unchanged (NaN and −0 included).
            const __m512d key =
                keys.unorm ? _mm512_sub_pd(_mm512_add_pd(_mm512_mul_pd(windowDepth, maxCode), noFractionBits), noFractionBits)
                           : _mm512_cvtps_pd(_mm512_cvtpd_ps(windowDepth));
            const __m512d stored = _mm512_maskz_loadu_pd(covered, keyRow + col);
            const __mmask8 nearer = depth.reversed ? _mm512_mask_cmp_pd_mask(covered, stored, key, _CMP_LT_OQ)
                                                   : _mm512_mask_cmp_pd_mask(covered, key, stored, _CMP_LT_OQ);
            _mm512_mask_storeu_pd(keyRow + col, nearer, key);
            _mm256_mask_storeu_epi32(primitiveRow + col, nearer, primitive);
            e0 = _mm512_add_epi64(e0, across0), e1 = _mm512_add_epi64(e1, across1), e2 = _mm512_add_epi64(e2, across2);
            centre = _mm512_add_pd(centre, eight);
        }
        rowE0 = _mm512_add_epi64(rowE0, down0), rowE1 = _mm512_add_epi64(rowE1, down1), rowE2 = _mm512_add_epi64(rowE2, down2);
    }
}

// Matrix column c, row r of a glm::dmat4 (m[c][r]) in every lane.
ZCHECK_TARGET_AVX512 inline __m512d broadcast(const glm::dmat4& m, int c, int r) { return _mm512_set1_pd(m[c][r]); }

// Row r of m · (x, y, z, 1) in glm's order: (m0·x + m1·y) + (m2·z + m3·1).
ZCHECK_TARGET_AVX512 inline __m512d transformRow(const glm::dmat4& m, int r, __m512d x, __m512d y, __m512d z)
{
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(broadcast(m, 0, r), x), _mm512_mul_pd(broadcast(m, 1, r), y)),
                         _mm512_add_pd(_mm512_mul_pd(broadcast(m, 2, r), z), broadcast(m, 3, r)));
}

// roundHalfAwayFromZero per lane (|x| < 2^52): the truncation and the fraction are exact.
ZCHECK_TARGET_AVX512 inline __m512i roundHalfAwayFromZero(__m512d x)
{
    const __m512i t = _mm512_cvttpd_epi64(x);
    const __m512d fraction = _mm512_sub_pd(x, _mm512_cvtepi64_pd(t));
    const __mmask8 up = _mm512_cmp_pd_mask(fraction, _mm512_set1_pd(0.5), _CMP_GE_OQ);
    const __mmask8 down = _mm512_cmp_pd_mask(fraction, _mm512_set1_pd(-0.5), _CMP_LE_OQ);
    const __m512i one = _mm512_set1_epi64(1);
    const __m512i roundedUp = _mm512_mask_add_epi64(t, up, t, one);
    return _mm512_mask_sub_epi64(roundedUp, down, roundedUp, one);
}

// The vertex stage for vertices v .. v+7 at once: clip space, outcodes and stored vertices
// exactly as clipOf, Viewport::outcode, snapVertex and StoredVertex compute them one by one
// (glm's order of operations for a matrix times a vector and for a dot product). Not for the
// fault that interpolates eye-z (snapVertex's z is then another quantity).
ZCHECK_TARGET_AVX512 void snapEight(const Viewport& vp, const glm::vec3* positions, std::size_t v, StoredVertex* stored)
{
    static_assert(sizeof(glm::vec3) == 12, "positions are three packed floats");
    const float* xyz = reinterpret_cast<const float*>(positions + v);
    const __m512 first16 = _mm512_loadu_ps(xyz);
    const __m512 last8 = _mm512_zextps256_ps512(_mm256_loadu_ps(xyz + 16));
    __m512d p[3];
    for (int k = 0; k < 3; ++k) {
        const __m512i corner = _mm512_add_epi32(_mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 21, 18, 15, 12, 9, 6, 3, 0),
                                                _mm512_set1_epi32(k));
        p[k] = _mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_permutex2var_ps(first16, corner, last8)));
    }
    __m512d clip[4];
    for (int r = 0; r < 4; ++r) clip[r] = transformRow(vp.clipFromWorld, r, p[0], p[1], p[2]);
    // Outcodes: plane · pClip < 0, the dot product as glm's (t.x + t.y) + (t.z + t.w).
    __m512i code = _mm512_setzero_si512();
    for (int k = 0; k < vp.planes.size; ++k) {
        const glm::dvec4& plane = vp.planes.plane[k];
        const __m512d dot = _mm512_add_pd(
            _mm512_add_pd(_mm512_mul_pd(_mm512_set1_pd(plane.x), clip[0]), _mm512_mul_pd(_mm512_set1_pd(plane.y), clip[1])),
            _mm512_add_pd(_mm512_mul_pd(_mm512_set1_pd(plane.z), clip[2]), _mm512_mul_pd(_mm512_set1_pd(plane.w), clip[3])));
        code = _mm512_mask_or_epi64(code, _mm512_cmp_pd_mask(dot, _mm512_setzero_pd(), _CMP_LT_OQ), code,
                                    _mm512_set1_epi64(std::int64_t(1) << k));
    }
    // Divide, viewport, image rows top-down, snap (snapVertex); lanes outside a plane are
    // computed too and then replaced (StoredVertex::outside).
    __m512d ndc[3];
    for (int k = 0; k < 3; ++k) ndc[k] = _mm512_div_pd(clip[k], clip[3]);
    const __m512d windowX = transformRow(vp.windowFromNdc, 0, ndc[0], ndc[1], ndc[2]);
    const __m512d windowY = transformRow(vp.windowFromNdc, 1, ndc[0], ndc[1], ndc[2]);
    const __m512d windowZ = transformRow(vp.windowFromNdc, 2, ndc[0], ndc[1], ndc[2]);
    const __m512d imageY = vp.camera.convention().windowOriginTop
                               ? windowY
                               : _mm512_sub_pd(_mm512_set1_pd(double(vp.camera.height())), windowY);
    const __m512d limit = _mm512_set1_pd(2 * kMaxImageCoordinate);
    const __mmask8 inside = _mm512_cmpeq_epi64_mask(code, _mm512_setzero_si512());
    const __mmask8 valid = inside & _mm512_cmp_pd_mask(_mm512_abs_pd(windowX), limit, _CMP_LT_OQ) &
                           _mm512_cmp_pd_mask(_mm512_abs_pd(imageY), limit, _CMP_LT_OQ);
    const __m512d subpixel = _mm512_set1_pd(double(kSubpixel));
    const __m512i X = roundHalfAwayFromZero(_mm512_mul_pd(windowX, subpixel));
    const __m512i Y = roundHalfAwayFromZero(_mm512_mul_pd(imageY, subpixel));
    // StoredVertex: snapped {z, X, Y}; not snappable {0, INT32_MIN, 0}; outside {0, INT32_MIN, outcode}.
    const __m512i notSnapped = _mm512_set1_epi64(std::int64_t(std::uint32_t(INT32_MIN)));
    const __m512i xy = _mm512_mask_or_epi64(_mm512_or_si512(notSnapped, _mm512_slli_epi64(code, 32)), valid,
                                            _mm512_and_si512(X, _mm512_set1_epi64(0xFFFFFFFF)), _mm512_slli_epi64(Y, 32));
    const __m512d z = _mm512_maskz_mov_pd(valid, windowZ);
    const __m512d xyAsDouble = _mm512_castsi512_pd(xy);
    double* out = reinterpret_cast<double*>(stored + v);
    _mm512_storeu_pd(out, _mm512_permutex2var_pd(z, _mm512_set_epi64(11, 3, 10, 2, 9, 1, 8, 0), xyAsDouble));
    _mm512_storeu_pd(out + 8, _mm512_permutex2var_pd(z, _mm512_set_epi64(15, 7, 14, 6, 13, 5, 12, 4), xyAsDouble));
}

// The prepare stage's loop body for triangles p .. p+7 at once: the bin items of those whose
// vertices all lie inside every clip plane, appended in submission order with the boxes
// coveredBox gives (the same int64 area, the same int32 box arithmetic); those wholly outside
// one plane are skipped. Returns false, appending nothing, when one of the eight needs
// clipping: the scalar loop then takes all eight, so that the order of items stays. Outcodes
// come from the stored vertices (StoredVertex::outside).
static_assert(sizeof(glm::uvec3) == 12 && sizeof(StoredVertex) == 16 && offsetof(StoredVertex, X) == 8 &&
                  offsetof(StoredVertex, Y) == 12,
              "the gathers' strides and offsets");
ZCHECK_TARGET_AVX512 bool binItemsOfEight(const Viewport& vp, const glm::uvec3* triangles, std::uint32_t p,
                                           const StoredVertex* snapped, std::vector<BinItem>& items)
{
    // The eight triangles' 24 vertex indices, loaded as they lie and dealt out by corner.
    const int* corners = reinterpret_cast<const int*>(triangles + p);
    const __m512i indices0to15 = _mm512_loadu_si512(corners);
    const __m512i indices16to23 = _mm512_zextsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(corners + 16)));
    // X and Y of each corner, one 64-bit gather (X in the low half); a vertex not snapped
    // (X = INT32_MIN) holds its outcode in Y (StoredVertex).
    const char* xyBase = reinterpret_cast<const char*>(snapped) + offsetof(StoredVertex, X);
    const __m256i notSnapped = _mm256_set1_epi32(INT32_MIN);
    __m256i X[3], Y[3];
    __m256i orCodes = _mm256_setzero_si256(), andCodes = _mm256_set1_epi32(-1);
    __mmask8 snappedAll = 0xFF;
    for (int k = 0; k < 3; ++k) {
        const __m512i corner = _mm512_add_epi32(_mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 21, 18, 15, 12, 9, 6, 3, 0),
                                                _mm512_set1_epi32(k));
        const __m256i vertex = _mm512_castsi512_si256(_mm512_permutex2var_epi32(indices0to15, corner, indices16to23));
        const __m512i xy = _mm512_i64gather_epi64(_mm512_slli_epi64(_mm512_cvtepu32_epi64(vertex), 1), xyBase, 8);
        X[k] = _mm512_cvtepi64_epi32(xy), Y[k] = _mm512_cvtepi64_epi32(_mm512_srli_epi64(xy, 32));
        const __mmask8 isSnapped = _mm256_cmpneq_epi32_mask(X[k], notSnapped);
        const __m256i code = _mm256_maskz_mov_epi32(__mmask8(~isSnapped), Y[k]);
        orCodes = _mm256_or_si256(orCodes, code), andCodes = _mm256_and_si256(andCodes, code);
        snappedAll &= isSnapped;
    }
    const __mmask8 inside = _mm256_cmpeq_epi32_mask(orCodes, _mm256_setzero_si256());
    const __mmask8 outsideOne = _mm256_test_epi32_mask(andCodes, andCodes);
    if (__mmask8(~(inside | outsideOne))) return false;  // one needs clipping
    __mmask8 keep = inside & snappedAll;
    // coveredBox's twice signed area, in int64.
    __m512i wide[3][2];  // [corner][X, Y]
    for (int k = 0; k < 3; ++k) wide[k][0] = _mm512_cvtepi32_epi64(X[k]), wide[k][1] = _mm512_cvtepi32_epi64(Y[k]);
    const __m512i area2 = _mm512_sub_epi64(
        _mm512_mullo_epi64(_mm512_sub_epi64(wide[1][0], wide[0][0]), _mm512_sub_epi64(wide[2][1], wide[0][1])),
        _mm512_mullo_epi64(_mm512_sub_epi64(wide[1][1], wide[0][1]), _mm512_sub_epi64(wide[2][0], wide[0][0])));
    keep &= _mm512_test_epi64_mask(area2, area2);
    // coveredBox's box: firstCentre (lo + 127) >> 8 and lastCentre (hi − 128) >> 8, inside the image.
    const __m256i zero = _mm256_setzero_si256();
    const __m256i firstOffset = _mm256_set1_epi32(int(kSubpixel - 1 - kHalfPixel)), lastOffset = _mm256_set1_epi32(int(kHalfPixel));
    constexpr int kBits = RasterRenderer::kSubpixelBits;
    const __m256i firstCol = _mm256_max_epi32(zero, _mm256_srai_epi32(_mm256_add_epi32(_mm256_min_epi32(_mm256_min_epi32(X[0], X[1]), X[2]), firstOffset), kBits));
    const __m256i lastCol = _mm256_min_epi32(_mm256_set1_epi32(vp.width - 1), _mm256_srai_epi32(_mm256_sub_epi32(_mm256_max_epi32(_mm256_max_epi32(X[0], X[1]), X[2]), lastOffset), kBits));
    const __m256i firstRow = _mm256_max_epi32(zero, _mm256_srai_epi32(_mm256_add_epi32(_mm256_min_epi32(_mm256_min_epi32(Y[0], Y[1]), Y[2]), firstOffset), kBits));
    const __m256i lastRow = _mm256_min_epi32(_mm256_set1_epi32(vp.height - 1), _mm256_srai_epi32(_mm256_sub_epi32(_mm256_max_epi32(_mm256_max_epi32(Y[0], Y[1]), Y[2]), lastOffset), kBits));
    alignas(32) int minCol[8], maxCol[8], minRow[8], maxRow[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(minCol), firstCol);
    _mm256_store_si256(reinterpret_cast<__m256i*>(maxCol), lastCol);
    _mm256_store_si256(reinterpret_cast<__m256i*>(minRow), firstRow);
    _mm256_store_si256(reinterpret_cast<__m256i*>(maxRow), lastRow);
    keep &= _mm256_cmple_epi32_mask(firstCol, lastCol) & _mm256_cmple_epi32_mask(firstRow, lastRow);
    for (unsigned bits = keep; bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        items.push_back({p + std::uint32_t(k), {minCol[k], maxCol[k], minRow[k], maxRow[k]}});
    }
    return true;
}
ZCHECK_INTRINSICS_END
#endif

// Whether the vector kernels run (the clean chain's pixels eight at a time, the set-up of
// eight triangles at a time): kernel_choice.h, ZCHECK_RASTER_KERNEL=scalar|auto.
bool useVectorKernels() { return useAvx512Form("ZCHECK_RASTER_KERNEL", "scalar"); }

glm::dvec4 clipOf(const Viewport& vp, const glm::vec3& position)
{
    return vp.clipFromWorld * glm::dvec4(glm::dvec3(position), 1.0);
}

// The vertex stage: every vertex to clip space in double and its stored vertex (snapped
// where inside every clip plane, StoredVertex::outside with its outcode where not): eight at
// a time with `vector` (snapEight; the caller checks its condition), one at a time
// otherwise. Writes every element of `stored`, which is resized uninitialised.
void vertexStage(const Viewport& vp, const std::vector<glm::vec3>& positions, bool vector, LargeVector<StoredVertex>& stored)
{
    stored.resize(positions.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 4096), [&](const auto& range) {
        std::size_t v = range.begin();
#ifdef ZCHECK_X86_AVX512
        if (vector)
            for (; v + 8 <= range.end(); v += 8) snapEight(vp, positions.data(), v, stored.data());
#else
        (void)vector;
#endif
        for (; v != range.end(); ++v) {
            const glm::dvec4 pClip = clipOf(vp, positions[v]);
            const unsigned code = vp.outcode(pClip);
            stored[v] = code == 0 ? StoredVertex::from(snapVertex(vp, pClip)) : StoredVertex::outside(code);
        }
    });
}

}  // namespace

std::vector<RasterVertexForTesting> rasterVertexStageForTesting(const Scene& scene, const Camera& camera,
                                                                const RasterFaults& faults, bool vector)
{
    const Viewport vp(camera, faults);
    LargeVector<StoredVertex> stored;
    vertexStage(vp, scene.positions, vector && useVectorKernels() && !faults.screenLinearEyeZ, stored);
    std::vector<RasterVertexForTesting> out(stored.size());
    for (std::size_t v = 0; v < stored.size(); ++v) out[v] = {stored[v].outcode(), stored[v].X, stored[v].Y, stored[v].z};
    return out;
}

RasterRenderer::RasterRenderer(const Scene& scene) : scene_(scene) { validateScene(scene); }

// One camera's set-up: vertices snapped, triangles set up and binned into tiles. The camera
// and faults are the frame's own copies (the Viewport refers to them).
struct RasterFrame::Impl {
    // keyCodes > 0: depth keys of that many steps instead of the format's (tests only).
    Impl(const Scene& s, const Camera& c, const RasterFaults& f, double keyCodes = 0)
        : scene(s), camera(c), faults(f), vp(camera, faults),
          keys(keyCodes > 0 ? DepthKeys::withCodes(keyCodes) : DepthKeys(camera.depth().format)),
          clearKey(keys.keyOfStored(camera.clearDepth())), vectorKernels(useVectorKernels()),
          vectorDraw(vectorKernels && !vp.pixelFaults)
    {
    }

    glm::dvec4 clipOf(std::uint32_t v) const { return zcheck::clipOf(vp, scene.positions[v]); }
    void prepare();
    void drawTile(int tile, double* windowDepth, std::uint32_t* primitive, std::size_t stride,
                  RasterFrame::Stores stores) const;

    const Scene& scene;
    const Camera camera;
    const RasterFaults faults;
    const Viewport vp;
    const DepthKeys keys;
    const double clearKey;
    const bool vectorKernels;  // useVectorKernels: binItemsOfEight, and for the clean chain
    const bool vectorDraw;     // drawInTileAvx512
    LargeVector<StoredVertex> snapped;  // per vertex: snapped, or its outcode (StoredVertex)
    std::vector<Chunk> chunks;
};

void RasterFrame::Impl::prepare()
{
    // Vertices to clip space in double, their outcodes, and those inside every clip plane
    // snapped once (a vertex outside one is snapped only where clipping made it).
    vertexStage(vp, scene.positions, vectorKernels && !faults.screenLinearEyeZ, snapped);

    // Set-up and binning, one fixed-size chunk of triangles per task.
    const std::size_t triangleCount = scene.triangles.size();
    if (triangleCount >= kClippedBit) throw Error("the raster route draws at most 2^31 - 1 triangles");
    constexpr std::size_t kChunkTriangles = RasterRenderer::kChunkTriangles;
    chunks.resize((triangleCount + kChunkTriangles - 1) / kChunkTriangles);
    tbb::parallel_for(std::size_t(0), chunks.size(), [&](std::size_t c) {
        Chunk& chunk = chunks[c];
        const std::size_t first = c * kChunkTriangles, last = std::min(triangleCount, first + kChunkTriangles);
        // The worker's own list, kept from chunk to chunk and frame to frame: a new one per chunk
        // (~330 KB) was memory the C library mapped afresh, ~110 page faults of a cold frame's
        // 430 (the raster ~1.5 ms faster cold in process).
        static thread_local std::vector<BinItem> items;
        items.clear();
        items.reserve(last - first);
        auto setUp = [&](std::size_t p) {
            const glm::uvec3& tri = scene.triangles[p];
            const StoredVertex &a = snapped[tri[0]], &b = snapped[tri[1]], &c = snapped[tri[2]];
            const unsigned codeA = a.outcode(), codeB = b.outcode(), codeC = c.outcode();
            if (codeA & codeB & codeC) return;  // wholly outside one plane
            if ((codeA | codeB | codeC) == 0) {
                PixelBox box;
                std::int64_t area2;
                if (coveredBox(vp, a.snapped(), b.snapped(), c.snapped(), box, area2))
                    items.push_back({std::uint32_t(p), box});
                return;
            }
            const std::size_t before = chunk.clipped.size();
            setupClippedPrimitive(vp, clipOf(tri[0]), clipOf(tri[1]), clipOf(tri[2]), std::uint32_t(p), chunk.clipped);
            for (std::size_t k = before; k < chunk.clipped.size(); ++k)
                items.push_back({kClippedBit | std::uint32_t(k), chunk.clipped[k].box});
        };
        std::size_t p = first;
#ifdef ZCHECK_X86_AVX512
        if (vectorKernels)
            for (; p + 8 <= last; p += 8)
                if (!binItemsOfEight(vp, scene.triangles.data(), std::uint32_t(p), snapped.data(), items))
                    for (std::size_t q = p; q < p + 8; ++q) setUp(q);
#endif
        for (; p < last; ++p) setUp(p);
        binChunk(vp, items, chunk);
    });
}

// Inside a tile, chunks and their triangles in submission order. A triangle that needed no
// clipping is set up again from its snapped vertices.
void RasterFrame::Impl::drawTile(int tile, double* windowDepth, std::uint32_t* primitive, std::size_t stride,
                                 RasterFrame::Stores stores) const
{
    const PixelRect rect = vp.tiles.rect(tile);
    const int col0 = rect.col0, row0 = rect.row0, col1 = rect.col1 - 1, row1 = rect.row1 - 1;  // inclusive
    TriangleSetup t;
    TileBuffer tileBuffer;
    tileBuffer.col0 = col0, tileBuffer.row0 = row0;
    std::fill(std::begin(tileBuffer.key), std::end(tileBuffer.key), clearKey);
    std::fill(std::begin(tileBuffer.primitive), std::end(tileBuffer.primitive), kNoPrimitive);
    auto draw = [&](const TriangleSetup& setup) {
#ifdef ZCHECK_X86_AVX512
        if (vectorDraw) return drawInTileAvx512(camera.depth(), keys, setup, col0, row0, col1, row1, tileBuffer);
#endif
        vp.pixelFaults ? drawInTile<true>(vp, keys, setup, col0, row0, col1, row1, tileBuffer)
                       : drawInTile<false>(vp, keys, setup, col0, row0, col1, row1, tileBuffer);
    };
    // The corners an entry reads (its index triple, then its three snapped vertices) asked for
    // ahead: each is a load that misses as often as not (a tile's entries come from a few runs
    // of the mesh, in submission order), and the loop waited on them (the raster ~4 % faster).
    constexpr std::uint32_t kIndicesAhead = 16, kVerticesAhead = 8;
    for (const Chunk& chunk : chunks)
        for (std::uint32_t k = chunk.tileStart[tile], end = chunk.tileStart[tile + 1]; k < end; ++k) {
            if (k + kIndicesAhead < end && !(chunk.binned[k + kIndicesAhead] & kClippedBit))
                __builtin_prefetch(&scene.triangles[chunk.binned[k + kIndicesAhead]]);
            if (k + kVerticesAhead < end && !(chunk.binned[k + kVerticesAhead] & kClippedBit)) {
                const glm::uvec3& ahead = scene.triangles[chunk.binned[k + kVerticesAhead]];
                for (int corner = 0; corner < 3; ++corner) __builtin_prefetch(&snapped[ahead[corner]]);
            }
            const std::uint32_t entry = chunk.binned[k];
            if (entry & kClippedBit) {
                draw(chunk.clipped[entry & ~kClippedBit]);
            } else {
                const glm::uvec3& tri = scene.triangles[entry];
                // Always true (binning took only triangles coveredBox accepted); never draw a stale set-up.
                if (setupFromSnapped(vp, snapped[tri[0]].snapped(), snapped[tri[1]].snapped(), snapped[tri[2]].snapped(),
                                     entry, t))
                    draw(t);
            }
        }
    for (int row = row0; row <= row1; ++row) {
        const int from = (row - row0) * TileBuffer::kSide, count = col1 - col0 + 1;
        double* depthTo = windowDepth + std::size_t(row - row0) * stride;
        std::uint32_t* primitiveTo = primitive + std::size_t(row - row0) * stride;
        if (stores == RasterFrame::Stores::Cached) {
            for (int k = 0; k < count; ++k) depthTo[k] = keys.value(tileBuffer.key[from + k]);
            std::copy_n(tileBuffer.primitive + from, count, primitiveTo);
        } else {
            double depth[TileBuffer::kSide];
            for (int k = 0; k < count; ++k) depth[k] = keys.value(tileBuffer.key[from + k]);
            copyRowStreaming(depth, std::size_t(count), depthTo);
            copyRowStreaming(tileBuffer.primitive + from, std::size_t(count), primitiveTo);
        }
    }
    if (stores == RasterFrame::Stores::Streaming) finishStreamingCopies();
}

RasterFrame::RasterFrame(const Scene& scene, const Camera& camera, const RasterFaults& faults)
    : RasterFrame(std::make_unique<Impl>(scene, camera, faults))
{
}

RasterFrame::RasterFrame(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) { impl_->prepare(); }

RasterFrame::~RasterFrame() = default;

const TileGrid& RasterFrame::tiles() const { return impl_->vp.tiles; }

void RasterFrame::drawTile(int tile, double* windowDepth, std::uint32_t* primitive, std::size_t stride,
                           Stores stores) const
{
    impl_->drawTile(tile, windowDepth, primitive, stride, stores);
}

RasterFrame RasterRenderer::prepare(const Camera& camera, const RasterFaults& faults) const
{
    if (faults.otherDepthMapping && camera.spec().projection.type != ProjectionType::Matrix) {
        CameraSpec other = camera.spec();
        other.depth.reversed = !other.depth.reversed;
        RasterFaults rest = faults;
        rest.otherDepthMapping = false;
        return RasterFrame(scene_, Camera(other), rest);
    }
    return RasterFrame(scene_, camera, faults);
}

namespace {

// Every tile of `frame`, drawn in parallel into a render of its camera's size (with streaming
// stores: the raster ~4 % faster when its buffers are reused, the same on fresh ones).
RenderResult drawnFrame(const RasterFrame& frame, int W, int H)
{
    RenderResult result = RenderResult::allocated(W, H);  // drawTile writes every pixel
    tbb::parallel_for(0, frame.tiles().count(), [&](int tile) {
        const std::size_t first = frame.tiles().firstPixel(tile);
        frame.drawTile(tile, result.windowDepth.value.data() + first, result.primitiveId.data() + first, std::size_t(W),
                       RasterFrame::Stores::Streaming);
    });
    return result;
}

}  // namespace

RenderResult RasterRenderer::render(const Camera& camera, const RasterFaults& faults) const
{
    const auto start = Clock::now();
    RenderResult result = drawnFrame(prepare(camera, faults), camera.width(), camera.height());
    result.renderMilliseconds =
        millisecondsSince(start);
    return result;
}

// The frame drawn with depth keys of 2^52 steps: window depth to within 2^-52 before the
// format quantizes it, so that tests can compare the kernels' depth arithmetic where a
// last-bit difference would almost never survive the format.
struct RasterFrameTesting {
    static RenderResult renderWithFineKeys(const Scene& scene, const Camera& camera)
    {
        const RasterFrame frame(std::make_unique<RasterFrame::Impl>(scene, camera, RasterFaults{}, 4503599627370496.0));
        return drawnFrame(frame, camera.width(), camera.height());
    }
};

RenderResult rasterRenderWithFineKeysForTesting(const Scene& scene, const Camera& camera)
{
    return RasterFrameTesting::renderWithFineKeys(scene, camera);
}

}  // namespace zcheck
