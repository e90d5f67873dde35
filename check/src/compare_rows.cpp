// The comparison's row pass (compare_rows.h): a tile's row lane by lane in the baseline form,
// eight lanes at a time with AVX-512 intrinsics in the other; the tolerance rule they both
// instantiate is PixelJudge::ToleranceTerms (compare.h), the tile driver that calls them
// compare.cpp's.
#include "compare_rows.h"

#include "zcheck/detail/lane_mask.h"
#include "slope_table.h"

#ifdef ZCHECK_X86_AVX512
#include <immintrin.h>
#endif

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
// compiled for (several pixels per instruction with AVX-512).
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

}  // namespace zcheck
