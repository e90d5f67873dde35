// The comparison's tile driver (compare.h: TileComparison, compareRoutes): a call's rows of its
// tiles, row by row, each row's lane pass (compare_rows.h) and then, in scan order, what depends
// on the order; the tiles' tallies merged into the report, the percentiles' keepers and their
// floors. The per-pixel rule it applies is PixelJudge's (pixel_rule.cpp).
#include "zcheck/compare.h"

#include "zcheck/camera_rays.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/detail/lane_mask.h"
#include "compare_rows.h"
#include "percentile.h"
#include "slope_table.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <vector>

namespace zcheck {

namespace {

// What one tile contributes to the report; tiles are merged in tile order, and what depends
// on scan order (the first unexplained pixels, the worst pixel among equals) is restored.
struct TileTally {
    ComparisonReport report;  // counts, maxima, worst pixel, samples, bounding box, bias samples
    double signedErrorSum = 0;
    std::int64_t quarterCounts[4] = {0, 0, 0, 0};
};

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

// What compareBody's steps share, and those of its steps that need nothing of
// TileComparison::Impl (the others follow compareBody). A tile's row is n ≤ kLanes pixels.

// The arrays a row's measures are put in for its lane pass (RowInputs), on compareBody's stack
// and reused row after row.
struct LanePassArrays {
    alignas(64) std::uint32_t surface[kLanes];  // the triangle both routes hit, else kNoPrimitive
    alignas(64) double slope[kLanes], quantum[kLanes], relative[kLanes];
};

// What does not depend on the tile, found once per call of compareBody (PixelMeasures): the
// quantum where the format gives one for every pixel, the relative error's closed form.
struct RowForms {
    std::optional<double> constantQuantum;
    std::optional<CameraRays::RelativeForm> relativeForm;
};

// One tile's row as compareBody's steps see it: pixel j (j < n) is (col0 + j, row), entry a0 + j
// of the ray's arrays, b0 + j of the raster's and i0 + j of the image's (the per-pixel results);
// the routes' primitives and depths from pixel 0 on.
struct TileRow {
    int col0, row, n;
    std::size_t a0, b0, i0;
    const std::uint32_t* rayPrimitive;
    const std::uint32_t* rasterPrimitive;
    const double* rayDepth;
    const double* rasterDepth;
};

// A tile's report as the scan-order visits of one of its rows change it, with the calling
// thread's keepers.
struct ScanOrderVisits {
    ComparisonReport& r;
    StatisticCounts& counts;
    // Whether the tile compared a pixel on depth before the one visited now: from the tile's
    // counts as the row begins (before its common lanes are tallied), then noteWorst's.
    bool comparedBefore;

