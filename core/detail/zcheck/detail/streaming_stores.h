#pragma once
// Internal to zcheck (core/detail, never installed): huge-page advice for vectors a reader sizes
// itself, and rows streamed into frame-sized images (large_buffer.h holds the buffers).
#include "zcheck/large_buffer.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace zcheck {

// Advises huge pages for the whole pages inside [data, data + bytes); small ranges are left alone.
void adviseHugePages(void* data, std::size_t bytes);

// v.reserve(n), with the new storage (if any) advised huge pages before it is first touched.
// For a reader that knows its item count up front: one allocation, no growth by copying into
// fresh pages. n must be a count the input has been checked to hold, not one it merely declares.
template <class T>
void reserveLarge(std::vector<T>& v, std::size_t n)
{
    if (n <= v.capacity()) return;
    std::vector<T> bigger;
    bigger.reserve(n);
    adviseHugePages(bigger.data(), n * sizeof(T));
    bigger.insert(bigger.end(), v.begin(), v.end());
    v.swap(bigger);
}

// A row of n values copied into a frame-sized image that is written once and read back only
// much later (a render's result): with streaming stores where the destination is whole cache
// lines, which ordinary stores would first read in for nothing and then keep in the cache in
// place of what the writer works on; with std::memcpy elsewhere. After its last such copy, a
// thread calls finishStreamingCopies before another may read what it wrote.
//
//   for (int r = 0; r < rows; ++r) copyRowStreaming(tile + r * side, width, image + r * stride);
//   finishStreamingCopies();
template <class T>
void copyRowStreaming(const T* from, std::size_t n, T* to)
{
    static_assert(std::is_trivially_copyable<T>::value && 16 % sizeof(T) == 0, "whole values per 16 bytes");
    const std::size_t bytes = sizeof(T) * n;
#ifdef __SSE2__
    if (reinterpret_cast<std::uintptr_t>(to) % 64 == 0 && bytes % 64 == 0) {
        for (std::size_t offset = 0; offset < bytes; offset += 16)
            _mm_stream_si128(reinterpret_cast<__m128i*>(reinterpret_cast<char*>(to) + offset),
                             _mm_loadu_si128(reinterpret_cast<const __m128i*>(reinterpret_cast<const char*>(from) + offset)));
        return;
    }
#endif
    std::memcpy(to, from, bytes);
}

inline void finishStreamingCopies()
{
#ifdef __SSE2__
    _mm_sfence();
#endif
}

}  // namespace zcheck
