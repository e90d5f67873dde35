#include "zcheck/large_buffer.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>

namespace zcheck {

void adviseHugePages(void* data, std::size_t bytes)
{
    constexpr std::size_t kHugePage = std::size_t(2) << 20;
    if (bytes < kHugePage) return;  // nothing a huge page could hold
    const auto page = std::uintptr_t(sysconf(_SC_PAGESIZE));
    const auto begin = (std::uintptr_t(data) + page - 1) / page * page;
    const auto end = (std::uintptr_t(data) + bytes) / page * page;
    // Advice only: a kernel without transparent huge pages answers EINVAL, and nothing changes.
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

}  // namespace zcheck