    // A pixel compared on depth (agree or depth error), in scan order: whether it is the worst so
    // far (its finding is then r.worst): the first compared, or a ratio above every one before.
    // So the worst is the first pixel in scan order with the largest ratio (NaN ratios aside), and
    // a row's common-case pixels that are neither its first compared one nor the first with its
    // largest ratio can be left out without changing it.
    ZCHECK_ALWAYS_INLINE bool noteWorst(double ratio)
    {
        const bool worst = ratio > r.maxErrorOverTolerance || !comparedBefore;
        comparedBefore = true;
        if (worst) r.maxErrorOverTolerance = std::max(r.maxErrorOverTolerance, ratio);
        return worst;
    }
    // A pixel compared on depth off the common case: its count, the statistics, noteWorst.
    ZCHECK_ALWAYS_INLINE bool noteCompared(bool agree, double ratio, double errorQuanta, double relative)
    {
        agree ? ++r.agree : ++r.depthErrors;
        counts.errorQuanta.add(float(errorQuanta));
        counts.relativeEyeZ.add(float(relative));
        r.maxRelativeEyeZError = std::max(r.maxRelativeEyeZError, relative);
        r.maxErrorQuanta = std::max(r.maxErrorQuanta, errorQuanta);
        return noteWorst(ratio);
    }
};

// q of a row's lane j: the one for every pixel where the format gives it, else the row's array.
ZCHECK_ALWAYS_INLINE inline double quantumOfLane(const RowForms& forms, const LanePassArrays& arrays, std::size_t j)
{
    return forms.constantQuantum ? *forms.constantQuantum : arrays.quantum[j];
}

// Asks for the n pixels from (col0, row) of both routes' arrays (primitives and depths): a
// prefetch, nothing read.
ZCHECK_ALWAYS_INLINE inline void prefetchRow(const RoutePixels& ray, const RoutePixels& raster, int col0, int row,
                                             int n)
{
    const std::size_t aAhead = ray.at(col0, row), bAhead = raster.at(col0, row);
    for (int j = 0; j < n; j += 16) {
        __builtin_prefetch(ray.primitive + aAhead + j), __builtin_prefetch(raster.primitive + bAhead + j);
        __builtin_prefetch(ray.windowDepth + aAhead + j), __builtin_prefetch(ray.windowDepth + aAhead + j + 8);
        __builtin_prefetch(raster.windowDepth + bAhead + j);
        __builtin_prefetch(raster.windowDepth + bAhead + j + 8);
    }
}

// The larger of `start` and value k of the row's common lanes (RowLanes::largest: 0 |Δ|/q,
// 1 the relative error, 2 the ratio); `start` where no lane counts.
ZCHECK_ALWAYS_INLINE inline double maxOfCommon(const RowLanes& lanes, double start, int k)
{
    double largestValue;
    std::memcpy(&largestValue, &lanes.largest[k], sizeof largestValue);
    return lanes.largest[k] < 0 ? start : std::max(start, largestValue);
}

// The row's lanes where their order cannot matter, into the tile's report: its misses and its
// common lanes' counts and maxima.
ZCHECK_ALWAYS_INLINE inline void tallyCommonLanes(ComparisonReport& r, const RowLanes& lanes, int n)
{
    const int commons = __builtin_popcountll(lanes.common), hits = __builtin_popcountll(lanes.hit);
    const int agreeing = __builtin_popcountll(lanes.common & lanes.agree);
    r.bothMiss += n - hits;  // their class and ratio are written already
    r.bothHit += commons, r.agree += agreeing, r.depthErrors += commons - agreeing;
    r.maxErrorQuanta = maxOfCommon(lanes, r.maxErrorQuanta, 0);
    r.maxRelativeEyeZError = maxOfCommon(lanes, r.maxRelativeEyeZError, 1);
}

// The bias test's sum in scan order (its rounding depends on the order): its signed
// error, and where its exact depth falls within its quantum (the depth in quanta, inQuanta).
ZCHECK_ALWAYS_INLINE inline void sumBiasInScanOrder(TileTally& tally, const RowLanes& lanes, const TileRow& tileRow,
                                                    const RowForms& forms, const LanePassArrays& arrays)
{
    double signedErrorSum = tally.signedErrorSum;
    std::int64_t quarters[4] = {0, 0, 0, 0};
    forEachSetBit(lanes.bias, [&](std::size_t j) ZCHECK_ALWAYS_INLINE {
        signedErrorSum += lanes.signedErrorQuanta[j];
        const double position = inQuanta(tileRow.rayDepth[j], quantumOfLane(forms, arrays, j));
        ++quarters[std::clamp(int(4 * (position - std::floor(position))), 0, 3)];
    });
    tally.signedErrorSum = signedErrorSum;
    for (int k = 0; k < 4; ++k) tally.quarterCounts[k] += quarters[k];
    tally.report.biasSamples += __builtin_popcountll(lanes.bias);
}

// What is left in scan order (noteWorst), as bits: the pixels off the common case, the common
// case's depth errors (a NaN ratio is one), its first pixel when nothing was compared
// before, and its first with the row's largest ratio when that may be the worst (above
// `maxErrorOverTolerance`, the tile's so far).
ZCHECK_ALWAYS_INLINE inline std::uint64_t pixelsToVisit(const RowLanes& lanes, bool comparedBefore,
                                                        double maxErrorOverTolerance)
{
    const int commons = __builtin_popcountll(lanes.common);
    const double rowMaxRatio = maxOfCommon(lanes, -1.0, 2);
    std::uint64_t visit = (lanes.common & ~lanes.agree) | (~lanes.common & lanes.hit);
    if (commons > 0 && !comparedBefore) visit |= lanes.common & (0 - lanes.common);
    if (commons > 0 && rowMaxRatio > maxErrorOverTolerance)
        for (std::uint64_t c = lanes.common; c != 0; c &= c - 1)
            if (lanes.ratio[__builtin_ctzll(c)] == rowMaxRatio) {
                visit |= c & (0 - c);
                break;
            }
    return visit;
}

// A common-case pixel the scan-order pass visits (a depth error, or one that may be the worst):
// its counts, statistics, class and ratio came with its row's lanes; here noteWorst, and its
// finding where it is the worst so far or unexplained.
ZCHECK_ALWAYS_INLINE inline void noteCommonPixel(const TileRow& tileRow, int j, const RowLanes& lanes,
                                                 const RowForms& forms, const LanePassArrays& arrays,
                                                 ScanOrderVisits& scan)
{
    ComparisonReport& r = scan.r;
    const bool agree = lanes.agree >> j & 1;
    const PixelClass c = agree ? PixelClass::Agree : PixelClass::DepthError;  // written already
    const bool worst = scan.noteWorst(lanes.ratio[j]);
    if (agree && !worst) return;  // nothing to note: no finding is built
    PixelFinding f;
    f.col = tileRow.col0 + j, f.row = tileRow.row;
    f.rayWindowDepth = tileRow.rayDepth[j], f.rasterWindowDepth = tileRow.rasterDepth[j];
    f.rayPrimitive = f.rasterPrimitive = tileRow.rayPrimitive[j];
    f.pixelClass = c;
    f.errorQuanta = lanes.errorQuanta[j];
    f.toleranceQuanta = inQuanta(lanes.bound[j], quantumOfLane(forms, arrays, std::size_t(j)));
    if (worst) r.worst = f;
    if (!agree) noteUnexplained(r, f);
}

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
    template <KernelForm kForm>
    void compareBody(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                     const RoutePixels& raster);
    // compareBody's steps.
    template <KernelForm kForm>
    void compareTileRow(TileTally& tally, const PixelRect& rect, int row, const RoutePixels& ray,
                        const RoutePixels& raster, const RowForms& forms, LanePassArrays& arrays,
                        StatisticCounts& counts, RowLanes& lanes);
    template <KernelForm kForm>
    RowInputs lanePassInputs(const TileRow& tileRow, const RoutePixels& ray, const RoutePixels& raster,
                             const RowForms& forms, LanePassArrays& arrays) const;
    void judgeOffCommonPixel(const TileRow& tileRow, int j, const RoutePixels& ray, const RoutePixels& raster,
                             ScanOrderVisits& scan);
    void compareBaseline(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                         const RoutePixels& raster);
#ifdef ZCHECK_X86_FORMS
    ZCHECK_KERNEL_ENTRY_AVX2 void compareAvx2(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                                              const RoutePixels& raster);
    ZCHECK_KERNEL_ENTRY_AVX512 void compareAvx512(int tileBegin, int tileEnd, int rowBegin, int rowEnd,
                                                  const RoutePixels& ray, const RoutePixels& raster);
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

// Impl::compare's work, inlined into one function per form (compareBaseline, compareAvx2,
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
// Its steps (compareTileRow and what it calls) are always inlined too, so that each form
// compiles its own copy of them.
template <KernelForm kForm>
ZCHECK_ALWAYS_INLINE inline void TileComparison::Impl::compareBody(int tileBegin, int tileEnd, int rowBegin,
                                                                   int rowEnd, const RoutePixels& ray,
                                                                   const RoutePixels& raster)
{
    StatisticCounts& counts = statisticCounts.local();
    const PixelRect band = grid.rect(tileBegin);  // the rows of every tile of the call
    const int row0 = std::max(band.row0, rowBegin), row1 = std::min(band.row1, rowEnd);
    const RowForms forms{measures.constantQuantum(raster), measures.relativeForm(ray)};

    constexpr int kRowsAhead = 2;
    LanePassArrays arrays;
    RowLanes lanes;

    for (int row = row0; row < row1; ++row) {
        for (int tile = tileBegin; tile < tileEnd; ++tile) {
            const PixelRect rect = grid.rect(tile);
            // A later row's pixels asked for now, for a tile alone: its row of a full-frame image
            // is a few cache lines, too short for the hardware to see a stream, and each row began
            // with misses. (Across a band's tiles a row is one stream.)
            if (tileEnd - tileBegin == 1 && row + kRowsAhead < row1)
                prefetchRow(ray, raster, rect.col0, row + kRowsAhead, rect.col1 - rect.col0);
            compareTileRow<kForm>(tallies[std::size_t(tile)], rect, row, ray, raster, forms, arrays, counts, lanes);
        }
    }
}

// Row `row` of the tile `rect` whose tally is `tally`, compareBody's step: the row's lane pass
// (each form's own), the tally of its misses and common lanes, its bias sum, then in scan order
// the pixels pixelsToVisit picks. `arrays` and `lanes` are the call's, overwritten.
template <KernelForm kForm>
ZCHECK_ALWAYS_INLINE inline void TileComparison::Impl::compareTileRow(TileTally& tally, const PixelRect& rect,
                                                                      int row, const RoutePixels& ray,
                                                                      const RoutePixels& raster, const RowForms& forms,
                                                                      LanePassArrays& arrays, StatisticCounts& counts,
                                                                      RowLanes& lanes)
{
    ScanOrderVisits scan{tally.report, counts, tally.report.agree + tally.report.depthErrors > 0};
    const std::size_t a0 = ray.at(rect.col0, row), b0 = raster.at(rect.col0, row);
    const TileRow tileRow{rect.col0, row, rect.col1 - rect.col0,
                          a0, b0, std::size_t(row) * W + rect.col0,
                          ray.primitive + a0, raster.primitive + b0, ray.windowDepth + a0, raster.windowDepth + b0};
    const RowInputs in = lanePassInputs<kForm>(tileRow, ray, raster, forms, arrays);
#ifdef ZCHECK_X86_FORMS
    if constexpr (kForm == KernelForm::Avx2) rowLanesAvx2(in, judge.toleranceTerms(), counts, lanes);
    if constexpr (kForm == KernelForm::Avx512) rowLanesAvx512(in, judge.toleranceTerms(), counts, lanes);
#endif
    if constexpr (kForm == KernelForm::Baseline) rowLanesBaseline(in, judge.toleranceTerms(), counts, lanes);

    tallyCommonLanes(tally.report, lanes, tileRow.n);
    sumBiasInScanOrder(tally, lanes, tileRow, forms, arrays);
    // The pixels to visit (a few per row, mostly none), in scan order.
    forEachSetBit(pixelsToVisit(lanes, scan.comparedBefore, tally.report.maxErrorOverTolerance),
                  [&](std::size_t j) ZCHECK_ALWAYS_INLINE {
                      if (lanes.common >> j & 1)  // tallied already
                          noteCommonPixel(tileRow, int(j), lanes, forms, arrays, scan);
                      else
                          judgeOffCommonPixel(tileRow, int(j), ray, raster, scan);
                  });
}

// The lane pass's inputs for a tile's row: its pixels, and its slopes, quanta and relative
// errors put in `arrays`, except those the vector forms compute themselves (RowInputs); its
// surface in `arrays` in every form.
template <KernelForm kForm>
ZCHECK_ALWAYS_INLINE inline RowInputs TileComparison::Impl::lanePassInputs(const TileRow& tileRow,
                                                                          const RoutePixels& ray,
                                                                          const RoutePixels& raster,
                                                                          [[maybe_unused]] const RowForms& forms,
                                                                          LanePassArrays& arrays) const
{
    const int n = tileRow.n;
    RowInputs in;
    in.rayPrimitive = tileRow.rayPrimitive, in.rasterPrimitive = tileRow.rasterPrimitive, in.surface = arrays.surface;
    in.rayDepth = tileRow.rayDepth, in.rasterDepth = tileRow.rasterDepth;
    in.slope = arrays.slope, in.quantum = arrays.quantum, in.relative = arrays.relative, in.n = n;
    in.allowance = raster.allowance ? raster.allowance + tileRow.b0 : kNoAllowance;
#ifdef ZCHECK_X86_FORMS
    if constexpr (kForm != KernelForm::Baseline) {
        const SlopeTable* table = judge.slopeTable();
        const std::uint32_t blocks = table ? table->blockCount() : 0;
        const std::uint64_t blockRuns =
            kForm == KernelForm::Avx2
                ? surfaceAndBlockRunsAvx2(tileRow.rayPrimitive, tileRow.rasterPrimitive, n, blocks, arrays.surface)
                : surfaceAndBlockRunsAvx512(tileRow.rayPrimitive, tileRow.rasterPrimitive, n, blocks, arrays.surface);
        if (table && gatherable(table->none()))
            in.slopeTable = table->tableForRuns(arrays.surface, blockRuns), in.slopeTableNone = table->none();
        in.constantQuantum = forms.constantQuantum, in.relativeForm = forms.relativeForm;
    }
#endif
    if constexpr (kForm == KernelForm::Baseline)
        for (int j = 0; j < n; ++j) {
            const bool common =
                tileRow.rayPrimitive[j] != kNoPrimitive && tileRow.rayPrimitive[j] == tileRow.rasterPrimitive[j];
            arrays.surface[j] = common ? tileRow.rayPrimitive[j] : kNoPrimitive;
        }
    if (!in.slopeTable) slopesOf(judge, arrays.surface, std::size_t(n), arrays.slope);
    if (!in.constantQuantum) measures.quanta(ray, raster, tileRow.a0, tileRow.b0, std::size_t(n), arrays.quantum);
    if (!in.relativeForm)
        measures.relativeEyeZErrors(ray, raster, tileRow.a0, tileRow.b0, tileRow.col0, tileRow.row, std::size_t(n),
                                    arrays.relative);
    in.pixelClass = perPixel ? perPixel->pixelClass.data() + tileRow.i0 : nullptr;
    in.errorOverTolerance = perPixel ? perPixel->errorOverTolerance.data() + tileRow.i0 : nullptr;
    return in;
}

// Pixel j of a tile's row off the common case (both routes hit, different triangles; or one
// route only), through PixelJudge's rule: its class (kept per pixel), its counts, noteCompared
// where it is compared on depth, and its finding where it is unexplained or the worst so far.
ZCHECK_ALWAYS_INLINE inline void TileComparison::Impl::judgeOffCommonPixel(const TileRow& tileRow, int j,
                                                                          const RoutePixels& ray,
                                                                          const RoutePixels& raster,
                                                                          ScanOrderVisits& scan)
{
    ComparisonReport& r = scan.r;
    const int col = tileRow.col0 + j, row = tileRow.row;
    const std::size_t a = tileRow.a0 + std::size_t(j), b = tileRow.b0 + std::size_t(j), i = tileRow.i0 + std::size_t(j);
    const std::uint32_t rayPrimitive = tileRow.rayPrimitive[j], rasterPrimitive = tileRow.rasterPrimitive[j];
    const bool rayHit = rayPrimitive != kNoPrimitive, rasterHit = rasterPrimitive != kNoPrimitive;
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
        const double q = measures.quantum(ray, raster, a, b);
        const double error = std::abs(f.rasterWindowDepth - f.rayWindowDepth);
        double bound = 0;
        f.pixelClass = judge.bothHit(f.rayWindowDepth, f.rayPrimitive, f.rasterWindowDepth, f.rasterPrimitive, q,
                                     pWindow, bound, raster.allowance ? raster.allowance[b] : 0.0);
        f.errorQuanta = std::abs(PixelMeasures::signedErrorQuanta(ray.windowDepth[a], raster.windowDepth[b], q));
        const double ratio = ratioOf(error, bound);
        auto withTolerance = [&](PixelFinding& finding) -> PixelFinding& {  // a finding kept
            finding.toleranceQuanta = inQuanta(bound, q);
            return finding;
        };
        if (f.pixelClass == PixelClass::EdgeSurface) {
            ++r.edgeSurface;
        } else {
            if (perPixel) perPixel->errorOverTolerance[i] = static_cast<float>(ratio);
            if (scan.noteCompared(f.pixelClass == PixelClass::Agree, ratio, f.errorQuanta,
                                  measures.relativeEyeZError(ray, raster, a, b, col, row)))
                r.worst = withTolerance(f);
        }
        if (f.pixelClass == PixelClass::DepthError) withTolerance(f);
    } else {
        // Coverage mismatch: only one route sees a surface (PixelJudge::oneHit).
        rayHit ? ++r.rayOnly : ++r.rasterOnly;
        f.pixelClass = judge.oneHit(rayHit, rayHit ? f.rayWindowDepth : f.rasterWindowDepth,
                                    rayHit ? f.rayPrimitive : f.rasterPrimitive, measures.quantum(ray, raster, a, b),
                                    pWindow, raster.holesAllowed);
        if (f.pixelClass == PixelClass::RayOnlyAtClear) ++r.lostAtClearValue;
        if (f.pixelClass == PixelClass::AtClipPlane) ++r.atClipPlane;
        if (f.pixelClass == PixelClass::Hole) ++r.holes;
        isUnexplained(f.pixelClass) ? ++r.coverageUnexplained : ++r.coverageExplained;
    }
    if (perPixel) perPixel->pixelClass[i] = f.pixelClass;
    if (isUnexplained(f.pixelClass)) noteUnexplained(r, f);
}

void TileComparison::Impl::compareBaseline(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                                           const RoutePixels& raster)
{
    compareBody<KernelForm::Baseline>(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
}

#ifdef ZCHECK_X86_FORMS
ZCHECK_KERNEL_ENTRY_AVX2 void TileComparison::Impl::compareAvx2(int tileBegin, int tileEnd, int rowBegin, int rowEnd,
                                                                const RoutePixels& ray, const RoutePixels& raster)
{
    compareBody<KernelForm::Avx2>(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
}

ZCHECK_KERNEL_ENTRY_AVX512 void TileComparison::Impl::compareAvx512(int tileBegin, int tileEnd, int rowBegin,
                                                                    int rowEnd, const RoutePixels& ray,
                                                                    const RoutePixels& raster)
{
    compareBody<KernelForm::Avx512>(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
}
#endif

void TileComparison::Impl::compare(int tileBegin, int tileEnd, int rowBegin, int rowEnd, const RoutePixels& ray,
                                   const RoutePixels& raster)
{
    auto body = &Impl::compareBaseline;
#ifdef ZCHECK_X86_FORMS
    body = formOf(judge.form(), body, &Impl::compareAvx2, &Impl::compareAvx512);
#endif
    (this->*body)(tileBegin, tileEnd, rowBegin, rowEnd, ray, raster);
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
