#include "zcheck/png_file.h"

#include "png_codec.h"
#include "zcheck/atomic_file.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace zcheck {

void writePng8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb)
{
    writeFileBytes(path, encodePng(width, height, 3, 8, rgb.data()));
}

std::string pngDataUri(int width, int height, const std::vector<std::uint8_t>& rgb)
{
    const std::string bytes = encodePng(width, height, 3, 8, rgb.data());
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out = "data:image/png;base64,";
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t n = (std::uint32_t(std::uint8_t(bytes[i])) << 16) |
                                (i + 1 < bytes.size() ? std::uint32_t(std::uint8_t(bytes[i + 1])) << 8 : 0) |
                                (i + 2 < bytes.size() ? std::uint32_t(std::uint8_t(bytes[i + 2])) : 0);
        out += digits[(n >> 18) & 63];
        out += digits[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? digits[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? digits[n & 63] : '=';
    }
    return out;
}

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// viridis (matplotlib), sampled at 9 points and interpolated.
Rgb viridis(double t)
{
    static const double stops[9][3] = {{68, 1, 84},    {71, 45, 123},  {59, 82, 139},  {44, 114, 142}, {33, 145, 140},
                                       {39, 173, 129}, {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
    t = std::clamp(t, 0.0, 1.0) * 8;
    const int k = std::min(7, int(t));
    const double f = t - k;
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = std::uint8_t(std::lround(stops[k][c] + f * (stops[k + 1][c] - stops[k][c])));
    return out;
}

}  // namespace

std::vector<std::uint8_t> previewRgb(const QuantityImage& image, double lo, double hi)
{
    const std::size_t pixels = std::size_t(image.width) * image.height;
    std::vector<std::uint8_t> rgb(pixels * 3, 0);
    for (std::size_t i = 0; i < pixels; ++i) {
        if (image.isMiss(i)) continue;
        const Rgb c = viridis(hi > lo ? (image.value[i] - lo) / (hi - lo) : 0.5);
        std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(3 * i));
    }
    return rgb;
}

std::vector<std::uint8_t> previewRgb(const QuantityImage& image)
{
    const std::size_t pixels = std::size_t(image.width) * image.height;
    std::vector<std::uint8_t> rgb(pixels * 3, 0);
    const std::size_t C = image.channels.size();
    if (C == 1 && image.quantity != ExportQuantity::PrimitiveId) {  // a depth: on its own range
        double lo = INFINITY, hi = -INFINITY;
        for (std::size_t i = 0; i < pixels; ++i)
            if (!image.isMiss(i)) lo = std::min(lo, image.value[i]), hi = std::max(hi, image.value[i]);
        return previewRgb(image, lo, hi);
    }
    double boxLo[3] = {INFINITY, INFINITY, INFINITY}, boxHi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (C == 3)
        for (std::size_t i = 0; i < pixels; ++i)
            for (int k = 0; k < 3 && !image.isMiss(i); ++k)
                boxLo[k] = std::min(boxLo[k], image.value[i * 3 + k]), boxHi[k] = std::max(boxHi[k], image.value[i * 3 + k]);
    for (std::size_t i = 0; i < pixels; ++i) {
        if (image.isMiss(i)) continue;
        Rgb c{};
        if (image.quantity == ExportQuantity::PrimitiveId) {
            std::uint32_t h = image.id[i] * 2654435761u;  // Knuth's multiplicative hash
            c = {std::uint8_t(64 + (h >> 24) % 192), std::uint8_t(64 + (h >> 16) % 192), std::uint8_t(64 + (h >> 8) % 192)};
        } else if (C == 3) {
            // Normals as (n + 1)/2; positions scaled per axis to their bounding box.
            for (int k = 0; k < 3; ++k) {
                const double v = image.value[i * 3 + k];
                const double t = image.quantity == ExportQuantity::Normal ? (v + 1) / 2
                                 : boxHi[k] > boxLo[k]                    ? (v - boxLo[k]) / (boxHi[k] - boxLo[k])
                                                                          : 0.5;
                c[k] = std::uint8_t(std::lround(255 * std::clamp(t, 0.0, 1.0)));
            }
        } else {
            c = viridis(0.5);  // no range to place it on
        }
        std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(3 * i));
    }
    return rgb;
}

}  // namespace zcheck
