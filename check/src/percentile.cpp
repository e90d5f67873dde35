#include "percentile.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace zcheck {

std::uint32_t kthSmallestBits(const std::vector<BitsSpan>& parts, std::size_t k)
{
    // (Three passes of 11, 11 and 10 bits, each copying the patterns of the digit found into a
    // new array for the next, took ~2× as long over a 1080p comparison's keepers, whose values
    // mostly share their top bits: bench/speed-log.md, session 8.)
    constexpr std::size_t kDigits = std::size_t(1) << 16;
    LargeVector<std::uint32_t> count;  // counts of under 2^32 patterns: a keeper's, a frame's
    count.assign(kDigits, 0);
    for (const BitsSpan& part : parts)
        for (std::size_t i = 0; i < part.n; ++i) ++count[part.bits[i] >> 16];
    // The digit holding rank k of what was counted (k less than that), k made its rank there.
    const auto digitOf = [&] {
        std::uint32_t digit = 0;
        while (k >= count[digit]) k -= count[digit++];
        return digit;
    };
    const std::uint32_t high = digitOf();
    std::fill(count.begin(), count.end(), 0u);
    for (const BitsSpan& part : parts)
        for (std::size_t i = 0; i < part.n; ++i) {
            const std::uint32_t b = part.bits[i];
            count[b & 0xFFFFu] += std::uint32_t(b >> 16 == high);
        }
    return high << 16 | digitOf();
}

LargestValues::LargestValues(std::size_t keep, float floor) : keep_(std::max<std::size_t>(keep, 1)), floor_(floatBits(floor))
{
    kept_.reserve(2 * keep_);
}

void LargestValues::shrink()
{
    // The keep_ largest: all above the keep_-th largest, and as many copies of it as fill up.
    const std::uint32_t cut = kthSmallestBits({{kept_.data(), kept_.size()}}, kept_.size() - keep_);
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
    std::size_t n = 0, kept = 0;
    std::vector<BitsSpan> parts;
    for (const LargestValues* keeper : keepers) {
        n += keeper->count_, kept += keeper->kept_.size();
        parts.push_back({keeper->kept_.data(), keeper->kept_.size()});
    }
    if (n == 0) return 0.0;
    const std::size_t rank = std::min(n - 1, static_cast<std::size_t>(std::ceil(0.99 * double(n))) - 1);
    const std::size_t fromTop = n - rank;  // the percentile is the fromTop-th largest value
    if (fromTop > kept) return std::nullopt;
    const std::uint32_t bits = kthSmallestBits(parts, kept - fromTop);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

float LargestValues::floorBelowPercentile99(const std::vector<float>& sample)
{
    if (sample.size() < 1000) return 0.0f;
    std::vector<std::uint32_t> bits(sample.size());
    std::memcpy(bits.data(), sample.data(), sizeof(float) * sample.size());
    const std::uint32_t at = kthSmallestBits({{bits.data(), bits.size()}}, std::size_t(0.97 * double(sample.size())));
    float value;
    std::memcpy(&value, &at, sizeof value);
    return value;
}

}  // namespace zcheck
