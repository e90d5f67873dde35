#pragma once
// EXR and TIFF depth maps (library zcheck::imageio, the only place OpenImageIO is used): two rows
// of the table of depth-map formats (depth_map_formats.h), which a program registers when it
// links this library, and the EXR writer the check's --out folder uses. Row 0 of every image is
// the top row as seen. Writers write the path they are given, checking every write and close;
// a command makes its outputs atomic with OutputFiles (atomic_file.h).
#include "zcheck/depth_map_formats.h"
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

// The rows: EXR (its header walked first, since OpenEXR allocates whatever an attribute's size
// field claims; read by OpenImageIO's openexr plugin alone) and TIFF (its tiff plugin alone);
// both written as float32 (primitive ids uint32), EXR with ZIP and any number of quantities.
std::vector<const DepthMapFormat*> imageIoDepthMapFormats();
// Adds them to this program's table (idempotent).
void registerImageIoDepthMapFormats();

// readDepthMapFile and writeDepthMapFile (depth_map_formats.h) with EXR and TIFF registered:
// every format, by its first bytes when reading and by its extension when writing.
DepthMapFile readDepthMap(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight);
std::string writeQuantityFile(const std::string& path, const std::vector<QuantityImage>& images, double scale);

}  // namespace zcheck
