// glTF 2.0 (.gltf JSON text and .glb binary), read without a third-party glTF parser.
//
// What is read: the triangles of the default scene (`scene`, else scenes[0], else every root
// node when the file has no scenes), in world space: each node's `matrix` or
// translation/rotation/scale, composed parent·child in double down the hierarchy, applied to
// POSITION. A mesh instanced by several nodes is emitted once per instance, all its POSITION
// vertices each time.
//
// Accepted:
//   GLB      12-byte header (magic, version 2, length = file size), a JSON chunk, an optional
//            BIN chunk; chunk lengths need not be multiples of 4; further chunks are ignored.
//   buffers  the BIN chunk (buffers[0] without uri), base64 `data:` URIs (any media type),
//            relative file URIs (%XX decoded) resolved beside the glTF: regular files of at
//            most 1 GiB, no `..`; byteLength may be less than the data, never more.
//   modes    TRIANGLES (default), TRIANGLE_STRIP (a strip triangle repeating an index is a
//            joint and is dropped; odd triangles are re-wound per the spec), TRIANGLE_FAN;
//            indexed (UNSIGNED_BYTE/SHORT/INT) or not. POINTS and LINES are skipped.
//   POSITION VEC3 FLOAT; BYTE/UNSIGNED_BYTE/SHORT/UNSIGNED_SHORT (normalized or not) when
//            KHR_mesh_quantization is declared.
//   extensionsRequired: KHR_mesh_quantization, and extensions that change only appearance
//            (KHR_materials_*, KHR_texture_*, EXT_texture_*, KHR_lights_punctual).
// Cameras: the camera nodes of the same scene, with their world transforms (camera_sources.h
// states the rules), in Scene::cameras; readGltfCameraNodes reads them alone.
// Ignored: materials, textures, images, animations, morph targets (the base
// positions are read), skins (the node transform is applied as for a static mesh), unknown
// keys and extensions that are not required.
// Refused (Error, one line, naming the JSON path or value and the rule): JSON nested deeper
// than 256 levels, glTF 1.x, a value of the wrong JSON type, non-finite numbers, sparse
// accessors, accessors without a bufferView, any count/offset/stride/index the bytes do not
// hold, URIs with a scheme other than data:, absolute paths, node hierarchies with a cycle
// or a node with two parents, scenes listing a non-root node, a TRIANGLES count that is not a
// multiple of 3, and output beyond 2^28 vertices or triangles or beyond 64 bytes per input
// byte plus 128 MiB (instancing multiplies geometry; this bounds what a small file can cost).
// Cost: time linear in the input plus the output; memory is the output plus the JSON DOM
// (nlohmann: a few bytes per JSON byte for real files, up to ~40 for JSON made of empty
// objects) plus decoded data: URIs and external buffers. Nothing recurses on input structure.
#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_formats.h"
#include "zcheck/pose.h"
#include "zcheck/scene.h"

#include <nlohmann/json.hpp>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace zcheck {

namespace {

using json = nlohmann::json;

// nlohmann's parser recurses once per nesting level; real glTF nests less than 10 deep.
constexpr int kMaxJsonDepth = 256;
constexpr std::uint64_t kMaxExternalBufferBytes = 1ull << 30;
constexpr std::uint64_t kMaxOutputVertices = 1ull << 28;
constexpr std::uint64_t kMaxOutputTriangles = 1ull << 28;
constexpr std::uint64_t kOutputBytesPerInputByte = 64;
constexpr std::uint64_t kOutputBytesHeadroom = 128ull << 20;
// Integers beyond 2^53 are not exact in a double; no real count or offset comes close.
constexpr std::uint64_t kMaxJsonInteger = 1ull << 53;
constexpr double kMaxFloat = 3.4028234663852886e38;
constexpr std::size_t kNone = static_cast<std::size_t>(-1);

constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;      // "BIN\0"

enum ComponentType : std::uint32_t {
    kByte = 5120,
    kUnsignedByte = 5121,
    kShort = 5122,
    kUnsignedShort = 5123,
    kUnsignedInt = 5125,
    kFloat = 5126,
};

enum Mode : std::uint32_t { kTriangles = 4, kTriangleStrip = 5, kTriangleFan = 6 };

std::uint32_t componentSize(std::uint64_t type)
{
    switch (type) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0;  // not a glTF component type
    }
}

const char* componentName(std::uint32_t type)
{
    switch (type) {
    case kByte: return "BYTE";
    case kUnsignedByte: return "UNSIGNED_BYTE";
    case kShort: return "SHORT";
    case kUnsignedShort: return "UNSIGNED_SHORT";
    case kUnsignedInt: return "UNSIGNED_INT";
    default: return "FLOAT";
    }
}

// Little-endian whatever the host, and without alignment: offsets come from the file.
std::uint16_t le16(const unsigned char* p) { return std::uint16_t(p[0] | (p[1] << 8)); }
std::uint32_t le32(const unsigned char* p)
{
    return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) | (std::uint32_t(p[3]) << 24);
}
float leFloat(const unsigned char* p)
{
    const std::uint32_t bits = le32(p);
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

std::string str(std::uint64_t n) { return std::to_string(n); }
std::string at(const std::string& array, std::size_t i) { return array + "[" + str(i) + "]"; }

// A string from the file, shortened and with control characters escaped, so that messages
// stay one line.
std::string printable(std::string_view s)
{
    std::string out;
    for (const char ch : s) {
        if (out.size() >= 80) return out + "...";
        const auto c = static_cast<unsigned char>(ch);
        if (c < 0x20 || c == 0x7f) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
            out += escaped;
        } else {
            out += ch;
        }
    }
    return out;
}

// A JSON value as it appears in the file, shortened (dump escapes control characters).
std::string describe(const json& value)
{
    std::string text = value.dump(-1, ' ', true, json::error_handler_t::replace);
    if (text.size() > 60) text = text.substr(0, 60) + "...";
    return text;
}

// "the string \"4\"", "an array [1,2]", "null": a wrong value as messages name it.
std::string kind(const json& value)
{
    if (value.is_string()) return "the string " + describe(value);
    if (value.is_array()) return "an array " + describe(value);
    if (value.is_object()) return "an object " + describe(value);
    if (value.is_number()) return "the number " + describe(value);
    return describe(value);  // null, true, false
}

