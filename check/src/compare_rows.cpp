// The comparison's row pass (compare_rows.h): a tile's row lane by lane in the baseline form,
// eight lanes at a time over a lane type (lanes.h) in the AVX2 and AVX-512 forms; the
// tolerance rule they all instantiate is PixelJudge::ToleranceTerms (compare.h), the tile
// driver that calls them compare.cpp's.
#include "compare_rows.h"

#include "zcheck/detail/lane_mask.h"
#include "zcheck/detail/lanes.h"
#include "slope_table.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace zcheck {

namespace {

// A float's or a double's bits, read through a pointer to it (the lane loops below stay SIMD
// where std::memcpy would not).
typedef std::uint32_t __attribute__((may_alias)) AliasedBits32;
typedef std::int64_t __attribute__((may_alias)) AliasedBits64;

}  // namespace

// A row's lane pass, lane by lane (its contract: compare_rows.h). Auto-vectorised where it is
// compiled for (several pixels per instruction in a vector form's target).
void rowLanesBaseline(const RowInputs& in, const PixelJudge::ToleranceTerms& terms, StatisticCounts& counts,
                      RowLanes& out)
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

#ifdef ZCHECK_X86_FORMS
// A row's surface (the triangle both routes hit, else kNoPrimitive) into `surface`, eight
// lanes at a time, and, as bits, the lanes that begin a run in one slope block of the scene's
// (SlopeTable::tableForRuns): found from the lanes in registers, each one's left
// neighbour's block shifted in, where reading the stored surface back one lane off waited on
// the stores (~10 % of the row pass's samples).
static_assert(kLanes <= 64, "a row's run starts fit one word");
template <class L>
ZCHECK_ALWAYS_INLINE inline std::uint64_t surfaceAndBlockRunsLanes(const std::uint32_t* rayPrimitive,
                                                                   const std::uint32_t* rasterPrimitive, int n,
                                                                   std::uint32_t blocks, std::uint32_t* surface)
{
    using Int32 = typename L::Int32;
    using Mask = typename L::Mask;
    static_assert(SlopeTable::kBlock == 64, "a block is a shift by 6");
    const Int32 none = L::set1(std::int32_t(kNoPrimitive)), blockCount = L::set1(std::int32_t(blocks));
    Int32 previousBlocks = L::set1(std::int32_t(-1));  // lane 7: the block left of lane 0, none of the scene's
    std::uint64_t runStarts = 0;
    for (int j = 0; j < n; j += 8) {
        const Mask lanes = L::firstLanes(std::min(8, n - j));
        const Int32 ray = L::maskedLoad(lanes, rayPrimitive + j), raster = L::maskedLoad(lanes, rasterPrimitive + j);
        const Mask common = lanes & L::notEqual(ray, none) & L::equal(ray, raster);
        const Int32 row = L::select(common, ray, none);
        L::maskedStore(lanes, surface + j, row);
        const Int32 block = L::template shiftRightLogical<6>(row);
        const Int32 leftBlock = L::shiftedIn(block, previousBlocks);  // lane k: block of lane k − 1
        const Mask starts = L::andNot(lanes, L::atLeastUnsigned(block, blockCount)) & L::notEqual(block, leftBlock);
        runStarts |= std::uint64_t(L::bits(starts)) << j;
        previousBlocks = block;
    }
    return runStarts;
}

