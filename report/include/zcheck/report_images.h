#pragma once
// The check's pictures, as 8-bit RGB (width·height·3 bytes, row 0 at the top), for PNG files
// and the HTML suite report:
//   error heatmap    — |Δ| / tolerance on both-hit pixels: black 0, through blue and green to
//                      yellow at 1 (the tolerance), red above; unexplained coverage magenta;
//                      misses black, explained edges dark grey.
//   coverage classes — one colour per PixelClass (legend in docs/tolerance.md).
#include "zcheck/compare.h"

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace zcheck {

std::vector<std::uint8_t> errorHeatmapRgb(const Comparison& comparison);
std::vector<std::uint8_t> pixelClassRgb(const Comparison& comparison);
// Every class and its colour in pixelClassRgb, for legends.
std::vector<std::pair<PixelClass, std::array<std::uint8_t, 3>>> pixelClassLegend();

}  // namespace zcheck
