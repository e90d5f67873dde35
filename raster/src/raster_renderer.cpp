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
#include "zcheck/detail/lanes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cmath>

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
    DepthFormat format;
    bool formatCodes;  // unorm keys are `format`'s codes (false: withCodes' own)

    explicit DepthKeys(DepthFormat f)
        : unorm(f != DepthFormat::Float32), maxCode(unorm ? unormMax(f) : 1.0), format(f), formatCodes(unorm)
    {
    }
    // Integer codes of `codes` steps whatever the format (RasterFrameTesting's fine keys).
    static DepthKeys withCodes(double codes)
    {
        DepthKeys keys(DepthFormat::Unorm24);
        keys.maxCode = codes, keys.formatCodes = false;
        return keys;
    }
    // The key of window depth d: the value it stands for (values()) is quantizeDepth(format, d), bit for bit
    // (unormCode's arithmetic, with maxCode = unormMax(format)).
    double key(double windowDepth) const
    {
        return unorm ? nearbyintNonNegative(std::clamp(windowDepth, 0.0, 1.0) * maxCode) : roundedToBinary32(windowDepth);
    }
    // The values n keys stand for, as the buffer stores them (a tile's row as it is copied into
    // the frame), the case chosen once: a format's codes through unormValue (no division).
    void values(const double* key, std::size_t n, double* out) const
    {
        if (!unorm)
            std::copy_n(key, n, out);
        else if (formatCodes)
            for (std::size_t k = 0; k < n; ++k) out[k] = unormValue(format, key[k]);
        else
            for (std::size_t k = 0; k < n; ++k) out[k] = key[k] / maxCode;
    }
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
    if (vp.faults.truncateUnorm && depth.format != DepthFormat::Float32)  // quantizeDepth's code truncated, not rounded
        return unormValue(depth.format, std::floor(windowDepth * unormMax(depth.format)));
    return quantizeDepth(depth.format, windowDepth);
}

