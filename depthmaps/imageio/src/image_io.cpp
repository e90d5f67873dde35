#include "zcheck/image_io.h"

#include "zcheck/depth_map_formats.h"
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


bool isExr(std::string_view head) { return head.substr(0, 4) == std::string_view("\x76\x2f\x31\x01", 4); }

bool isTiff(std::string_view head)
{
    return head.substr(0, 4) == std::string_view("II\x2a\x00", 4) || head.substr(0, 4) == std::string_view("MM\x00\x2a", 4);
}

// An EXR or TIFF through OpenImageIO's plugin of that format alone (`plugin`: "openexr" or
// "tiff"), never through its other plugins.
DepthMapFile readThroughPlugin(const char* plugin, const std::string& path, const DepthMapReading& reading,
                               int expectedWidth, int expectedHeight)
{
    auto in = OIIO::ImageInput::create(plugin);
    OIIO::ImageSpec opened;
    if (!in || !in->open(path, opened)) {
        std::string reason = in ? in->geterror() : OIIO::geterror();
        for (char& c : reason)
            if (c == '\n') c = ' ';
        refuseDepthMap(path, "malformed " + std::string(plugin == std::string("openexr") ? "EXR" : "TIFF") +
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
    if (integer) reading.requireScaleForIntegers(path, format.c_str());
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

// EXR or TIFF: each quantity's channels interleaved as 4 bytes, float32 or uint32 for ids.
void writeThroughOiio(const std::string& path, const std::vector<QuantityImage>& images, bool exr)
{
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
    if (exr) spec.attribute("compression", "zip");
    writeImage(path, spec, words.data());
}

DepthMapFile readExr(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    preflightExr(path, expectedWidth, expectedHeight);
    return readThroughPlugin("openexr", path, reading, expectedWidth, expectedHeight);
}

DepthMapFile readTiff(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    return readThroughPlugin("tiff", path, reading, expectedWidth, expectedHeight);
}

const DepthMapFormat kExr{"exr", "EXR", {".exr"}, "any quantities, one channel each, float32 (ids uint32), ZIP", isExr, readExr,
                          [](const std::string& path, const std::vector<QuantityImage>& images, double) {
                              writeThroughOiio(path, images, true);
                          },
                          true};
const DepthMapFormat kTiff{"tiff", "TIFF", {".tif", ".tiff"}, "one quantity, float32 (ids uint32)", isTiff, readTiff,
                           [](const std::string& path, const std::vector<QuantityImage>& images, double) {
                               writeThroughOiio(path, images, false);
                           }};

}  // namespace

std::vector<const DepthMapFormat*> imageIoDepthMapFormats() { return {&kExr, &kTiff}; }

void registerImageIoDepthMapFormats()
{
    for (const DepthMapFormat* format : imageIoDepthMapFormats()) registerDepthMapFormat(*format);
}

DepthMapFile readDepthMap(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    registerImageIoDepthMapFormats();
    return readDepthMapFile(path, reading, expectedWidth, expectedHeight);
}

std::string writeQuantityFile(const std::string& path, const std::vector<QuantityImage>& images, double scale)
{
    registerImageIoDepthMapFormats();
    return writeDepthMapFile(path, images, scale);
}

}  // namespace zcheck
