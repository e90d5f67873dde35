#include "zcheck/percentile.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace zcheck {

LargestValues::LargestValues(std::size_t keep, float floor) : keep_(std::max<std::size_t>(keep, 1)), floor_(floatBits(floor)) {}

void LargestValues::shrink()
{
    const auto cut = kept_.end() - std::ptrdiff_t(keep_);
    std::nth_element(kept_.begin(), cut, kept_.end());
    kept_.erase(kept_.begin(), cut);
    threshold_ = *std::min_element(kept_.begin(), kept_.end());
}

std::optional<double> LargestValues::percentile99(const std::vector<const LargestValues*>& keepers)
{
    std::size_t n = 0;
    std::vector<std::uint32_t> all;
    for (const LargestValues* keeper : keepers) {
        n += keeper->count_;
        all.insert(all.end(), keeper->kept_.begin(), keeper->kept_.end());
    }
    if (n == 0) return 0.0;
    const std::size_t rank = std::min(n - 1, static_cast<std::size_t>(std::ceil(0.99 * double(n))) - 1);
    const std::size_t fromTop = n - rank;  // the percentile is the fromTop-th largest value
    if (fromTop > all.size()) return std::nullopt;
    const auto at = all.end() - std::ptrdiff_t(fromTop);
    std::nth_element(all.begin(), at, all.end());
    float value;
    std::memcpy(&value, &*at, sizeof value);
    return value;
}

float LargestValues::floorBelowPercentile99(std::vector<float>& sample)
{
    if (sample.size() < 1000) return 0.0f;
    const auto at = sample.begin() + std::ptrdiff_t(0.97 * double(sample.size()));
    std::nth_element(sample.begin(), at, sample.end(), [](float a, float b) { return floatBits(a) < floatBits(b); });
    return *at;
}

}  // namespace zcheck
