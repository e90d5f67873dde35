// NumPy .npy and COLMAP dense depth maps, read and written by zcheck itself (depth_formats.h
// states the formats and what is refused). Sizes are compared with the camera's before any
// pixel is allocated, and the data must be exactly as long as the header says.
#include "depth_formats.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace zcheck::depthformats {

namespace {

// IEEE binary16 to double, exactly (every half is a double).
double fromHalf(std::uint16_t h)
{
    const int sign = (h >> 15) ? -1 : 1;
    const int exponent = (h >> 10) & 0x1F;
    const int mantissa = h & 0x3FF;
    if (exponent == 0) return sign * std::ldexp(double(mantissa), -24);
    if (exponent == 31) return mantissa ? NAN : sign * INFINITY;
    return sign * std::ldexp(double(mantissa | 0x400), exponent - 25);
}

// ---- .npy header: a Python dict literal ------------------------------------------------

class NpyHeader {
public:
    NpyHeader(std::string_view text, const std::string& path) : text_(text), path_(path) {}

    std::string descr;
    bool fortran = false;
    std::vector<long long> shape;

    void parse()
    {
        expect('{');
        bool sawDescr = false, sawOrder = false, sawShape = false;
        while (true) {
            skipSpace();
            if (peek() == '}') break;
            const std::string key = quoted();
            expect(':');
            if (key == "descr") {
                skipSpace();
                if (peek() != '\'' && peek() != '"')
                    fail("its dtype is structured (a list of fields): zcheck reads one plain dtype (float16/32/64, "
                         "(u)int16/32)");
                descr = quoted(), sawDescr = true;
            } else if (key == "fortran_order") {
                fortran = boolean(), sawOrder = true;
            } else if (key == "shape") {
                shape = tuple(), sawShape = true;
            } else {
                fail("its header has an unknown key '" + printableExcerpt(key, 30) + "'");
            }
            skipSpace();
            if (peek() == ',') ++at_;
        }
        ++at_;
        if (!sawDescr || !sawOrder || !sawShape) fail("its header lacks one of 'descr', 'fortran_order', 'shape'");
    }

private:
    [[noreturn]] void fail(const std::string& why) const { throw Error("cannot read depth map '" + path_ + "': " + why); }
    char peek() const { return at_ < text_.size() ? text_[at_] : '\0'; }
    void skipSpace()
    {
        while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\n' || text_[at_] == '\t')) ++at_;
    }
    void expect(char c)
    {
        skipSpace();
        if (peek() != c) fail(std::string("malformed .npy header: expected '") + c + "' at byte " + std::to_string(at_));
        ++at_;
    }
    std::string quoted()
    {
        skipSpace();
        const char q = peek();
        if (q != '\'' && q != '"') fail("malformed .npy header: expected a quoted string at byte " + std::to_string(at_));
        const std::size_t start = ++at_;
        while (at_ < text_.size() && text_[at_] != q) ++at_;
        if (at_ >= text_.size()) fail("malformed .npy header: an unterminated string");
        return std::string(text_.substr(start, at_++ - start));
    }
    bool boolean()
    {
        skipSpace();
        if (text_.substr(at_, 4) == "True") return at_ += 4, true;
        if (text_.substr(at_, 5) == "False") return at_ += 5, false;
        fail("malformed .npy header: fortran_order must be True or False");
    }
    std::vector<long long> tuple()
    {
        expect('(');
        std::vector<long long> out;
        while (true) {
            skipSpace();
            if (peek() == ')') break;
            const std::size_t start = at_;
            while (at_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[at_]))) ++at_;
            long long v = 0;
            const auto [end, error] = std::from_chars(text_.data() + start, text_.data() + at_, v);
            if (start == at_ || error != std::errc() || end != text_.data() + at_ || out.size() >= 8)
                fail("malformed .npy header: the shape must be a tuple of at most 8 whole numbers");
            out.push_back(v);
            skipSpace();
            if (peek() == ',') ++at_;
        }
        ++at_;
        return out;
    }

    std::string_view text_;
    std::string path_;
    std::size_t at_ = 0;
};

