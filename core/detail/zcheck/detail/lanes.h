#pragma once
// Internal to zcheck (core/detail, never installed).
// Eight lanes at a time, in the two vector forms of the kernels (kernel_choice.h): a lane type
// per instruction set, with the same members, so that a kernel is written once as a template
// over it and compiled per form by that form's entry function.
//
//   Avx512Lanes  one 512-bit register per eight doubles or 64-bit integers, masks in mask registers
//   Avx2Lanes    two 256-bit registers per eight doubles or 64-bit integers, masks as vectors
//                whose lanes are all ones or all zeros
//   Avx2Lanes4   four lanes in one 256-bit register, for the raster's pixel loop in the AVX2 form
//                (only the members that loop uses)
//
// L::kLanes says how many lanes. Each eight-lane type L has
//   L::Real   eight doubles: + − × ÷ (IEEE, lane by lane), < <= > >= (a Mask), select, min, max, abs
//   L::Int64  eight 64-bit integers: + − | & <<, steps, select, load, store, and realOfBits
//             (bitsOf's inverse)
//   L::Int32  eight 32-bit integers: + −, == !=, min/max (unsigned), select
//   L::Float  eight floats: the rounded doubles the keepers and the heatmap take
//   L::Mask   eight lanes' truth: & | ^ andNot, bits() (lane j: bit j)
//   L::Mask32 eight 32-bit lanes' truth, in the form's cheapest shape for 32-bit work: & andNot32,
//             bits32, and toMask (to a Mask, where doubles' lanes need it)
// and the loads, stores, gathers and conversions the kernels need, each named for what it does.
// A masked load reads no memory of a lane outside its mask, a masked store writes none (so a
// group of eight may run past the end of its row). L::kFastMaskedStores says whether a masked
// store costs what a store does: with AVX-512's mask registers it does; AVX2's vmaskmov
// stores are microcode on AMD's Zen 1–3 and never forward to a later load on Intel, so a hot
// loop of the AVX2 form that may write its whole group reads it, blends (select) and stores it.
// L::kFastGathers says whether eight floats gathered from eight places (gatherFloats) cost less
// than eight loads, converted and dealt into lanes one by one: on Sapphire Rapids in the AVX-512
// form they did (the comparison's slopes), in the AVX2 form they did not, and on AMD's Zen 2
// and 3 a gather is microcode.
// Every operation on doubles is the one IEEE operation its name says, so a kernel's lanes
// compute the bits its scalar form computes.
//
// The members carry their form's target and are inlined into the entry function (flatten); call
// them only from code of that target (ZCHECK_TARGET_AVX2 / _AVX512), never from baseline code.
#include "zcheck/detail/kernel_choice.h"

#ifdef ZCHECK_X86_FORMS
#include <immintrin.h>

#include <cstdint>

namespace zcheck {

ZCHECK_INTRINSICS_BEGIN

// ---------------------------------------------------------------------------------------------
// Eight 32-bit lanes in one 256-bit register, with the operations both eight-lane forms do alike
// (AVX2 instructions: an AVX-512 function inlines them too); each form derives from it.
struct Lanes32 {
#define ZCHECK_LANE ZCHECK_TARGET_AVX2 inline
    struct Int32 {
        __m256i v;
        friend ZCHECK_LANE Int32 operator+(Int32 a, Int32 b) { return {_mm256_add_epi32(a.v, b.v)}; }
        friend ZCHECK_LANE Int32 operator-(Int32 a, Int32 b) { return {_mm256_sub_epi32(a.v, b.v)}; }
        friend ZCHECK_LANE Int32 operator|(Int32 a, Int32 b) { return {_mm256_or_si256(a.v, b.v)}; }
        friend ZCHECK_LANE Int32 operator&(Int32 a, Int32 b) { return {_mm256_and_si256(a.v, b.v)}; }
    };
    struct Float {
        __m256 v;
    };
    static ZCHECK_LANE Int32 set1(std::int32_t x) { return {_mm256_set1_epi32(x)}; }
    static ZCHECK_LANE Int32 load(const std::uint32_t* p) { return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p))}; }
    static ZCHECK_LANE void store(float* p, Float a) { _mm256_storeu_ps(p, a.v); }
    static ZCHECK_LANE Int32 minUnsigned(Int32 a, Int32 b) { return {_mm256_min_epu32(a.v, b.v)}; }
    static ZCHECK_LANE Int32 min(Int32 a, Int32 b) { return {_mm256_min_epi32(a.v, b.v)}; }
    static ZCHECK_LANE Int32 max(Int32 a, Int32 b) { return {_mm256_max_epi32(a.v, b.v)}; }
    template <int kShift>
    static ZCHECK_LANE Int32 shiftRightArithmetic(Int32 a) { return {_mm256_srai_epi32(a.v, kShift)}; }
    template <int kShift>
    static ZCHECK_LANE Int32 shiftRightLogical(Int32 a) { return {_mm256_srli_epi32(a.v, kShift)}; }
    static ZCHECK_LANE void store(std::int32_t* p, Int32 a) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), a.v); }
    static ZCHECK_LANE Int32 bitsOf(Float a) { return {_mm256_castps_si256(a.v)}; }
    // Lane k: a's lane k − 1, lane 0: `before`'s lane 7 (the lanes moved one up, the previous group's last shifted in).
    static ZCHECK_LANE Int32 shiftedIn(Int32 a, Int32 before)
    {
        const __m256i up = _mm256_permutevar8x32_epi32(a.v, _mm256_setr_epi32(7, 0, 1, 2, 3, 4, 5, 6));
        const __m256i last = _mm256_permutevar8x32_epi32(before.v, _mm256_set1_epi32(7));
        return {_mm256_blend_epi32(up, last, 0x01)};
    }

    // The truth of eight 32-bit lanes, for work on 32-bit lanes alone, which then needs no
    // widening to the form's Mask (toMask widens it where a Real's lanes need it): here lanes of
    // all ones or zeros, the AVX2 form's; the AVX-512 form's is its Mask (a mask register).
    struct Mask32 {
        __m256i v;
        friend ZCHECK_LANE Mask32 operator&(Mask32 a, Mask32 b) { return {_mm256_and_si256(a.v, b.v)}; }
    };
    static ZCHECK_LANE Mask32 firstLanes32(int n)  // lanes [0, n), n in [0, 8]
    {
        return {_mm256_cmpgt_epi32(_mm256_set1_epi32(n), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7))};
    }
    static ZCHECK_LANE Mask32 andNot32(Mask32 a, Mask32 b) { return {_mm256_andnot_si256(b.v, a.v)}; }  // a & ~b
    static ZCHECK_LANE unsigned bits32(Mask32 m) { return unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(m.v))); }
    static ZCHECK_LANE Mask32 equal32(Int32 a, Int32 b) { return {_mm256_cmpeq_epi32(a.v, b.v)}; }
    static ZCHECK_LANE Mask32 atLeastUnsigned32(Int32 a, Int32 b) { return {_mm256_cmpeq_epi32(_mm256_max_epu32(a.v, b.v), a.v)}; }
    static ZCHECK_LANE Int32 select32(Mask32 m, Int32 ifTrue, Int32 ifFalse) { return {_mm256_blendv_epi8(ifFalse.v, ifTrue.v, m.v)}; }
    static ZCHECK_LANE Int32 maskedLoad32(Mask32 m, const std::uint32_t* p)  // 0 outside m
    {
        return {_mm256_maskload_epi32(reinterpret_cast<const int*>(p), m.v)};
    }
    static ZCHECK_LANE void maskedStore32(Mask32 m, std::uint32_t* p, Int32 a) { _mm256_maskstore_epi32(reinterpret_cast<int*>(p), m.v, a.v); }
    static ZCHECK_LANE Float zeroWhereNot32(Mask32 m, Float a) { return {_mm256_and_ps(a.v, _mm256_castsi256_ps(m.v))}; }
    static ZCHECK_LANE void store(std::uint32_t* p, Int32 a) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), a.v); }
    // Lane k: base[index[k]], each index a non-negative 32-bit integer.
    static ZCHECK_LANE Float gatherFloats(const float* base, Int32 index) { return {_mm256_i32gather_ps(base, index.v, 4)}; }
