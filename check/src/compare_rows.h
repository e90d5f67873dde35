#pragma once
// Private to zcheck_check (check/src/): the comparison's row pass, as its tile driver
// (compare.cpp: TileComparison, compareRoutes) hands a tile's row to the row kernels
// (compare_rows.cpp) and reads back what they found; and what both measure, written once.
//
// A row is n ≤ kLanes pixels of one tile, pixel j at entry j of each array of RowInputs. Its
// lane pass comes in three forms (kernel_choice.h), chosen once per call of the driver
// (PixelJudge::form): rowLanesBaseline, lane loops compiled for the build's baseline, and
// rowLanesAvx2 and rowLanesAvx512, one template over a lane type (lanes.h), eight lanes at a
// time. All instantiate the one tolerance rule (PixelJudge::ToleranceTerms) with the same IEEE
// operations in the same order, so their RowLanes, the row's per-pixel results and the values
// given to the keepers are the same bits; the driver does everything else (the bias sum and the
// pixels off the common case, in scan order).
//
// Thread-safety: a lane pass writes only its RowLanes, the row's entries of the per-pixel
// arrays and the calling thread's StatisticCounts; rows of different tiles may be passed from
// several threads at once.
//
// The kernels and kNoAllowance, which the two files share as symbols, have hidden visibility
// (they are no part of zcheck's interface): the driver calls the kernels directly, not through
// the PLT of a shared object that links this library (the Python module), and takes
// kNoAllowance's address without the GOT, as when all of it was one file.
#include "zcheck/camera_rays.h"
#include "zcheck/compare.h"
#include "zcheck/detail/kernel_choice.h"
#include "percentile.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace zcheck {

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
    // (d_raster − d_ray)/q as inQuanta takes it, of which the statistics take the absolute value.
    static double signedErrorQuanta(double rayDepth, double rasterDepth, double q) { return inQuanta(rasterDepth - rayDepth, q); }
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

// A tile's row, as its lane pass (rowLanesBaseline, rowLanesAvx2, rowLanesAvx512) reads it: n ≤ kLanes
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
    // The vector forms only: where these are given, they compute the three arrays above themselves
    // (which are then not read): the slopes from PixelJudge::slopeTableFor, the quantum one for
    // all, the relative error in closed form.
    const double* slopeTable = nullptr;  // SlopeTable::tableFor (where gatherable())
    std::uint32_t slopeTableNone = 0;
    std::optional<double> constantQuantum;
    std::optional<CameraRays::RelativeForm> relativeForm;
    PixelClass* pixelClass = nullptr;  // the row's per-pixel results, or null (none kept)
    float* errorOverTolerance = nullptr;
};

// A row's allowances where the raster side declares none. One object for the library (an
// inline variable): the vector forms tell it from the raster's own array by its address.
alignas(64) inline constexpr double kNoAllowance[kLanes] __attribute__((visibility("hidden"))) = {};

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

// Whether the vector forms can look up slopes in a table whose largest index (SlopeTable::none())
// is this itself: its gathers take signed 32-bit indices (so not for 2^31 triangles or more,
// beyond any scene a machine of today holds; the lane loops then look them up).
inline bool gatherable(std::uint32_t largestIndex) { return largestIndex < (1u << 31); }

// A row's lane pass, lane by lane: the measures and masks above; each pixel's class and ratio
// as the common case or a miss has them (the scan-order pass rewrites the others); the common
// lanes' |Δ|/q and relative errors given to the keepers. Reads the row's slope, quantum and
// relative arrays (RowInputs), never its vector-only entries.
__attribute__((visibility("hidden"))) void rowLanesBaseline(const RowInputs& in,
                                                           const PixelJudge::ToleranceTerms& terms,
                                                           StatisticCounts& counts, RowLanes& out);

#ifdef ZCHECK_X86_FORMS
// A row's surface (the triangle both routes hit, else kNoPrimitive) into `surface` (n entries),
// and, as bits, the lanes that begin a run in one slope block of the scene's `blocks` blocks:
// the run starts SlopeTable::tableForRuns takes. One function per vector form; call each only
// from code of its target (kernel_choice.h), where the processor has the form.
__attribute__((visibility("hidden"))) ZCHECK_TARGET_AVX2 std::uint64_t
surfaceAndBlockRunsAvx2(const std::uint32_t* rayPrimitive, const std::uint32_t* rasterPrimitive, int n,
                        std::uint32_t blocks, std::uint32_t* surface);
__attribute__((visibility("hidden"))) ZCHECK_TARGET_AVX512 std::uint64_t
surfaceAndBlockRunsAvx512(const std::uint32_t* rayPrimitive, const std::uint32_t* rasterPrimitive, int n,
                          std::uint32_t blocks, std::uint32_t* surface);
// rowLanesBaseline's results, bit for bit; computes the slopes, the quantum or the relative
// errors itself where RowInputs gives their vector-only entries. One function per vector form,
// as above.
__attribute__((visibility("hidden"))) ZCHECK_TARGET_AVX2 void
rowLanesAvx2(const RowInputs& in, const PixelJudge::ToleranceTerms& termsOfJudge, StatisticCounts& counts,
             RowLanes& out);
__attribute__((visibility("hidden"))) ZCHECK_TARGET_AVX512 void
rowLanesAvx512(const RowInputs& in, const PixelJudge::ToleranceTerms& termsOfJudge, StatisticCounts& counts,
               RowLanes& out);
#endif

}  // namespace zcheck
