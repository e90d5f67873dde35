#pragma once
// The depth-map formats datasets use beside EXR, TIFF, PNG and PFM (depth_map_formats.h
// dispatches to them by their first bytes), and the rows of the table each file defines.
// Private to zcheck::depthmaps.
//
//   .npy    NumPy's format (numpy.org/neps/nep-0001): "\x93NUMPY", version 1, 2 or 3, a Python
//           dict header {'descr', 'fortran_order', 'shape'}, then the raw array. Read: shape
//           (H, W), (H, W, 1) or (H, W, C) (channels "0".."C−1"), dtype float16/32/64 or
//           (u)int16/32 of either byte order, C or Fortran order. Refused: 8-bit and 64-bit
//           integers, bool, complex, structured and object dtypes, other shapes, a data size
//           other than the header's.
//   COLMAP  a dense depth map of patch_match_stereo ("W&H&C&" then W·H·C little-endian float32,
//           one channel after another, each row-major, row 0 at the top): C must be 1 (3 is a
//           normal map); values are eye-z in model units, ≤ 0 where there is no depth (read as
//           a miss).
//   HDF5    (depth_hdf5.cpp) a 2-D dataset, or 3-D with one channel last, chosen by --channel
//           (its path, e.g. "depth", "dataset", "group/depth") or as image_io.h chooses a
//           channel; float or integer of 16 bits or more. Read in a child process: a malformed
//           file that crashes or hangs the HDF5 library is refused, never fatal.
#include "zcheck/depth_map_formats.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"

#include <vector>

#include <string>
#include <string_view>

namespace zcheck::depthformats {

// Whether the first bytes are those of each format.
bool isNpy(std::string_view head);
bool isColmapDepth(std::string_view head);
bool isHdf5(std::string_view head);

DepthMapFile readNpy(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight);
DepthMapFile readColmapDepth(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight);
DepthMapFile readHdf5(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight);

// Writers for export: .npy float32 (H, W) or (H, W, C) of one quantity; a COLMAP depth map of
// one single-channel depth quantity (misses as 0); HDF5, one float32 dataset per quantity named
// by its channels (export.h), primitive ids as uint32.
void writeNpy(const std::string& path, const QuantityImage& image);
void writeColmapDepth(const std::string& path, const QuantityImage& image);
void writeHdf5(const std::string& path, const std::vector<QuantityImage>& images);

// The rows of the table (depth_map_formats.cpp lists them).
const DepthMapFormat& npyFormat();          // depth_formats.cpp
const DepthMapFormat& colmapDepthFormat();  // depth_formats.cpp
const DepthMapFormat& hdf5Format();         // depth_hdf5.cpp
const DepthMapFormat& pfmFormat();          // depth_map_files.cpp
const DepthMapFormat& png16Format();        // depth_map_files.cpp

}  // namespace zcheck::depthformats