#undef ZCHECK_LANE
};
// The base's overloads of the names a form also defines (set1, load, store, min, max, bitsOf).
#define ZCHECK_LANES32_NAMES                                                                      \
    using Lanes32::set1;                                                                          \
    using Lanes32::load;                                                                          \
    using Lanes32::store;                                                                         \
    using Lanes32::min;                                                                           \
    using Lanes32::max;                                                                           \
    using Lanes32::bitsOf

// ---------------------------------------------------------------------------------------------
// AVX2 + FMA: lanes 0–3 in `lo`, 4–7 in `hi`.
struct Avx2Lanes : Lanes32 {
#define ZCHECK_LANE ZCHECK_TARGET_AVX2 inline
    static constexpr int kLanes = 8;
    static constexpr bool kFastMaskedStores = false;
    static constexpr bool kFastGathers = false;
    ZCHECK_LANES32_NAMES;
    struct Mask {
        __m256i lo, hi;  // per 64-bit lane: all ones (true) or zeros
        friend ZCHECK_LANE Mask operator&(Mask a, Mask b) { return {_mm256_and_si256(a.lo, b.lo), _mm256_and_si256(a.hi, b.hi)}; }
        friend ZCHECK_LANE Mask operator|(Mask a, Mask b) { return {_mm256_or_si256(a.lo, b.lo), _mm256_or_si256(a.hi, b.hi)}; }
        friend ZCHECK_LANE Mask operator^(Mask a, Mask b) { return {_mm256_xor_si256(a.lo, b.lo), _mm256_xor_si256(a.hi, b.hi)}; }
    };
    struct Real {
        __m256d lo, hi;
        friend ZCHECK_LANE Real operator+(Real a, Real b) { return {_mm256_add_pd(a.lo, b.lo), _mm256_add_pd(a.hi, b.hi)}; }
        friend ZCHECK_LANE Real operator-(Real a, Real b) { return {_mm256_sub_pd(a.lo, b.lo), _mm256_sub_pd(a.hi, b.hi)}; }
        friend ZCHECK_LANE Real operator*(Real a, Real b) { return {_mm256_mul_pd(a.lo, b.lo), _mm256_mul_pd(a.hi, b.hi)}; }
        friend ZCHECK_LANE Real operator/(Real a, Real b) { return {_mm256_div_pd(a.lo, b.lo), _mm256_div_pd(a.hi, b.hi)}; }
        friend ZCHECK_LANE Real operator+(Real a, double b) { return a + set1(b); }
        friend ZCHECK_LANE Real operator*(double a, Real b) { return set1(a) * b; }
        friend ZCHECK_LANE Mask operator<(Real a, Real b) { return compare<_CMP_LT_OQ>(a, b); }
        friend ZCHECK_LANE Mask operator<=(Real a, Real b) { return compare<_CMP_LE_OQ>(a, b); }
        friend ZCHECK_LANE Mask operator>(Real a, Real b) { return compare<_CMP_GT_OQ>(a, b); }
        friend ZCHECK_LANE Mask operator>=(Real a, Real b) { return compare<_CMP_GE_OQ>(a, b); }
    };
    struct Int64 {
        __m256i lo, hi;
        friend ZCHECK_LANE Int64 operator+(Int64 a, Int64 b) { return {_mm256_add_epi64(a.lo, b.lo), _mm256_add_epi64(a.hi, b.hi)}; }
        friend ZCHECK_LANE Int64 operator-(Int64 a, Int64 b) { return {_mm256_sub_epi64(a.lo, b.lo), _mm256_sub_epi64(a.hi, b.hi)}; }
        friend ZCHECK_LANE Int64 operator|(Int64 a, Int64 b) { return {_mm256_or_si256(a.lo, b.lo), _mm256_or_si256(a.hi, b.hi)}; }
        friend ZCHECK_LANE Int64 operator&(Int64 a, Int64 b) { return {_mm256_and_si256(a.lo, b.lo), _mm256_and_si256(a.hi, b.hi)}; }
    };

