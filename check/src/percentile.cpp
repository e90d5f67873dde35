#include "percentile.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace zcheck {

std::uint32_t kthSmallestBits(const std::uint32_t* bits, std::size_t n, std::size_t k)
{
    constexpr int kShift[3] = {21, 10, 0}, kWidth[3] = {11, 11, 10};
    std::vector<std::uint32_t> bucket;  // the patterns whose bits above `shift` are those found
    const std::uint32_t* v = bits;
    std::uint32_t found = 0;
    for (int level = 0; level < 3; ++level) {
        const int shift = kShift[level];
        const std::uint32_t mask = (1u << kWidth[level]) - 1;
        std::array<std::size_t, 2048> count{};
        for (std::size_t i = 0; i < n; ++i) ++count[(v[i] >> shift) & mask];
        std::uint32_t digit = 0;
        while (k >= count[digit]) k -= count[digit++];  // ends: k < n, the counts sum to n
        found |= digit << shift;
        if (level == 2) break;
        std::vector<std::uint32_t> next;
        next.reserve(count[digit]);
        for (std::size_t i = 0; i < n; ++i)
            if (((v[i] >> shift) & mask) == digit) next.push_back(v[i]);
        bucket.swap(next);
        v = bucket.data(), n = bucket.size();
    }
    return found;
}

LargestValues::LargestValues(std::size_t keep, float floor) : keep_(std::max<std::size_t>(keep, 1)), floor_(floatBits(floor))
{
    kept_.reserve(2 * keep_);
}

void LargestValues::shrink()
{
    // The keep_ largest: all above the keep_-th largest, and as many copies of it as fill up.
    const std::uint32_t cut = kthSmallestBits(kept_.data(), kept_.size(), kept_.size() - keep_);
    std::size_t above = 0;
    for (const std::uint32_t b : kept_) above += b > cut;
    std::size_t ties = keep_ - above;
    auto end = std::remove_if(kept_.begin(), kept_.end(), [&](std::uint32_t b) {
        if (b > cut) return false;
        if (b == cut && ties > 0) return --ties, false;
        return true;
    });
    kept_.erase(end, kept_.end());
    threshold_ = cut;
}

std::optional<double> LargestValues::percentile99(const std::vector<const LargestValues*>& keepers)
{
    std::size_t n = 0, most = 0;
    for (const LargestValues* keeper : keepers) n += keeper->count_, most += 2 * keeper->keep_;
    // A block kept from frame to frame, as the keepers' own: of the size they may hold at most,
    // the same each frame (what they hold varies, and a block of a size not kept gives up all).
    LargeVector<std::uint32_t> all;
    all.reserve(most);
    for (const LargestValues* keeper : keepers) all.insert(all.end(), keeper->kept_.begin(), keeper->kept_.end());
    if (n == 0) return 0.0;
    const std::size_t rank = std::min(n - 1, static_cast<std::size_t>(std::ceil(0.99 * double(n))) - 1);
    const std::size_t fromTop = n - rank;  // the percentile is the fromTop-th largest value
    if (fromTop > all.size()) return std::nullopt;
    const std::uint32_t bits = kthSmallestBits(all.data(), all.size(), all.size() - fromTop);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

float LargestValues::floorBelowPercentile99(const std::vector<float>& sample)
{
    if (sample.size() < 1000) return 0.0f;
    std::vector<std::uint32_t> bits(sample.size());
    std::memcpy(bits.data(), sample.data(), sizeof(float) * sample.size());
    const std::uint32_t at = kthSmallestBits(bits.data(), bits.size(), std::size_t(0.97 * double(sample.size())));
    float value;
    std::memcpy(&value, &at, sizeof value);
    return value;
}

}  // namespace zcheck