std::uint64_t readUnsigned(const unsigned char* p, int bytes, bool bigEndian)
{
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= std::uint64_t(p[bigEndian ? bytes - 1 - i : i]) << (8 * i);
    return v;
}

}  // namespace

bool isNpy(std::string_view head) { return head.size() >= 6 && head.substr(0, 6) == "\x93NUMPY"; }

bool isColmapDepth(std::string_view head)
{
    // "W&H&C&": three runs of digits, each ended by '&'.
    std::size_t at = 0;
    for (int field = 0; field < 3; ++field) {
        const std::size_t start = at;
        while (at < head.size() && at - start < 10 && std::isdigit(static_cast<unsigned char>(head[at]))) ++at;
        if (at == start || at >= head.size() || head[at] != '&') return false;
        ++at;
    }
    return true;
}

bool isHdf5(std::string_view head) { return head.size() >= 8 && head.substr(0, 8) == std::string_view("\x89HDF\r\n\x1a\n", 8); }

DepthMapFile readNpy(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    const std::string bytes = readInputFile(path, kDepthMapInput);
    auto refuse = [&](const std::string& why) { throw Error("cannot read depth map '" + path + "': " + why); };
    if (bytes.size() < 10) refuse("the .npy header is cut short");
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
    const int major = b[6];
    if (major < 1 || major > 3) refuse(".npy version " + std::to_string(major) + " is not 1, 2 or 3");
    const std::size_t lengthBytes = major == 1 ? 2 : 4;
    const std::size_t headerStart = 8 + lengthBytes;
    if (bytes.size() < headerStart) refuse("the .npy header is cut short");
    const std::uint64_t headerLength = readUnsigned(b + 8, int(lengthBytes), false);
    if (headerLength > bytes.size() - headerStart) refuse("the .npy header claims " + std::to_string(headerLength) + " bytes, more than the file holds");
    NpyHeader header(std::string_view(bytes).substr(headerStart, std::size_t(headerLength)), path);
    header.parse();

    // dtype: byte order, kind, size.
    const std::string& d = header.descr;
    if (d.size() < 3 || std::string("<>|=").find(d[0]) == std::string::npos)
        refuse("dtype '" + printableExcerpt(d, 20) + "' is not a plain numeric dtype");
    const char kind = d[1];
    int size = 0;
    const auto [end, error] = std::from_chars(d.data() + 2, d.data() + d.size(), size);
    if (error != std::errc() || end != d.data() + d.size()) refuse("dtype '" + printableExcerpt(d, 20) + "' is not a plain numeric dtype");
    const bool bigEndian = d[0] == '>';
    const bool floating = kind == 'f' && (size == 2 || size == 4 || size == 8);
    const bool integer = (kind == 'u' || kind == 'i') && (size == 2 || size == 4);
    if ((kind == 'u' || kind == 'i') && size == 1) refuse("dtype " + d + " stores 8-bit integers, which cannot hold depth (a picture, not a depth map?)");
    if (!floating && !integer)
        refuse("dtype " + d + " is not one zcheck reads as depth (float16, float32, float64, (u)int16, (u)int32)");
    if (integer) reading.requireScaleForIntegers(path, ".npy " + d);

    // shape: (H, W), (H, W, C).
    const std::vector<long long>& s = header.shape;
    if (s.size() != 2 && s.size() != 3)
        refuse("its shape has " + std::to_string(s.size()) + " dimensions: a depth map is (height, width) or (height, width, channels)");
    const long long height = s[0], width = s[1], channels = s.size() == 3 ? s[2] : 1;
    if (channels < 1 || channels > 64) refuse("its shape has " + std::to_string(channels) + " channels (1..64 are read)");
    requireDepthMapSize(path, width, height, expectedWidth, expectedHeight);
    const std::uint64_t need = std::uint64_t(width) * std::uint64_t(height) * std::uint64_t(channels) * std::uint64_t(size);
    const std::uint64_t have = bytes.size() - headerStart - headerLength;
    if (have != need)
        refuse("the .npy data holds " + std::to_string(have) + " bytes, but shape " + std::to_string(height) + "x" +
               std::to_string(width) + "x" + std::to_string(channels) + " of " + d + " needs " + std::to_string(need) +
               (have < need ? " (truncated)" : ""));

    std::vector<std::string> names;
    for (long long c = 0; c < channels; ++c) names.push_back(std::to_string(c));
    DepthMapFile map;
    map.width = int(width), map.height = int(height);
    map.channel = chooseDepthChannel(path, names, reading.channel, reading.quantityChannel);
    const std::size_t channel = std::size_t(std::stoll(map.channel));
    const unsigned char* data = b + headerStart + headerLength;
    map.value.resize(std::size_t(width) * std::size_t(height));
    for (long long row = 0; row < height; ++row)
        for (long long col = 0; col < width; ++col) {
            // C order: (row, col, c) at (row·W + col)·C + c; Fortran order: row + H·(col + W·c).
            const std::uint64_t element = header.fortran
                                              ? std::uint64_t(row) + std::uint64_t(height) * (std::uint64_t(col) + std::uint64_t(width) * channel)
                                              : (std::uint64_t(row) * std::uint64_t(width) + std::uint64_t(col)) * std::uint64_t(channels) + channel;
            const std::uint64_t raw = readUnsigned(data + element * std::uint64_t(size), size, bigEndian);
            double v = 0;
            if (kind == 'f' && size == 2) {
                v = fromHalf(std::uint16_t(raw));
            } else if (kind == 'f' && size == 4) {
                float f;
                const auto bits = std::uint32_t(raw);
                std::memcpy(&f, &bits, 4);
                v = f;
            } else if (kind == 'f') {
                std::memcpy(&v, &raw, 8);
            } else if (kind == 'u') {
                v = double(raw);
            } else {
                v = size == 2 ? double(std::int16_t(std::uint16_t(raw))) : double(std::int32_t(std::uint32_t(raw)));
            }
            map.value[std::size_t(row) * std::size_t(width) + std::size_t(col)] = v;
        }
    const bool half = kind == 'f' && size == 2;
    depthsFromStored(map, integer ? StoredValues::Integer : (half ? StoredValues::Half : StoredValues::Float), reading);
    return map;
}

