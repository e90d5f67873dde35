#include "zcheck/image_io.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"

#include <OpenImageIO/imageio.h>

#include <cmath>

#include <algorithm>
#include <array>
#include <cmath>

namespace zcheck {

namespace {

void writeImage(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels)
{
    writeAtomically(path, [&](const std::string& temporary) {
        auto out = OIIO::ImageOutput::create(temporary);
        if (!out) throw Error("cannot write '" + path + "': " + OIIO::geterror());
        if (!out->open(temporary, spec) || !out->write_image(spec.format, pixels) || !out->close())
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
    for (const std::string& name : {preferredChannel, std::string("Z")}) {
        const int found = spec.channelindex(name);
        if (found >= 0) {
            channel = found;
            break;
        }
    }
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

using Rgb = std::array<std::uint8_t, 3>;

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
