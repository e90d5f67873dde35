#include "zcheck/detail/kernel_choice.h"

#include "zcheck/error.h"

#include <cstdlib>
#include <cstring>
#include <string>

namespace zcheck {

bool useAvx512Form(const char* variable, const char* baselineValue)
{
    const char* requested = std::getenv(variable);
    if (requested && std::strcmp(requested, baselineValue) == 0) return false;
    if (requested && *requested && std::strcmp(requested, "auto") != 0)
        throw Error(std::string(variable) + "=" + requested + ": must be 'auto' or '" + baselineValue + "'");
#ifdef ZCHECK_X86_AVX512
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
    return false;
#endif
}

}  // namespace zcheck
