#include "zcheck/image_io.h"

#include "depth_formats.h"

#include "png_codec.h"
#include "zcheck/atomic_file.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <OpenImageIO/imageio.h>

#include <cmath>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <cerrno>
#include <charconv>
#include <fcntl.h>
#include <unistd.h>

namespace zcheck {

namespace {

// `pixelFormat`: the buffer's format; UNKNOWN means each channel in spec.channelformats.
// Writes `path` itself (callers make it atomic, atomic_file.h); OpenImageIO's own result of
// open, write and close is checked, then the file is synced.
void writeImage(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels,
                OIIO::TypeDesc pixelFormat = OIIO::TypeDesc::UNKNOWN)
{
    if (spec.channelformats.empty() && pixelFormat == OIIO::TypeDesc::UNKNOWN) pixelFormat = spec.format;
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Error("cannot write '" + path + "': " + OIIO::geterror());
    if (!out->open(path, spec) || !out->write_image(pixelFormat, pixels) || !out->close())
        throw Error("cannot write '" + path + "': " + out->geterror());
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
        const std::string why = std::strerror(errno);
        if (fd >= 0) ::close(fd);
        throw Error("cannot write '" + path + "': " + why);
    }
    ::close(fd);
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

namespace {

// OpenEXR allocates what a header attribute's size field claims (up to 2 GiB for a string)
// before anything else is checked. The header is walked here first: every attribute must fit
// in the file, and the data window (the image size) must be the camera's. The layout per the
// OpenEXR file format: magic, version flags, then attributes `name\0 type\0 int32 size, value`
// ending with an empty name; multi-part files repeat headers up to an empty header.
void preflightExr(const std::string& path, int expectedWidth, int expectedHeight)
{
    const std::uint64_t fileSize = checkInputFile(path, kDepthMapInput);
    constexpr std::size_t kMaxHeaderBytes = 16 << 20;
    std::string head(std::size_t(std::min<std::uint64_t>(fileSize, kMaxHeaderBytes)), '\0');
    {
        std::ifstream in(path, std::ios::binary);
        in.read(head.data(), std::streamsize(head.size()));
        if (std::uint64_t(in.gcount()) != head.size()) refuseDepthMap(path, "the file could not be read whole");
    }
    auto malformed = [&](const std::string& why) { refuseDepthMap(path, "malformed EXR header: " + why); };
    if (head.size() < 8) malformed("shorter than 8 bytes");
    std::uint32_t version = 0;
    std::memcpy(&version, head.data() + 4, 4);
    const bool multipart = version & 0x1000, longNames = version & 0x400;
    if ((version & 0xff) != 2) malformed("version " + std::to_string(version & 0xff) + " (expected 2)");
    std::size_t at = 8;
    bool sawDataWindow = false;
    auto text = [&](const char* what) {
        const std::size_t end = head.find('\0', at);
        const std::size_t limit = longNames ? 255 : 31;
        if (end == std::string::npos || end - at > limit)
            malformed(std::string(what) + " longer than " + std::to_string(limit) + " bytes or unterminated");
        std::string value = head.substr(at, end - at);
        at = end + 1;
        return value;
    };
    for (;;) {  // one header (one part)
        for (;;) {  // its attributes, up to an empty name
            if (at >= head.size()) malformed("the header does not end within the file's first 16 MiB");
            if (head[at] == '\0') {
                ++at;
                break;
            }
            const std::string name = text("an attribute name"), type = text("an attribute type");
            if (at + 4 > head.size()) malformed("attribute '" + name + "' has no size");
            std::int32_t size = 0;
            std::memcpy(&size, head.data() + at, 4);
            at += 4;
            if (size < 0 || std::uint64_t(size) > fileSize - at)
                malformed("attribute '" + name + "' declares " + std::to_string(size) + " bytes, more than the file holds");
            if (name == "dataWindow" && !sawDataWindow) {
                if (type != "box2i" || size != 16 || at + 16 > head.size()) malformed("dataWindow is not a box2i");
                std::int32_t box[4];
                std::memcpy(box, head.data() + at, 16);
                requireDepthMapSize(path, std::int64_t(box[2]) - box[0] + 1, std::int64_t(box[3]) - box[1] + 1, expectedWidth,
                            expectedHeight);
                sawDataWindow = true;
            }
            at += std::size_t(size);
        }
        if (!multipart) break;
        if (at >= head.size()) malformed("the list of part headers does not end");
        if (head[at] == '\0') break;  // an empty header ends a multi-part file's headers
    }
    if (!sawDataWindow) malformed("no dataWindow attribute");
}

}  // namespace

DepthMapFile readDepthMap(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    if (std::optional<DepthMapFile> native = readDepthMapNatively(path, reading, expectedWidth, expectedHeight))
        return std::move(*native);
    const double scale = reading.scale;
    // EXR or TIFF (readDepthMapNatively refused anything else): only that format's reader sees
    // the file — OpenImageIO would otherwise offer unknown bytes to every plugin it has (video,
    // camera raw, DICOM, ...).
    unsigned char magic[4] = {0, 0, 0, 0};
    {
        std::ifstream probe(path, std::ios::binary);
        probe.read(reinterpret_cast<char*>(magic), 4);
    }
    const char* plugin = magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01 ? "openexr"
                         : (magic[0] == 'I' && magic[1] == 'I' && magic[2] == 42 && magic[3] == 0) ||
                                   (magic[0] == 'M' && magic[1] == 'M' && magic[2] == 0 && magic[3] == 42)
                             ? "tiff"
                                                                                                      : nullptr;
    if (!plugin) refuseDepthMap(path, "not an EXR or TIFF file (judged by its first bytes)");
    auto requireScale = [&](const std::string& what) {
        if (!(scale > 0))
            throw Error("depth map '" + path + "' stores integers (" + what +
                        "): give --scale (stored value = depth × scale, e.g. 1000 for millimetres, 5000 for many RGB-D "
                        "sets, 256 for KITTI)");
    };
    if (plugin == std::string("openexr")) preflightExr(path, expectedWidth, expectedHeight);
    auto in = OIIO::ImageInput::create(plugin);
    OIIO::ImageSpec opened;
    if (!in || !in->open(path, opened)) {
        std::string reason = in ? in->geterror() : OIIO::geterror();
        for (char& c : reason)
            if (c == '\n') c = ' ';
        refuseDepthMap(path, "malformed " + std::string(plugin == std::string("openexr") ? "EXR" : plugin == std::string("tiff") ? "TIFF" : "PNG") +
                            (reason.empty() ? "" : ": " + reason));
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width < 1 || spec.height < 1 || spec.depth > 1 || spec.nchannels < 1) refuseDepthMap(path, "not a 2-D image");
    // Compared with the camera before a pixel is allocated: a header may declare anything.
    requireDepthMapSize(path, spec.width, spec.height, expectedWidth, expectedHeight);
    std::vector<std::string> names;
    for (int c = 0; c < spec.nchannels; ++c)
        names.push_back(c < int(spec.channelnames.size()) && !spec.channelnames[std::size_t(c)].empty()
                            ? spec.channelnames[std::size_t(c)]
                            : std::to_string(c));
    DepthMapFile map;
    map.width = spec.width, map.height = spec.height;
    map.channel = chooseDepthChannel(path, names, reading.channel, reading.quantityChannel);
    const int channel = int(std::find(names.begin(), names.end(), map.channel) - names.begin());
    const OIIO::TypeDesc format = spec.channelformat(channel);
    const bool integer = !format.is_floating_point();
    if (integer && format.size() < 2)
        refuseDepthMap(path, "channel '" + map.channel + "' stores " + std::to_string(8 * format.size()) +
                            "-bit integers, which cannot hold depth (a picture, not a depth map?)");
    if (integer) requireScale(format.c_str());
    std::vector<double> pixels(std::size_t(spec.width) * std::size_t(spec.height));
    if (!in->read_image(0, 0, channel, channel + 1, OIIO::TypeDesc::DOUBLE, pixels.data())) {
        std::string reason = in->geterror();
        for (char& c : reason)
            if (c == '\n') c = ' ';
        refuseDepthMap(path, reason.empty() ? "the pixel data is truncated or corrupt" : reason);
    }
    // read_image scales integers to [0,1]; undo it to get the stored code.
    if (integer) {
        const double maxCode = std::pow(2.0, double(format.size() * 8)) - 1;
        for (double& v : pixels) v = std::round(v * maxCode);
    }
    map.value = std::move(pixels);
    depthsFromStored(map, integer                              ? StoredValues::Integer
                          : format == OIIO::TypeDesc::HALF ? StoredValues::Half
                                                            : StoredValues::Float,
                     reading);
    return map;
}

namespace {

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
    writeFileBytes(path, encodePng(image.width, image.height, 1, 16, codes.data()));
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
    std::string bytes = std::string(C == 1 ? "Pf" : "PF") + "\n" + std::to_string(image.width) + " " +
                        std::to_string(image.height) + "\n-1.0\n";
    std::vector<float> row(std::size_t(image.width) * C);
    for (int y = image.height - 1; y >= 0; --y) {
        for (std::size_t k = 0; k < row.size(); ++k) row[k] = float(image.value[std::size_t(y) * image.width * C + k]);
        bytes.append(reinterpret_cast<const char*>(row.data()), row.size() * sizeof(float));
    }
    writeFileBytes(path, bytes);
}

}  // namespace

std::string writeQuantityFile(const std::string& path, const std::vector<QuantityImage>& images, double scale)
{
    const std::string ext = lowerExtension(path);
    const std::string format = ext == ".exr" ? "exr" : ext == ".pfm" ? "pfm" : (ext == ".tif" || ext == ".tiff") ? "tiff"
                               : ext == ".png"                    ? "png"
                               : ext == ".npy"                    ? "npy"
                               : (ext == ".h5" || ext == ".hdf5") ? "hdf5"
                               : ext == ".bin"                    ? "colmap"
                                                                  : "";
    if (format.empty())
        throw Error("cannot write '" + path + "': unknown format '" + ext +
                    "' (expected .exr, .pfm, .tif, .png, .npy, .h5 or .bin for a COLMAP depth map)");
    if (images.empty()) throw Error("nothing to write to '" + path + "'");
    if (format != "exr" && format != "hdf5" && images.size() > 1)
        throw Error("cannot write '" + path + "': several quantities go into one file only as .exr or .h5");
    if (format == "npy") {
        depthformats::writeNpy(path, images[0]);
        return format;
    }
    if (format == "colmap") {
        depthformats::writeColmapDepth(path, images[0]);
        return format;
    }
    if (format == "hdf5") {
        depthformats::writeHdf5(path, images);
        return format;
    }
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

}  // namespace zcheck