    // Masks.
    static ZCHECK_LANE Mask andNot(Mask a, Mask b) { return {_mm256_andnot_si256(b.lo, a.lo), _mm256_andnot_si256(b.hi, a.hi)}; }  // a & ~b
    static ZCHECK_LANE unsigned bits(Mask m)
    {
        return unsigned(_mm256_movemask_pd(_mm256_castsi256_pd(m.lo))) |
               unsigned(_mm256_movemask_pd(_mm256_castsi256_pd(m.hi))) << 4;
    }
    static ZCHECK_LANE Mask firstLanes(int n)  // lanes [0, n), n in [0, 8]
    {
        const __m256i count = _mm256_set1_epi64x(n);
        return {_mm256_cmpgt_epi64(count, _mm256_setr_epi64x(0, 1, 2, 3)), _mm256_cmpgt_epi64(count, _mm256_setr_epi64x(4, 5, 6, 7))};
    }
    // The mask with one 32-bit lane per lane (for the 32-bit masked stores).
    static ZCHECK_LANE __m256i narrow(Mask m)
    {
        const __m256 pairs = _mm256_shuffle_ps(_mm256_castsi256_ps(m.lo), _mm256_castsi256_ps(m.hi), _MM_SHUFFLE(2, 0, 2, 0));
        return _mm256_permute4x64_epi64(_mm256_castps_si256(pairs), _MM_SHUFFLE(3, 1, 2, 0));
    }
    static ZCHECK_LANE Mask widen(__m256i m32)  // narrow's inverse
    {
        return {_mm256_cvtepi32_epi64(_mm256_castsi256_si128(m32)), _mm256_cvtepi32_epi64(_mm256_extracti128_si256(m32, 1))};
    }
    static ZCHECK_LANE Mask toMask(Mask32 m) { return widen(m.v); }

