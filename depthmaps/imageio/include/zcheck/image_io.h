#pragma once
// Depth-map, EXR and TIFF files (library zcheck::imageio, the only place OpenImageIO is used).
// Writers write the path they are given, checking every write and close (PNG and PFM are
// encoded by zcheck and written with writeFileBytes; EXR and TIFF by OpenImageIO); a
// command makes its outputs atomic with OutputFiles (atomic_file.h). Row 0 of every image is
// the top row as seen.
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"

#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

// A float32 EXR (ZIP, lossless) with one channel per name; `channels` holds
// width·height·names.size() values, interleaved.
void writeExr(const std::string& path, int width, int height, const std::vector<std::string>& names,
              const std::vector<float>& channels);

// Reads a map as `reading` says (depth_map_reading.h): its channel, scale, offset and misses.
// The file must be a regular file of at most 2 GiB, and its declared size must be
// expectedWidth × expectedHeight (0 × 0: any size a camera may have, for a camera that takes the
// map's size), checked before any pixel is allocated (for EXR after
// walking its header, whose attribute sizes must fit in the file). Integer files of 8 bits
// are refused (8 bits cannot hold depth). PFM is read by zcheck itself; EXR, TIFF and PNG by
// OpenImageIO, each only by its own reader (unknown bytes are never offered to OpenImageIO's
// other plugins). Throws Error naming the file and the rule.
DepthMapFile readDepthMap(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight);

// Writes exported quantities by the file's extension:
//   .exr  any quantities, one channel each (names in export.h), float32 (id: uint32), ZIP
//   .pfm  one quantity of 1 or 3 float channels; rows stored bottom to top as PFM specifies
//         (written by zcheck: OpenImageIO 2.4 reads PFM but cannot write it)
//   .tif  one quantity, float32 (id: uint32)
//   .png  one of window, ndc, eye-z, distance as 16-bit unsigned: round(value × scale),
//         0 = miss; `scale` is required, and a value that does not fit in 1..65535 is an
//         error naming the largest depth and the largest scale that would fit.
// Returns the format's name ("exr", "pfm", "tiff", "png"). Throws Error naming the file.
std::string writeQuantityFile(const std::string& path, const std::vector<QuantityImage>& images, double scale);


}  // namespace zcheck
