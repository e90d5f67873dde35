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
#include <type_traits>

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
// the stores (~10 % of the row pass's samples). All in 32-bit lanes' masks (Mask32): in the
// AVX2 form, widening each to the Mask of doubles' lanes made this pass 2.7× as long.
static_assert(kLanes <= 64, "a row's run starts fit one word");
template <class L>
ZCHECK_ALWAYS_INLINE inline std::uint64_t surfaceAndBlockRunsLanes(const std::uint32_t* rayPrimitive,
                                                                   const std::uint32_t* rasterPrimitive, int n,
                                                                   std::uint32_t blocks, std::uint32_t* surface)
{
    using Int32 = typename L::Int32;
    using Mask32 = typename L::Mask32;
    static_assert(SlopeTable::kBlock == 64, "a block is a shift by 6");
    const Int32 none = L::set1(std::int32_t(kNoPrimitive)), blockCount = L::set1(std::int32_t(blocks));
    Int32 previousBlocks = L::set1(std::int32_t(-1));  // lane 7: the block left of lane 0, none of the scene's
    std::uint64_t runStarts = 0;
    // Eight lanes from j (kFull: plain loads and stores), or the row's last n − j (masked).
    auto group = [&](int j, auto full) ZCHECK_ALWAYS_INLINE {
        constexpr bool kFull = decltype(full)::value;
        const Mask32 lanes = L::firstLanes32(kFull ? 8 : n - j);
        const Int32 ray = kFull ? L::load(rayPrimitive + j) : L::maskedLoad32(lanes, rayPrimitive + j);
        const Int32 raster = kFull ? L::load(rasterPrimitive + j) : L::maskedLoad32(lanes, rasterPrimitive + j);
        const Mask32 common = L::andNot32(L::equal32(ray, raster), L::equal32(ray, none)) & lanes;
        const Int32 row = L::select32(common, ray, none);
        if constexpr (kFull)
            L::store(surface + j, row);
        else
            L::maskedStore32(lanes, surface + j, row);
        const Int32 block = L::template shiftRightLogical<6>(row);
        const Int32 leftBlock = L::shiftedIn(block, previousBlocks);  // lane k: block of lane k − 1
        const Mask32 inTable = L::andNot32(lanes, L::atLeastUnsigned32(block, blockCount));
        const Mask32 starts = L::andNot32(inTable, L::equal32(block, leftBlock));
        runStarts |= std::uint64_t(L::bits32(starts)) << j;
        previousBlocks = block;
    };
    int j = 0;
    for (; j + 8 <= n; j += 8) group(j, std::true_type{});
    if (j < n) group(j, std::false_type{});
    return runStarts;
}

// RowLanes::largest of lanes each ≥ +0 or −1 (none): the largest value's bits, or −1.
template <class L>
ZCHECK_ALWAYS_INLINE inline std::int64_t largestBits(typename L::Real lanes)
{
    alignas(64) double lane[L::kLanes];
    L::store(lane, lanes);
    double largest = lane[0];
    for (int k = 1; k < L::kLanes; ++k) largest = lane[k] > largest ? lane[k] : largest;
    std::int64_t bits;
    __builtin_memcpy(&bits, &largest, sizeof bits);
    return largest < 0 ? -1 : bits;
}

// Which of a row's inputs rowLanesOf reads from arrays, fixed per instantiation where they are
// the common case's, so that its loop carries no branch and no value merged from two (which
// spilled): ClosedForm and ClosedFormParallel have a slope table, one quantum for all, the
// relative error in closed form (the view's z axis along each ray or parallel to it) and no
// allowance; General reads RowInputs to find out.
enum class RowCase { General, ClosedForm, ClosedFormParallel };

