#pragma once
// Per-frame buffers of a million pixels or triangles, filled without a page fault per 4 KiB,
// and a frame's scratch of tens of KiB and more, kept from frame to frame.
//
// A fresh buffer is faulted in by the kernel page by page on first touch. On the 1M-triangle
// 1080p workload that was most of the time of a check (the raster route 150 ms instead of
// 39 ms, on a virtual machine where a fault is dear). Asking for transparent huge pages
// (madvise MADV_HUGEPAGE, honoured where /sys/kernel/mm/transparent_hugepage/enabled is
// `madvise` or `always`) cuts the faults 512-fold. Elsewhere the advice is ignored and only
// the speed differs.
//
// The advice works only on whole 2 MiB pages: a buffer that std::allocator places on a 4 KiB
// boundary (glibc's mmap) or in the heap was faulted in 4 KiB at a time after all, 7-30 ms
// for 16 MiB here against 1.3-1.5 ms on aligned huge pages (the 1080p window depth cleared
// before each render took 12-30 ms of the raster's 45). LargeVector's allocator places large
// buffers on 2 MiB boundaries, and leaves elements it makes with no value uninitialised, so
// that a buffer every element of which is written anyway (a render's pixels) is faulted in
// by the threads that write it, once, and not cleared first by one thread.
//
//   zcheck::LargeVector<double> depth;
//   depth.resize(width * height);                            // uninitialised: write every element
//   depth.assign(width * height, clearValue);                // on huge pages, every element set
//
// (Huge-page advice for other vectors and streaming stores into such buffers are zcheck's own:
// zcheck/detail/streaming_stores.h, not installed.)
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace zcheck {

// Memory for `bytes`: from 1 MiB up, whole 2 MiB pages on a 2 MiB boundary, advised huge
// pages (a 1080p byte-per-pixel image fits one); from 64 KiB, whole pages mapped for it,
// rounded up to 64 KiB (a frame's scratch: a comparison's keepers); smaller from operator new. Release with releaseLarge and the same byte count. Throws std::bad_alloc.
//
// Released blocks of 64 KiB and more are kept (huge-page blocks up to 1 GiB, the others up to
// 64 MiB), already faulted in, and handed back to the next allocation of the same rounded
// size: a program that renders frame after frame pays the page faults of its buffers once,
// not per frame (as a GPU driver's reused framebuffer does). An allocation that finds no block
// of its size first releases every kept one, so the cache never raises the peak of the memory
// these functions hold: it keeps only memory that was in use together, and gives it back
// before more is mapped. It does keep that memory resident until then, while
// the rest of the process (a mesh, a BVH, other allocations) may grow: a long-lived program
// that is done rendering calls releaseCachedLargeBuffers. Thread-safe. The contents of a
// reused block are whatever its last user left.
void* allocateLarge(std::size_t bytes);
void releaseLarge(void* data, std::size_t bytes) noexcept;
// Gives every kept block back to the system, and has the C library give back the free memory
// its heap holds (glibc keeps freed blocks of up to its raised mmap threshold, tens of MiB,
// and hands them out again faulted in): the next large buffers are fresh memory, and a first
// frame measured as a fresh process pays what one pays. Takes milliseconds; not per frame.
void releaseCachedLargeBuffers() noexcept;
// The bytes the kept blocks hold.
std::size_t cachedLargeBufferBytes() noexcept;

// std::allocator's contract, with memory from allocateLarge and elements made with no value
// default-initialised (an int or a double is then left as it was, not zeroed).
template <class T>
struct LargeBufferAllocator {
    using value_type = T;

    LargeBufferAllocator() = default;
    template <class U>
    LargeBufferAllocator(const LargeBufferAllocator<U>&) noexcept {}

    T* allocate(std::size_t n)
    {
        static_assert(alignof(T) <= __STDCPP_DEFAULT_NEW_ALIGNMENT__, "small blocks come from plain operator new");
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_alloc();
        return static_cast<T*>(allocateLarge(n * sizeof(T)));
    }
    void deallocate(T* data, std::size_t n) noexcept { releaseLarge(data, n * sizeof(T)); }

    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value)
    {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args)
    {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }

    template <class U>
    bool operator==(const LargeBufferAllocator<U>&) const noexcept { return true; }
    template <class U>
    bool operator!=(const LargeBufferAllocator<U>&) const noexcept { return false; }
};

// A per-frame buffer: a std::vector on pages of its own (aligned huge pages from 1 MiB) whose
// resize() leaves new elements of trivial types uninitialised.
template <class T>
using LargeVector = std::vector<T, LargeBufferAllocator<T>>;

}  // namespace zcheck
