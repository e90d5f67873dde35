#pragma once
// Internal to zcheck (core/detail, never installed).
// How a kernel comes in its three forms (zcheck/kernel_form.h: baseline, AVX2 + FMA, AVX-512)
// and how one is chosen at run time.
//
// A kernel is written once. Its vector steps are a template over a lane type (lanes.h:
// Avx2Lanes, Avx512Lanes — eight lanes of each, the same operations); its scalar steps are
// plain code the compiler vectorises for each target. One entry function per form compiles the
// one body for that form's instructions:
//
//   template <class Lanes> ZCHECK_ALWAYS_INLINE inline void drawBody(...) { ... }  // one source ...
//   void drawBaseline(...) { drawScalar(...); }
//   #ifdef ZCHECK_X86_FORMS
//   ZCHECK_KERNEL_ENTRY_AVX2 void drawAvx2(...) { drawBody<Avx2Lanes>(...); }       // ... compiled
//   ZCHECK_KERNEL_ENTRY_AVX512 void drawAvx512(...) { drawBody<Avx512Lanes>(...); } // per form
//   #endif
//   auto* draw = formOf<decltype(&drawBaseline)>(kernelForm(), drawBaseline, drawAvx2, drawAvx512);
//
// An entry function is `flatten`: everything it calls that can be inlined is, recursively, so
// that no step of its body (nor a lane operation, nor a lambda) stays a call into code compiled
// for another target. The forms do the same IEEE operations in the same order (the build has
// -ffp-contract=off, so no multiply and add are fused into one rounding), so their outputs
// are bit-identical; the tests run each form the processor has and compare them bit for bit.
//
// Read the choice once per render, frame or comparison, on the calling thread (not per tile on
// the workers: a program may change its environment meanwhile).
#include "zcheck/kernel_form.h"

// A function inlined wherever it is called, also into a function compiled for other
// instructions (a body shared by the forms, and the lambdas inside it).
#define ZCHECK_ALWAYS_INLINE __attribute__((always_inline))

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define ZCHECK_X86_FORMS 1
// x86-64-v3's vector and bit instructions (AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C); the AVX-512
// target includes them all, so that an AVX2 helper inlines into an AVX-512 function too.
#define ZCHECK_TARGET_AVX2 __attribute__((target("avx,avx2,fma,bmi,bmi2,lzcnt,movbe,f16c,popcnt")))
#define ZCHECK_TARGET_AVX512 \
    __attribute__((target("avx,avx2,fma,bmi,bmi2,lzcnt,movbe,f16c,popcnt,avx512f,avx512dq,avx512vl")))
// A form's entry function: its target, and everything it calls inlined into it (above).
#define ZCHECK_KERNEL_ENTRY_AVX2 ZCHECK_TARGET_AVX2 __attribute__((flatten))
#define ZCHECK_KERNEL_ENTRY_AVX512 ZCHECK_TARGET_AVX512 __attribute__((flatten))
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

// The function of `form` among a kernel's three entry functions (the vector ones exist where
// ZCHECK_X86_FORMS is defined; elsewhere kernelForm() is always Baseline).
template <class Function>
Function formOf(KernelForm form, Function baseline, [[maybe_unused]] Function avx2, [[maybe_unused]] Function avx512)
{
    switch (form) {
    case KernelForm::Avx2: return avx2;
    case KernelForm::Avx512: return avx512;
    case KernelForm::Baseline: break;
    }
    return baseline;
}

}  // namespace zcheck