// rowLanesBaseline's results, eight lanes at a time: the same IEEE operations lane for lane
// (bit-identical), its masks as masks and the keepers' candidates found among them, a row in
// one pass. (The lane loops above compiled for AVX-512, each through arrays of bytes, made the
// whole comparison ~1.3× as long; bench/speed-log.md.) The masks of 32-bit lanes (the
// primitives', the keepers') stay Mask32; only the common lanes' is widened, once.
template <class L, RowCase kCase>
ZCHECK_ALWAYS_INLINE inline void rowLanesOf(const RowInputs& in, const PixelJudge::ToleranceTerms& termsOfJudge,
                                            StatisticCounts& counts, RowLanes& out)
{
    using Real = typename L::Real;
    using Int32 = typename L::Int32;
    using Mask = typename L::Mask;
    using Mask32 = typename L::Mask32;
    using Float = typename L::Float;
    const PixelJudge::ToleranceTerms terms = termsOfJudge;  // its C, S and E in registers for the row
    alignas(64) float errorQuantaOfLane[kLanes], relativeOfLane[kLanes];
    const Int32 none = L::set1(std::int32_t(kNoPrimitive));
    const Real zero = L::zero(), infinity = L::set1(double(INFINITY));
    // A keeper's candidates: the common lanes at or above its leastKeepable() (none at 2^32).
    const std::uint64_t leastQ = counts.errorQuanta.leastKeepable(), leastE = counts.relativeEyeZ.leastKeepable();
    constexpr int kGroup = L::kLanes;
    const Mask32 keepsQ = L::firstLanes32(leastQ >> 32 ? 0 : kGroup), keepsE = L::firstLanes32(leastE >> 32 ? 0 : kGroup);
    const Int32 leastQBits = L::set1(std::int32_t(std::uint32_t(leastQ)));
    const Int32 leastEBits = L::set1(std::int32_t(std::uint32_t(leastE)));
    const Int32 slopeTableNone = L::set1(std::int32_t(in.slopeTableNone));
    const Int32 agreeClass = L::set1(std::int32_t(PixelClass::Agree)), errorClass = L::set1(std::int32_t(PixelClass::DepthError));
    const Int32 bothMissClass = L::set1(std::int32_t(PixelClass::BothMiss));
    const Real constantQuantum = L::set1(in.constantQuantum.value_or(0.0));
    // inQuanta's multiplier where the row's constant quantum is a unorm format's (0: none).
    const double rowCodesPerUnit = in.constantQuantum ? unormCodesPerUnit(*in.constantQuantum) : 0.0;
    const Real codesPerUnit = L::set1(rowCodesPerUnit);
    const Real quantum24 = L::set1(storageQuantum(DepthFormat::Unorm24, 0.0)), codes24 = L::set1(unormMax(DepthFormat::Unorm24));
    const Real quantum16 = L::set1(storageQuantum(DepthFormat::Unorm16, 0.0)), codes16 = L::set1(unormMax(DepthFormat::Unorm16));
    const Real relativeA = L::set1(in.relativeForm ? in.relativeForm->A : 0.0);
    constexpr bool kClosedForm = kCase != RowCase::General;
    const bool parallel = kClosedForm ? kCase == RowCase::ClosedFormParallel : in.relativeForm && in.relativeForm->parallel;
    // The three maxima as doubles, −1 where no lane counts: each lane's value where common, −1
    // elsewhere, through x86's max(candidate, largest) (which keeps `largest` where the
    // candidate is NaN). The values are ≥ +0 or NaN, so the largest is the one std::max's.
    const Real noLargest = L::set1(-1.0);
    Real largestQ = noLargest, largestE = noLargest, largestR = noLargest;
    std::uint64_t common = 0, agree = 0, hit = 0, bias = 0, candidateQ = 0, candidateE = 0;
    // The inputs in locals: the stores below may alias `in`, which would be read again each group.
    const int n = in.n;
    const std::uint32_t *rayPrimitives = in.rayPrimitive, *rasterPrimitives = in.rasterPrimitive;
    const double *rayDepths = in.rayDepth, *rasterDepths = in.rasterDepth, *slopeTable = in.slopeTable;
    const double *slopes = in.slope, *quanta = in.quantum, *relatives = in.relative;
    const double* allowances = kClosedForm || in.allowance == kNoAllowance ? nullptr : in.allowance;
    const bool quantumConstant = kClosedForm || in.constantQuantum, relativeInClosedForm = kClosedForm || in.relativeForm;
    std::uint8_t* pixelClasses = reinterpret_cast<std::uint8_t*>(in.pixelClass);
    float* errorOverTolerance = in.errorOverTolerance;
    // A group of lanes from j: all kGroup of them (kFull: plain loads and stores), or the row's
    // last n − j (masked: nothing read or written past the row).
    auto group = [&](int j, auto full) ZCHECK_ALWAYS_INLINE {
        constexpr bool kFull = decltype(full)::value;
        const Mask lanes = L::firstLanes(kFull ? kGroup : n - j);
        const Mask32 lanes32 = L::firstLanes32(kFull ? kGroup : n - j);
        const auto within = [&](Mask m) ZCHECK_ALWAYS_INLINE { return kFull ? m : lanes & m; };
        const auto load = [&](const auto* p) ZCHECK_ALWAYS_INLINE {
            if constexpr (kFull) return L::load(p + j);
            else return L::maskedLoad(lanes, p + j);
        };
        const Int32 rayPrimitive = load(rayPrimitives), rasterPrimitive = load(rasterPrimitives);
        // Either route hit where the smaller id is one; both hit one triangle where the ids
        // are equal too. (As 32-bit lanes' masks: c is widened once, h never.)
        const Mask32 h = L::andNot32(lanes32, L::equal32(L::minUnsigned(rayPrimitive, rasterPrimitive), none));
        const Mask32 c32 = h & L::equal32(rayPrimitive, rasterPrimitive);
        const Mask c = L::toMask(c32);
        const Real rayDepth = load(rayDepths), rasterDepth = load(rasterDepths);
        // The slope of a common lane's triangle (0 elsewhere, as table[slopeTableNone] is).
        const Real m = kClosedForm || slopeTable
                           ? L::gather(c, slopeTable, L::minUnsigned(rayPrimitive, slopeTableNone))
                           : load(slopes);
        const Real q = quantumConstant ? constantQuantum : load(quanta);
        // CameraRays::relativeEyeZDifferences (reference: the ray's depth, other: the raster's).
        Real relative;
        if (!relativeInClosedForm)
            relative = load(relatives);
        else if (parallel)
            relative = L::abs((rasterDepth - rayDepth) / (rayDepth - relativeA));
        else
            relative = L::abs((rayDepth - rasterDepth) / (rasterDepth - relativeA));
        const Real allowance = allowances ? load(allowances) : zero;
        // The tolerance model's rules, as the baseline form and PixelJudge apply them (compare.h).
        Real bound;
        terms.bound(m, q, allowance, bound);
        const Real difference = rasterDepth - rayDepth;
        const Real error = L::abs(difference);
        // PixelMeasures::signedErrorQuanta (inQuanta): one multiplication where the row's one
        // quantum is a unorm format's (a division cost the AVX-512 comparison ~9 %), else lane by lane.
        Real signedErrorQuanta;
        if (rowCodesPerUnit != 0) {
            signedErrorQuanta = difference * codesPerUnit;
        } else {
            const Real perUnit = L::select((q >= quantum24) & (q <= quantum24), codes24,
                                           L::select((q >= quantum16) & (q <= quantum16), codes16, zero));
            signedErrorQuanta = L::select(perUnit > zero, difference * perUnit, difference / q);
        }
        const Real errorQuanta = L::abs(signedErrorQuanta);
        // ratioOf(error, bound).
        const Real unbounded = L::select(error > zero, infinity, zero);
        const Real ratio = L::select(bound > zero, error / bound, unbounded);
        const Mask a = within(error <= bound);
        Mask dominates;
        terms.quantizationDominates(m, q, allowance, dominates);
        const Mask b = c & dominates;
        L::store(out.bound + j, bound);
        L::store(out.signedErrorQuanta + j, signedErrorQuanta);
        L::store(out.errorQuanta + j, errorQuanta);
        L::store(out.ratio + j, ratio);
        const Float errorQuantaOfLanes = L::toFloat(errorQuanta), relativeOfLanes = L::toFloat(relative);
        if (pixelClasses) {
            const Int32 pixelClass = L::select32(c32, L::select(a, agreeClass, errorClass), bothMissClass);
            const Float ratioOfCommon = L::zeroWhereNot32(c32, L::toFloat(ratio));
            if constexpr (kFull) {
                L::storeBytes(pixelClasses + j, pixelClass);
                L::store(errorOverTolerance + j, ratioOfCommon);
            } else {
                L::maskedStoreBytes(lanes, pixelClasses + j, pixelClass);
                L::maskedStore(lanes, errorOverTolerance + j, ratioOfCommon);
            }
        }
        largestQ = L::max(L::select(c, errorQuanta, noLargest), largestQ);
        largestE = L::max(L::select(c, relative, noLargest), largestE);
        largestR = L::max(L::select(c, ratio, noLargest), largestR);
        L::store(errorQuantaOfLane + j, errorQuantaOfLanes);
        L::store(relativeOfLane + j, relativeOfLanes);
        const Mask32 keptQ = c32 & keepsQ & L::atLeastUnsigned32(L::bitsOf(errorQuantaOfLanes), leastQBits);
        const Mask32 keptE = c32 & keepsE & L::atLeastUnsigned32(L::bitsOf(relativeOfLanes), leastEBits);
        common |= std::uint64_t(L::bits32(c32)) << j, agree |= std::uint64_t(L::bits(a)) << j;
        hit |= std::uint64_t(L::bits32(h)) << j, bias |= std::uint64_t(L::bits(b)) << j;
        candidateQ |= std::uint64_t(L::bits32(keptQ)) << j, candidateE |= std::uint64_t(L::bits32(keptE)) << j;
    };
    int j = 0;
    for (; j + kGroup <= n; j += kGroup) group(j, std::true_type{});
    if (j < n) group(j, std::false_type{});
    out.common = common, out.agree = agree, out.hit = hit, out.bias = bias;
    out.largest[0] = largestBits<L>(largestQ);
    out.largest[1] = largestBits<L>(largestE);
    out.largest[2] = largestBits<L>(largestR);
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
        if (!in.slopeTable || !in.constantQuantum || !in.relativeForm || in.allowance != kNoAllowance)           \
            rowLanesOf<Form##Lanes, RowCase::General>(in, terms, counts, out);                                    \
        else if (in.relativeForm->parallel)                                                                       \
            rowLanesOf<Form##Lanes, RowCase::ClosedFormParallel>(in, terms, counts, out);                         \
        else                                                                                                      \
            rowLanesOf<Form##Lanes, RowCase::ClosedForm>(in, terms, counts, out);                                 \
    }
ZCHECK_ROWS_FORM(ZCHECK_KERNEL_ENTRY_AVX2, Avx2)
ZCHECK_ROWS_FORM(ZCHECK_KERNEL_ENTRY_AVX512, Avx512)
#undef ZCHECK_ROWS_FORM
#endif

}  // namespace zcheck
