#pragma once
// The image-file functions the command line needs (image_io.h), loaded on first use from the
// plugin libzcheck_images.so. OpenImageIO pulls in ~260 shared libraries and ~0.35 s of
// start-up; loading it only when a command reads or writes an EXR, TIFF, PFM or PNG depth
// file keeps `zcheck --help`, `--version`, `matrices`, `precision` and `unproject --pixel`
// fast. It is found as every plugin is (plugin.h); one that cannot be loaded is an internal
// failure (exit 3) naming the paths tried.
#include "zcheck/image_io.h"

namespace zcheck::cli {

struct ImageFunctions {
    decltype(&zcheck::readDepthMap) readDepthMap;
    decltype(&zcheck::writeExr) writeExr;
    decltype(&zcheck::writeQuantityFile) writeQuantityFile;
};

// Loads the plugin once (thread-safe), then returns its functions.
const ImageFunctions& images();

// A depth map as readDepthMap reads it (image_io.h); the plugin is loaded only for EXR and TIFF,
// the formats zcheck does not read by itself (readDepthMapNatively).
DepthMapFile readDepthMapFile(const std::string& path, const DepthMapReading& reading, int width, int height);

}  // namespace zcheck::cli

// The plugin's one entry point.
extern "C" const zcheck::cli::ImageFunctions* zcheck_image_functions();
