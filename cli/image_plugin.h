#pragma once
// The image-file functions the command line needs (zcheck::imageio, image_io.h), loaded on first use from the
// plugin libzcheck_images.so. OpenImageIO pulls in ~260 shared libraries and ~0.35 s of
// start-up; loading it only when a command reads or writes an EXR or TIFF file keeps `zcheck
// --help`, `--version`, `matrices`, `precision`, `unproject --pixel` and every map zcheck reads
// by itself fast. It is found as every plugin is (plugin.h); one that cannot be loaded is an
// internal failure (exit 3) naming the paths tried.
#include "zcheck/depth_map_formats.h"

#include <cstddef>
#include <string>
#include <vector>

namespace zcheck::cli {

struct ImageFunctions {
    const DepthMapFormat* const* formats;  // the plugin's rows of the depth-map table (EXR, TIFF)
    std::size_t formatCount;
    // image_io.h's writeExr
    void (*writeExr)(const std::string& path, int width, int height, const std::vector<std::string>& names,
                     const std::vector<float>& channels);
};

// Loads the plugin once (thread-safe), then returns its functions.
const ImageFunctions& images();

// Makes the depth-map table (depth_map_formats.h) load the plugin's formats the first time a
// file is none of zcheck's own. Called once, before any map is read or written.
void loadImageFormatsWhenNeeded();

}  // namespace zcheck::cli

// The plugin's one entry point.
extern "C" const zcheck::cli::ImageFunctions* zcheck_image_functions();
