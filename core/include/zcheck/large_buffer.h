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

}  // namespace zcheck