// rowLanesBaseline's results, eight lanes at a time: the same IEEE operations lane for lane
// (bit-identical), its masks as masks and the keepers' candidates found among them, a row in
// one pass. (The lane loops above compiled for AVX-512, each through arrays of bytes, made the
// whole comparison ~1.3× as long; bench/speed-log.md.)
template <class L>
ZCHECK_ALWAYS_INLINE inline void rowLanesOf(const RowInputs& in, const PixelJudge::ToleranceTerms& termsOfJudge,
                                            StatisticCounts& counts, RowLanes& out)
{
    using Real = typename L::Real;
    using Int32 = typename L::Int32;
    using Int64 = typename L::Int64;
    using Mask = typename L::Mask;
    using Float = typename L::Float;
    const PixelJudge::ToleranceTerms terms = termsOfJudge;  // its C, S and E in registers for the row
    alignas(64) float errorQuantaOfLane[kLanes], relativeOfLane[kLanes];
    const Int32 none = L::set1(std::int32_t(kNoPrimitive));
    const Real zero = L::zero(), infinity = L::set1(double(INFINITY));
    // A keeper's candidates: the common lanes at or above its leastKeepable() (none at 2^32).
    const std::uint64_t leastQ = counts.errorQuanta.leastKeepable(), leastE = counts.relativeEyeZ.leastKeepable();
    const Mask keepsQ = L::firstLanes(leastQ >> 32 ? 0 : 8), keepsE = L::firstLanes(leastE >> 32 ? 0 : 8);
    const Int32 leastQBits = L::set1(std::int32_t(std::uint32_t(leastQ)));
    const Int32 leastEBits = L::set1(std::int32_t(std::uint32_t(leastE)));
    const Int32 slopeTableNone = L::set1(std::int32_t(in.slopeTableNone));
    const Int32 agreeClass = L::set1(std::int32_t(PixelClass::Agree)), errorClass = L::set1(std::int32_t(PixelClass::DepthError));
    const Int32 bothMissClass = L::set1(std::int32_t(PixelClass::BothMiss));
    const Real constantQuantum = L::set1(in.constantQuantum.value_or(0.0));
    const Real relativeA = L::set1(in.relativeForm ? in.relativeForm->A : 0.0);
    const bool parallel = in.relativeForm && in.relativeForm->parallel;
    Int64 largestQ = L::set1(std::int64_t(-1)), largestE = largestQ, largestR = largestQ;
    std::uint64_t common = 0, agree = 0, hit = 0, bias = 0, candidateQ = 0, candidateE = 0;
    // The inputs in locals: the stores below may alias `in`, which would be read again each group.
    const int n = in.n;
    const std::uint32_t *rayPrimitives = in.rayPrimitive, *rasterPrimitives = in.rasterPrimitive;
    const double *rayDepths = in.rayDepth, *rasterDepths = in.rasterDepth, *slopeTable = in.slopeTable;
    const double *slopes = in.slope, *quanta = in.quantum, *relatives = in.relative;
    const double* allowances = in.allowance == kNoAllowance ? nullptr : in.allowance;
    const bool quantumConstant = bool(in.constantQuantum), relativeInClosedForm = bool(in.relativeForm);
    std::uint8_t* pixelClasses = reinterpret_cast<std::uint8_t*>(in.pixelClass);
    float* errorOverTolerance = in.errorOverTolerance;
    for (int j = 0; j < n; j += 8) {
        const Mask lanes = L::firstLanes(std::min(8, n - j));
        const Int32 rayPrimitive = L::maskedLoad(lanes, rayPrimitives + j);
        const Int32 rasterPrimitive = L::maskedLoad(lanes, rasterPrimitives + j);
        const Mask rayHit = lanes & L::notEqual(rayPrimitive, none);
        const Mask c = rayHit & L::equal(rayPrimitive, rasterPrimitive);
        const Mask h = rayHit | (lanes & L::notEqual(rasterPrimitive, none));
        const Real rayDepth = L::maskedLoad(lanes, rayDepths + j);
        const Real rasterDepth = L::maskedLoad(lanes, rasterDepths + j);
        // The slope of a common lane's triangle (0 elsewhere, as table[slopeTableNone] is).
        const Real m = slopeTable ? L::gather(c, slopeTable, L::minUnsigned(rayPrimitive, slopeTableNone))
                                  : L::maskedLoad(lanes, slopes + j);
        const Real q = quantumConstant ? constantQuantum : L::maskedLoad(lanes, quanta + j);
        // CameraRays::relativeEyeZDifferences (reference: the ray's depth, other: the raster's).
        Real relative;
        if (!relativeInClosedForm)
            relative = L::maskedLoad(lanes, relatives + j);
        else if (parallel)
            relative = L::abs((rasterDepth - rayDepth) / (rayDepth - relativeA));
        else
            relative = L::abs((rayDepth - rasterDepth) / (rasterDepth - relativeA));
        const Real allowance = allowances ? L::maskedLoad(lanes, allowances + j) : zero;
        // The tolerance model's rules, as the baseline form and PixelJudge apply them (compare.h).
        Real bound;
        terms.bound(m, q, allowance, bound);
        const Real difference = rasterDepth - rayDepth;
        const Real error = L::abs(difference);
        const Real signedErrorQuanta = difference / q;
        const Real errorQuanta = L::abs(signedErrorQuanta);
        // ratioOf(error, bound).
        const Real unbounded = L::select(error > zero, infinity, zero);
        const Real ratio = L::select(bound > zero, error / bound, unbounded);
        const Mask a = lanes & (error <= bound);
        Mask dominates;
        terms.quantizationDominates(m, q, allowance, dominates);
        const Mask b = c & dominates;
        L::store(out.bound + j, bound);
        L::store(out.signedErrorQuanta + j, signedErrorQuanta);
        L::store(out.errorQuanta + j, errorQuanta);
        L::store(out.ratio + j, ratio);
        const Float errorQuantaOfLanes = L::toFloat(errorQuanta), relativeOfLanes = L::toFloat(relative);
        if (pixelClasses) {
            const Int32 pixelClass = L::select(c & a, agreeClass, L::select(L::andNot(c, a), errorClass, bothMissClass));
            L::maskedStoreBytes(lanes, pixelClasses + j, pixelClass);
            L::maskedStore(lanes, errorOverTolerance + j, L::zeroWhereNot(c, L::toFloat(ratio)));
        }
        largestQ = L::select(c & L::ordered(errorQuanta), L::max(largestQ, L::bitsOf(errorQuanta)), largestQ);
        largestE = L::select(c & L::ordered(relative), L::max(largestE, L::bitsOf(relative)), largestE);
        largestR = L::select(c & L::ordered(ratio), L::max(largestR, L::bitsOf(ratio)), largestR);
        L::store(errorQuantaOfLane + j, errorQuantaOfLanes);
        L::store(relativeOfLane + j, relativeOfLanes);
        const Mask keptQ = c & keepsQ & L::atLeastUnsigned(L::bitsOf(errorQuantaOfLanes), leastQBits);
        const Mask keptE = c & keepsE & L::atLeastUnsigned(L::bitsOf(relativeOfLanes), leastEBits);
        common |= std::uint64_t(L::bits(c)) << j, agree |= std::uint64_t(L::bits(a)) << j;
        hit |= std::uint64_t(L::bits(h)) << j, bias |= std::uint64_t(L::bits(b)) << j;
        candidateQ |= std::uint64_t(L::bits(keptQ)) << j, candidateE |= std::uint64_t(L::bits(keptE)) << j;
    }
    out.common = common, out.agree = agree, out.hit = hit, out.bias = bias;
    out.largest[0] = L::reduceMax(largestQ);
    out.largest[1] = L::reduceMax(largestE);
    out.largest[2] = L::reduceMax(largestR);
    const std::size_t commons = std::size_t(__builtin_popcountll(common));
    counts.errorQuanta.addCandidates(errorQuantaOfLane, candidateQ, commons);
    counts.relativeEyeZ.addCandidates(relativeOfLane, candidateE, commons);
}

// Each form's entry functions (compare_rows.h).
#define ZCHECK_ROWS_FORM(Entry, Form)                                                                             \
    Entry std::uint64_t surfaceAndBlockRuns##Form(const std::uint32_t* rayPrimitive,                              \
                                                  const std::uint32_t* rasterPrimitive, int n, std::uint32_t blocks, \
                                                  std::uint32_t* surface)                                         \
    {                                                                                                             \
        return surfaceAndBlockRunsLanes<Form##Lanes>(rayPrimitive, rasterPrimitive, n, blocks, surface);          \
    }                                                                                                             \
    Entry void rowLanes##Form(const RowInputs& in, const PixelJudge::ToleranceTerms& terms, StatisticCounts& counts, \
                              RowLanes& out)                                                                      \
    {                                                                                                             \
        rowLanesOf<Form##Lanes>(in, terms, counts, out);                                                          \
    }
ZCHECK_ROWS_FORM(ZCHECK_KERNEL_ENTRY_AVX2, Avx2)
ZCHECK_ROWS_FORM(ZCHECK_KERNEL_ENTRY_AVX512, Avx512)
#undef ZCHECK_ROWS_FORM
#endif

}  // namespace zcheck
