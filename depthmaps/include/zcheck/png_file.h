#pragma once
// 8-bit RGB pictures (libpng, private to zcheck::depthmaps; no OpenImageIO): a PNG file written with
// checked writes (a command makes it atomic with OutputFiles), a data: URI for self-contained
// HTML, and the colour-mapped preview of a quantity. `rgb` holds width·height·3 bytes, row 0
// at the top. Throws Error naming the file.
#include "zcheck/quantity.h"

#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

void writePng8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);
std::string pngDataUri(int width, int height, const std::vector<std::uint8_t>& rgb);

// An 8-bit picture of one quantity for a person: depths through the viridis colour map
// (near dark blue, far yellow), normals as RGB = (n + 1)/2, ids hashed to colours; misses black.
std::vector<std::uint8_t> previewRgb(const QuantityImage& image);
// The same for a one-channel depth image on a given range [lo, hi] (near dark, far yellow), so
// that two pictures of one view share their colours; misses black.
std::vector<std::uint8_t> previewRgb(const QuantityImage& image, double lo, double hi);

}  // namespace zcheck
