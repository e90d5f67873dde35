#pragma once
// Internal to zcheck (core/detail, never installed).
// The choice, at run time, between a routine's AVX-512 form and its baseline form.
//
// The raster's vector kernels and the comparison's row pass (hand-written, eight lanes at a
// time), the trace and the rest of the comparison (the same source compiled twice, once for
// AVX-512) run their AVX-512 forms where the processor has AVX-512 F, DQ and VL, and their
// baseline forms elsewhere. The two forms do the same IEEE operations in the same order (the
// build has -ffp-contract=off, so no multiply and add are fused into one rounding), so their
// outputs are bit-identical; the tests run both and compare them bit for bit. An environment
// variable per stage forces the baseline form:
//
//   ZCHECK_RASTER_KERNEL=scalar     the raster's scalar loops
//   ZCHECK_RAY_KERNEL=baseline      the trace compiled for the build's baseline (x86-64: SSE2)
//   ZCHECK_COMPARE_KERNEL=baseline  the comparison's row pass (its lane loops) and slopes, likewise
//
// A variable unset, empty or `auto` lets the processor decide.
//
//   ZCHECK_ALWAYS_INLINE inline void drawBody(...) { ... }       // one source ...
//   void drawBaseline(...) { drawBody(...); }
//   #ifdef ZCHECK_X86_AVX512
//   ZCHECK_TARGET_AVX512 void drawAvx512(...) { drawBody(...); } // ... compiled twice
//   #endif
//   auto* draw = &drawBaseline;
//   #ifdef ZCHECK_X86_AVX512
//   if (useAvx512Form("ZCHECK_RAY_KERNEL", "baseline")) draw = &drawAvx512;
//   #endif
//
// Read the choice once per render or frame, on the calling thread (not per tile on the
// workers: a program may change its environment meanwhile).

// A function inlined wherever it is called, also into a function compiled for other
// instructions (a body shared by two forms, and the lambdas inside it, must be).
#define ZCHECK_ALWAYS_INLINE __attribute__((always_inline))

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define ZCHECK_X86_AVX512 1
// A function compiled for AVX-512 F, DQ and VL; its callers check useAvx512Form first.
#define ZCHECK_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl")))
#endif

// Around hand-written intrinsics: GCC 12's intrinsics headers start many conversions from an
// "undefined" vector, which its -W(maybe-)uninitialized then reports inside the headers (GCC
// bug 105593).
#if defined(__GNUC__) && !defined(__clang__)
#define ZCHECK_INTRINSICS_BEGIN                                                                  \
    _Pragma("GCC diagnostic push") _Pragma("GCC diagnostic ignored \"-Wmaybe-uninitialized\"") \
        _Pragma("GCC diagnostic ignored \"-Wuninitialized\"")
#define ZCHECK_INTRINSICS_END _Pragma("GCC diagnostic pop")
#else
#define ZCHECK_INTRINSICS_BEGIN
#define ZCHECK_INTRINSICS_END
#endif

namespace zcheck {

// Whether the AVX-512 form runs: the processor has AVX-512 F, DQ and VL (and the build
// targets x86-64), and the environment variable `variable` is unset, empty or "auto", not
// `baselineValue`. Any other value throws Error naming the variable, the value and the two
// allowed. Reads the environment on every call (cheap next to a render).
bool useAvx512Form(const char* variable, const char* baselineValue);

}  // namespace zcheck