DepthMapFile readColmapDepth(const std::string& path, const DepthMapReading& reading, int expectedWidth, int expectedHeight)
{
    const std::string bytes = readInputFile(path, kDepthMapInput);
    auto refuse = [&](const std::string& why) { throw Error("cannot read depth map '" + path + "': " + why); };
    long long fields[3] = {0, 0, 0};
    std::size_t at = 0;
    for (long long& field : fields) {
        const std::size_t start = at;
        while (at < bytes.size() && at - start < 10 && std::isdigit(static_cast<unsigned char>(bytes[at]))) ++at;
        const auto [end, error] = std::from_chars(bytes.data() + start, bytes.data() + at, field);
        if (at == start || error != std::errc() || at >= bytes.size() || bytes[at] != '&')
            refuse("malformed COLMAP depth map header: expected \"WIDTH&HEIGHT&CHANNELS&\"");
        ++at;
    }
    const long long width = fields[0], height = fields[1], channels = fields[2];
    if (channels != 1)
        refuse("a COLMAP map of " + std::to_string(channels) + " channels is a normal map, not a depth map (depth has 1)");
    requireDepthMapSize(path, width, height, expectedWidth, expectedHeight);
    const std::uint64_t need = std::uint64_t(width) * std::uint64_t(height) * 4;
    if (bytes.size() - at != need)
        refuse("the COLMAP data holds " + std::to_string(bytes.size() - at) + " bytes, but " + std::to_string(width) + "x" +
               std::to_string(height) + " float32 values need " + std::to_string(need) + (bytes.size() - at < need ? " (truncated)" : ""));
    DepthMapFile map;
    map.width = int(width), map.height = int(height);
    map.channel = chooseDepthChannel(path, {"depth"}, reading.channel, reading.quantityChannel);
    map.value.resize(std::size_t(width) * std::size_t(height));
    for (std::size_t i = 0; i < map.value.size(); ++i) {
        float v;
        std::memcpy(&v, bytes.data() + at + 4 * i, 4);
        // COLMAP marks "no depth" with values ≤ 0 (its fusion skips them).
        map.value[i] = v <= 0 && !reading.miss.given() ? NAN : reading.depthOf(v, true);
    }
    return map;
}

