#include "zcheck/image_io.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"

#include <OpenImageIO/imageio.h>

#include <cmath>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace zcheck {

namespace {

// `pixelFormat`: the buffer's format; UNKNOWN means each channel in spec.channelformats.
void writeImage(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels,
                OIIO::TypeDesc pixelFormat = OIIO::TypeDesc::UNKNOWN)
{
    if (spec.channelformats.empty() && pixelFormat == OIIO::TypeDesc::UNKNOWN) pixelFormat = spec.format;
    writeAtomically(path, [&](const std::string& temporary) {
        auto out = OIIO::ImageOutput::create(temporary);
        if (!out) throw Error("cannot write '" + path + "': " + OIIO::geterror());
        if (!out->open(temporary, spec) || !out->write_image(pixelFormat, pixels) || !out->close())
            throw Error("cannot write '" + path + "': " + out->geterror());
    });
}

}  // namespace

void writeExr(const std::string& path, int width, int height, const std::vector<std::string>& names,
              const std::vector<float>& channels)
{
    OIIO::ImageSpec spec(width, height, int(names.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.attribute("compression", "zip");
    writeImage(path, spec, channels.data());
}

void writePng8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb)
{
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    writeImage(path, spec, rgb.data());
}

std::string pngDataUri(int width, int height, const std::vector<std::uint8_t>& rgb)
{
    const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                       ("zcheck-" + std::to_string(::getpid()) + "-inline.png");
    writePng8(file.string(), width, height, rgb);
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::error_code ignored;
    std::filesystem::remove(file, ignored);
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out = "data:image/png;base64,";
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t n = (std::uint32_t(std::uint8_t(bytes[i])) << 16) |
                                (i + 1 < bytes.size() ? std::uint32_t(std::uint8_t(bytes[i + 1])) << 8 : 0) |
                                (i + 2 < bytes.size() ? std::uint32_t(std::uint8_t(bytes[i + 2])) : 0);
        out += digits[(n >> 18) & 63];
        out += digits[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? digits[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? digits[n & 63] : '=';
    }
    return out;
}

DepthMapFile readDepthMap(const std::string& path, const std::string& preferredChannel, double scale)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        std::string reason = OIIO::geterror();
        for (char& c : reason)
            if (c == '\n') c = ' ';
        throw Error("cannot read depth map '" + path + "': " + (reason.empty() ? "unreadable" : reason));
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width < 1 || spec.height < 1 || spec.depth > 1)
        throw Error("cannot read depth map '" + path + "': not a 2-D image");
    int channel = 0;
    if (spec.channelindex(preferredChannel) >= 0) channel = spec.channelindex(preferredChannel);
    const bool integer = !spec.format.is_floating_point();
    if (integer && !(scale > 0))
        throw Error("depth map '" + path + "' stores integers (" + std::string(spec.format.c_str()) +
                    "): give --scale (stored value = depth × scale, e.g. 1000 for millimetres)");
    DepthMapFile map;
    map.width = spec.width, map.height = spec.height;
    map.channel = spec.channelnames.empty() ? "0" : spec.channelnames[std::size_t(channel)];
    std::vector<double> pixels(std::size_t(spec.width) * spec.height);
    if (!in->read_image(0, 0, channel, channel + 1, OIIO::TypeDesc::DOUBLE, pixels.data()))
        throw Error("cannot read depth map '" + path + "': " + in->geterror());
    if (integer) {
        // read_image scales integers to [0,1]; undo it to get the stored code.
        const double maxCode = std::pow(2.0, double(spec.format.size() * 8)) - 1;
        for (double& v : pixels) {
            const double code = std::round(v * maxCode);
            v = code == 0 ? NAN : code / scale;
        }
    } else if (scale > 0) {
        for (double& v : pixels) v /= scale;
    }
    map.value = std::move(pixels);
    return map;
}

