#include "zcheck/large_buffer.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <new>

namespace zcheck {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
}

void adviseHugePages(void* data, std::size_t bytes)
{
    if (bytes < kHugePage) return;  // nothing a huge page could hold
    const auto page = std::uintptr_t(sysconf(_SC_PAGESIZE));
    const auto begin = (std::uintptr_t(data) + page - 1) / page * page;
    const auto end = (std::uintptr_t(data) + bytes) / page * page;
    // Advice only: a kernel without transparent huge pages answers EINVAL, and nothing changes.
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

void* allocateLarge(std::size_t bytes)
{
    if (bytes < kHugePage) return ::operator new(bytes);
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    if (rounded < bytes) throw std::bad_alloc();
    void* data = std::aligned_alloc(kHugePage, rounded);
    if (!data) throw std::bad_alloc();
    adviseHugePages(data, rounded);
    return data;
}

void releaseLarge(void* data, std::size_t bytes) noexcept
{
    if (bytes < kHugePage) {
        ::operator delete(data);
    } else {
        std::free(data);
    }
}

}  // namespace zcheck