    // Reals.
    static ZCHECK_LANE Real set1(double x) { return {_mm256_set1_pd(x), _mm256_set1_pd(x)}; }
    static ZCHECK_LANE Real zero() { return {_mm256_setzero_pd(), _mm256_setzero_pd()}; }
    static ZCHECK_LANE Real load(const double* p) { return {_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)}; }
    static ZCHECK_LANE void store(double* p, Real a) { _mm256_storeu_pd(p, a.lo), _mm256_storeu_pd(p + 4, a.hi); }
    static ZCHECK_LANE Real maskedLoad(Mask m, const double* p)  // 0 outside m
    {
        return {_mm256_maskload_pd(p, m.lo), _mm256_maskload_pd(p + 4, m.hi)};
    }
    static ZCHECK_LANE void maskedStore(Mask m, double* p, Real a) { _mm256_maskstore_pd(p, m.lo, a.lo), _mm256_maskstore_pd(p + 4, m.hi, a.hi); }
    template <int kPredicate>
    static ZCHECK_LANE Mask compare(Real a, Real b)
    {
        return {_mm256_castpd_si256(_mm256_cmp_pd(a.lo, b.lo, kPredicate)), _mm256_castpd_si256(_mm256_cmp_pd(a.hi, b.hi, kPredicate))};
    }
    static ZCHECK_LANE Real select(Mask m, Real ifTrue, Real ifFalse)
    {
        return {_mm256_blendv_pd(ifFalse.lo, ifTrue.lo, _mm256_castsi256_pd(m.lo)),
                _mm256_blendv_pd(ifFalse.hi, ifTrue.hi, _mm256_castsi256_pd(m.hi))};
    }
    // x86's max and min: a > b ? a : b and a < b ? a : b (b where either is NaN, or both are zeros).
    static ZCHECK_LANE Real max(Real a, Real b) { return {_mm256_max_pd(a.lo, b.lo), _mm256_max_pd(a.hi, b.hi)}; }
    static ZCHECK_LANE Real min(Real a, Real b) { return {_mm256_min_pd(a.lo, b.lo), _mm256_min_pd(a.hi, b.hi)}; }
    static ZCHECK_LANE Real abs(Real a)  // the sign bit cleared, as std::abs (NaN's too)
    {
        const __m256d magnitude = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffff));
        return {_mm256_and_pd(a.lo, magnitude), _mm256_and_pd(a.hi, magnitude)};
    }
    static ZCHECK_LANE Float toFloat(Real a)  // rounded to nearest, as float(x)
    {
        return {_mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(a.lo)), _mm256_cvtpd_ps(a.hi), 1)};
    }
    static ZCHECK_LANE Real toReal(Float a)
    {
        return {_mm256_cvtps_pd(_mm256_castps256_ps128(a.v)), _mm256_cvtps_pd(_mm256_extractf128_ps(a.v, 1))};
    }
    static ZCHECK_LANE Real toReal(Int32 a)
    {
        return {_mm256_cvtepi32_pd(_mm256_castsi256_si128(a.v)), _mm256_cvtepi32_pd(_mm256_extracti128_si256(a.v, 1))};
    }
    // x truncated towards zero, for |x| < 2^31 (other lanes: INT32_MIN).
    static ZCHECK_LANE Int32 truncateToInt32(Real x)
    {
        return {_mm256_inserti128_si256(_mm256_castsi128_si256(_mm256_cvttpd_epi32(x.lo)), _mm256_cvttpd_epi32(x.hi), 1)};
    }
    // Lane k of table[index[k]] where m holds, 0 elsewhere (not read).
    static ZCHECK_LANE Real gather(Mask m, const double* table, Int32 index)
    {
        return {_mm256_mask_i32gather_pd(_mm256_setzero_pd(), table, _mm256_castsi256_si128(index.v), _mm256_castsi256_pd(m.lo), 8),
                _mm256_mask_i32gather_pd(_mm256_setzero_pd(), table, _mm256_extracti128_si256(index.v, 1), _mm256_castsi256_pd(m.hi), 8)};
    }
    // Element k of each of eight packed triples, from the 24 32-bit values in a, b, c (8 each):
    // two blends and a permute, where three gathers were several times the work (and slow on
    // AMD's Zen 2 and 3).
    template <int k>
    static ZCHECK_LANE __m256 tripleElements(__m256 a, __m256 b, __m256 c)
    {
        // Lane j of a, b, c holds element (j mod 3), (j + 2) mod 3, (j + 1) mod 3 of some triple.
        constexpr int kFromB = k == 0 ? 0x92 : k == 1 ? 0x24 : 0x49, kFromC = k == 0 ? 0x24 : k == 1 ? 0x49 : 0x92;
        const __m256 lanes = _mm256_blend_ps(_mm256_blend_ps(a, b, kFromB), c, kFromC);
        const __m256i order = k == 0 ? _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)
                            : k == 1 ? _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)
                                     : _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7);
        return _mm256_permutevar8x32_ps(lanes, order);
    }
    // Eight packed float triples (24 floats from p) as three lanes of doubles: x, y, z.
    static ZCHECK_LANE void loadTriples(const float* p, Real (&xyz)[3])
    {
        const __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
        xyz[0] = toReal(Float{tripleElements<0>(a, b, c)});
        xyz[1] = toReal(Float{tripleElements<1>(a, b, c)});
        xyz[2] = toReal(Float{tripleElements<2>(a, b, c)});
    }

    // 64-bit integers.
    static ZCHECK_LANE Int64 set1(std::int64_t x) { return {_mm256_set1_epi64x(x), _mm256_set1_epi64x(x)}; }
    static ZCHECK_LANE Int64 load(const std::int64_t* p)
    {
        return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)), _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 4))};
    }
    // Lane j: first + j·step, in wrapping 64-bit arithmetic.
    static ZCHECK_LANE Int64 steps(std::int64_t first, std::int64_t step)
    {
        const std::uint64_t f = std::uint64_t(first), s = std::uint64_t(step);
        const __m256i lo = _mm256_set_epi64x(std::int64_t(f + 3 * s), std::int64_t(f + 2 * s), std::int64_t(f + s), first);
        return {lo, _mm256_add_epi64(lo, _mm256_set1_epi64x(std::int64_t(4 * s)))};
    }
    static ZCHECK_LANE Int64 bitsOf(Real a) { return {_mm256_castpd_si256(a.lo), _mm256_castpd_si256(a.hi)}; }
    static ZCHECK_LANE Real realOfBits(Int64 a) { return {_mm256_castsi256_pd(a.lo), _mm256_castsi256_pd(a.hi)}; }
    static ZCHECK_LANE void store(std::int64_t* p, Int64 a)
    {
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), a.lo), _mm256_storeu_si256(reinterpret_cast<__m256i*>(p + 4), a.hi);
    }
    template <int kShift>
    static ZCHECK_LANE Int64 shiftLeft(Int64 a) { return {_mm256_slli_epi64(a.lo, kShift), _mm256_slli_epi64(a.hi, kShift)}; }
    static ZCHECK_LANE Mask nonNegative(Int64 a)
    {
        const __m256i minusOne = _mm256_set1_epi64x(-1);
        return {_mm256_cmpgt_epi64(a.lo, minusOne), _mm256_cmpgt_epi64(a.hi, minusOne)};
    }
    static ZCHECK_LANE Mask isZero(Int64 a)
    {
        const __m256i zero = _mm256_setzero_si256();
        return {_mm256_cmpeq_epi64(a.lo, zero), _mm256_cmpeq_epi64(a.hi, zero)};
    }
    static ZCHECK_LANE Int64 select(Mask m, Int64 ifTrue, Int64 ifFalse)
    {
        return {_mm256_blendv_epi8(ifFalse.lo, ifTrue.lo, m.lo), _mm256_blendv_epi8(ifFalse.hi, ifTrue.hi, m.hi)};
    }
    // Lane k: lo[k] in its low 32 bits, hi[k] in its high 32.
    static ZCHECK_LANE Int64 joined(Int32 lo, Int32 hi)
    {
        const __m256i first = _mm256_unpacklo_epi32(lo.v, hi.v), second = _mm256_unpackhi_epi32(lo.v, hi.v);  // lanes 0 1 4 5, 2 3 6 7
        return {_mm256_permute2x128_si256(first, second, 0x20), _mm256_permute2x128_si256(first, second, 0x31)};
    }
    // The low and the high 32 bits of each lane.
    static ZCHECK_LANE Int32 lowHalves(Int64 a) { return {narrow(Mask{a.lo, a.hi})}; }
    static ZCHECK_LANE Int32 highHalves(Int64 a)
    {
        const __m256 pairs = _mm256_shuffle_ps(_mm256_castsi256_ps(a.lo), _mm256_castsi256_ps(a.hi), _MM_SHUFFLE(3, 1, 3, 1));
        return {_mm256_permute4x64_epi64(_mm256_castps_si256(pairs), _MM_SHUFFLE(3, 1, 2, 0))};
    }
    // Lane k of the 64-bit word at base + 8·index[k].
    static ZCHECK_LANE Int64 gather(const void* base, Int64 index)
    {
        const long long* words = static_cast<const long long*>(base);
        return {_mm256_i64gather_epi64(words, index.lo, 8), _mm256_i64gather_epi64(words, index.hi, 8)};
    }
    static ZCHECK_LANE Int64 widen(Int32 a)  // each lane's 32 bits, sign-extended
    {
        return {_mm256_cvtepi32_epi64(_mm256_castsi256_si128(a.v)), _mm256_cvtepi32_epi64(_mm256_extracti128_si256(a.v, 1))};
    }
    // a·b, exact where both fit in 32 signed bits (other lanes: the product of their low halves).
    static ZCHECK_LANE Int64 multiplySmall(Int64 a, Int64 b) { return {_mm256_mul_epi32(a.lo, b.lo), _mm256_mul_epi32(a.hi, b.hi)}; }
    static ZCHECK_LANE Int64 widenUnsigned(Int32 a)  // each lane's 32 bits, zero-extended
    {
        return {_mm256_cvtepu32_epi64(_mm256_castsi256_si128(a.v)), _mm256_cvtepu32_epi64(_mm256_extracti128_si256(a.v, 1))};
    }
    // Eight 16-byte records {double a; 64 bits b} from out: lane k's a and b.
    static ZCHECK_LANE void storePairs(double* out, Real a, Int64 b)
    {
        const __m256d b0 = _mm256_castsi256_pd(b.lo), b1 = _mm256_castsi256_pd(b.hi);
        const __m256d even0 = _mm256_unpacklo_pd(a.lo, b0), odd0 = _mm256_unpackhi_pd(a.lo, b0);  // a0 b0 a2 b2, a1 b1 a3 b3
        const __m256d even1 = _mm256_unpacklo_pd(a.hi, b1), odd1 = _mm256_unpackhi_pd(a.hi, b1);
        _mm256_storeu_pd(out, _mm256_permute2f128_pd(even0, odd0, 0x20));
        _mm256_storeu_pd(out + 4, _mm256_permute2f128_pd(even0, odd0, 0x31));
        _mm256_storeu_pd(out + 8, _mm256_permute2f128_pd(even1, odd1, 0x20));
        _mm256_storeu_pd(out + 12, _mm256_permute2f128_pd(even1, odd1, 0x31));
    }

    // 32-bit integers.
    static ZCHECK_LANE Int32 maskedLoad(Mask m, const std::uint32_t* p)  // 0 outside m
    {
        return {_mm256_maskload_epi32(reinterpret_cast<const int*>(p), narrow(m))};
    }
    static ZCHECK_LANE void maskedStore(Mask m, float* p, Float a) { _mm256_maskstore_ps(p, narrow(m), a.v); }
    // The low byte of each lane to p[k] where m holds.
    static ZCHECK_LANE void storeBytes(std::uint8_t* p, Int32 a)  // the low byte of each lane to p[k]
    {
        const __m256i bytes = _mm256_shuffle_epi8(a.v, _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                                                                        0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
        const __m256i together = _mm256_permutevar8x32_epi32(bytes, _mm256_setr_epi32(0, 4, 0, 0, 0, 0, 0, 0));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(p), _mm256_castsi256_si128(together));
    }
    static ZCHECK_LANE void maskedStoreBytes(Mask m, std::uint8_t* p, Int32 a)  // the same where m holds
    {
        const unsigned lanes = bits(m);
        if (lanes == 0xFF) return storeBytes(p, a);
        alignas(32) std::int32_t lane[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(lane), a.v);
        for (int k = 0; k < 8; ++k)
            if (lanes >> k & 1) p[k] = std::uint8_t(lane[k]);
    }
    static ZCHECK_LANE Mask equal(Int32 a, Int32 b) { return widen(_mm256_cmpeq_epi32(a.v, b.v)); }
    static ZCHECK_LANE Mask notEqual(Int32 a, Int32 b) { return widen(_mm256_xor_si256(_mm256_cmpeq_epi32(a.v, b.v), _mm256_set1_epi32(-1))); }
    static ZCHECK_LANE Mask lessOrEqual(Int32 a, Int32 b) { return widen(_mm256_xor_si256(_mm256_cmpgt_epi32(a.v, b.v), _mm256_set1_epi32(-1))); }
    static ZCHECK_LANE Mask anyBits(Int32 a) { return widen(_mm256_xor_si256(_mm256_cmpeq_epi32(a.v, _mm256_setzero_si256()), _mm256_set1_epi32(-1))); }
    static ZCHECK_LANE Int32 select(Mask m, Int32 ifTrue, Int32 ifFalse) { return {_mm256_blendv_epi8(ifFalse.v, ifTrue.v, narrow(m))}; }
    static ZCHECK_LANE Int32 allOnesWhere(Mask m) { return {narrow(m)}; }  // −1 where m holds, 0 elsewhere
    // Eight packed int32 triples (24 ints from p) as three lanes: corner 0, 1, 2.
    static ZCHECK_LANE void loadTriples(const std::uint32_t* p, Int32 (&corner)[3])
    {
        const float* f = reinterpret_cast<const float*>(p);  // moved as bits, never as numbers
        const __m256 a = _mm256_loadu_ps(f), b = _mm256_loadu_ps(f + 8), c = _mm256_loadu_ps(f + 16);
        corner[0] = {_mm256_castps_si256(tripleElements<0>(a, b, c))};
        corner[1] = {_mm256_castps_si256(tripleElements<1>(a, b, c))};
        corner[2] = {_mm256_castps_si256(tripleElements<2>(a, b, c))};
    }
