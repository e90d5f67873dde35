#pragma once
// The lanes set in a mask of one byte per lane (0 or 1), in increasing order, found eight at a
// time: for the masks of the lane loops (kernel_choice.h) where a few lanes of many are set, so
// that a loop over them takes no branch per lane.
//
//   alignas(64) std::uint8_t sample[64];   // 0 or 1 per lane, computed lane by lane
//   forEachSetLane(sample, n, [&](std::size_t j) { sum += value[j]; });  // in lane order
//
// Bytes [0, n) are the mask; bytes from n up to n rounded up to 8 are read and ignored (the
// array must hold them). Always inlined, so that each form of a kernel compiles its own copy.
#include "zcheck/kernel_choice.h"

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace zcheck {

template <class Visit>
ZCHECK_ALWAYS_INLINE inline void forEachSetLane(const std::uint8_t* mask, std::size_t n, Visit&& visit)
{
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "byte k of a mask word is lane w + k");
    for (std::size_t w = 0; w < n; w += 8) {
        std::uint64_t word;
        std::memcpy(&word, mask + w, sizeof word);
        if (n - w < 8) word &= (std::uint64_t(1) << (8 * (n - w))) - 1;
        for (; word != 0; word &= word - 1) visit(w + std::size_t(__builtin_ctzll(word) >> 3));
    }
}

}  // namespace zcheck
