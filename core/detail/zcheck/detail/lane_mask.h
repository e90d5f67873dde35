#pragma once
// Internal to zcheck (core/detail, never installed).
// The lanes set in a mask of one byte per lane (0 or 1), in increasing order: for the masks
// of the lane loops (kernel_choice.h) where a few lanes of many are set, so that a loop over
// them takes no branch per lane, and none per eight lanes either. Each 64 lanes' bytes are
// packed into one 64-bit word of bits first (eight bytes per multiplication), then its set
// bits are walked.
//
//   alignas(64) std::uint8_t sample[64];   // 0 or 1 per lane, computed lane by lane
//   forEachSetLane(sample, n, [&](std::size_t j) { sum += value[j]; });  // in lane order
//
// Bytes [0, n) are the mask; bytes from n up to n rounded up to 8 are read and ignored (the
// array must hold them). Always inlined, so that each form of a kernel compiles its own copy.
#include "zcheck/detail/kernel_choice.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace zcheck {

// Lane k's byte (0 or 1) of an 8-byte word, as bit k: the product's top byte gathers bit 8k
// of the word at bit 56 + k, and no other term or carry reaches it.
ZCHECK_ALWAYS_INLINE inline std::uint64_t laneBitsOfBytes(std::uint64_t word)
{
    return (word * 0x0102040810204080ull) >> 56;
}

// The bytes of mask[0, n), n <= 64, as bits: lane k's as bit k.
ZCHECK_ALWAYS_INLINE inline std::uint64_t laneBits(const std::uint8_t* mask, std::size_t n)
{
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "byte k of a mask word is lane w + k");
    std::uint64_t bits = 0;
    for (std::size_t w = 0; w < n; w += 8) {
        std::uint64_t word;
        std::memcpy(&word, mask + w, sizeof word);
        if (n - w < 8) word &= (std::uint64_t(1) << (8 * (n - w))) - 1;
        bits |= laneBitsOfBytes(word) << w;
    }
    return bits;
}

// visit(k) for each bit k set in `bits`, in increasing order.
template <class Visit>
ZCHECK_ALWAYS_INLINE inline void forEachSetBit(std::uint64_t bits, Visit&& visit)
{
    for (; bits != 0; bits &= bits - 1) visit(std::size_t(__builtin_ctzll(bits)));
}

template <class Visit>
ZCHECK_ALWAYS_INLINE inline void forEachSetLane(const std::uint8_t* mask, std::size_t n, Visit&& visit)
{
    for (std::size_t first = 0; first < n; first += 64)
        forEachSetBit(laneBits(mask + first, std::min<std::size_t>(64, n - first)),
                      [&](std::size_t k) ZCHECK_ALWAYS_INLINE { visit(first + k); });
}

}  // namespace zcheck