#undef ZCHECK_LANE
};

// ---------------------------------------------------------------------------------------------
// AVX-512 F, DQ, VL: eight lanes per 512-bit register (Real, Int64) or 256-bit one (Int32, Float).
struct Avx512Lanes : Lanes32 {
#define ZCHECK_LANE ZCHECK_TARGET_AVX512 inline
    static constexpr int kLanes = 8;
    static constexpr bool kFastMaskedStores = true;
    static constexpr bool kFastGathers = true;
    ZCHECK_LANES32_NAMES;
    struct Mask {
        __mmask8 k;
        friend ZCHECK_LANE Mask operator&(Mask a, Mask b) { return {__mmask8(a.k & b.k)}; }
        friend ZCHECK_LANE Mask operator|(Mask a, Mask b) { return {__mmask8(a.k | b.k)}; }
        friend ZCHECK_LANE Mask operator^(Mask a, Mask b) { return {__mmask8(a.k ^ b.k)}; }
    };
    struct Real {
        __m512d v;
        friend ZCHECK_LANE Real operator+(Real a, Real b) { return {_mm512_add_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Real operator-(Real a, Real b) { return {_mm512_sub_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Real operator*(Real a, Real b) { return {_mm512_mul_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Real operator/(Real a, Real b) { return {_mm512_div_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Real operator+(Real a, double b) { return a + set1(b); }
        friend ZCHECK_LANE Real operator*(double a, Real b) { return set1(a) * b; }
        friend ZCHECK_LANE Mask operator<(Real a, Real b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ)}; }
        friend ZCHECK_LANE Mask operator<=(Real a, Real b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ)}; }
        friend ZCHECK_LANE Mask operator>(Real a, Real b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_GT_OQ)}; }
        friend ZCHECK_LANE Mask operator>=(Real a, Real b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_GE_OQ)}; }
    };
    struct Int64 {
        __m512i v;
        friend ZCHECK_LANE Int64 operator+(Int64 a, Int64 b) { return {_mm512_add_epi64(a.v, b.v)}; }
        friend ZCHECK_LANE Int64 operator-(Int64 a, Int64 b) { return {_mm512_sub_epi64(a.v, b.v)}; }
        friend ZCHECK_LANE Int64 operator|(Int64 a, Int64 b) { return {_mm512_or_si512(a.v, b.v)}; }
        friend ZCHECK_LANE Int64 operator&(Int64 a, Int64 b) { return {_mm512_and_si512(a.v, b.v)}; }
    };