namespace {

std::string lowerExtension(const std::string& path)
{
    const std::size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

void writePng16(const std::string& path, const QuantityImage& image, double scale)
{
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
    OIIO::ImageSpec spec(image.width, image.height, 1, OIIO::TypeDesc::UINT16);
    writeImage(path, spec, codes.data());
}

// PFM, written here because OpenImageIO 2.4 (Debian 12) reads PFM but has no writer for it.
// Per the format: "Pf" (1 channel) or "PF" (3), "width height", a negative scale for
// little-endian data, then float32 rows from the BOTTOM row of the picture to the top.
void writePfm(const std::string& path, const QuantityImage& image)
{
    const std::size_t C = image.channels.size();
    if (image.quantity == ExportQuantity::PrimitiveId || (C != 1 && C != 3))
        throw Error("cannot write '" + path + "': PFM holds 1 or 3 float channels, not " + toString(image.quantity) +
                    " (use .exr or .tif)");
    writeAtomically(path, [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << (C == 1 ? "Pf" : "PF") << "\n" << image.width << " " << image.height << "\n-1.0\n";
        std::vector<float> row(std::size_t(image.width) * C);
        for (int y = image.height - 1; y >= 0; --y) {
            for (std::size_t k = 0; k < row.size(); ++k) row[k] = float(image.value[std::size_t(y) * image.width * C + k]);
            out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
        }
        out.flush();
        if (!out) throw Error("cannot write '" + path + "': write failed");
    });
}

}  // namespace

std::string writeQuantityFile(const std::string& path, const std::vector<QuantityImage>& images, double scale)
{
    const std::string ext = lowerExtension(path);
    const std::string format = ext == ".exr" ? "exr" : ext == ".pfm" ? "pfm" : (ext == ".tif" || ext == ".tiff") ? "tiff"
                                                                            : ext == ".png" ? "png" : "";
    if (format.empty())
        throw Error("cannot write '" + path + "': unknown format '" + ext + "' (expected .exr, .pfm, .tif or .png)");
    if (images.empty()) throw Error("nothing to write to '" + path + "'");
    if (format != "exr" && images.size() > 1)
        throw Error("cannot write '" + path + "': several quantities go into one file only as .exr");
    if (format == "png") {
        writePng16(path, images[0], scale);
        return format;
    }
    if (format == "pfm") {
        writePfm(path, images[0]);
        return format;
    }
    const QuantityImage& first = images[0];
    const bool hasId = std::any_of(images.begin(), images.end(), [](const QuantityImage& q) { return q.quantity == ExportQuantity::PrimitiveId; });
    // Interleave every channel as 4 bytes: float32, or uint32 for ids.
    std::vector<std::string> names;
    std::vector<OIIO::TypeDesc> formats;
    for (const auto& image : images)
        for (const auto& name : image.channels) {
            names.push_back(name);
            formats.push_back(image.quantity == ExportQuantity::PrimitiveId ? OIIO::TypeDesc::UINT32 : OIIO::TypeDesc::FLOAT);
        }
    const std::size_t pixels = std::size_t(first.width) * first.height, channels = names.size();
    std::vector<std::uint32_t> words(pixels * channels);
    std::size_t c0 = 0;
    for (const auto& image : images) {
        const std::size_t C = image.channels.size();
        for (std::size_t i = 0; i < pixels; ++i)
            for (std::size_t c = 0; c < C; ++c) {
                std::uint32_t word;
                if (image.quantity == ExportQuantity::PrimitiveId) {
                    word = image.id[i];
                } else {
                    const float v = float(image.value[i * C + c]);
                    std::memcpy(&word, &v, 4);
                }
                words[i * channels + c0 + c] = word;
            }
        c0 += C;
    }
    const bool mixed = hasId && channels > 1;
    OIIO::ImageSpec spec(first.width, first.height, int(channels), hasId && !mixed ? OIIO::TypeDesc::UINT32 : OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    if (mixed) spec.channelformats = formats;
    if (format == "exr") spec.attribute("compression", "zip");
    writeImage(path, spec, words.data());
    return format;
}

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// viridis (matplotlib), sampled at 9 points and interpolated.
Rgb viridis(double t)
{
    static const double stops[9][3] = {{68, 1, 84},    {71, 45, 123},  {59, 82, 139},  {44, 114, 142}, {33, 145, 140},
                                       {39, 173, 129}, {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
    t = std::clamp(t, 0.0, 1.0) * 8;
    const int k = std::min(7, int(t));
    const double f = t - k;
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = std::uint8_t(std::lround(stops[k][c] + f * (stops[k + 1][c] - stops[k][c])));
    return out;
}

}  // namespace

std::vector<std::uint8_t> previewRgb(const QuantityImage& image)
{
    const std::size_t pixels = std::size_t(image.width) * image.height;
    std::vector<std::uint8_t> rgb(pixels * 3, 0);
    const std::size_t C = image.channels.size();
    double lo = INFINITY, hi = -INFINITY;
    if (C == 1 && image.quantity != ExportQuantity::PrimitiveId)
        for (std::size_t i = 0; i < pixels; ++i)
            if (!image.isMiss(i)) lo = std::min(lo, image.value[i]), hi = std::max(hi, image.value[i]);
    double boxLo[3] = {INFINITY, INFINITY, INFINITY}, boxHi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (C == 3)
        for (std::size_t i = 0; i < pixels; ++i)
            for (int k = 0; k < 3 && !image.isMiss(i); ++k)
                boxLo[k] = std::min(boxLo[k], image.value[i * 3 + k]), boxHi[k] = std::max(boxHi[k], image.value[i * 3 + k]);
    for (std::size_t i = 0; i < pixels; ++i) {
        if (image.isMiss(i)) continue;
        Rgb c{};
        if (image.quantity == ExportQuantity::PrimitiveId) {
            std::uint32_t h = image.id[i] * 2654435761u;  // Knuth's multiplicative hash
            c = {std::uint8_t(64 + (h >> 24) % 192), std::uint8_t(64 + (h >> 16) % 192), std::uint8_t(64 + (h >> 8) % 192)};
        } else if (C == 3) {
            // Normals as (n + 1)/2; positions scaled per axis to their bounding box.
            for (int k = 0; k < 3; ++k) {
                const double v = image.value[i * 3 + k];
                const double t = image.quantity == ExportQuantity::Normal ? (v + 1) / 2
                                 : boxHi[k] > boxLo[k]                    ? (v - boxLo[k]) / (boxHi[k] - boxLo[k])
                                                                          : 0.5;
                c[k] = std::uint8_t(std::lround(255 * std::clamp(t, 0.0, 1.0)));
            }
        } else {
            c = viridis(hi > lo ? (image.value[i] - lo) / (hi - lo) : 0.5);
        }
        std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(3 * i));
    }
    return rgb;
}

namespace {

Rgb classColour(PixelClass c)
{
    switch (c) {
    case PixelClass::BothMiss: return {0, 0, 0};
    case PixelClass::Agree: return {70, 160, 70};
    case PixelClass::EdgeSurface: return {60, 120, 200};
    case PixelClass::DepthError: return {230, 30, 30};
    case PixelClass::RayOnlyEdge: return {220, 200, 60};
    case PixelClass::RasterOnlyEdge: return {60, 200, 200};
    case PixelClass::RayOnlyAtClear: return {120, 80, 160};
    case PixelClass::AtClipPlane: return {150, 110, 60};
    case PixelClass::RayOnly: return {255, 0, 255};
    case PixelClass::RasterOnly: return {255, 140, 0};
    }
    return {255, 255, 255};
}

Rgb heat(float ratio)
{
    if (!(ratio <= 1.0f)) return {255, 0, 0};  // beyond tolerance (or NaN)
    // black → blue → green → yellow over [0, 1]; the square root shows small errors.
    static const float stops[4][3] = {{0, 0, 0}, {0, 0, 255}, {0, 200, 0}, {255, 255, 0}};
    const float t = std::sqrt(std::max(0.0f, ratio)) * 3;
    const int k = std::min(2, int(t));
    const float f = t - float(k);
    Rgb out;
    for (int c = 0; c < 3; ++c) out[c] = std::uint8_t(stops[k][c] + f * (stops[k + 1][c] - stops[k][c]));
    return out;
}

template <class Colour>
std::vector<std::uint8_t> paint(const Comparison& comparison, Colour colour)
{
    std::vector<std::uint8_t> rgb(comparison.pixelClass.size() * 3);
    for (std::size_t i = 0; i < comparison.pixelClass.size(); ++i) {
        const Rgb c = colour(i);
        std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(3 * i));
    }
    return rgb;
}

}  // namespace

std::vector<std::uint8_t> errorHeatmapRgb(const Comparison& comparison)
{
    return paint(comparison, [&](std::size_t i) -> Rgb {
        switch (comparison.pixelClass[i]) {
        case PixelClass::Agree:
        case PixelClass::DepthError: return heat(comparison.errorOverTolerance[i]);
        case PixelClass::RayOnly:
        case PixelClass::RasterOnly: return {255, 0, 255};
        case PixelClass::BothMiss: return {0, 0, 0};
        default: return {40, 40, 40};
        }
    });
}

std::vector<std::uint8_t> pixelClassRgb(const Comparison& comparison)
{
    return paint(comparison, [&](std::size_t i) { return classColour(comparison.pixelClass[i]); });
}

}  // namespace zcheck