namespace {

std::string npyHeaderFor(const std::string& descr, int height, int width, std::size_t channels)
{
    std::string dict = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (" + std::to_string(height) + ", " +
                       std::to_string(width) + (channels > 1 ? ", " + std::to_string(channels) : "") + "), }";
    // Version 1.0: the magic, the version, a 16-bit length; the whole header a multiple of 64 bytes.
    const std::size_t unpadded = 10 + dict.size() + 1;
    dict.append((64 - unpadded % 64) % 64, ' ');
    dict += '\n';
    const auto length = std::uint16_t(dict.size());
    std::string out("\x93NUMPY\x01\x00", 8);
    out += char(length & 0xFF);
    out += char(length >> 8);
    return out + dict;
}

}  // namespace

void writeNpy(const std::string& path, const QuantityImage& image)
{
    std::string bytes;
    if (image.quantity == ExportQuantity::PrimitiveId) {
        bytes = npyHeaderFor("<u4", image.height, image.width, 1);
        bytes.append(reinterpret_cast<const char*>(image.id.data()), image.id.size() * 4);
    } else {
        bytes = npyHeaderFor("<f4", image.height, image.width, image.channels.size());
        for (double v : image.value) {
            const float f = float(v);
            bytes.append(reinterpret_cast<const char*>(&f), 4);
        }
    }
    writeFileBytes(path, bytes);
}

void writeColmapDepth(const std::string& path, const QuantityImage& image)
{
    const ExportQuantity q = image.quantity;
    if (q != ExportQuantity::Window && q != ExportQuantity::Ndc && q != ExportQuantity::EyeZ && q != ExportQuantity::Distance)
        throw Error("cannot write '" + path + "': a COLMAP depth map holds one depth quantity (eye-z as COLMAP's own), not " +
                    toString(q));
    std::string bytes = std::to_string(image.width) + "&" + std::to_string(image.height) + "&1&";
    for (std::size_t i = 0; i < image.value.size(); ++i) {
        const float f = image.isMiss(i) ? 0.0f : float(image.value[i]);  // COLMAP's "no depth"
        bytes.append(reinterpret_cast<const char*>(&f), 4);
    }
    writeFileBytes(path, bytes);
}

const DepthMapFormat& npyFormat()
{
    static const DepthMapFormat row{
        "npy", "NumPy .npy", {".npy"}, "one quantity as float32 (H, W) or (H, W, C); primitive ids as uint32", isNpy, readNpy,
        [](const std::string& path, const std::vector<QuantityImage>& images, double) { writeNpy(path, images.front()); }};
    return row;
}

const DepthMapFormat& colmapDepthFormat()
{
    static const DepthMapFormat row{
        "colmap", "COLMAP depth map", {".bin"}, "one depth quantity as COLMAP's dense maps hold eye-z (W&H&1&, float32, 0 a miss)",
        isColmapDepth, readColmapDepth,
        [](const std::string& path, const std::vector<QuantityImage>& images, double) { writeColmapDepth(path, images.front()); }};
    return row;
}

}  // namespace zcheck::depthformats