    // Masks.
    static ZCHECK_LANE Mask andNot(Mask a, Mask b) { return {__mmask8(a.k & ~b.k)}; }
    static ZCHECK_LANE unsigned bits(Mask m) { return m.k; }
    static ZCHECK_LANE Mask firstLanes(int n) { return {__mmask8((1u << n) - 1)}; }

    // Reals.
    static ZCHECK_LANE Real set1(double x) { return {_mm512_set1_pd(x)}; }
    static ZCHECK_LANE Real zero() { return {_mm512_setzero_pd()}; }
    static ZCHECK_LANE Real load(const double* p) { return {_mm512_loadu_pd(p)}; }
    static ZCHECK_LANE void store(double* p, Real a) { _mm512_storeu_pd(p, a.v); }
    static ZCHECK_LANE Real maskedLoad(Mask m, const double* p) { return {_mm512_maskz_loadu_pd(m.k, p)}; }
    static ZCHECK_LANE void maskedStore(Mask m, double* p, Real a) { _mm512_mask_storeu_pd(p, m.k, a.v); }
    static ZCHECK_LANE Real select(Mask m, Real ifTrue, Real ifFalse) { return {_mm512_mask_blend_pd(m.k, ifFalse.v, ifTrue.v)}; }
    static ZCHECK_LANE Real max(Real a, Real b) { return {_mm512_max_pd(a.v, b.v)}; }
    static ZCHECK_LANE Real min(Real a, Real b) { return {_mm512_min_pd(a.v, b.v)}; }
    static ZCHECK_LANE Real abs(Real a) { return {_mm512_abs_pd(a.v)}; }
    static ZCHECK_LANE Float toFloat(Real a) { return {_mm512_cvtpd_ps(a.v)}; }
    static ZCHECK_LANE Real toReal(Float a) { return {_mm512_cvtps_pd(a.v)}; }
    static ZCHECK_LANE Real toReal(Int32 a) { return {_mm512_cvtepi32_pd(a.v)}; }
    static ZCHECK_LANE Int32 truncateToInt32(Real x) { return {_mm512_cvttpd_epi32(x.v)}; }
    static ZCHECK_LANE Real gather(Mask m, const double* table, Int32 index)
    {
        return {_mm512_mask_i32gather_pd(_mm512_setzero_pd(), m.k, index.v, table, 8)};
    }
    static ZCHECK_LANE void loadTriples(const float* p, Real (&xyz)[3])
    {
        const __m512 first16 = _mm512_loadu_ps(p);
        const __m512 last8 = _mm512_zextps256_ps512(_mm256_loadu_ps(p + 16));
        for (int k = 0; k < 3; ++k) {
            const __m512i corner = _mm512_add_epi32(_mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 21, 18, 15, 12, 9, 6, 3, 0), _mm512_set1_epi32(k));
            xyz[k] = {_mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_permutex2var_ps(first16, corner, last8)))};
        }
    }

    // 64-bit integers.
    static ZCHECK_LANE Int64 set1(std::int64_t x) { return {_mm512_set1_epi64(x)}; }
    static ZCHECK_LANE Int64 load(const std::int64_t* p) { return {_mm512_loadu_si512(p)}; }
    static ZCHECK_LANE Int64 steps(std::int64_t first, std::int64_t step)
    {
        return {_mm512_add_epi64(_mm512_set1_epi64(first), _mm512_mullo_epi64(_mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0), _mm512_set1_epi64(step)))};
    }
    static ZCHECK_LANE Int64 bitsOf(Real a) { return {_mm512_castpd_si512(a.v)}; }
    static ZCHECK_LANE Real realOfBits(Int64 a) { return {_mm512_castsi512_pd(a.v)}; }
    static ZCHECK_LANE void store(std::int64_t* p, Int64 a) { _mm512_storeu_si512(p, a.v); }
    template <int kShift>
    static ZCHECK_LANE Int64 shiftLeft(Int64 a) { return {_mm512_slli_epi64(a.v, kShift)}; }
    static ZCHECK_LANE Mask nonNegative(Int64 a) { return {_mm512_cmpge_epi64_mask(a.v, _mm512_setzero_si512())}; }
    static ZCHECK_LANE Mask isZero(Int64 a) { return {_mm512_cmpeq_epi64_mask(a.v, _mm512_setzero_si512())}; }
    static ZCHECK_LANE Int64 select(Mask m, Int64 ifTrue, Int64 ifFalse) { return {_mm512_mask_blend_epi64(m.k, ifFalse.v, ifTrue.v)}; }
    static ZCHECK_LANE Int64 joined(Int32 lo, Int32 hi)
    {
        return {_mm512_or_si512(_mm512_cvtepu32_epi64(lo.v), _mm512_slli_epi64(_mm512_cvtepu32_epi64(hi.v), 32))};
    }
    static ZCHECK_LANE Int32 lowHalves(Int64 a) { return {_mm512_cvtepi64_epi32(a.v)}; }
    static ZCHECK_LANE Int32 highHalves(Int64 a) { return {_mm512_cvtepi64_epi32(_mm512_srli_epi64(a.v, 32))}; }
    static ZCHECK_LANE Int64 gather(const void* base, Int64 index) { return {_mm512_i64gather_epi64(index.v, base, 8)}; }
    static ZCHECK_LANE Int64 widenUnsigned(Int32 a) { return {_mm512_cvtepu32_epi64(a.v)}; }
    static ZCHECK_LANE Int64 widen(Int32 a) { return {_mm512_cvtepi32_epi64(a.v)}; }
    static ZCHECK_LANE Int64 multiplySmall(Int64 a, Int64 b) { return {_mm512_mul_epi32(a.v, b.v)}; }
    static ZCHECK_LANE void storePairs(double* out, Real a, Int64 b)
    {
        const __m512d bAsDouble = _mm512_castsi512_pd(b.v);
        _mm512_storeu_pd(out, _mm512_permutex2var_pd(a.v, _mm512_set_epi64(11, 3, 10, 2, 9, 1, 8, 0), bAsDouble));
        _mm512_storeu_pd(out + 8, _mm512_permutex2var_pd(a.v, _mm512_set_epi64(15, 7, 14, 6, 13, 5, 12, 4), bAsDouble));
    }

    // 32-bit integers.
    static ZCHECK_LANE Int32 maskedLoad(Mask m, const std::uint32_t* p) { return {_mm256_maskz_loadu_epi32(m.k, p)}; }
    static ZCHECK_LANE void maskedStore(Mask m, std::uint32_t* p, Int32 a) { _mm256_mask_storeu_epi32(p, m.k, a.v); }
    static ZCHECK_LANE void maskedStore(Mask m, float* p, Float a) { _mm256_mask_storeu_ps(p, m.k, a.v); }
    static ZCHECK_LANE void storeBytes(std::uint8_t* p, Int32 a) { _mm_storel_epi64(reinterpret_cast<__m128i*>(p), _mm256_cvtepi32_epi8(a.v)); }
    static ZCHECK_LANE void maskedStoreBytes(Mask m, std::uint8_t* p, Int32 a) { _mm256_mask_cvtepi32_storeu_epi8(p, m.k, a.v); }
    static ZCHECK_LANE Mask equal(Int32 a, Int32 b) { return {_mm256_cmpeq_epi32_mask(a.v, b.v)}; }
    static ZCHECK_LANE Mask notEqual(Int32 a, Int32 b) { return {_mm256_cmpneq_epi32_mask(a.v, b.v)}; }
    static ZCHECK_LANE Mask lessOrEqual(Int32 a, Int32 b) { return {_mm256_cmple_epi32_mask(a.v, b.v)}; }
    static ZCHECK_LANE Mask anyBits(Int32 a) { return {_mm256_test_epi32_mask(a.v, a.v)}; }
    static ZCHECK_LANE Int32 select(Mask m, Int32 ifTrue, Int32 ifFalse) { return {_mm256_mask_blend_epi32(m.k, ifFalse.v, ifTrue.v)}; }
    static ZCHECK_LANE Int32 allOnesWhere(Mask m) { return {_mm256_movm_epi32(m.k)}; }
    static ZCHECK_LANE void loadTriples(const std::uint32_t* p, Int32 (&corner)[3])
    {
        const __m512i first16 = _mm512_loadu_si512(p);
        const __m512i last8 = _mm512_zextsi256_si512(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 16)));
        for (int k = 0; k < 3; ++k) {
            const __m512i index = _mm512_add_epi32(_mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 21, 18, 15, 12, 9, 6, 3, 0), _mm512_set1_epi32(k));
            corner[k] = {_mm512_castsi512_si256(_mm512_permutex2var_epi32(first16, index, last8))};
        }
    }
    static ZCHECK_LANE Int32 shiftedIn(Int32 a, Int32 before) { return {_mm256_alignr_epi32(a.v, before.v, 7)}; }
    // Mask32: the mask registers themselves.
    using Mask32 = Mask;
    static ZCHECK_LANE Mask toMask(Mask32 m) { return m; }
    static ZCHECK_LANE Mask32 firstLanes32(int n) { return firstLanes(n); }
    static ZCHECK_LANE Mask32 andNot32(Mask32 a, Mask32 b) { return andNot(a, b); }
    static ZCHECK_LANE unsigned bits32(Mask32 m) { return m.k; }
    static ZCHECK_LANE Mask32 equal32(Int32 a, Int32 b) { return equal(a, b); }
    static ZCHECK_LANE Mask32 atLeastUnsigned32(Int32 a, Int32 b) { return {_mm256_cmpge_epu32_mask(a.v, b.v)}; }
    static ZCHECK_LANE Int32 select32(Mask32 m, Int32 ifTrue, Int32 ifFalse) { return select(m, ifTrue, ifFalse); }
    static ZCHECK_LANE Int32 maskedLoad32(Mask32 m, const std::uint32_t* p) { return maskedLoad(m, p); }
    static ZCHECK_LANE void maskedStore32(Mask32 m, std::uint32_t* p, Int32 a) { maskedStore(m, p, a); }
    static ZCHECK_LANE Float zeroWhereNot32(Mask32 m, Float a) { return {_mm256_maskz_mov_ps(m.k, a.v)}; }
