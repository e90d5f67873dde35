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

// A depth map read from a file (EXR, PFM, TIFF, PNG, anything OpenImageIO reads), row 0 at
// the top as seen (OpenImageIO returns PFM's bottom-to-top rows flipped).
struct DepthMapFile {
    int width = 0, height = 0;
    std::string channel;          // the channel read
    std::vector<double> value;    // width·height; NaN where an integer file stores 0 (a miss)
};
// The channel named `preferredChannel` if there is one, else "Z", else the first. Integer
// files (16-bit PNG) need `scale`: value = stored / scale, 0 = miss. Float files are divided
// by `scale` when it is given. Throws Error naming the file.
DepthMapFile readDepthMap(const std::string& path, const std::string& preferredChannel, double scale);

// The check's pictures:
//   error heatmap — |Δ| / tolerance on both-hit pixels: black 0, through blue and green to
//                   yellow at 1 (the tolerance), red above; unexplained coverage magenta;
//                   misses and explained edges dark grey.
//   coverage classes — one colour per PixelClass (legend in the README).
std::vector<std::uint8_t> errorHeatmapRgb(const Comparison& comparison);
std::vector<std::uint8_t> pixelClassRgb(const Comparison& comparison);

}  // namespace zcheck
