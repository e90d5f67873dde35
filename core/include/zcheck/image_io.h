#pragma once
// Image files (library zcheck_imageio, the only place OpenImageIO is used). All writes are
// atomic (atomic_file.h). Row 0 of every image is the top row as seen.
#include "zcheck/compare.h"
#include "zcheck/render.h"

#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

// A float32 EXR (ZIP, lossless) with one channel per name; `channels` holds
// width·height·names.size() values, interleaved.
void writeExr(const std::string& path, int width, int height, const std::vector<std::string>& names,
              const std::vector<float>& channels);

// An 8-bit RGB PNG; `rgb` holds width·height·3 bytes.
void writePng8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

// The check's pictures:
//   error heatmap — |Δ| / tolerance on both-hit pixels: black 0, through blue and green to
//                   yellow at 1 (the tolerance), red above; unexplained coverage magenta;
//                   misses and explained edges dark grey.
//   coverage classes — one colour per PixelClass (legend in the README).
std::vector<std::uint8_t> errorHeatmapRgb(const Comparison& comparison);
std::vector<std::uint8_t> pixelClassRgb(const Comparison& comparison);

}  // namespace zcheck