#undef ZCHECK_LANE
};

// ---------------------------------------------------------------------------------------------
// AVX2 + FMA, four lanes in one 256-bit register: the members the raster's pixel loop needs
// (drawInTileLanes), for the AVX2 form, where a row of a small triangle's pixels (the common
// case of a large mesh) fits one group of four and eight lanes in two registers did twice the work.
struct Avx2Lanes4 {
#define ZCHECK_LANE ZCHECK_TARGET_AVX2 inline
    static constexpr int kLanes = 4;
    static constexpr bool kFastMaskedStores = false;
    struct Mask {
        __m256i v;  // per 64-bit lane: all ones or zeros
        friend ZCHECK_LANE Mask operator&(Mask a, Mask b) { return {_mm256_and_si256(a.v, b.v)}; }
        friend ZCHECK_LANE Mask operator|(Mask a, Mask b) { return {_mm256_or_si256(a.v, b.v)}; }
    };
    struct Real {
        __m256d v;
        friend ZCHECK_LANE Real operator+(Real a, Real b) { return {_mm256_add_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Real operator-(Real a, Real b) { return {_mm256_sub_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Real operator*(Real a, Real b) { return {_mm256_mul_pd(a.v, b.v)}; }
        friend ZCHECK_LANE Mask operator<(Real a, Real b) { return {_mm256_castpd_si256(_mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ))}; }
    };
    struct Int64 {
        __m256i v;
        friend ZCHECK_LANE Int64 operator+(Int64 a, Int64 b) { return {_mm256_add_epi64(a.v, b.v)}; }
        friend ZCHECK_LANE Int64 operator|(Int64 a, Int64 b) { return {_mm256_or_si256(a.v, b.v)}; }
    };
    struct Int32 {
        __m128i v;
    };
    struct Float {
        __m128 v;
    };
    static ZCHECK_LANE Real set1(double x) { return {_mm256_set1_pd(x)}; }
    static ZCHECK_LANE Real load(const double* p) { return {_mm256_loadu_pd(p)}; }
    static ZCHECK_LANE void store(double* p, Real a) { _mm256_storeu_pd(p, a.v); }
    static ZCHECK_LANE Real select(Mask m, Real ifTrue, Real ifFalse) { return {_mm256_blendv_pd(ifFalse.v, ifTrue.v, _mm256_castsi256_pd(m.v))}; }
    static ZCHECK_LANE Real max(Real a, Real b) { return {_mm256_max_pd(a.v, b.v)}; }
    static ZCHECK_LANE Real min(Real a, Real b) { return {_mm256_min_pd(a.v, b.v)}; }
    static ZCHECK_LANE Float toFloat(Real a) { return {_mm256_cvtpd_ps(a.v)}; }
    static ZCHECK_LANE Real toReal(Float a) { return {_mm256_cvtps_pd(a.v)}; }
    static ZCHECK_LANE Int64 set1(std::int64_t x) { return {_mm256_set1_epi64x(x)}; }
    static ZCHECK_LANE Int64 steps(std::int64_t first, std::int64_t step)  // lane j: first + j·step, wrapping
    {
        const std::uint64_t f = std::uint64_t(first), s = std::uint64_t(step);
        return {_mm256_set_epi64x(std::int64_t(f + 3 * s), std::int64_t(f + 2 * s), std::int64_t(f + s), first)};
    }
    static ZCHECK_LANE Mask nonNegative(Int64 a) { return {_mm256_cmpgt_epi64(a.v, _mm256_set1_epi64x(-1))}; }
    static ZCHECK_LANE Int32 set1(std::int32_t x) { return {_mm_set1_epi32(x)}; }
    static ZCHECK_LANE Int32 load(const std::uint32_t* p) { return {_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))}; }
    static ZCHECK_LANE void store(std::uint32_t* p, Int32 a) { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), a.v); }
    // The mask with one 32-bit lane per lane.
    static ZCHECK_LANE __m128i narrow(Mask m)
    {
        return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(m.v, _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0)));
    }
    static ZCHECK_LANE Int32 select(Mask m, Int32 ifTrue, Int32 ifFalse) { return {_mm_blendv_epi8(ifFalse.v, ifTrue.v, narrow(m))}; }
#undef ZCHECK_LANE
};

// std::clamp(v, lo, hi) per lane: v < lo ? lo : hi < v ? hi : v, NaN and signed zeros included
// (max(lo, v) is lo > v ? lo : v, min(hi, w) is hi < w ? hi : w: the same choices).
template <class L>
ZCHECK_ALWAYS_INLINE inline typename L::Real clampLanes(typename L::Real v, typename L::Real lo, typename L::Real hi)
{
    return L::min(hi, L::max(lo, v));
}

#undef ZCHECK_LANES32_NAMES
ZCHECK_INTRINSICS_END

}  // namespace zcheck

#endif  // ZCHECK_X86_FORMS
