#include "zcheck/kernel_form.h"

#include "zcheck/detail/kernel_choice.h"
#include "zcheck/error.h"

#include <cstdlib>
#include <cstring>
#include <string>

namespace zcheck {

bool kernelFormSupported(KernelForm form)
{
    switch (form) {
    case KernelForm::Baseline: return true;
#ifdef ZCHECK_X86_FORMS
    case KernelForm::Avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case KernelForm::Avx512:
        return kernelFormSupported(KernelForm::Avx2) && __builtin_cpu_supports("avx512f") &&
               __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
    case KernelForm::Avx2:
    case KernelForm::Avx512: return false;
#endif
    }
    return false;
}

const char* nameOf(KernelForm form)
{
    switch (form) {
    case KernelForm::Baseline: return "baseline";
    case KernelForm::Avx2: return "avx2";
    case KernelForm::Avx512: return "avx512";
    }
    return "?";
}

KernelForm kernelForm()
{
    const char* requested = std::getenv("ZCHECK_KERNELS");
    if (!requested || !*requested || std::strcmp(requested, "auto") == 0) {
        for (KernelForm form : {KernelForm::Avx512, KernelForm::Avx2})
            if (kernelFormSupported(form)) return form;
        return KernelForm::Baseline;
    }
    for (KernelForm form : {KernelForm::Baseline, KernelForm::Avx2, KernelForm::Avx512}) {
        if (std::strcmp(requested, nameOf(form)) != 0) continue;
        if (!kernelFormSupported(form))
            throw Error(std::string("ZCHECK_KERNELS=") + requested + ": this processor cannot run the " + requested +
                        " form (" + (form == KernelForm::Avx2 ? "it needs AVX2 and FMA" : "it needs AVX-512 F, DQ and VL") +
                        "); use auto, or a form it has");
        return form;
    }
    throw Error(std::string("ZCHECK_KERNELS=") + requested + ": must be auto, baseline, avx2 or avx512");
}

}  // namespace zcheck
