#include "zcheck/large_buffer.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <new>
#include <vector>

namespace zcheck {

namespace {

constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kCacheLimit = std::size_t(1) << 30;  // bytes the cache may hold at most

// Blocks of 2 MiB and more that were released, kept faulted in for an allocation of the
// same rounded size (the next frame's buffers). An allocation that finds none releases them
// all before it maps new memory, so that the cache never raises the peak of the memory
// allocateLarge holds: what it keeps was in use together before, and is given back before
// more is mapped. Blocks are freed outside the lock.
class BlockCache {
public:
    void* take(std::size_t rounded)
    {
        std::vector<Block> released;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            for (std::size_t k = 0; k < blocks_.size(); ++k)
                if (blocks_[k].bytes == rounded) {
                    void* data = blocks_[k].data;
                    held_ -= rounded;
                    blocks_[k] = blocks_.back();
                    blocks_.pop_back();
                    return data;
                }
            if (blocks_.empty()) return nullptr;
            released.swap(blocks_);
            blocks_.reserve(released.capacity());  // keep() never allocates
            held_ = 0;
        }
        for (const Block& block : released) std::free(block.data);
        return nullptr;
    }
    void keep(void* data, std::size_t rounded) noexcept
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (held_ + rounded <= kCacheLimit && blocks_.size() < blocks_.capacity()) {
            blocks_.push_back({data, rounded});
            held_ += rounded;
        } else {
            std::free(data);
        }
    }
    void releaseAll() noexcept
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        releaseAllLocked();
    }
    std::size_t held() noexcept
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        return held_;
    }
    BlockCache() { blocks_.reserve(64); }  // keep() never allocates

private:
    struct Block {
        void* data;
        std::size_t bytes;
    };
    void releaseAllLocked() noexcept
    {
        for (const Block& block : blocks_) std::free(block.data);
        blocks_.clear();
        held_ = 0;
    }
    std::mutex mutex_;
    std::vector<Block> blocks_;
    std::size_t held_ = 0;
};

// Never destroyed: buffers may be released by static destructors after this file's ones ran.
BlockCache& blockCache()
{
    static BlockCache* cache = new BlockCache;
    return *cache;
}

// A block's size: whole huge pages (wraps to less than `bytes` only for impossible sizes).
std::size_t roundedToHugePages(std::size_t bytes) noexcept { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

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
    if (bytes < kHugePage) return ::operator new(bytes);
    const std::size_t rounded = roundedToHugePages(bytes);
    if (rounded < bytes) throw std::bad_alloc();
    if (void* reused = blockCache().take(rounded)) return reused;
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
        blockCache().keep(data, roundedToHugePages(bytes));
    }
}

void releaseCachedLargeBuffers() noexcept { blockCache().releaseAll(); }

std::size_t cachedLargeBufferBytes() noexcept { return blockCache().held(); }

}  // namespace zcheck