// One tile's depth keys and primitive ids while it is drawn: kept in the worker's cache
// (48 KB), then copied into the frame once.
struct TileBuffer {
    static constexpr int kSide = RasterRenderer::kTileSize;
    // Entries past a row's last pixel that a vector kernel's group of lanes may read and write
    // back unchanged (at most 7, past the last row's: kept in the buffer).
    static constexpr int kOverrun = 8;
    int col0, row0;  // the tile's top-left pixel in the frame
    alignas(64) double key[kSide * kSide + kOverrun];
    alignas(64) std::uint32_t primitive[kSide * kSide + kOverrun];
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

#ifdef ZCHECK_X86_FORMS

// The vector kernels, written once over a lane type (lanes.h) and compiled per form below.

// drawInTile<false> with L::kLanes pixels of a row at a time: the same integer edge functions
// and the same double operations in the same order per pixel (the build forbids contracting
// them into fused multiply-adds), so its output is bit-identical to the scalar loop's. A
// triangle's pixels are distinct within a row, so lanes never depend on each other.
template <class L>
ZCHECK_ALWAYS_INLINE inline void drawInTileLanes(const DepthSettings& depth, const DepthKeys& keys, const TriangleSetup& t,
                                                 int tileCol0, int tileRow0, int tileCol1, int tileRow1, TileBuffer& out)
{
    using Real = typename L::Real;
    using Int64 = typename L::Int64;
    using Mask = typename L::Mask;
    const int col0 = std::max(t.box.minCol, tileCol0), col1 = std::min(t.box.maxCol, tileCol1);
    const int row0 = std::max(t.box.minRow, tileRow0), row1 = std::min(t.box.maxRow, tileRow1);
    // Edge function k at lane j of a group: its value at the group's first pixel + j·A_k·256;
    // a group eight pixels on adds 8·A_k·256, a row down B_k·256 (exact: what the scalar loop
    // computes as A_k·px + B_k·py + C_k, in the same wrapping int64 arithmetic).
    constexpr int kLanes = L::kLanes;  // pixels per group
    static_assert(kLanes - 1 <= TileBuffer::kOverrun, "a row's last group stays in the tile buffer");
    Int64 rowE[3], down[3], across[3];
    for (int k = 0; k < 3; ++k) {
        const std::int64_t px = col0 * kSubpixel + kHalfPixel, py = row0 * kSubpixel + kHalfPixel;
        rowE[k] = L::steps(t.A[k] * px + t.B[k] * py + t.C[k], t.A[k] * kSubpixel);
        down[k] = L::set1(std::int64_t(t.B[k] * kSubpixel)), across[k] = L::set1(std::int64_t(t.A[k] * kSubpixel * kLanes));
    }
    // A lane's pixel centre col + 0.5 (exact in double, as are its steps of kLanes); a lane is in
    // the box while its centre is left of col1 + 1.
    alignas(64) static constexpr double kCentres[8] = {0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5};
    const Real firstCentres = L::set1(double(col0)) + L::load(kCentres), boxEnd = L::set1(col1 + 1.0);
    const Real groupStep = L::set1(double(kLanes)), x0 = L::set1(t.x0), dzdx = L::set1(t.dzdx);
    const Real rangeMin = L::set1(depth.rangeMin), rangeMax = L::set1(depth.rangeMax);
    const Real maxCode = L::set1(keys.maxCode);
    const Real noFractionBits = L::set1(4503599627370496.0);  // nearbyintNonNegative's 2^52
    const typename L::Int32 primitive = L::set1(std::int32_t(t.primitive));
    const bool unorm = keys.unorm, reversed = depth.reversed;  // not read again after each store
    // One group of lanes of a row from col, e0..e2 and `centre` its lanes' edge functions and
    // centres. No branch on coverage: a group with no pixel covered changes nothing (its masks
    // are empty), and a branch on it was mispredicted often enough to cost 5 %.
    auto group = [&](double* keyRow, std::uint32_t* primitiveRow, int col, Int64 e0, Int64 e1, Int64 e2, Real centre,
                     const Real& rowDepth) ZCHECK_ALWAYS_INLINE {
        const Mask covered = (centre < boxEnd) & L::nonNegative(e0 | e1 | e2);
        const Real interpolated = rowDepth + dzdx * (centre - x0);
        const Real windowDepth = clampLanes<L>(interpolated, rangeMin, rangeMax);
        // unormCode's own clamp to [0, 1] is left out: the camera holds 0 ≤ rangeMin < rangeMax ≤ 1,
        // so it returns every clamped value unchanged (NaN and −0 included).
        const Real key = unorm ? (windowDepth * maxCode + noFractionBits) - noFractionBits
                               : L::toReal(L::toFloat(windowDepth));
        if constexpr (L::kFastMaskedStores) {
            const Real stored = L::maskedLoad(covered, keyRow + col);
            const Mask nearer = covered & (reversed ? stored < key : key < stored);
            L::maskedStore(nearer, keyRow + col, key);
            L::maskedStore(nearer, primitiveRow + col, primitive);
        } else {  // the whole group read and written back, the lanes not nearer unchanged (kOverrun)
            const Real stored = L::load(keyRow + col);
            const Mask nearer = covered & (reversed ? stored < key : key < stored);
            L::store(keyRow + col, L::select(nearer, key, stored));
            L::store(primitiveRow + col, L::select(nearer, primitive, L::load(primitiveRow + col)));
        }
    };
    // A row: the plane's depth at x0 on the row's centre line, the row's places in the tile
    // buffer, then the groups across it; rowE then moves down to the next row.
    auto drawRow = [&](int row, auto acrossTheRow) ZCHECK_ALWAYS_INLINE {
        const Real rowDepth = L::set1(t.z0 + t.dzdy * (row + 0.5 - t.y0));
        double* keyRow = out.key + (row - out.row0) * TileBuffer::kSide - out.col0;
        std::uint32_t* primitiveRow = out.primitive + (row - out.row0) * TileBuffer::kSide - out.col0;
        acrossTheRow(keyRow, primitiveRow, rowDepth);
        rowE[0] = rowE[0] + down[0], rowE[1] = rowE[1] + down[1], rowE[2] = rowE[2] + down[2];
    };
    // A box one group wide (most of a million-triangle mesh's at 1080p) in a loop of its own,
    // without the loop across the row, whose exit, after one group or two, was mispredicted row
    // after row (the raster 0.92–0.96 of its time, bench/speed-log.md).
    if (col1 - col0 < kLanes) {
        for (int row = row0; row <= row1; ++row)
            drawRow(row, [&](double* keyRow, std::uint32_t* primitiveRow, const Real& rowDepth) ZCHECK_ALWAYS_INLINE {
                group(keyRow, primitiveRow, col0, rowE[0], rowE[1], rowE[2], firstCentres, rowDepth);
            });
        return;
    }
    for (int row = row0; row <= row1; ++row)
        drawRow(row, [&](double* keyRow, std::uint32_t* primitiveRow, const Real& rowDepth) ZCHECK_ALWAYS_INLINE {
            Int64 e0 = rowE[0], e1 = rowE[1], e2 = rowE[2];
            Real centre = firstCentres;
            for (int col = col0; col <= col1; col += kLanes) {
                group(keyRow, primitiveRow, col, e0, e1, e2, centre, rowDepth);
                e0 = e0 + across[0], e1 = e1 + across[1], e2 = e2 + across[2];
                centre = centre + groupStep;
            }
        });
}

// Row r of m · (x, y, z, 1) in glm's order: (m0·x + m1·y) + (m2·z + m3·1).
template <class L>
ZCHECK_ALWAYS_INLINE inline typename L::Real transformRow(const glm::dmat4& m, int r, typename L::Real x,
                                                          typename L::Real y, typename L::Real z)
{
    return (L::set1(m[0][r]) * x + L::set1(m[1][r]) * y) + (L::set1(m[2][r]) * z + L::set1(m[3][r]));
}

// roundHalfAwayFromZero per lane, for |x| < 2^31 (the lanes StoredVertex keeps: |x| < 2^29):
// the truncation and the fraction are exact.
template <class L>
ZCHECK_ALWAYS_INLINE inline typename L::Int32 roundHalfAwayFromZero(typename L::Real x)
{
    const typename L::Int32 t = L::truncateToInt32(x);
    const typename L::Real fraction = x - L::toReal(t);
    // t + 1 where the fraction is ≥ 0.5, t − 1 where ≤ −0.5 (a mask's lanes are −1).
    return (t - L::allOnesWhere(fraction >= L::set1(0.5))) + L::allOnesWhere(fraction <= L::set1(-0.5));
}

// The vertex stage for vertices v .. v+7 at once: clip space, outcodes and stored vertices
// exactly as clipOf, Viewport::outcode, snapVertex and StoredVertex compute them one by one
// (glm's order of operations for a matrix times a vector and for a dot product). Not for the
// fault that interpolates eye-z (snapVertex's z is then another quantity).
template <class L>
ZCHECK_ALWAYS_INLINE inline void snapEightLanes(const Viewport& vp, const glm::vec3* positions, std::size_t v,
                                                StoredVertex* stored)
{
    using Real = typename L::Real;
    using Int64 = typename L::Int64;
    using Mask = typename L::Mask;
    static_assert(sizeof(glm::vec3) == 12, "positions are three packed floats");
    Real p[3];
    L::loadTriples(reinterpret_cast<const float*>(positions + v), p);
    Real clip[4];
    for (int r = 0; r < 4; ++r) clip[r] = transformRow<L>(vp.clipFromWorld, r, p[0], p[1], p[2]);
    // Outcodes: plane · pClip < 0, the dot product as glm's (t.x + t.y) + (t.z + t.w).
    const Real zero = L::zero();
    Int64 code = L::set1(std::int64_t(0));
    for (int k = 0; k < vp.planes.size; ++k) {
        const glm::dvec4& plane = vp.planes.plane[k];
        const Real dot = (L::set1(plane.x) * clip[0] + L::set1(plane.y) * clip[1]) +
                         (L::set1(plane.z) * clip[2] + L::set1(plane.w) * clip[3]);
        code = L::select(dot < zero, code | L::set1(std::int64_t(1) << k), code);
    }
    // Divide, viewport, image rows top-down, snap (snapVertex); lanes outside a plane are
    // computed too and then replaced (StoredVertex::outside).
    Real ndc[3];
    for (int k = 0; k < 3; ++k) ndc[k] = clip[k] / clip[3];
    const Real windowX = transformRow<L>(vp.windowFromNdc, 0, ndc[0], ndc[1], ndc[2]);
    const Real windowY = transformRow<L>(vp.windowFromNdc, 1, ndc[0], ndc[1], ndc[2]);
    const Real windowZ = transformRow<L>(vp.windowFromNdc, 2, ndc[0], ndc[1], ndc[2]);
    const Real imageY = vp.camera.convention().windowOriginTop ? windowY : L::set1(double(vp.camera.height())) - windowY;
    const Real limit = L::set1(2 * kMaxImageCoordinate);
    const Mask valid = L::isZero(code) & (L::abs(windowX) < limit) & (L::abs(imageY) < limit);
    const Real subpixel = L::set1(double(kSubpixel));
    const typename L::Int32 X = roundHalfAwayFromZero<L>(windowX * subpixel);
    const typename L::Int32 Y = roundHalfAwayFromZero<L>(imageY * subpixel);
    // StoredVertex: snapped {z, X, Y}; not snappable {0, INT32_MIN, 0}; outside {0, INT32_MIN, outcode}.
    const Int64 notSnapped = L::set1(std::int64_t(std::uint32_t(INT32_MIN))) | L::template shiftLeft<32>(code);
    L::storePairs(reinterpret_cast<double*>(stored + v), L::select(valid, windowZ, zero),
                  L::select(valid, L::joined(X, Y), notSnapped));
}

// coveredBox's twice signed area for eight triangles' snapped corners, in int64 (a snapped
// vertex's |X|, |Y| < 2^29: each difference fits 32 signed bits, each product 62).
template <class L>
ZCHECK_ALWAYS_INLINE inline typename L::Int64 twiceAreaLanes(const typename L::Int32 (&X)[3], const typename L::Int32 (&Y)[3])
{
    typename L::Int64 wide[3][2];  // [corner][X, Y]
    for (int k = 0; k < 3; ++k) wide[k][0] = L::widen(X[k]), wide[k][1] = L::widen(Y[k]);
    return L::multiplySmall(wide[1][0] - wide[0][0], wide[2][1] - wide[0][1]) -
           L::multiplySmall(wide[1][1] - wide[0][1], wide[2][0] - wide[0][0]);
}

// coveredBox's box for eight triangles' snapped corners: firstCentre (lo + 127) >> 8 and
// lastCentre (hi − 128) >> 8, inside the image (empty where first > last), in int32.
template <class L>
struct BoxLanes {
    typename L::Int32 minCol, maxCol, minRow, maxRow;
    typename L::Mask nonEmpty() const { return L::lessOrEqual(minCol, maxCol) & L::lessOrEqual(minRow, maxRow); }
};
template <class L>
ZCHECK_ALWAYS_INLINE inline BoxLanes<L> coveredBoxLanes(const Viewport& vp, const typename L::Int32 (&X)[3],
                                                        const typename L::Int32 (&Y)[3])
{
    using Int32 = typename L::Int32;
    const Int32 zero = L::set1(std::int32_t(0));
    const Int32 firstOffset = L::set1(std::int32_t(kSubpixel - 1 - kHalfPixel)), lastOffset = L::set1(std::int32_t(kHalfPixel));
    constexpr int kBits = RasterRenderer::kSubpixelBits;
    auto firstCentre = [&](const Int32 (&c)[3]) ZCHECK_ALWAYS_INLINE {
        return L::max(zero, L::template shiftRightArithmetic<kBits>(L::min(L::min(c[0], c[1]), c[2]) + firstOffset));
    };
    auto lastCentre = [&](const Int32 (&c)[3], int size) ZCHECK_ALWAYS_INLINE {
        return L::min(L::set1(std::int32_t(size - 1)), L::template shiftRightArithmetic<kBits>(L::max(L::max(c[0], c[1]), c[2]) - lastOffset));
    };
    return {firstCentre(X), lastCentre(X, vp.width), firstCentre(Y), lastCentre(Y, vp.height)};
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
template <class L>
ZCHECK_ALWAYS_INLINE inline bool binItemsOfEightLanes(const Viewport& vp, const glm::uvec3* triangles, std::uint32_t p,
                                                      const StoredVertex* snapped, std::vector<BinItem>& items)
{
    using Int32 = typename L::Int32;
    using Int64 = typename L::Int64;
    using Mask = typename L::Mask;
    // The eight triangles' 24 vertex indices, dealt out by corner.
    Int32 vertex[3];
    L::loadTriples(reinterpret_cast<const std::uint32_t*>(triangles + p), vertex);
    // X and Y of each corner, one 64-bit gather (X in the low half); a vertex not snapped
    // (X = INT32_MIN) holds its outcode in Y (StoredVertex).
    const char* xyBase = reinterpret_cast<const char*>(snapped) + offsetof(StoredVertex, X);
    const Int32 notSnapped = L::set1(std::int32_t(INT32_MIN)), zero = L::set1(std::int32_t(0));
    Int32 X[3], Y[3];
    Int32 orCodes = zero, andCodes = L::set1(std::int32_t(-1));
    Mask snappedAll = L::firstLanes(8);
    for (int k = 0; k < 3; ++k) {
        const Int64 xy = L::gather(xyBase, L::template shiftLeft<1>(L::widenUnsigned(vertex[k])));
        X[k] = L::lowHalves(xy), Y[k] = L::highHalves(xy);
        const Mask isSnapped = L::notEqual(X[k], notSnapped);
        const Int32 code = L::select(isSnapped, zero, Y[k]);
        orCodes = orCodes | code, andCodes = andCodes & code;
        snappedAll = snappedAll & isSnapped;
    }
    const Mask inside = L::equal(orCodes, zero);
    const Mask outsideOne = L::anyBits(andCodes);
    if (L::bits(inside | outsideOne) != 0xFF) return false;  // one needs clipping
    const BoxLanes<L> box = coveredBoxLanes<L>(vp, X, Y);
    const Mask keep = L::andNot(inside & snappedAll, L::isZero(twiceAreaLanes<L>(X, Y))) & box.nonEmpty();
    alignas(32) std::int32_t minCol[8], maxCol[8], minRow[8], maxRow[8];
    L::store(minCol, box.minCol), L::store(maxCol, box.maxCol), L::store(minRow, box.minRow), L::store(maxRow, box.maxRow);
    // The kept ones appended together (a push_back each stayed a call in the AVX2 form).
    BinItem kept[8];
    int count = 0;
    for (unsigned bits = L::bits(keep); bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        kept[count++] = {p + std::uint32_t(k), {minCol[k], maxCol[k], minRow[k], maxRow[k]}};
    }
    items.insert(items.end(), kept, kept + count);
    return true;
}

// setupFromSnapped for the eight bin entries entry[0..7] at once, each naming a triangle whose
// corners needed no clipping: out[j] is entry j's set-up where bit j of the result is set, and
// where it is not, setupFromSnapped returns false (a corner not snapped, or no pixel centre
// covered). Each lane computes what the scalar code does, in the same order: the int64 area,
// edges and biases (each product one of two 32-bit values: |X|, |Y| < 2^29), the int32 box, and
// the plane's double operations, the same IEEE operations (no contraction), so the bits agree.
template <class L>
ZCHECK_ALWAYS_INLINE inline unsigned setUpEightLanes(const Viewport& vp, const glm::uvec3* triangles, const std::uint32_t* entry,
                                                     const StoredVertex* snapped, TriangleSetup* out)
{
    using Real = typename L::Real;
    using Int32 = typename L::Int32;
    using Int64 = typename L::Int64;
    using Mask = typename L::Mask;
    alignas(32) std::uint32_t corner[3][8];  // the eight triangles' vertex indices, by corner
    for (int j = 0; j < 8; ++j) {
        const glm::uvec3& tri = triangles[entry[j]];
        corner[0][j] = tri[0], corner[1][j] = tri[1], corner[2][j] = tri[2];
    }
    const Int32 zero = L::set1(std::int32_t(0));
    const Mask all = L::firstLanes(8);
    Int32 X[3], Y[3];
    Real z[3];
    Mask valid = all;
    for (int k = 0; k < 3; ++k) {
        const Int64 record = L::template shiftLeft<1>(L::widenUnsigned(L::load(corner[k])));  // in 8-byte words
        const Int64 xy = L::gather(reinterpret_cast<const char*>(snapped) + offsetof(StoredVertex, X), record);
        X[k] = L::lowHalves(xy), Y[k] = L::highHalves(xy);
        z[k] = L::realOfBits(L::gather(snapped, record));
        valid = valid & L::notEqual(X[k], L::set1(std::int32_t(INT32_MIN)));
    }
    const Int64 area2 = twiceAreaLanes<L>(X, Y);
    const BoxLanes<L> box = coveredBoxLanes<L>(vp, X, Y);
    const unsigned drawn = L::bits(L::andNot(valid, L::isZero(area2)) & box.nonEmpty());
    if (!drawn) return 0;
    // Both windings drawn, normalised to area2 > 0: corners 1 and 2 swapped where it is negative.
    const Mask negative = L::andNot(all, L::nonNegative(area2));
    const Int32 X1 = X[1], Y1 = Y[1];
    const Real z1 = z[1];
    X[1] = L::select(negative, X[2], X1), X[2] = L::select(negative, X1, X[2]);
    Y[1] = L::select(negative, Y[2], Y1), Y[2] = L::select(negative, Y1, Y[2]);
    z[1] = L::select(negative, z[2], z1), z[2] = L::select(negative, z1, z[2]);

    alignas(64) std::int64_t A[3][8], B[3][8], C[3][8];
    for (int e = 0; e < 3; ++e) {
        const int a = e, b = (e + 1) % 3;
        const Int32 dx = X[b] - X[a], dy = Y[b] - Y[a];
        // The top-left rule: dy < 0, or dy == 0 and dx > 0.
        const Mask topLeft = L::andNot(all, L::lessOrEqual(zero, dy)) | (L::equal(dy, zero) & L::andNot(all, L::lessOrEqual(dx, zero)));
        const Int64 wideDy = L::widen(dy), wideDx = L::widen(dx);
        const Int64 c = L::multiplySmall(wideDy, L::widen(X[a])) - L::multiplySmall(wideDx, L::widen(Y[a]));
        L::store(A[e], L::widen(zero - dy));
        L::store(B[e], wideDx);
        L::store(C[e], L::select(topLeft, c, c - L::set1(std::int64_t(1))));
    }
    const Real subpixel = L::set1(double(kSubpixel));
    const Real dx1 = L::toReal(X[1] - X[0]) / subpixel, dy1 = L::toReal(Y[1] - Y[0]) / subpixel;
    const Real dx2 = L::toReal(X[2] - X[0]) / subpixel, dy2 = L::toReal(Y[2] - Y[0]) / subpixel;
    const Real dz1 = z[1] - z[0], dz2 = z[2] - z[0];
    const Real det = dx1 * dy2 - dx2 * dy1;
    alignas(64) double x0[8], y0[8], z0[8], dzdx[8], dzdy[8];
    L::store(x0, L::toReal(X[0]) / subpixel), L::store(y0, L::toReal(Y[0]) / subpixel), L::store(z0, z[0]);
    L::store(dzdx, (dz1 * dy2 - dz2 * dy1) / det), L::store(dzdy, (dx1 * dz2 - dx2 * dz1) / det);
    alignas(32) std::int32_t minCol[8], maxCol[8], minRow[8], maxRow[8];
    L::store(minCol, box.minCol), L::store(maxCol, box.maxCol), L::store(minRow, box.minRow), L::store(maxRow, box.maxRow);
    for (unsigned bits = drawn; bits; bits &= bits - 1) {
        const int j = __builtin_ctz(bits);
        TriangleSetup& t = out[j];
        for (int e = 0; e < 3; ++e) t.A[e] = A[e][j], t.B[e] = B[e][j], t.C[e] = C[e][j];
        t.x0 = x0[j], t.y0 = y0[j], t.z0 = z0[j], t.dzdx = dzdx[j], t.dzdy = dzdy[j];
        t.box = {minCol[j], maxCol[j], minRow[j], maxRow[j]};
        t.primitive = entry[j];
    }
    return drawn;
}

#endif  // ZCHECK_X86_FORMS

// The raster's vector kernels in one form; null in the baseline form (the scalar loops run).
struct RasterKernels {
    void (*draw)(const DepthSettings&, const DepthKeys&, const TriangleSetup&, int, int, int, int, TileBuffer&) = nullptr;
    void (*snapEight)(const Viewport&, const glm::vec3*, std::size_t, StoredVertex*) = nullptr;
    bool (*binItemsOfEight)(const Viewport&, const glm::uvec3*, std::uint32_t, const StoredVertex*,
                            std::vector<BinItem>&) = nullptr;
    unsigned (*setUpEight)(const Viewport&, const glm::uvec3*, const std::uint32_t*, const StoredVertex*, TriangleSetup*) = nullptr;
    // setUpEight, then draw for each entry set up, in one call of the form's code; null wherever
    // draw is: one call per eight triangles, the draw's constants made once (the `avx2` raster
    // 0.97–0.98 of its time; the `avx512` one's within its noise, median 0.987).
    void (*setUpAndDrawEight)(const Viewport&, const DepthKeys&, const glm::uvec3*, const std::uint32_t*,
                              const StoredVertex*, int, int, int, int, TileBuffer&) = nullptr;
};

#ifdef ZCHECK_X86_FORMS
// Each kernel's entry function of one form (kernel_choice.h).
#define ZCHECK_RASTER_FORM(Entry, Form, DrawLanes)                                                                     \
    Entry void drawInTile##Form(const DepthSettings& depth, const DepthKeys& keys, const TriangleSetup& t, int c0, int r0, \
                                int c1, int r1, TileBuffer& out)                                                       \
    {                                                                                                                  \
        drawInTileLanes<DrawLanes>(depth, keys, t, c0, r0, c1, r1, out);                                               \
    }                                                                                                                  \
    Entry void snapEight##Form(const Viewport& vp, const glm::vec3* positions, std::size_t v, StoredVertex* stored)    \
    {                                                                                                                  \
        snapEightLanes<Form##Lanes>(vp, positions, v, stored);                                                         \
    }                                                                                                                  \
    Entry bool binItemsOfEight##Form(const Viewport& vp, const glm::uvec3* triangles, std::uint32_t p,                 \
                                     const StoredVertex* snapped, std::vector<BinItem>& items)                         \
    {                                                                                                                  \
        return binItemsOfEightLanes<Form##Lanes>(vp, triangles, p, snapped, items);                                    \
    }                                                                                                                  \
    Entry unsigned setUpEight##Form(const Viewport& vp, const glm::uvec3* triangles, const std::uint32_t* entry,       \
                                    const StoredVertex* snapped, TriangleSetup* out)                                   \
    {                                                                                                                  \
        return setUpEightLanes<Form##Lanes>(vp, triangles, entry, snapped, out);                                       \
    }                                                                                                                  \
    Entry void setUpAndDrawEight##Form(const Viewport& vp, const DepthKeys& keys, const glm::uvec3* triangles,         \
                                       const std::uint32_t* entry, const StoredVertex* snapped, int c0, int r0, int c1, \
                                       int r1, TileBuffer& out)                                                        \
    {                                                                                                                  \
        TriangleSetup eight[8];                                                                                        \
        const DepthSettings& depth = vp.camera.depth();                                                                \
        for (unsigned bits = setUpEightLanes<Form##Lanes>(vp, triangles, entry, snapped, eight); bits; bits &= bits - 1) \
            drawInTileLanes<DrawLanes>(depth, keys, eight[__builtin_ctz(bits)], c0, r0, c1, r1, out);                  \
    }
ZCHECK_RASTER_FORM(ZCHECK_KERNEL_ENTRY_AVX2, Avx2, Avx2Lanes4)  // four pixels a group: see Avx2Lanes4
ZCHECK_RASTER_FORM(ZCHECK_KERNEL_ENTRY_AVX512, Avx512, Avx512Lanes)
#undef ZCHECK_RASTER_FORM
#endif

// The vector kernels of kernelForm() (kernel_form.h; read by each frame when it is made).
RasterKernels rasterKernels()
{
    RasterKernels kernels;  // the baseline form: none (the scalar code)
#ifdef ZCHECK_X86_FORMS
    kernels = formOf(kernelForm(), kernels, RasterKernels{&drawInTileAvx2, &snapEightAvx2, &binItemsOfEightAvx2, &setUpEightAvx2, &setUpAndDrawEightAvx2},
                     RasterKernels{&drawInTileAvx512, &snapEightAvx512, &binItemsOfEightAvx512, &setUpEightAvx512, &setUpAndDrawEightAvx512});
#endif
    return kernels;
}

glm::dvec4 clipOf(const Viewport& vp, const glm::vec3& position)
{
    return vp.clipFromWorld * glm::dvec4(glm::dvec3(position), 1.0);
}

// The vertex stage: every vertex to clip space in double and its stored vertex (snapped
// where inside every clip plane, StoredVertex::outside with its outcode where not): eight at
// a time with `snapEight` (a form's kernel; the caller checks its condition), one at a time
// where it is null. Writes every element of `stored`, which is resized uninitialised.
void vertexStage(const Viewport& vp, const std::vector<glm::vec3>& positions, decltype(RasterKernels::snapEight) snapEight,
                 LargeVector<StoredVertex>& stored)
{
    stored.resize(positions.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 4096), [&](const auto& range) {
        std::size_t v = range.begin();
        if (snapEight)
            for (; v + 8 <= range.end(); v += 8) snapEight(vp, positions.data(), v, stored.data());
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
    vertexStage(vp, scene.positions, vector && !faults.screenLinearEyeZ ? rasterKernels().snapEight : nullptr, stored);
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
          clearKey(keys.keyOfStored(camera.clearDepth())), kernels(rasterKernels())
    {
        if (vp.pixelFaults) kernels.draw = nullptr, kernels.setUpAndDrawEight = nullptr;  // the scalar loop computes the faulty depths
        if (faults.screenLinearEyeZ) kernels.snapEight = nullptr;  // snapEight is for window depth only
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
    RasterKernels kernels;  // the vector kernels of kernelForm() this frame may run (null: the scalar loops)
    LargeVector<StoredVertex> snapped;  // per vertex: snapped, or its outcode (StoredVertex)
    std::vector<Chunk> chunks;
};

void RasterFrame::Impl::prepare()
{
    // Vertices to clip space in double, their outcodes, and those inside every clip plane
    // snapped once (a vertex outside one is snapped only where clipping made it).
    vertexStage(vp, scene.positions, kernels.snapEight, snapped);

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
        if (kernels.binItemsOfEight)
            for (; p + 8 <= last; p += 8)
                if (!kernels.binItemsOfEight(vp, scene.triangles.data(), std::uint32_t(p), snapped.data(), items))
                    for (std::size_t q = p; q < p + 8; ++q) setUp(q);
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
        if (kernels.draw) return kernels.draw(camera.depth(), keys, setup, col0, row0, col1, row1, tileBuffer);
        vp.pixelFaults ? drawInTile<true>(vp, keys, setup, col0, row0, col1, row1, tileBuffer)
                       : drawInTile<false>(vp, keys, setup, col0, row0, col1, row1, tileBuffer);
    };
    // The corners an entry reads (its index triple, then its three snapped vertices) asked for
    // ahead: each is a load that misses as often as not (a tile's entries come from a few runs
    // of the mesh, in submission order), and the loop waited on them (the raster ~4 % faster).
    constexpr std::uint32_t kIndicesAhead = 16, kVerticesAhead = 8;
    TriangleSetup eight[8];
    for (const Chunk& chunk : chunks) {
        const std::uint32_t* binned = chunk.binned.data();
        const std::uint32_t end = chunk.tileStart[tile + 1];
        auto askAhead = [&](std::uint32_t k) {
            if (k + kIndicesAhead < end && !(binned[k + kIndicesAhead] & kClippedBit))
                __builtin_prefetch(&scene.triangles[binned[k + kIndicesAhead]]);
            if (k + kVerticesAhead < end && !(binned[k + kVerticesAhead] & kClippedBit)) {
                const glm::uvec3& ahead = scene.triangles[binned[k + kVerticesAhead]];
                for (int corner = 0; corner < 3; ++corner) __builtin_prefetch(&snapped[ahead[corner]]);
            }
        };
        for (std::uint32_t k = chunk.tileStart[tile]; k < end;) {
            // Eight entries that needed no clipping set up at once (a form's kernel), then drawn
            // in their order; the same set-ups as one at a time below.
            if (kernels.setUpEight && k + 8 <= end &&
                !((binned[k] | binned[k + 1] | binned[k + 2] | binned[k + 3] | binned[k + 4] | binned[k + 5] |
                   binned[k + 6] | binned[k + 7]) & kClippedBit)) {
                for (std::uint32_t j = 0; j < 8; ++j) askAhead(k + j);
                if (kernels.setUpAndDrawEight)
                    kernels.setUpAndDrawEight(vp, keys, scene.triangles.data(), binned + k, snapped.data(), col0, row0,
                                              col1, row1, tileBuffer);
                else
                    for (unsigned bits = kernels.setUpEight(vp, scene.triangles.data(), binned + k, snapped.data(), eight);
                         bits; bits &= bits - 1)
                        draw(eight[__builtin_ctz(bits)]);
                k += 8;
                continue;
            }
            askAhead(k);
            const std::uint32_t entry = binned[k++];
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
    }
    for (int row = row0; row <= row1; ++row) {
        const int from = (row - row0) * TileBuffer::kSide, count = col1 - col0 + 1;
        double* depthTo = windowDepth + std::size_t(row - row0) * stride;
        std::uint32_t* primitiveTo = primitive + std::size_t(row - row0) * stride;
        if (stores == RasterFrame::Stores::Cached) {
            keys.values(tileBuffer.key + from, std::size_t(count), depthTo);
            std::copy_n(tileBuffer.primitive + from, count, primitiveTo);
        } else {
            double depth[TileBuffer::kSide];
            keys.values(tileBuffer.key + from, std::size_t(count), depth);
            copyRowStreaming(depth, std::size_t(count), depthTo);
            copyRowStreaming(tileBuffer.primitive + from, std::size_t(count), primitiveTo);
        }
    }
    if (stores == RasterFrame::Stores::Streaming) finishStreamingCopies();
}

namespace {

// `faults` for the frame a scene is held in: a clip-from-world matrix given for the world
// (overrideClipFromWorld) moved about Scene::origin, as the camera is (cameraAboutOrigin).
RasterFaults faultsInSceneFrame(const Scene& scene, RasterFaults faults)
{
    if (faults.overrideClipFromWorld && scene.heldAboutOrigin())
        faults.clipFromWorld[3] = faults.clipFromWorld * glm::dvec4(scene.origin, 1.0);
    return faults;
}

}  // namespace

RasterFrame::RasterFrame(const Scene& scene, const Camera& camera, const RasterFaults& faults)
    : RasterFrame(std::make_unique<Impl>(scene, CameraInSceneFrame(scene, camera).get(), faultsInSceneFrame(scene, faults)))
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
        const RasterFrame frame(std::make_unique<RasterFrame::Impl>(scene, CameraInSceneFrame(scene, camera).get(), RasterFaults{}, 4503599627370496.0));
        return drawnFrame(frame, camera.width(), camera.height());
    }
};

RenderResult rasterRenderWithFineKeysForTesting(const Scene& scene, const Camera& camera)
{
    return RasterFrameTesting::renderWithFineKeys(scene, camera);
}

}  // namespace zcheck