int base64Value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

// Strict base64 (no whitespace; '=' padding only at the end, optional when unambiguous).
// Returns the offset of the first bad character, or kNone.
std::size_t decodeBase64(std::string_view in, std::string& out)
{
    std::size_t length = in.size();
    std::size_t padding = 0;
    while (padding < 2 && length > 0 && in[length - 1] == '=') {
        --length;
        ++padding;
    }
    if (padding > 0 && in.size() % 4 != 0) return length;
    if (length % 4 == 1) return length - 1;  // 6 bits cannot end a byte
    out.reserve(length / 4 * 3 + 2);
    std::uint32_t bits = 0;
    int bitCount = 0;
    for (std::size_t i = 0; i < length; ++i) {
        const int v = base64Value(static_cast<unsigned char>(in[i]));
        if (v < 0) return i;
        bits = ((bits << 6) | std::uint32_t(v)) & 0xFFFFFF;
        bitCount += 6;
        if (bitCount >= 8) {
            bitCount -= 8;
            out.push_back(static_cast<char>((bits >> bitCount) & 0xFF));
        }
    }
    return kNone;
}

int hexValue(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

bool isAppearanceOnlyExtension(const std::string& name)
{
    for (const char* prefix : {"KHR_materials_", "KHR_texture_", "EXT_texture_"})
        if (name.rfind(prefix, 0) == 0) return true;
    return name == "KHR_lights_punctual";
}

struct Bytes {
    const unsigned char* data = nullptr;
    std::uint64_t size = 0;
};

struct BufferView {
    const unsigned char* data = nullptr;
    std::uint64_t length = 0;
    std::uint64_t stride = 0;  // 0: tightly packed
};

// An accessor whose every element is known to lie inside its buffer.
struct Accessor {
    const unsigned char* data = nullptr;  // the first element
    std::uint64_t count = 0;
    std::uint64_t stride = 0;
    std::uint32_t componentType = 0;
    bool normalized = false;
    std::size_t index = 0;  // accessors[index], for messages
};

struct Primitive {
    Accessor positions;
    Accessor indices;
    bool indexed = false;
    std::uint32_t mode = kTriangles;
    std::uint64_t triangles = 0;  // before strip joints are dropped
};

struct Mesh {
    bool planned = false;
    std::vector<Primitive> primitives;  // only those that yield triangles
};

class GltfReader {
public:
    GltfReader(const std::string& path, std::string_view bytes) : path_(path), bytes_(bytes) {}

    Scene read()
    {
        try {
            parseJson(jsonText());
            checkAsset();
            checkExtensions();
            buffers_.resize(topArray("buffers").size());
            bufferLoaded_.assign(buffers_.size(), false);
            meshes_.resize(topArray("meshes").size());
            buildHierarchy();
            const std::vector<std::size_t> roots = sceneRoots();
            countOutput(roots);
            checkOutputBudget();
            Scene scene;
            scene.name = path_;
            reserveLarge(scene.positions, std::size_t(vertexTotal_));
            reserveLarge(scene.triangles, std::size_t(triangleTotal_));
            traverse(roots, [&](std::size_t node, const glm::dmat4& world) {
                const std::size_t m = meshOf(node);
                if (m == kNone) return;
                for (const Primitive& primitive : meshes_[m].primitives) emit(scene, primitive, node, world);
            });
            scene.cameras = cameras(roots);
            return scene;
        } catch (const json::exception& e) {
            // Every value is type-checked before use; this is a last line of defence.
            fail(std::string("unexpected JSON error: ") + e.what());
        }
    }

    // The camera nodes alone: no buffer is read.
    std::vector<ImportedCamera> readCameras()
    {
        camerasOnly_ = true;
        try {
            parseJson(jsonText());
            checkAsset();
            checkExtensions();
            buildHierarchy();
            return cameras(sceneRoots());
        } catch (const json::exception& e) {
            fail(std::string("unexpected JSON error: ") + e.what());
        }
    }

private:
    [[noreturn]] void fail(const std::string& why) const
    {
        throw Error((camerasOnly_ ? "cannot read the cameras of glTF '" : "cannot load mesh '") + path_ + "': malformed glTF: " +
                    why);
    }

    // ---- container -------------------------------------------------------------------

    std::string_view jsonText()
    {
        const std::string_view all(bytes_);
        if (all.size() >= 4 && le32(reinterpret_cast<const unsigned char*>(all.data())) == kGlbMagic)
            return glbJsonChunk();
        return all;
    }

    std::string_view glbJsonChunk()
    {
        const auto* b = reinterpret_cast<const unsigned char*>(bytes_.data());
        const std::uint64_t size = bytes_.size();
        if (size < 12) fail("the GLB header needs 12 bytes, the file has " + str(size));
        if (le32(b + 4) != 2) fail("GLB version " + str(le32(b + 4)) + " is not 2");
        if (le32(b + 8) != size)
            fail("the GLB header gives the length " + str(le32(b + 8)) + " but the file has " + str(size) + " bytes");
        std::string_view text;
        std::uint64_t offset = 12;
        std::size_t chunk = 0;
        for (; offset < size; ++chunk) {
            if (size - offset < 8)
                fail("GLB chunk " + str(chunk) + " at byte " + str(offset) + " is cut short: its 8-byte header does not fit");
            const std::uint64_t length = le32(b + offset);
            const std::uint32_t type = le32(b + offset + 4);
            offset += 8;
            if (length > size - offset)
                fail("GLB chunk " + str(chunk) + " declares " + str(length) + " bytes but only " + str(size - offset) +
                     " remain");
            if (chunk == 0) {
                if (type != kChunkJson) fail("the first GLB chunk is not JSON");
                text = std::string_view(bytes_.data() + offset, std::size_t(length));
            } else if (chunk == 1 && type == kChunkBin) {
                bin_ = {b + offset, length};
                hasBin_ = true;
            }  // the spec asks readers to skip chunks they do not know
            offset += length;
        }
        if (chunk == 0) fail("the GLB file has no JSON chunk");
        // Padding is spaces per the spec; some writers pad with zeros, which JSON rejects.
        while (!text.empty() && text.back() == '\0') text.remove_suffix(1);
        return text;
    }

    void parseJson(std::string_view text)
    {
        checkNesting(text);
        try {
            root_ = json::parse(text.begin(), text.end());
        } catch (const json::exception& e) {  // parse_error, or out_of_range for 1e400
            std::string what = e.what();
            const std::size_t tag = what.find("] ");
            if (tag != std::string::npos) what.erase(0, tag + 2);  // "[json.exception.parse_error.101] "
            fail("JSON " + what);
        }
        if (!root_.is_object()) fail("the top-level JSON value is " + std::string(root_.type_name()) + ", not an object");
    }

    // nlohmann's parser recurses per level: refuse deep nesting before it sees the text. The
    // parser stops at the first syntax error, so counting brackets outside strings up to
    // there is exact for what it would read.
    void checkNesting(std::string_view text) const
    {
        int depth = 0;
        bool inString = false;
        for (std::size_t i = 0; i < text.size(); ++i) {
            const char c = text[i];
            if (inString) {
                if (c == '\\') ++i;
                else if (c == '"') inString = false;
            } else if (c == '"') {
                inString = true;
            } else if (c == '[' || c == '{') {
                if (++depth > kMaxJsonDepth) fail("JSON nests deeper than " + str(kMaxJsonDepth) + " levels");
            } else if ((c == ']' || c == '}') && depth > 0) {
                --depth;
            }
        }
    }

    // ---- typed JSON access: every refusal names the path ------------------------------

    [[noreturn]] void wrongType(const json& v, const std::string& where, const char* expected) const
    {
        fail(where + " is " + kind(v) + ", not " + expected);
    }

    static const json* member(const json& object, const char* key)
    {
        const auto it = object.find(key);
        return it == object.end() ? nullptr : &*it;
    }

    const json& required(const json& object, const char* key, const std::string& where) const
    {
        const json* v = member(object, key);
        if (!v) fail(where + "." + key + " is missing");
        return *v;
    }

    const json& asObject(const json& v, const std::string& where) const
    {
        if (!v.is_object()) wrongType(v, where, "an object");
        return v;
    }

    const json& asArray(const json& v, const std::string& where) const
    {
        if (!v.is_array()) wrongType(v, where, "an array");
        return v;
    }

    const std::string& asString(const json& v, const std::string& where) const
    {
        if (!v.is_string()) wrongType(v, where, "a string");
        return v.get_ref<const std::string&>();
    }

    bool asBool(const json& v, const std::string& where) const
    {
        if (!v.is_boolean()) wrongType(v, where, "a boolean");
        return v.get<bool>();
    }

    double asNumber(const json& v, const std::string& where) const
    {
        if (!v.is_number()) wrongType(v, where, "a number");
        const double d = v.get<double>();
        if (!std::isfinite(d)) fail(where + " " + describe(v) + " is not finite");
        return d;
    }

    // A whole number in [0, 2^53]; 4.0 counts as 4, as JSON Schema's "integer" allows.
    std::uint64_t asUnsigned(const json& v, const std::string& where) const
    {
        if (v.is_number_unsigned()) {
            const auto u = v.get<std::uint64_t>();
            if (u > kMaxJsonInteger) fail(where + " " + str(u) + " is too large");
            return u;
        }
        if (v.is_number_integer()) {  // the parser stores only negative integers as signed
            const auto i = v.get<std::int64_t>();
            if (i < 0) fail(where + " " + std::to_string(i) + " is negative");
            if (std::uint64_t(i) > kMaxJsonInteger) fail(where + " " + std::to_string(i) + " is too large");
            return std::uint64_t(i);
        }
        if (v.is_number_float()) {
            const double d = v.get<double>();
            if (!(d >= 0 && d <= double(kMaxJsonInteger) && d == std::floor(d)))
                fail(where + " " + describe(v) + " is not a non-negative integer");
            return std::uint64_t(d);
        }
        wrongType(v, where, "a non-negative integer");
    }

    std::uint64_t optionalUnsigned(const json& object, const char* key, const std::string& where, std::uint64_t fallback) const
    {
        const json* v = member(object, key);
        return v ? asUnsigned(*v, where + "." + key) : fallback;
    }

    // An index into the top-level array `arrayName` of `size` entries.
    std::size_t reference(const json& v, const std::string& where, const char* arrayName, std::size_t size) const
    {
        const std::uint64_t i = asUnsigned(v, where);
        if (i >= size) fail(where + " " + str(i) + " is out of range: the file has " + str(size) + " " + arrayName);
        return std::size_t(i);
    }

    const json& topArray(const char* key) const
    {
        static const json empty = json::array();
        const json* v = member(root_, key);
        return v ? asArray(*v, key) : empty;
    }

    const json& topElement(const char* key, std::size_t i) const
    {
        const json& element = topArray(key).at(i);
        return element.is_object() ? element : asObject(element, at(key, i));  // formats the refusal
    }

    // ---- asset and extensions --------------------------------------------------------

    void checkAsset() const
    {
        const json* asset = member(root_, "asset");
        if (!asset) fail("asset is missing (a glTF 2.0 file names its version in asset.version)");
        asObject(*asset, "asset");
        const std::string& version = asString(required(*asset, "version", "asset"), "asset.version");
        if (version.rfind("2.", 0) != 0) fail("asset.version '" + printable(version) + "' is not 2.x: only glTF 2.0 is read");
        if (const json* minimum = member(*asset, "minVersion")) {
            const std::string& v = asString(*minimum, "asset.minVersion");
            if (v != "2.0") fail("asset.minVersion '" + printable(v) + "' is newer than 2.0");
        }
    }

    void checkExtensions()
    {
        if (const json* used = member(root_, "extensionsUsed")) {
            asArray(*used, "extensionsUsed");
            for (std::size_t i = 0; i < used->size(); ++i)
                if (asString((*used)[i], at("extensionsUsed", i)) == "KHR_mesh_quantization") quantization_ = true;
        }
        if (const json* requiredList = member(root_, "extensionsRequired")) {
            asArray(*requiredList, "extensionsRequired");
            for (std::size_t i = 0; i < requiredList->size(); ++i) {
                const std::string& name = asString((*requiredList)[i], at("extensionsRequired", i));
                if (name == "KHR_mesh_quantization") quantization_ = true;
                else if (!isAppearanceOnlyExtension(name))
                    fail("requires extension " + printable(name) + " which zcheck does not support (extensionsRequired[" +
                         str(i) + "])");
            }
        }
    }

    // ---- buffers ---------------------------------------------------------------------

    const Bytes& buffer(std::size_t i)
    {
        if (bufferLoaded_[i]) return buffers_[i];
        const std::string where = at("buffers", i);
        const json& object = topElement("buffers", i);
        const std::uint64_t byteLength = asUnsigned(required(object, "byteLength", where), where + ".byteLength");
        if (byteLength == 0) fail(where + ".byteLength is 0; a buffer has at least 1 byte");
        Bytes data;
        if (const json* uri = member(object, "uri")) {
            data = loadUri(asString(*uri, where + ".uri"), where);
        } else {
            if (!hasBin_) fail(where + " has no uri and the file has no GLB BIN chunk");
            if (i != 0) fail(where + " has no uri; only buffers[0] may refer to the GLB BIN chunk");
            data = bin_;
        }
        if (byteLength > data.size)
            fail(where + ".byteLength " + str(byteLength) + " exceeds the " + str(data.size) + " bytes of its data");
        buffers_[i] = {data.data, byteLength};
        bufferLoaded_[i] = true;
        return buffers_[i];
    }

    Bytes loadUri(const std::string& uri, const std::string& where)
    {
        if (uri.rfind("data:", 0) == 0) return decodeDataUri(uri, where);
        return readExternal(uri, where);
    }

    Bytes decodeDataUri(const std::string& uri, const std::string& where)
    {
        const std::size_t comma = uri.find(',');
        if (comma == std::string::npos) fail(where + ".uri is a data: URI without a comma");
        const std::string_view header(uri.data() + 5, comma - 5);
        const std::string_view base64 = ";base64";
        if (header.size() < base64.size() || header.substr(header.size() - base64.size()) != base64)
            fail(where + ".uri is a data: URI that is not base64 ('" + printable(header) + "')");
        auto decoded = std::make_unique<std::string>();
        const std::size_t bad = decodeBase64(std::string_view(uri).substr(comma + 1), *decoded);
        if (bad != kNone) fail(where + ".uri has invalid base64 at character " + str(comma + 1 + bad) + " of the URI");
        return keep(std::move(decoded));
    }

    Bytes keep(std::unique_ptr<std::string> data)
    {
        const Bytes bytes{reinterpret_cast<const unsigned char*>(data->data()), data->size()};
        storage_.push_back(std::move(data));
        return bytes;
    }

    std::string percentDecode(const std::string& uri, const std::string& where) const
    {
        std::string out;
        for (std::size_t i = 0; i < uri.size(); ++i) {
            if (uri[i] != '%') {
                out += uri[i];
                continue;
            }
            const int hi = i + 2 < uri.size() ? hexValue(uri[i + 1]) : -1;
            const int lo = hi >= 0 ? hexValue(uri[i + 2]) : -1;
            if (lo < 0) fail(where + ".uri '" + printable(uri) + "' has a bad %-escape at character " + str(i));
            out += static_cast<char>(hi * 16 + lo);
            i += 2;
        }
        return out;
    }

    Bytes readExternal(const std::string& uri, const std::string& where)
    {
        namespace fs = std::filesystem;
        const std::string quoted = where + ".uri '" + printable(uri) + "'";
        if (uri.empty()) fail(where + ".uri is empty");
        // A ':' before any '/' is a URI scheme (http:, file:) or a drive letter.
        const std::size_t colon = uri.find(':');
        if (colon != std::string::npos && colon < uri.find('/'))
            fail(quoted + " has a scheme; only data: URIs and relative file paths are read");
        const std::string relative = percentDecode(uri, where);
        if (relative.find('\0') != std::string::npos) fail(quoted + " contains a NUL character");
        if (relative[0] == '/' || relative[0] == '\\') fail(quoted + " is an absolute path; only relative paths are read");
        for (const fs::path& part : fs::path(relative))
            if (part == "..") fail(quoted + " leaves the glTF's folder ('..'); buffers are read beside the file or below");
        const fs::path file = fs::path(path_).parent_path() / relative;
        std::error_code error;
        if (!fs::is_regular_file(file, error)) fail(quoted + " is not a regular file ('" + printable(file.string()) + "')");
        const std::uint64_t size = fs::file_size(file, error);
        if (error) fail(quoted + ": cannot read its size (" + printable(error.message()) + ")");
        if (size > kMaxExternalBufferBytes) fail(quoted + " is larger than 1 GiB (" + str(size) + " bytes)");
        // Several buffers may name one file: read it once.
        const fs::path canonical = fs::canonical(file, error);
        const std::string key = error ? file.string() : canonical.string();
        const auto cached = externalFiles_.find(key);
        if (cached != externalFiles_.end()) return cached->second;
        auto data = std::make_unique<std::string>(std::size_t(size), '\0');
        std::ifstream in(file, std::ios::binary);
        in.read(data->data(), std::streamsize(size));
        if (!in || std::uint64_t(in.gcount()) != size) fail(quoted + ": cannot read " + str(size) + " bytes from it");
        externalBytes_ += size;
        const Bytes bytes = keep(std::move(data));
        externalFiles_[key] = bytes;
        return bytes;
    }

    // ---- bufferViews and accessors ---------------------------------------------------

    BufferView bufferView(std::size_t i)
    {
        const std::string where = at("bufferViews", i);
        const json& object = topElement("bufferViews", i);
        const std::size_t b = reference(required(object, "buffer", where), where + ".buffer", "buffers", buffers_.size());
        const std::uint64_t offset = optionalUnsigned(object, "byteOffset", where, 0);
        const std::uint64_t length = asUnsigned(required(object, "byteLength", where), where + ".byteLength");
        if (length == 0) fail(where + ".byteLength is 0; a bufferView has at least 1 byte");
        const Bytes& data = buffer(b);
        if (offset > data.size || length > data.size - offset)
            fail(where + " (byteOffset " + str(offset) + ", byteLength " + str(length) + ") exceeds buffers[" + str(b) + "] (" +
                 str(data.size) + " bytes)");
        const std::uint64_t stride = optionalUnsigned(object, "byteStride", where, 0);
        if (member(object, "byteStride") && (stride < 4 || stride > 252 || stride % 4 != 0))
            fail(where + ".byteStride " + str(stride) + " is not a multiple of 4 in 4...252");
        return {data.data + offset, length, stride};
    }

    // accessors[i] as `type` (SCALAR or VEC3, `components` wide), with every element inside
    // its bufferView. `role` says what it is used for, in messages.
    Accessor accessor(std::size_t i, const char* type, std::uint32_t components, const std::string& role)
    {
        const std::string where = at("accessors", i);
        const json& object = topElement("accessors", i);
        if (member(object, "sparse")) fail(where + " (" + role + ") is sparse; sparse accessors are not supported");
        const json* viewReference = member(object, "bufferView");
        if (!viewReference)
            fail(where + " (" + role + ") has no bufferView (an all-zero accessor); such accessors are not supported");
        const std::string& actualType = asString(required(object, "type", where), where + ".type");
        if (actualType != type) fail(where + ".type '" + printable(actualType) + "' is not " + type + " (" + role + ")");
        const std::uint64_t componentType = asUnsigned(required(object, "componentType", where), where + ".componentType");
        if (componentSize(componentType) == 0)
            fail(where + ".componentType " + str(componentType) + " is not a glTF component type (5120...5126)");
        const json* normalized = member(object, "normalized");
        const std::uint64_t count = asUnsigned(required(object, "count", where), where + ".count");
        if (count == 0) fail(where + ".count is 0; an accessor has at least 1 element");
        const std::uint64_t offset = optionalUnsigned(object, "byteOffset", where, 0);
        const std::size_t v = reference(*viewReference, where + ".bufferView", "bufferViews", topArray("bufferViews").size());
        const BufferView view = bufferView(v);

        const std::uint64_t elementSize = std::uint64_t(componentSize(componentType)) * components;
        const std::uint64_t stride = view.stride != 0 ? view.stride : elementSize;
        if (stride < elementSize)
            fail("bufferViews[" + str(v) + "].byteStride " + str(stride) + " is smaller than the " + str(elementSize) +
                 "-byte elements of " + where);
        // offset + stride·(count − 1) + elementSize ≤ length, without overflow.
        if (offset > view.length || elementSize > view.length - offset ||
            count - 1 > (view.length - offset - elementSize) / stride)
            fail(where + ".count " + str(count) + " (byteOffset " + str(offset) + ", stride " + str(stride) +
                 ") exceeds what bufferViews[" + str(v) + "] holds (" + str(view.length) + " bytes)");
        Accessor a;
        a.data = view.data + offset;
        a.count = count;
        a.stride = stride;
        a.componentType = std::uint32_t(componentType);
        a.normalized = normalized ? asBool(*normalized, where + ".normalized") : false;
        a.index = i;
        return a;
    }

    // ---- meshes ----------------------------------------------------------------------

    const Mesh& mesh(std::size_t m)
    {
        Mesh& plan = meshes_[m];
        if (plan.planned) return plan;
        const std::string where = at("meshes", m);
        const json& object = topElement("meshes", m);
        const json& primitives = asArray(required(object, "primitives", where), where + ".primitives");
        for (std::size_t k = 0; k < primitives.size(); ++k) addPrimitive(plan, primitives[k], at(where + ".primitives", k));
        plan.planned = true;
        return plan;
    }

    void addPrimitive(Mesh& plan, const json& v, const std::string& where)
    {
        const json& object = asObject(v, where);
        const std::uint64_t mode = optionalUnsigned(object, "mode", where, kTriangles);
        if (mode < kTriangles) return;  // points and lines have no depth to check
        if (mode > kTriangleFan) fail(where + ".mode " + str(mode) + " is not a glTF primitive mode (0...6)");
        const json& attributes = asObject(required(object, "attributes", where), where + ".attributes");
        const json* position = member(attributes, "POSITION");
        if (!position) fail(where + ".attributes has no POSITION");
        const std::size_t accessorCount = topArray("accessors").size();

        Primitive p;
        p.mode = std::uint32_t(mode);
        const std::size_t pi = reference(*position, where + ".attributes.POSITION", "accessors", accessorCount);
        p.positions = accessor(pi, "VEC3", 3, "POSITION of " + where);
        checkPositionType(p.positions);
        std::uint64_t n = p.positions.count;
        if (const json* indices = member(object, "indices")) {
            const std::size_t ii = reference(*indices, where + ".indices", "accessors", accessorCount);
            p.indices = accessor(ii, "SCALAR", 1, "indices of " + where);
            const std::uint32_t t = p.indices.componentType;
            if (t != kUnsignedByte && t != kUnsignedShort && t != kUnsignedInt)
                fail(at("accessors", ii) + ".componentType " + componentName(t) +
                     " is not an index type (UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)");
            p.indexed = true;
            n = p.indices.count;
        }
        if (p.mode == kTriangles) {
            if (n % 3 != 0)
                fail(where + " has " + str(n) + (p.indexed ? " indices" : " vertices") +
                     ", not a multiple of 3 as TRIANGLES needs");
            p.triangles = n / 3;
        } else {
            p.triangles = n >= 3 ? n - 2 : 0;
        }
        if (p.triangles > 0) plan.primitives.push_back(p);
    }

    void checkPositionType(const Accessor& a) const
    {
        const std::uint32_t t = a.componentType;
        if (t == kFloat) return;
        const std::string what = at("accessors", a.index) + " (POSITION) has componentType " + componentName(t);
        if (t == kUnsignedInt) fail(what + ", which POSITION may not have");
        if (!quantization_) fail(what + ", which needs KHR_mesh_quantization in extensionsUsed");
    }

    // ---- nodes -----------------------------------------------------------------------

    // Records each node's children and refuses a node with two parents or on a cycle, so
    // that traversals from roots visit every node at most once.
    void buildHierarchy()
    {
        const json& nodes = topArray("nodes");
        const std::size_t n = nodes.size();
        parent_.assign(n, kNone);
        childBegin_.assign(n + 1, 0);
        children_.clear();
        for (std::size_t i = 0; i < n; ++i) {
            const json& node = topElement("nodes", i);
            childBegin_[i] = children_.size();
            const json* list = member(node, "children");
            if (!list) continue;
            const std::string where = at("nodes", i);
            asArray(*list, where + ".children");
            for (std::size_t k = 0; k < list->size(); ++k) {
                const json& entry = (*list)[k];
                const std::size_t child =
                    entry.is_number_unsigned() && entry.get<std::uint64_t>() < n
                        ? std::size_t(entry.get<std::uint64_t>())
                        : reference(entry, at(where + ".children", k), "nodes", n);  // formats the refusal
                if (parent_[child] == i) fail(where + ".children lists nodes[" + str(child) + "] twice");
                if (parent_[child] != kNone)
                    fail("nodes[" + str(child) + "] is a child of both nodes[" + str(parent_[child]) + "] and " + where +
                         "; a node has at most one parent");
                parent_[child] = i;
                children_.push_back(child);
            }
        }
        childBegin_[n] = children_.size();
        // With one parent each, a node that no root reaches hangs from a cycle.
        std::vector<char> reached(n, 0);
        std::vector<std::size_t> stack;
        for (std::size_t i = 0; i < n; ++i)
            if (parent_[i] == kNone) stack.push_back(i);
        while (!stack.empty()) {
            const std::size_t node = stack.back();
            stack.pop_back();
            reached[node] = 1;
            for (std::size_t c = childBegin_[node]; c < childBegin_[node + 1]; ++c) stack.push_back(children_[c]);
        }
        for (std::size_t i = 0; i < n; ++i)
            if (!reached[i]) fail("nodes[" + str(i) + "] is on or below a cycle of the node hierarchy (no root node reaches it)");
    }

    std::vector<std::size_t> sceneRoots() const
    {
        const json& scenes = topArray("scenes");
        const std::size_t n = parent_.size();
        std::vector<std::size_t> roots;
        std::size_t s = kNone;
        if (const json* chosen = member(root_, "scene")) s = reference(*chosen, "scene", "scenes", scenes.size());
        else if (!scenes.empty()) s = 0;
        if (s == kNone) {  // no scenes: every root node
            for (std::size_t i = 0; i < n; ++i)
                if (parent_[i] == kNone) roots.push_back(i);
            return roots;
        }
        const std::string where = at("scenes", s);
        const json* list = member(topElement("scenes", s), "nodes");
        if (!list) return roots;
        asArray(*list, where + ".nodes");
        std::vector<char> listed(n, 0);
        for (std::size_t k = 0; k < list->size(); ++k) {
            const std::string entry = at(where + ".nodes", k);
            const std::size_t r = reference((*list)[k], entry, "nodes", n);
            if (parent_[r] != kNone)
                fail(entry + " = " + str(r) + " is not a root node: it is a child of nodes[" + str(parent_[r]) + "]");
            if (listed[r]) fail(where + ".nodes lists nodes[" + str(r) + "] twice");
            listed[r] = 1;
            roots.push_back(r);
        }
        return roots;
    }

    // Calls visit(node, world) for every node below `roots`, depth first and children in
    // order, with an explicit stack (hierarchies may be deep) that holds one frame per level,
    // not per pending sibling. buildHierarchy guarantees that no node is reached twice.
    template <typename Visit>
    void traverse(const std::vector<std::size_t>& roots, Visit&& visit) const
    {
        struct Frame {
            std::size_t node, nextChild;
            glm::dmat4 world;
        };
        std::vector<Frame> stack;
        for (const std::size_t root : roots) {
            const glm::dmat4 world = worldTransform(root, glm::dmat4(1.0));
            visit(root, world);
            stack.push_back({root, childBegin_[root], world});
            while (!stack.empty()) {
                Frame& top = stack.back();
                if (top.nextChild == childBegin_[top.node + 1]) {
                    stack.pop_back();
                    continue;
                }
                const std::size_t child = children_[top.nextChild++];
                const glm::dmat4 childWorld = worldTransform(child, top.world);
                visit(child, childWorld);
                stack.push_back({child, childBegin_[child], childWorld});
            }
        }
    }

    glm::dmat4 worldTransform(std::size_t node, const glm::dmat4& parentWorld) const
    {
        const glm::dmat4 world = parentWorld * localTransform(topElement("nodes", node), node);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(world[c][r]))
                    fail("the world transform of nodes[" + str(node) + "] is not finite (the transforms above it overflow)");
        return world;
    }

    // The mesh a node instances, or kNone.
    std::size_t meshOf(std::size_t node) const
    {
        const json* m = member(topElement("nodes", node), "mesh");
        return m ? reference(*m, at("nodes", node) + ".mesh", "meshes", meshes_.size()) : kNone;
    }

    // Plans every instanced mesh and totals the output before anything is emitted.
    void countOutput(const std::vector<std::size_t>& roots)
    {
        traverse(roots, [&](std::size_t node, const glm::dmat4&) {
            const std::size_t m = meshOf(node);
            if (m == kNone) return;
            for (const Primitive& p : mesh(m).primitives) {
                vertexTotal_ += p.positions.count;
                triangleTotal_ += p.triangles;
                if (vertexTotal_ > kMaxOutputVertices || triangleTotal_ > kMaxOutputTriangles)
                    fail("the scene exceeds 2^28 vertices or triangles (counting instances, at nodes[" + str(node) +
                         "] instancing meshes[" + str(m) + "])");
            }
        });
    }

    void checkOutputBudget() const
    {
        const std::uint64_t output = 12 * (vertexTotal_ + triangleTotal_);
        const std::uint64_t input = bytes_.size() + externalBytes_;
        if (output > kOutputBytesPerInputByte * input + kOutputBytesHeadroom)
            fail("instancing expands " + str(input) + " bytes of input to " + str(vertexTotal_) + " vertices and " +
                 str(triangleTotal_) + " triangles, beyond 64 bytes of output per input byte plus 128 MiB");
    }

    std::vector<double> numbers(const json& object, const char* key, std::size_t size, const std::string& where) const
    {
        const std::string path = where + "." + key;
        const json& list = asArray(required(object, key, where), path);
        if (list.size() != size) fail(path + " has " + str(list.size()) + " numbers, not " + str(size));
        std::vector<double> out(size);
        for (std::size_t k = 0; k < size; ++k) {
            const json& v = list[k];
            out[k] = v.is_number() && std::isfinite(v.get<double>()) ? v.get<double>() : asNumber(v, at(path, k));
        }
        return out;
    }

    glm::dmat4 localTransform(const json& node, std::size_t i) const
    {
        const bool hasTrs = member(node, "translation") || member(node, "rotation") || member(node, "scale");
        const bool hasMatrix = member(node, "matrix");
        if (!hasTrs && !hasMatrix) return glm::dmat4(1.0);
        const std::string where = at("nodes", i);
        if (hasMatrix) {
            if (hasTrs) fail(where + " has both matrix and translation/rotation/scale");
            const std::vector<double> m = numbers(node, "matrix", 16, where);
            // glTF matrices are affine (decomposable into TRS); allow writers' rounding.
            if (std::abs(m[3]) > 1e-6 || std::abs(m[7]) > 1e-6 || std::abs(m[11]) > 1e-6 || std::abs(m[15] - 1) > 1e-6)
                fail(where + ".matrix is not affine: its last row is not 0 0 0 1");
            glm::dmat4 result(1.0);
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 3; ++r) result[c][r] = m[std::size_t(4 * c + r)];  // column-major
            return result;
        }
        std::vector<double> t{0, 0, 0}, q{0, 0, 0, 1}, s{1, 1, 1};
        if (member(node, "translation")) t = numbers(node, "translation", 3, where);
        if (member(node, "rotation")) q = numbers(node, "rotation", 4, where);
        if (member(node, "scale")) s = numbers(node, "scale", 3, where);
        const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(std::abs(length - 1) <= 0.01))
            fail(where + ".rotation is not a unit quaternion (length " + formatNumber(length) + ")");
        const double x = q[0] / length, y = q[1] / length, z = q[2] / length, w = q[3] / length;
        const glm::dmat3 rotation(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),   // column 0
                                  2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),   // column 1
                                  2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));  // column 2
        glm::dmat4 result(1.0);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) result[c][r] = rotation[c][r] * s[std::size_t(c)];
        result[3] = glm::dvec4(t[0], t[1], t[2], 1.0);
        return result;  // T · R · S
    }

    // ---- cameras ---------------------------------------------------------------------

    // The camera nodes below `roots` in traversal order (camera_sources.h states the rules).
    std::vector<ImportedCamera> cameras(const std::vector<std::size_t>& roots) const
    {
        std::vector<ImportedCamera> out;
        const std::size_t count = topArray("cameras").size();
        traverse(roots, [&](std::size_t node, const glm::dmat4& world) {
            const json* c = member(topElement("nodes", node), "camera");
            if (!c) return;
            out.push_back(camera(node, reference(*c, at("nodes", node) + ".camera", "cameras", count), world));
        });
        return out;
    }

    ImportedCamera camera(std::size_t node, std::size_t index, const glm::dmat4& world) const
    {
        const std::string where = at("cameras", index);
        const json& c = asObject(topElement("cameras", index), where);
        const std::string& type = asString(required(c, "type", where), where + ".type");
        ImportedCamera out;
        const json& n = topElement("nodes", node);
        const json* nodeName = member(n, "name");
        out.name = nodeName ? asString(*nodeName, at("nodes", node) + ".name") : at("nodes", node);
        if (const json* cameraName = member(c, "name")) out.aliases.push_back(asString(*cameraName, where + ".name"));
        CameraSpec& spec = out.spec;
        spec.convention = Convention::preset("opengl");
        Projection& p = spec.projection;
        double aspect = 0;
        auto positive = [&](const json& object, const char* key, const std::string& at) {
            const double v = asNumber(required(object, key, at), at + "." + key);
            if (!(v > 0)) fail(at + "." + key + " " + formatNumber(v) + " must be > 0");
            return v;
        };
        if (type == "perspective") {
            const std::string at = where + ".perspective";
            const json& q = asObject(required(c, "perspective", where), at);
            const double yfov = positive(q, "yfov", at);
            if (!(yfov < M_PI)) fail(at + ".yfov " + formatNumber(yfov) + " must be below pi radians");
            if (member(q, "aspectRatio")) aspect = positive(q, "aspectRatio", at);
            p.type = ProjectionType::Perspective;
            p.fovyDeg = yfov * 180 / M_PI;
            p.aspect = aspect;  // 0: the image's, as glTF says when it is absent
            p.near = positive(q, "znear", at);
            p.far = member(q, "zfar") ? positive(q, "zfar", at) : INFINITY;  // absent: an infinite far plane
            if (!(p.far > p.near)) fail(at + ".zfar must be greater than znear");
            out.hasClipPlanes = true;
        } else if (type == "orthographic") {
            const std::string at = where + ".orthographic";
            const json& q = asObject(required(c, "orthographic", where), at);
            const double xmag = positive(q, "xmag", at), ymag = positive(q, "ymag", at);
            const double znear = asNumber(required(q, "znear", at), at + ".znear");
            const double zfar = positive(q, "zfar", at);
            if (!(znear >= 0 && zfar > znear)) fail(at + " needs 0 <= znear < zfar");
            p.type = ProjectionType::Orthographic;
            p.left = -xmag, p.right = xmag, p.bottom = -ymag, p.top = ymag;  // xmag, ymag: half the view's extents
            aspect = xmag / ymag;
            out.hasClipPlanes = znear > 0;  // zcheck needs near > 0: a znear of 0 is taken from the scene
            p.near = znear > 0 ? znear : kPlaceholderNear, p.far = znear > 0 ? zfar : kPlaceholderFar;
        } else {
            fail(where + ".type '" + printable(type) + "' is neither perspective nor orthographic");
        }
        // No image size in glTF: the depth map's when one is verified, else 640 wide at the aspect.
        out.hasImageSize = false;
        out.projectionForSize = [p](int, int) { return p; };
        spec.width = kPlaceholderWidth;
        spec.height = aspect > 0 ? std::max(1, int(std::lround(kPlaceholderWidth / aspect))) : kPlaceholderHeight;
        // The node's world transform without its scale (glTF: cameras ignore it), camera-to-world.
        glm::dmat4 worldFromCamera = world;
        for (int axis = 0; axis < 3; ++axis) {
            const double length = glm::length(glm::dvec3(world[axis]));
            if (!(length > 0)) fail(at("nodes", node) + " scales its camera to zero");
            worldFromCamera[axis] = world[axis] / length;
        }
        try {
            spec.view = viewFromPose(worldFromCamera, PoseDirection::WorldFromCamera, spec.convention, spec.convention,
                                     "the world transform of " + at("nodes", node));
            Camera validated(spec);
        } catch (const Error& e) {
            fail(where + " at " + at("nodes", node) + ": " + e.what());
        }
        return out;
    }

    // ---- output ----------------------------------------------------------------------

    static double component(const unsigned char* p, std::uint32_t type, bool normalized)
    {
        switch (type) {
        case kByte: {
            const double c = static_cast<std::int8_t>(p[0]);
            return normalized ? std::max(c / 127.0, -1.0) : c;
        }
        case kUnsignedByte: return normalized ? p[0] / 255.0 : p[0];
        case kShort: {
            const double c = static_cast<std::int16_t>(le16(p));
            return normalized ? std::max(c / 32767.0, -1.0) : c;
        }
        case kUnsignedShort: return normalized ? le16(p) / 65535.0 : le16(p);
        default: return leFloat(p);
        }
    }

    static std::uint32_t index(const Accessor& a, std::uint64_t k)
    {
        const unsigned char* p = a.data + k * a.stride;
        switch (a.componentType) {
        case kUnsignedByte: return p[0];
        case kUnsignedShort: return le16(p);
        default: return le32(p);
        }
    }

    void emit(Scene& scene, const Primitive& p, std::size_t node, const glm::dmat4& world) const
    {
        const auto base = static_cast<std::uint32_t>(scene.positions.size());
        emitPositions(scene, p.positions, node, world);
        const std::uint64_t count = p.positions.count;
        auto vertex = [&](std::uint64_t k) -> std::uint32_t {
            if (!p.indexed) return base + std::uint32_t(k);
            const std::uint32_t v = index(p.indices, k);
            if (v >= count)
                fail(at("accessors", p.indices.index) + " holds index " + str(v) + " at element " + str(k) + ", but " +
                     at("accessors", p.positions.index) + " (POSITION) has " + str(count) + " vertices");
            return base + v;
        };
        auto& out = scene.triangles;
        if (p.mode == kTriangles) {
            for (std::uint64_t t = 0; t < p.triangles; ++t) out.emplace_back(vertex(3 * t), vertex(3 * t + 1), vertex(3 * t + 2));
        } else if (p.mode == kTriangleStrip) {
            for (std::uint64_t i = 0; i < p.triangles; ++i) {
                const std::uint32_t a = vertex(i), b = vertex(i + 1 + i % 2), c = vertex(i + 2 - i % 2);
                if (a != b && b != c && a != c) out.emplace_back(a, b, c);  // equal indices join strips
            }
        } else {
            const std::uint32_t hub = vertex(0);
            for (std::uint64_t i = 0; i < p.triangles; ++i) out.emplace_back(vertex(i + 1), vertex(i + 2), hub);
        }
    }

    void emitPositions(Scene& scene, const Accessor& a, std::size_t node, const glm::dmat4& m) const
    {
        const std::uint32_t size = componentSize(a.componentType);
        for (std::uint64_t v = 0; v < a.count; ++v) {
            const unsigned char* e = a.data + v * a.stride;
            const glm::dvec4 local(component(e, a.componentType, a.normalized), component(e + size, a.componentType, a.normalized),
                                   component(e + 2 * size, a.componentType, a.normalized), 1.0);
            if (!std::isfinite(local.x) || !std::isfinite(local.y) || !std::isfinite(local.z))
                fail(at("accessors", a.index) + " (POSITION) has a non-finite coordinate at element " + str(v));
            const glm::dvec4 world = m * local;
            // Converting a double beyond the binary32 range to float is undefined: test first.
            if (!(std::abs(world.x) <= kMaxFloat && std::abs(world.y) <= kMaxFloat && std::abs(world.z) <= kMaxFloat))
                fail("nodes[" + str(node) + "] moves element " + str(v) + " of " + at("accessors", a.index) +
                     " beyond the binary32 range");
            scene.positions.push_back(scene.rounding.store(glm::dvec3(world)));
        }
    }

    const std::string& path_;
    bool camerasOnly_ = false;  // read as a camera file: messages say so
    std::string_view bytes_;
    json root_;
    Bytes bin_;
    bool hasBin_ = false;
    bool quantization_ = false;
    std::vector<Bytes> buffers_;
    std::vector<bool> bufferLoaded_;
    std::vector<std::unique_ptr<std::string>> storage_;  // decoded data: URIs and external files
    std::map<std::string, Bytes> externalFiles_;         // canonical path → its bytes
    std::uint64_t externalBytes_ = 0;
    std::vector<Mesh> meshes_;
    std::vector<std::size_t> parent_;      // kNone for a root
    std::vector<std::size_t> childBegin_;  // children of node i: children_[childBegin_[i] … childBegin_[i+1])
    std::vector<std::size_t> children_;
    std::uint64_t vertexTotal_ = 0;
    std::uint64_t triangleTotal_ = 0;
};

}  // namespace

Scene readGltf(const std::string& path, std::string_view bytes)
{
    return GltfReader(path, bytes).read();
}

std::vector<ImportedCamera> readGltfCameraNodes(const std::string& path, std::string_view bytes)
{
    return GltfReader(path, bytes).readCameras();
}

}  // namespace zcheck
