#pragma once
// Private to zcheck_check (check/src/): the comparison's percentiles.
// The 99th percentile of many non-negative binary32 values in one pass, without storing them
// all: the comparison's p99 of |Δ|/q and of the relative eye-z error over two million pixels.
//
// The percentile of n values is the value at rank ⌈0.99·n⌉ − 1 of the sorted values, which
// lies among the n − rank ≤ n/100 + 1 largest. Each thread keeps only its own `keep` largest
// (choose keep ≥ n/100 + 1 for the largest n possible), and the percentile is selected from
// what all threads kept: exact, and the same whichever thread saw which value. A value above
// a keeper's threshold is appended; when 2·keep have gathered, the largest keep are selected
// and the threshold raised: O(1) per value however the values arrive. A `floor` (for example
// floorBelowPercentile99 of a sample) keeps nothing below it from the start: far fewer values
// kept and no re-selection, and if it was too high after all, percentile99 says so.
// Values are ordered by their bit patterns, as non-negative floats order (a NaN above +inf).
//
//   LargestValues mine(width * height / 100 + 2);                // one per thread
//   mine.add(float(errorQuanta));                                // each value
//   std::optional<double> p99 = LargestValues::percentile99({&mine, &other});
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/detail/lane_mask.h"
#include "zcheck/large_buffer.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

namespace zcheck {

// Patterns to select from: `n` of them at `bits` (a keeper's, or a sample's).
struct BitsSpan {
    const std::uint32_t* bits;
    std::size_t n;
};
// The k-th smallest (from 0, k less than the patterns in all the parts) of 32-bit patterns as
// unsigned integers, the parts taken together: what std::nth_element over their concatenation
// would select. Exact, in two counting passes over the parts: by their top 16 bits, then those
// whose top bits hold rank k by their low 16. Nothing is copied or reordered; the counts are a
// 256 KiB block that large_buffer.h keeps from call to call.
std::uint32_t kthSmallestBits(const std::vector<BitsSpan>& parts, std::size_t k);

class LargestValues {
public:
    // Holds 8·keep bytes from the start (2·keep values; large_buffer.h keeps such a block from
    // frame to frame), whatever it is given.
    explicit LargestValues(std::size_t keep, float floor = 0.0f);

    void add(float value)
    {
        ++count_;
        keepIfLargest(floatBits(value));
    }
    // add() of each values[k] with use[k] = 1 (0 or 1), k < n: the same keepers (whatever the order, see
    // above). Which values might be kept is found for all n first, several per instruction;
    // inlined, so that each form of a kernel (kernel_choice.h) compiles its own.
    ZCHECK_ALWAYS_INLINE void add(const float* values, const std::uint8_t* use, std::size_t n)
    {
        typedef std::uint32_t __attribute__((may_alias)) AliasedBits;  // (memcpy would not vectorise)
        const AliasedBits* bits = reinterpret_cast<const AliasedBits*>(values);
        constexpr std::size_t kChunk = 64;
        for (std::size_t first = 0; first < n; first += kChunk) {
            const std::size_t m = std::min(kChunk, n - first);
            alignas(8) std::uint8_t candidate[kChunk] = {};
            int used = 0;
            const std::uint64_t least = leastKeepable();
            for (std::size_t k = 0; k < m; ++k) {
                used += use[first + k];
                candidate[k] = std::uint8_t(use[first + k] & (bits[first + k] >= least));
            }
            addCandidates(values + first, laneBits(candidate, m), std::size_t(used));
        }
    }
    // The smallest bit pattern a value must have to be kept now (2^32: none can be); it only
    // rises. For a kernel that finds its candidates itself, several per instruction.
    std::uint64_t leastKeepable() const
    {
        return kept_.size() >= keep_ ? std::max<std::uint64_t>(floor_, std::uint64_t(threshold_) + 1) : floor_;
    }
    // `used` values added, of which values[k] for each bit k set in `candidates` (k < 64) may be
    // kept: the candidates must include every one at or above leastKeepable() (keepIfLargest
    // decides, and what it would refuse now it refuses later too); the rest are only counted.
    void addCandidates(const float* values, std::uint64_t candidates, std::size_t used)
    {
        count_ += used;
        for (; candidates != 0; candidates &= candidates - 1) keepIfLargest(floatBits(values[__builtin_ctzll(candidates)]));
    }
    std::size_t count() const { return count_; }  // values added

    // The 99th percentile of every value the keepers were given (0 when there were none), or
    // nullopt when they kept too few values to hold it: a floor above it, or keep below n/100 + 1.
    static std::optional<double> percentile99(const std::vector<const LargestValues*>& keepers);
    // A floor for keepers from a sample of the values: its 97th percentile, or 0 for a sample
    // under 1000 values.
    static float floorBelowPercentile99(const std::vector<float>& sample);

private:
    static std::uint32_t floatBits(float value)
    {
        std::uint32_t bits;
        std::memcpy(&bits, &value, sizeof bits);
        return bits;
    }
    void keepIfLargest(std::uint32_t bits)
    {
        if (bits < leastKeepable()) return;  // not among the largest
        kept_.push_back(bits);
        if (kept_.size() == 2 * keep_) shrink();
    }
    void shrink();

    std::size_t keep_;
    std::size_t count_ = 0;
    std::uint32_t floor_;          // values below it are counted, never kept
    std::uint32_t threshold_ = 0;  // the smallest kept value once keep_ are kept
    // At most 2·keep_, reserved by the constructor: ~160 KiB at 1080p, a block kept from frame to
    // frame (large_buffer.h), where growing a std::vector each frame faulted its pages in again.
    LargeVector<std::uint32_t> kept_;
};

}  // namespace zcheck
