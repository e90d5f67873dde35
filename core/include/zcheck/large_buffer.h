#pragma once
// Per-frame buffers of a million pixels or triangles, filled without a page fault per 4 KiB.
//
// A fresh buffer is faulted in by the kernel page by page on first touch. On the 1M-triangle
// 1080p workload that was most of the time of a check (the raster route 150 ms instead of
// 39 ms, on a virtual machine where a fault is dear). Asking for transparent huge pages
// (madvise MADV_HUGEPAGE, honoured where /sys/kernel/mm/transparent_hugepage/enabled is
// `madvise` or `always`) cuts the faults 512-fold. Elsewhere the advice is ignored and only
// the speed differs.
//
//   std::vector<double> depth;
//   zcheck::assignLarge(depth, width * height, clearValue);  // = depth.assign(n, clearValue)
//   zcheck::reserveLarge(scene.triangles, faceCount);        // = triangles.reserve(faceCount)
#include <cstddef>
#include <vector>

namespace zcheck {

// Advises huge pages for the whole pages inside [data, data + bytes); small ranges are left alone.
void adviseHugePages(void* data, std::size_t bytes);

// v.assign(n, value), with the new storage advised huge pages before it is first touched.
template <class T>
void assignLarge(std::vector<T>& v, std::size_t n, const T& value)
{
    std::vector<T>().swap(v);
    v.reserve(n);  // allocates, touches nothing
    adviseHugePages(v.data(), n * sizeof(T));
    v.assign(n, value);
}

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

}  // namespace zcheck
