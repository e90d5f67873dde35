#include "zcheck/report_images.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace zcheck {

namespace {

using Rgb = std::array<std::uint8_t, 3>;

Rgb classColour(PixelClass c)
{
    switch (c) {
    case PixelClass::BothMiss: return {0, 0, 0};
    case PixelClass::Agree: return {70, 160, 70};
    case PixelClass::EdgeSurface: return {60, 120, 200};
    case PixelClass::DepthError: return {230, 30, 30};
    case PixelClass::RayOnlyEdge: return {220, 200, 60};
    case PixelClass::RasterOnlyEdge: return {60, 200, 200};
    case PixelClass::RayOnlyAtClear: return {120, 80, 160};
    case PixelClass::AtClipPlane: return {150, 110, 60};
    case PixelClass::RayOnly: return {255, 0, 255};
    case PixelClass::RasterOnly: return {255, 140, 0};
    case PixelClass::Hole: return {90, 90, 90};
    }
    return {255, 255, 255};
}

Rgb heat(float ratio)
{
    if (!(ratio <= 1.0f)) return {255, 0, 0};  // beyond tolerance (or NaN)
    // black → blue → green → yellow over [0, 1]; the square root shows small errors.
    static const float stops[4][3] = {{0, 0, 0}, {0, 0, 255}, {0, 200, 0}, {255, 255, 0}};
    const float t = std::sqrt(std::max(0.0f, ratio)) * 3;
    const int k = std::min(2, int(t));
    const float f = t - float(k);
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = std::uint8_t(stops[k][c] + f * (stops[k + 1][c] - stops[k][c]));
    return out;
}

template <class Colour>
std::vector<std::uint8_t> paint(const Comparison& comparison, Colour colour)
{
    std::vector<std::uint8_t> rgb(comparison.pixelClass.size() * 3);
    for (std::size_t i = 0; i < comparison.pixelClass.size(); ++i) {
        const Rgb c = colour(i);
        std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(3 * i));
    }
    return rgb;
}

}  // namespace

std::vector<std::uint8_t> errorHeatmapRgb(const Comparison& comparison)
{
    return paint(comparison, [&](std::size_t i) -> Rgb {
        switch (comparison.pixelClass[i]) {
        case PixelClass::Agree:
        case PixelClass::DepthError: return heat(comparison.errorOverTolerance[i]);
        case PixelClass::RayOnly:
        case PixelClass::RasterOnly: return {255, 0, 255};
        case PixelClass::BothMiss: return {0, 0, 0};
        default: return {40, 40, 40};
        }
    });
}

std::vector<std::pair<PixelClass, std::array<std::uint8_t, 3>>> pixelClassLegend()
{
    std::vector<std::pair<PixelClass, std::array<std::uint8_t, 3>>> out;
    for (const PixelClass c : {PixelClass::BothMiss, PixelClass::Agree, PixelClass::EdgeSurface, PixelClass::DepthError,
                               PixelClass::RayOnlyEdge, PixelClass::RasterOnlyEdge, PixelClass::RayOnlyAtClear,
                               PixelClass::AtClipPlane, PixelClass::RayOnly, PixelClass::RasterOnly, PixelClass::Hole})
        out.emplace_back(c, classColour(c));
    return out;
}

std::vector<std::uint8_t> pixelClassRgb(const Comparison& comparison)
{
    return paint(comparison, [&](std::size_t i) { return classColour(comparison.pixelClass[i]); });
}

}  // namespace zcheck
