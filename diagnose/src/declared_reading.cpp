#include "zcheck/declared_reading.h"

#include "numerics.h"
#include "verify_estimators.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace zcheck {

namespace {

// Not a miss: a depth, or a value its quantity cannot hold (still something the map holds there).
bool holdsSurface(const Camera& camera, const DepthMap& map, int col, int row)
{
    return kindOfDepthValue(camera, map.quantity, map.value[std::size_t(row) * map.width + col]) != DepthValueKind::Miss;
}

// binary32's spacing at v.
double binary32Spacing(double v)
{
    const float f = float(std::abs(v));
    return double(std::nextafter(f, INFINITY)) - double(f);
}

// "54,155".
std::string grouped(std::int64_t n)
{
    std::string digits = std::to_string(n), out;
    for (std::size_t k = 0; k < digits.size(); ++k) {
        if (k > 0 && (digits.size() - k) % 3 == 0) out += ',';
        out += digits[k];
    }
    return out;
}

// The smallest of 1, 2, 5 × 10^k not below x (one significant digit, rounded up).
double roundedUp(double x)
{
    const double decade = std::pow(10.0, std::floor(std::log10(x)));
    for (const double m : {1.0, 2.0, 5.0, 10.0})
        if (m * decade >= x * (1 - 1e-12)) return m * decade;
    return 10 * decade;
}

}  // namespace

ReadingFindings findReading(const Camera& camera, const DepthMap& map, const RenderResult& truth)
{
    ReadingFindings out;
    const int W = map.width, H = map.height;
    // The values where the truth sees nothing, and where it hits.
    std::map<double, std::int64_t> atMisses;
    std::int64_t truthMisses = 0;
    std::vector<double> hitValues;
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const double v = map.value[i];
            if (!truth.hit(i)) {
                ++truthMisses;
                if (std::isfinite(v)) ++atMisses[v];
            } else if (holdsSurface(camera, map, col, row)) {
                hitValues.push_back(v);
            }
        }
    // The miss value.
    if (!atMisses.empty()) {
        const auto most = std::max_element(atMisses.begin(), atMisses.end(),
                                           [](const auto& a, const auto& b) { return a.second < b.second; });
        const std::int64_t alsoAtHits = std::count(hitValues.begin(), hitValues.end(), most->first);
        if (most->second >= 16 && most->second * 10 >= truthMisses * 9 && alsoAtHits * 100 <= most->second) {
            out.missValue = most->first;
            out.missPixels = most->second;
            const double stored = map.storedOf(most->first);
            out.missRule = stored >= 1e9 ? ">=1e9" : formatNumber(stored);
        }
    }
    // The grid: the largest step of the candidates that ≥ 99 % of the values lie on.
    if (hitValues.size() >= 16) {
        double largest = 0;
        for (double v : hitValues) largest = std::max(largest, std::abs(v));
        const double finest = 16 * binary32Spacing(largest);
        std::vector<double> candidates;
        for (int k = -6; k <= 0; ++k)
            for (const double m : {1.0, 2.0, 5.0}) candidates.push_back(m * std::pow(10.0, k));
        for (int k = 1; k <= 24; ++k) candidates.push_back(std::ldexp(1.0, -k));
        std::sort(candidates.rbegin(), candidates.rend());
        const std::size_t stride = std::max<std::size_t>(1, hitValues.size() / 20000);  // a sample suffices
        for (const double q : candidates) {
            if (q < finest || q < map.accuracy.quantum * 1.5 || q <= map.valueQuantum * 1.5) continue;
            std::size_t on = 0, of = 0;
            for (std::size_t k = 0; k < hitValues.size(); k += stride) {
                const double v = hitValues[k];
                const double off = std::abs(v / q - std::round(v / q)) * q;
                on += off <= std::max(1e-3 * q, 4 * binary32Spacing(v)) ? 1 : 0;
                ++of;
            }
            if (on * 100 >= of * 99) {
                out.grid = q;
                break;
            }
        }
    }
    return out;
}

std::vector<Declared> Declared::readingsToTry() const
{
    std::vector<Declared> readings;
    for (const auto member : {&Declared::missValue, &Declared::grid, &Declared::holes})
        if (this->*member) {
            Declared alone;
            alone.*member = true;
            readings.push_back(alone);
        }
    if (readings.size() > 1) readings.push_back(*this);
    return readings;
}

std::string Declared::name() const
{
    std::string out;
    for (const auto& [declared, part] : {std::pair{missValue, "miss-value"}, std::pair{grid, "quantum"}, std::pair{holes, "holes"}})
        if (declared) out += (out.empty() ? "" : " + ") + std::string(part);
    return out;
}

DepthMap declaredReading(const DepthMap& map, const ReadingFindings& findings, const Declared& use)
{
    DepthMap out = map;
    if (use.missValue && findings.missValue)
        for (double& v : out.value)
            if (v == *findings.missValue) v = NAN;
    if (use.grid && findings.grid > 0) out.accuracy.quantum = findings.grid;
    if (use.holes) out.accuracy.allowHoles = true;
    return out;
}

