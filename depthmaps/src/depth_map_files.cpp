// PFM and 16-bit PNG depth maps (libpng), read and written by zcheck itself, and the rules every
// depth-map reader shares (the size check, refusals).
#include "zcheck/depth_map_formats.h"
#include "zcheck/depth_map_reading.h"

#include "depth_formats.h"
#include "png_codec.h"
#include "zcheck/camera.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/atomic_file.h"

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

namespace {

DepthMapFile readPfmFile(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    DepthMapFile map = readPfm(path, readInputFile(path, kDepthMapInput), reading, expectedWidth, expectedHeight);
    depthsFromStored(map, StoredValues::Float, reading);
    return map;
}

// zcheck's own libpng reader (OpenImageIO's leaks on libpng's error path).
DepthMapFile readPng16File(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    reading.requireScaleForIntegers(path, "16-bit PNG");
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

// round(value × scale) as 16-bit codes, 0 a miss: every value must fit in 1..65535.
void writePng16(const std::string& path, const std::vector<QuantityImage>& images, double scale)
{
    const QuantityImage& image = images.front();
    const ExportQuantity q = image.quantity;
    if (q != ExportQuantity::Window && q != ExportQuantity::Ndc && q != ExportQuantity::EyeZ && q != ExportQuantity::Distance)
        throw Error("cannot write '" + path + "': 16-bit PNG holds one depth quantity (window, ndc, eye-z or distance), not " +
                    toString(q));
    if (!(scale > 0) || !std::isfinite(scale))
        throw Error("cannot write '" + path + "': 16-bit PNG needs --scale (stored = value × scale, e.g. 1000 for millimetres)");
    double largest = 0, smallest = INFINITY;
    for (std::size_t i = 0; i < image.value.size(); ++i) {
        if (image.isMiss(i)) continue;
        largest = std::max(largest, image.value[i]);
        smallest = std::min(smallest, image.value[i]);
    }
    if (smallest < 0)
        throw Error("cannot write '" + path + "': " + toString(q) + " has negative values (" + formatNumber(smallest) +
                    "), which 16-bit PNG cannot store");
    if (std::round(largest * scale) > 65535)
        throw Error("cannot write '" + path + "': the largest " + toString(q) + " " + formatNumber(largest) +
                    " times --scale " + formatNumber(scale) + " exceeds 65535; the largest scale that fits is " +
                    formatNumber(std::floor(65535.0 / largest * 1e6) / 1e6));
    if (std::isfinite(smallest) && std::round(smallest * scale) < 1)
        throw Error("cannot write '" + path + "': the smallest " + toString(q) + " " + formatNumber(smallest) +
                    " rounds to 0 at --scale " + formatNumber(scale) + ", which means a miss; raise --scale");
    std::vector<std::uint16_t> codes(image.value.size(), 0);
    for (std::size_t i = 0; i < codes.size(); ++i)
        if (!image.isMiss(i)) codes[i] = static_cast<std::uint16_t>(std::lround(image.value[i] * scale));
    writeFileBytes(path, encodePng(image.width, image.height, 1, 16, codes.data()));
}

// PFM, written here because OpenImageIO 2.4 (Debian 12) reads PFM but has no writer for it.
// Per the format: "Pf" (1 channel) or "PF" (3), "width height", a negative scale for
// little-endian data, then float32 rows from the BOTTOM row of the picture to the top.
void writePfm(const std::string& path, const std::vector<QuantityImage>& images, double)
{
    const QuantityImage& image = images.front();
    const std::size_t C = image.channels.size();
    if (image.quantity == ExportQuantity::PrimitiveId || (C != 1 && C != 3))
        throw Error("cannot write '" + path + "': PFM holds 1 or 3 float channels, not " + toString(image.quantity) +
                    " (use .exr or .tif)");
    std::string bytes = std::string(C == 1 ? "Pf" : "PF") + "\n" + std::to_string(image.width) + " " +
                        std::to_string(image.height) + "\n-1.0\n";
    std::vector<float> row(std::size_t(image.width) * C);
    for (int y = image.height - 1; y >= 0; --y) {
        for (std::size_t k = 0; k < row.size(); ++k) row[k] = float(image.value[std::size_t(y) * image.width * C + k]);
        bytes.append(reinterpret_cast<const char*>(row.data()), row.size() * sizeof(float));
    }
    writeFileBytes(path, bytes);
}

bool isPfm(std::string_view head)
{
    return head.size() >= 3 && head[0] == 'P' && (head[1] == 'f' || head[1] == 'F') &&
           std::isspace(static_cast<unsigned char>(head[2]));
}

bool isPng(std::string_view head) { return head.substr(0, 4) == "\x89PNG"; }

}  // namespace

namespace depthformats {

const DepthMapFormat& pfmFormat()
{
    static const DepthMapFormat row{"pfm", "PFM", {".pfm"}, "one quantity of 1 or 3 float32 channels, rows bottom to top",
                                    isPfm, readPfmFile, writePfm};
    return row;
}

const DepthMapFormat& png16Format()
{
    static const DepthMapFormat row{"png", "16-bit PNG", {".png"},
                                    "one depth quantity (window, ndc, eye-z, distance) as round(value × --scale), 0 a miss",
                                    isPng, readPng16File, writePng16};
    return row;
}

}  // namespace depthformats

}  // namespace zcheck
