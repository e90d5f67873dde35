// The depth-map files zcheck reads by itself — PFM, 16-bit PNG (libpng), NumPy .npy, COLMAP
// maps, HDF5 — in zcheck::depthmaps, so that reading them never loads the image library (image_io.h
// reads EXR and TIFF through it, and every format).
#include "zcheck/depth_map_reading.h"

#include "depth_formats.h"
#include "png_codec.h"
#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string_view>

namespace zcheck {

void requireDepthMapSize(const std::string& path, long long width, long long height, int expectedWidth, int expectedHeight)
{
    if (expectedWidth == 0 && expectedHeight == 0) {
        if (!Camera::isImageSize(width, height))
            throw Error("depth map '" + path + "' is " + std::to_string(width) + "x" + std::to_string(height) +
                        ", outside the 1.." + std::to_string(Camera::kMaxImageSide) + " pixels per side (2^25 in all) a camera may have");
        return;
    }
    if (width != expectedWidth || height != expectedHeight)
        throw Error("depth map '" + path + "' is " + std::to_string(width) + "x" + std::to_string(height) +
                    " but the camera's image is " + std::to_string(expectedWidth) + "x" + std::to_string(expectedHeight));
}

namespace {

// PFM (Paul Debevec's portable float map): "Pf" (1 channel) or "PF" (3), whitespace, width,
// height, scale (negative: little-endian), one whitespace byte, then float32 rows from the
// bottom row of the picture to the top. Read here, strictly: the size is compared with the
// camera's before anything is allocated, and the data must be exactly as long as declared.
DepthMapFile readPfm(const std::string& path, const std::string& bytes, const DepthMapReading& reading, int expectedWidth,
                     int expectedHeight)
{
    std::size_t at = 2;
    auto field = [&](const char* what) {
        while (at < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
        const std::size_t start = at;
        while (at < bytes.size() && at - start < 40 && !std::isspace(static_cast<unsigned char>(bytes[at]))) ++at;
        if (at == start || at >= bytes.size()) refuseDepthMap(path, std::string("malformed PFM header: no ") + what);
        return bytes.substr(start, at - start);
    };
    const int channels = bytes[1] == 'f' ? 1 : 3;
    const std::string widthText = field("width"), heightText = field("height"), scaleText = field("scale");
    auto whole = [&](const std::string& text, const char* what) {
        long long v = -1;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (error != std::errc() || end != text.data() + text.size() || v < 1)
            refuseDepthMap(path, std::string("malformed PFM header: ") + what + " '" + text + "' is not a positive whole number");
        return v;
    };
    const long long width = whole(widthText, "width"), height = whole(heightText, "height");
    double scale = 0;
    const auto [end, error] = std::from_chars(scaleText.data(), scaleText.data() + scaleText.size(), scale);
    if (error != std::errc() || end != scaleText.data() + scaleText.size() || !std::isfinite(scale) || scale == 0)
        refuseDepthMap(path, "malformed PFM header: scale '" + scaleText + "' must be a nonzero number");
    ++at;  // the single whitespace byte that ends the header
    requireDepthMapSize(path, width, height, expectedWidth, expectedHeight);
    const std::uint64_t expectedBytes = std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(channels) * 4;
    if (bytes.size() - at != expectedBytes)
        refuseDepthMap(path, "the PFM data holds " + std::to_string(bytes.size() - at) + " bytes, but " +
                            std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels) +
                            " float32 values need " + std::to_string(expectedBytes) + (bytes.size() - at < expectedBytes ? " (truncated)" : ""));
    const std::vector<std::string> names = channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
    DepthMapFile map;
    map.width = int(width), map.height = int(height);
    map.channel = chooseDepthChannel(path, names, reading.channel, reading.quantityChannel);
    const std::size_t channel = std::size_t(std::find(names.begin(), names.end(), map.channel) - names.begin());
    map.value.resize(std::size_t(width) * std::size_t(height));
    const bool bigEndian = scale > 0;
    for (long long row = 0; row < height; ++row)
        for (long long col = 0; col < width; ++col) {
            unsigned char raw[4];
            std::memcpy(raw, bytes.data() + at + 4 * ((std::size_t(row) * std::size_t(width) + std::size_t(col)) * std::size_t(channels) + channel), 4);
            if (bigEndian) std::reverse(raw, raw + 4);
            float v;
            std::memcpy(&v, raw, 4);
            map.value[std::size_t(height - 1 - row) * std::size_t(width) + std::size_t(col)] = v;  // stored bottom-up
        }
    return map;
}

}  // namespace

std::optional<DepthMapFile> readDepthMapNatively(const std::string& path, const DepthMapReading& reading, int expectedWidth,
                                                 int expectedHeight)
{
    const double scale = reading.scale;
    if (scale != 0) DepthMapReading::requireScale(scale, "--scale");
    DepthMapReading::requireOffset(reading.offset, "--offset");
    checkInputFile(path, kDepthMapInput);
    // The format is decided by the file's first bytes, and only that format's reader sees it.
    char head[32] = {};
    std::streamsize headBytes = 0;
    {
        std::ifstream probe(path, std::ios::binary);
        probe.read(head, sizeof head);
        headBytes = probe.gcount();
    }
    const std::string_view first(head, std::size_t(headBytes));
    if (depthformats::isNpy(first)) return depthformats::readNpy(path, reading, expectedWidth, expectedHeight);
    if (depthformats::isHdf5(first)) return depthformats::readHdf5(path, reading, expectedWidth, expectedHeight);
    if (depthformats::isColmapDepth(first)) return depthformats::readColmapDepth(path, reading, expectedWidth, expectedHeight);
    const auto* magic = reinterpret_cast<const unsigned char*>(head);
    if (magic[0] == 'P' && (magic[1] == 'f' || magic[1] == 'F') && std::isspace(magic[2])) {
        DepthMapFile map = readPfm(path, readInputFile(path, kDepthMapInput), reading, expectedWidth, expectedHeight);
        depthsFromStored(map, StoredValues::Float, reading);
        return map;
    }
    if (magic[0] == 0x89 && magic[1] == 'P' && magic[2] == 'N' && magic[3] == 'G') {
        // zcheck's own libpng reader (OpenImageIO's leaks on libpng's error path).
        if (!(scale > 0))
            throw Error("depth map '" + path +
                        "' stores integers (16-bit PNG): give --scale (stored value = depth × scale, e.g. 1000 for "
                        "millimetres, 5000 for many RGB-D sets, 256 for KITTI)");
        Png16 png;
        try {
            png = decodePng16(readInputFile(path, kDepthMapInput), [&](long long width, long long height) {
                requireDepthMapSize(path, width, height, expectedWidth, expectedHeight);
            });
        } catch (const Error& e) {
            const std::string what = e.what();
            if (what.rfind("depth map '", 0) == 0) throw;  // the size message names the file already
            refuseDepthMap(path, what);
        }
        DepthMapFile map;
        map.width = png.width, map.height = png.height;
        map.channel = chooseDepthChannel(path, {"Y"}, reading.channel, reading.quantityChannel);
        map.value.assign(png.codes.begin(), png.codes.end());
        depthsFromStored(map, StoredValues::Integer, reading);
        return map;
    }
    const bool exr = magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
    const bool tiff = (magic[0] == 'I' && magic[1] == 'I' && magic[2] == 42 && magic[3] == 0) ||
                      (magic[0] == 'M' && magic[1] == 'M' && magic[2] == 0 && magic[3] == 42);
    if (exr || tiff) return std::nullopt;
    refuseDepthMap(path, "not an EXR, TIFF, PNG, PFM, NumPy .npy, HDF5 or COLMAP depth map file (judged by its first bytes)");
}

}  // namespace zcheck
