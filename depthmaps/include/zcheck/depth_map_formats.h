#pragma once
// The depth-map file formats, one row each (library zcheck::depthmaps), and the one dispatch
// over them: a file read is judged by its first bytes, and only the format that claims them
// sees it (OpenImageIO would offer unknown bytes to every plugin it has: video, camera raw,
// DICOM...); a file written takes the format of its extension.
//
// zcheck::depthmaps holds the formats zcheck reads and writes itself: NumPy .npy, HDF5 (read
// by a program of its own), COLMAP dense maps, PFM, 16-bit PNG. EXR and TIFF are OpenImageIO's:
// zcheck::imageio registers them (registerImageIoDepthMapFormats, image_io.h), and the command
// line, which loads OpenImageIO only when a file needs it, installs a loader that does
// (setDepthMapFormatLoader). `zcheck formats` and docs/export.md print the table.
//
// Thread-safety: register and install the loader before reading from several threads; the
// dispatch itself is safe from any thread.
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace zcheck {

struct DepthMapFormat {
    std::string name;                     // "npy": what writeQuantityFile returns, and reports say
    std::string title;                    // "NumPy .npy", in messages and help
    std::vector<std::string> extensions;  // ".npy": a file written takes its extension's format
    std::string holds;                    // what a file of it holds when zcheck writes one, for help and docs
    // The file's first bytes (at most kDepthMapHeadBytes) are this format's.
    bool (*detects)(std::string_view head) = nullptr;
    // The map as `reading` says, at expectedWidth × expectedHeight (0 × 0: any size a camera may
    // have), values turned into depths (depthsFromStored). Throws Error naming the file.
    DepthMapFile (*read)(const std::string& path, const DepthMapReading& reading, int expectedWidth,
                         int expectedHeight) = nullptr;
    // Writes the quantities (one, unless `writesSeveral`); `scale` for integer formats. nullptr:
    // read only.
    void (*write)(const std::string& path, const std::vector<QuantityImage>& images, double scale) = nullptr;
    bool writesSeveral = false;
};

inline constexpr std::size_t kDepthMapHeadBytes = 32;

// Every registered format, in the table's order.
std::vector<const DepthMapFormat*> depthMapFormats();
// Adds a row; a name registered twice is ignored (registration is idempotent). Returns true.
bool registerDepthMapFormat(const DepthMapFormat& format);
// What to call, once, when a file is no registered format's: it may register more (the command
// line loads OpenImageIO's plugin). Reading and writing then try the table again.
void setDepthMapFormatLoader(std::function<void()> loader);

// Reads a depth map of any registered format, told by its first bytes, as `reading` says: the
// file must be a regular file of at most 2 GiB (input_file.h), its declared size is compared
// with expectedWidth × expectedHeight (0 × 0: any size a camera may have) before any pixel is
// allocated, 8-bit integers are refused (8 bits cannot hold depth), integers need a scale.
// Throws Error naming the file and the rule.
DepthMapFile readDepthMapFile(const std::string& path, const DepthMapReading& reading, int expectedWidth,
                              int expectedHeight);

// Writes exported quantities in the format of `path`'s extension; returns the format's name.
// Throws Error naming the file (an unknown extension lists the known ones).
std::string writeDepthMapFile(const std::string& path, const std::vector<QuantityImage>& images, double scale);

// Runs the loader (setDepthMapFormatLoader) now, if it has not run: every format is then in
// the table (`zcheck formats` lists them all).
void loadAllDepthMapFormats();

// The table as Markdown, every format loaded (`zcheck formats` prints it).
std::string depthMapFormatTable();

}  // namespace zcheck
