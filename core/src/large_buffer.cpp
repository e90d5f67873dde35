#include "zcheck/large_buffer.h"

#include "zcheck/detail/streaming_stores.h"
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <new>

namespace zcheck {

namespace {

constexpr std::size_t kHugePage = std::size_t(2) << 20;
// From here up a buffer gets whole huge pages of its own, below 2 MiB too: a 1080p image of
// one byte a pixel (2,073,600 bytes) from operator new was mostly a fresh glibc mmap, faulted
// in 4 KiB at a time (~480 of the faults of a comparison made right after its renders), where
// one huge page takes one fault and one entry of the address cache. (The time those faults
// took was within the noise of this machine: the kernel's zeroing of the pages dominates, and
// that is the same either way.) A buffer of 1 to 2 MiB leaves at most half of its page unused.
constexpr std::size_t kLargeFrom = kHugePage / 2;
// From here up to kLargeFrom a buffer is whole pages of its own (rounded up to kMediumStep),
// kept when released as the large ones are: per-frame scratch of tens to hundreds of KiB (a
// comparison's keepers, ~160 KiB each at 1080p) was given back by glibc as soon as it was
// freed and faulted in again the next frame, ~150 faults a warm comparison.
constexpr std::size_t kKeptFrom = std::size_t(64) << 10;
constexpr std::size_t kMediumStep = kKeptFrom;
constexpr std::size_t kPage = 4096;
constexpr std::size_t kCacheLimit = std::size_t(1) << 30;        // bytes the huge-page blocks' cache may hold at most
constexpr std::size_t kMediumCacheLimit = std::size_t(64) << 20;  // and the medium blocks' (a frame's scratch)

// Blocks of one class (whole huge pages, or whole medium steps) that were released, kept
// faulted in for an allocation of the same rounded size (the next frame's buffers), up to
// `limit` bytes. An allocation that finds none (take returns null) has every kept block of both
// classes released before it maps new memory (allocateLarge), so that the caches never raise
// the peak of the memory allocateLarge holds: what they keep was in use together before, and
// is given back before more is mapped. Blocks are given back outside the lock.
class BlockCache {
public:
    using GiveBack = void (*)(void* data, std::size_t bytes) noexcept;
    BlockCache(std::size_t limit, GiveBack giveBack) : limit_(limit), giveBack_(giveBack) {}

    // A kept block of `rounded` bytes, or null (none: the caller releases every kept block).
    void* take(std::size_t rounded)
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        for (std::size_t k = 0; k < kept_.count; ++k)
            if (kept_.block[k].bytes == rounded) {
                void* data = kept_.block[k].data;
                held_ -= rounded;
                kept_.block[k] = kept_.block[--kept_.count];
                return data;
            }
        return nullptr;
    }
    void keep(void* data, std::size_t rounded) noexcept
    {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            if (held_ + rounded <= limit_ && kept_.count < kMaxBlocks) {
                kept_.block[kept_.count++] = {data, rounded};
                held_ += rounded;
                return;
            }
        }
        giveBack_(data, rounded);
    }
    void releaseAll() noexcept
    {
        Blocks released;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            released = takeAllLocked();
        }
        freeAll(released);
    }
    std::size_t held() noexcept
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        return held_;
    }

private:
    static constexpr std::size_t kMaxBlocks = 256;  // a frame's keepers: two a thread
    struct Block {
        void* data;
        std::size_t bytes;
    };
    struct Blocks {  // a fixed array: keeping a block never allocates
        std::array<Block, kMaxBlocks> block;
        std::size_t count = 0;
    };
    // Every kept block, handed out to be freed outside the lock.
    Blocks takeAllLocked() noexcept
    {
        const Blocks all = kept_;
        kept_.count = 0;
        held_ = 0;
        return all;
    }
    void freeAll(const Blocks& blocks) const noexcept
    {
        for (std::size_t k = 0; k < blocks.count; ++k) giveBack_(blocks.block[k].data, blocks.block[k].bytes);
    }
    const std::size_t limit_;
    const GiveBack giveBack_;
    std::mutex mutex_;
    Blocks kept_;
    std::size_t held_ = 0;
};

// A medium block is mapped for itself and unmapped when given back: from glibc's heap, one
// given back held its old contents after malloc_trim (a "cold" frame's memory was not new).
// Under AddressSanitizer it comes from the sanitizer's allocator, which watches it.
#if defined(__SANITIZE_ADDRESS__)
void* mapMedium(std::size_t bytes) { return std::aligned_alloc(kPage, bytes); }
void unmapMedium(void* data, std::size_t) noexcept { std::free(data); }
#else
void* mapMedium(std::size_t bytes)
{
    void* data = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    return data == MAP_FAILED ? nullptr : data;
}
void unmapMedium(void* data, std::size_t bytes) noexcept { munmap(data, bytes); }
#endif

// The caches of huge-page blocks (from std::aligned_alloc) and of medium ones (mapMedium).
// Never destroyed: buffers may be released by static destructors after this file's ones ran.
BlockCache& blockCache()
{
    static BlockCache* cache = new BlockCache(kCacheLimit, [](void* data, std::size_t) noexcept { std::free(data); });
    return *cache;
}
BlockCache& mediumBlockCache()
{
    static BlockCache* cache = new BlockCache(kMediumCacheLimit, unmapMedium);
    return *cache;
}

void releaseBothCaches() noexcept
{
    blockCache().releaseAll();
    mediumBlockCache().releaseAll();
}

// A kept block of `rounded` bytes from `cache`, else new memory from `allocate` (null: none),
// every kept block of both classes given back before it is mapped.
void* keptOrNew(BlockCache& cache, std::size_t rounded, void* (*allocate)(std::size_t bytes))
{
    if (void* reused = cache.take(rounded)) return reused;
    releaseBothCaches();
    void* data = allocate(rounded);
    if (!data) throw std::bad_alloc();
    return data;
}

// A huge-page block: 2 MiB-aligned and advised huge pages before it is first touched.
void* allocateHugePages(std::size_t bytes)
{
    void* data = std::aligned_alloc(kHugePage, bytes);
    if (data) adviseHugePages(data, bytes);
    return data;
}

// A block's size: whole steps (wraps to less than `bytes` only for impossible sizes).
std::size_t roundedUp(std::size_t bytes, std::size_t step) noexcept { return (bytes + step - 1) / step * step; }

}  // namespace

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
    if (bytes < kKeptFrom) return ::operator new(bytes);
    if (bytes < kLargeFrom) return keptOrNew(mediumBlockCache(), roundedUp(bytes, kMediumStep), mapMedium);
    const std::size_t rounded = roundedUp(bytes, kHugePage);
    if (rounded < bytes) throw std::bad_alloc();
    return keptOrNew(blockCache(), rounded, allocateHugePages);
}

void releaseLarge(void* data, std::size_t bytes) noexcept
{
    if (bytes < kKeptFrom) {
        ::operator delete(data);
    } else if (bytes < kLargeFrom) {
        mediumBlockCache().keep(data, roundedUp(bytes, kMediumStep));
    } else {
        blockCache().keep(data, roundedUp(bytes, kHugePage));
    }
}

void releaseCachedLargeBuffers() noexcept
{
    releaseBothCaches();
#ifdef __GLIBC__
    malloc_trim(0);  // the heap's free pages too, not only those at its top
#endif
}

std::size_t cachedLargeBufferBytes() noexcept { return blockCache().held() + mediumBlockCache().held(); }

}  // namespace zcheck