std::optional<MapAccuracy> toleranceFinding(const Camera& camera, const DepthMap& map, const RenderResult& truth)
{
    if (map.quantity != DepthQuantity::EyeZ && map.quantity != DepthQuantity::Distance) return std::nullopt;
    const int W = map.width, H = map.height;
    std::vector<double> absolute, relative;
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            if (!truth.hit(i) || !holdsSurface(camera, map, col, row)) continue;
            const double expected = truthValueAt(camera, truth, col, row, map.quantity);
            const double error = std::abs(map.value[i] - expected);
            absolute.push_back(error), relative.push_back(error / expected);
        }
    if (absolute.size() < 16) return std::nullopt;
    auto largestOverMedian = [](const std::vector<double>& v, double& largest) {
        largest = *std::max_element(v.begin(), v.end());
        return largest / std::max(medianOf(v), 1e-300);
    };
    double largestAbsolute = 0, largestRelative = 0;
    const double spreadAbsolute = largestOverMedian(absolute, largestAbsolute);
    const double spreadRelative = largestOverMedian(relative, largestRelative);
    // A convention mistake is not a tolerance: only small errors qualify.
    if (!(largestRelative <= 0.01) || largestAbsolute == 0) return std::nullopt;
    MapAccuracy out = map.accuracy;
    if (spreadRelative <= spreadAbsolute) out.relative = roundedUp(largestRelative * 1.05);
    else out.absolute = roundedUp(largestAbsolute * 1.05);
    return out;
}

std::optional<NoiseFinding> noiseFinding(const Camera& camera, const DepthMap& map, const RenderResult& truth)
{
    if (map.quantity != DepthQuantity::EyeZ && map.quantity != DepthQuantity::Distance) return std::nullopt;
    const int W = map.width, H = map.height;
    std::vector<double> error(std::size_t(W) * H, NAN);
    std::vector<double> z, e;  // the compared pixels' values and errors
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            if (!truth.hit(i) || kindOfDepthValue(camera, map.quantity, map.value[i]) != DepthValueKind::Depth) continue;
            const double expected = truthValueAt(camera, truth, col, row, map.quantity);
            error[i] = map.value[i] - expected;
            z.push_back(map.value[i]), e.push_back(error[i]);
        }
    if (e.size() < 256) return std::nullopt;
    // Unbiased: the median well inside the robust spread.
    const double centre = medianOf(e);
    std::vector<double> deviation(e.size());
    for (std::size_t k = 0; k < e.size(); ++k) deviation[k] = std::abs(e[k] - centre);
    const double spread = 1.4826 * medianOf(deviation);
    if (!(spread > 0) || !(std::abs(centre) <= 0.1 * spread)) return std::nullopt;
    // Uncorrelated: each pixel's error against its right-hand neighbour's.
    double both = 0, left = 0, right = 0;
    for (int row = 0; row < H; ++row)
        for (int col = 0; col + 1 < W; ++col) {
            const double a = error[std::size_t(row) * W + col], b = error[std::size_t(row) * W + col + 1];
            if (!std::isfinite(a) || !std::isfinite(b)) continue;
            both += a * b, left += a * a, right += b * b;
        }
    NoiseFinding out;
    out.correlation = left > 0 && right > 0 ? both / std::sqrt(left * right) : 1.0;
    if (!(std::abs(out.correlation) < 0.3)) return std::nullopt;
    // σ of eight bins of depth, and a + b·z² fitted to them by least squares with a, b ≥ 0.
    std::vector<std::size_t> order(z.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return z[a] < z[b]; });
    constexpr int kBins = 8;
    std::vector<double> binZ2, binSigma;
    for (int bin = 0; bin < kBins; ++bin) {
        const std::size_t from = order.size() * bin / kBins, to = order.size() * (bin + 1) / kBins;
        std::vector<double> zs, magnitudes;
        for (std::size_t k = from; k < to; ++k) zs.push_back(z[order[k]]), magnitudes.push_back(std::abs(e[order[k]]));
        const double zMedian = medianOf(zs);
        binZ2.push_back(zMedian * zMedian), binSigma.push_back(1.4826 * medianOf(magnitudes));
    }
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int bin = 0; bin < kBins; ++bin)
        sx += binZ2[bin], sy += binSigma[bin], sxx += binZ2[bin] * binZ2[bin], sxy += binZ2[bin] * binSigma[bin];
    const double det = kBins * sxx - sx * sx;
    double a = det > 0 ? (sxx * sy - sx * sxy) / det : sy / kBins, b = det > 0 ? (kBins * sxy - sx * sy) / det : 0;
    if (b < 0) b = 0, a = sy / kBins;
    if (a < 0) a = 0, b = sxx > 0 ? sxy / sxx : 0;
    NoiseModel model{a, b, 0};
    if (!model.any()) return std::nullopt;
    // Scaled until 6σ bounds every pixel; noise has no outliers far beyond that.
    double worst = 0;
    for (std::size_t k = 0; k < e.size(); ++k) worst = std::max(worst, std::abs(e[k]) / model.allowance(std::abs(z[k])));
    if (!(worst <= 1.5)) return std::nullopt;
    const double factor = std::max(1.0, worst * 1.05);
    auto roundedUp2 = [](double x) {  // two significant digits, up
        if (!(x > 0)) return 0.0;
        const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1);
        return std::ceil(x / unit * (1 - 1e-12)) * unit;
    };
    out.model = {roundedUp2(a * factor), roundedUp2(b * factor), 0};
    std::sort(z.begin(), z.end());
    out.zNear = z[z.size() / 20], out.zFar = z[z.size() - 1 - z.size() / 20];
    return out;
}

std::string describeFindings(const ReadingFindings& f, const Declared& use)
{
    std::string out;
    auto add = [&](const std::string& clause) { out += (out.empty() ? "" : "; ") + clause; };
    if (use.missValue && f.missValue)
        add("the map holds " + formatNumber(*f.missValue) + " at " + grouped(f.missPixels) +
            " pixels where nothing is hit: its miss value (pass --miss '" + f.missRule + "')");
    if (use.grid && f.grid > 0)
        add("the map's values lie on a " + formatNumber(f.grid) + " grid: consistent with --quantum " + formatNumber(f.grid));
    if (use.holes && f.holes > 0)
        add(grouped(f.holes) + " pixels have no depth where the surface is hit: holes (pass --allow-holes if your sensor "
                               "or renderer leaves them)");
    return out;
}

}  // namespace zcheck
