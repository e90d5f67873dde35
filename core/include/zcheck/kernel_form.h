#pragma once
// The form zcheck's kernels run in: the trace's steps around Embree, the raster's vertex
// stage, set-up and pixels, and the comparison's row pass, each compiled for three
// instruction sets and chosen at run time.
//
//   baseline  the build's baseline (x86-64: SSE2), on any processor
//   avx2      AVX2 + FMA (x86-64-v3: Haswell, Zen and later), eight lanes in two 256-bit registers
//   avx512    AVX-512 F, DQ and VL, eight lanes in one 512-bit register and mask registers
//
// Every form does the same IEEE operations in the same order (the build has -ffp-contract=off:
// no multiply and add are fused into one rounding, FMA or not), so every form's output is
// bit-identical to the baseline's; the tests compare them bit for bit in each form the
// processor has.
//
// The environment variable ZCHECK_KERNELS chooses: unset, empty or `auto` takes the widest form
// the processor has; `baseline`, `avx2` or `avx512` forces that form, and is refused (Error, one
// line) where the processor lacks it or the value is none of these.
//
//   const zcheck::KernelForm form = zcheck::kernelForm();   // throws Error for a bad ZCHECK_KERNELS
//   std::cout << zcheck::nameOf(form);                       // "avx2"
//
// The choice is read when a renderer, frame or comparison is made (not per tile: a program may
// change its environment meanwhile).

namespace zcheck {

enum class KernelForm { Baseline, Avx2, Avx512 };

// The form ZCHECK_KERNELS and the processor give (above). Reads the environment on each call.
KernelForm kernelForm();
// Whether this processor (and this build) can run `form`.
bool kernelFormSupported(KernelForm form);
// "baseline", "avx2", "avx512".
const char* nameOf(KernelForm form);

}  // namespace zcheck
