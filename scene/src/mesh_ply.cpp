// PLY (Greg Turk's format, as documented by Paul Bourke): a text header of `element` and
// `property` lines up to `end_header`, then the items of each element in order, ascii (one
// item a line) or binary (packed, in the declared byte order).
#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_formats.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace zcheck {

namespace {

enum class PlyType : std::uint8_t { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

int sizeOf(PlyType type)
{
    switch (type) {
    case PlyType::Int8:
    case PlyType::Uint8: return 1;
    case PlyType::Int16:
    case PlyType::Uint16: return 2;
    case PlyType::Int32:
    case PlyType::Uint32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
    }
    return 8;
}

bool isUnsigned(PlyType type) { return type == PlyType::Uint8 || type == PlyType::Uint16 || type == PlyType::Uint32; }

// What a property means to zcheck.
enum class Role : std::uint8_t { Ignored, X, Y, Z, Indices };

struct Property {
    std::string name;
    PlyType type = PlyType::Float32;
    bool isList = false;
    PlyType countType = PlyType::Uint8;
    Role role = Role::Ignored;
};

enum class ElementKind : std::uint8_t { Other, Vertex, Face, Strips };

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
    ElementKind kind = ElementKind::Other;
};

class PlyReader {
public:
    PlyReader(const std::string& path, std::string_view bytes) : path_(path), bytes_(bytes) {}

    Scene read()
    {
        readHeader();
        scene_.name = path_;
        for (const Element& element : elements_) readElement(element);
        if (scene_.triangles.empty() && stripJoins_ > 0)
            fail("all " + std::to_string(stripJoins_) +
                 " triangles of its strips repeat a vertex index (degenerate, zero area): nothing to draw");
        for (const auto& t : scene_.triangles)
            for (int k = 0; k < 3; ++k)
                if (t[k] >= scene_.positions.size())
                    fail("a face refers to vertex " + std::to_string(t[k]) + " but the file has " +
                         std::to_string(scene_.positions.size()) + " vertices");
        for (const auto& [firstTriangle, corners] : fans_)
            scene_.planarity.addFan(scene_.positions, scene_.rounding, scene_.triangles, firstTriangle, corners);
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(const std::string& why) const
    {
        throw Error("cannot load mesh '" + path_ + "': malformed PLY: " + why);
    }
    [[noreturn]] void failItem(const Element& element, std::uint64_t item, const std::string& why) const
    {
        fail(element.name + " " + std::to_string(item) + ": " + why);
    }

    static std::string printable(std::string_view text) { return printableExcerpt(text, 60); }

    PlyType typeNamed(const std::string& name) const
    {
        static const std::pair<const char*, PlyType> names[] = {
            {"char", PlyType::Int8},     {"int8", PlyType::Int8},       {"uchar", PlyType::Uint8},
            {"uint8", PlyType::Uint8},   {"short", PlyType::Int16},     {"int16", PlyType::Int16},
            {"ushort", PlyType::Uint16}, {"uint16", PlyType::Uint16},   {"int", PlyType::Int32},
            {"int32", PlyType::Int32},   {"uint", PlyType::Uint32},     {"uint32", PlyType::Uint32},
            {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
            {"float64", PlyType::Float64}};
        for (const auto& [text, type] : names)
            if (name == text) return type;
        fail("unknown property type '" + printable(name) + "'");
    }

    // The header: "ply", "format …", element/property/comment/obj_info lines, "end_header".
    void readHeader()
    {
        constexpr std::size_t kMaxHeaderBytes = 1 << 20;
        std::size_t position = 0, lineNumber = 0;
        bool sawFormat = false;
        auto nextLine = [&]() -> std::string {
            const std::size_t end = bytes_.find('\n', position);
            if (end == std::string_view::npos || end > kMaxHeaderBytes)
                fail(lineNumber == 0 ? "not a PLY file (no header line)"
                                     : "the header has no end_header line within its first 1 MiB");
            std::string line(bytes_.substr(position, end - position));
            if (!line.empty() && line.back() == '\r') line.pop_back();
            position = end + 1;
            ++lineNumber;
            return line;
        };
        if (nextLine() != "ply") fail("not a PLY file (the first line is not 'ply')");
        for (;;) {
            const std::string line = nextLine();
            std::vector<std::string> words;
            for (std::size_t i = 0; i < line.size();) {
                while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
                std::size_t j = i;
                while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
                if (j > i) words.emplace_back(line.substr(i, j - i));
                i = j;
            }
            if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
            const std::string where = "header line " + std::to_string(lineNumber) + " '" + printable(line) + "': ";
            if (words[0] == "end_header") break;
            if (words[0] == "format") {
                if (words.size() != 3 || words[2] != "1.0") fail(where + "expected 'format <kind> 1.0'");
                if (words[1] == "ascii") ascii_ = true;
                else if (words[1] == "binary_big_endian") bigEndian_ = true;
                else if (words[1] != "binary_little_endian") fail(where + "unknown format '" + printable(words[1]) + "'");
                sawFormat = true;
            } else if (words[0] == "element") {
                if (!sawFormat) fail(where + "an element before the format line");
                Element element;
                if (words.size() != 3) fail(where + "expected 'element <name> <count>'");
                element.name = words[1];
                const auto [end, error] = std::from_chars(words[2].data(), words[2].data() + words[2].size(), element.count);
                if (error != std::errc() || end != words[2].data() + words[2].size())
                    fail(where + "the count is not a whole number");
                element.kind = element.name == "vertex"      ? ElementKind::Vertex
                               : element.name == "face"      ? ElementKind::Face
                               : element.name == "tristrips" ? ElementKind::Strips
                                                             : ElementKind::Other;
                for (const Element& other : elements_)
                    if (other.kind != ElementKind::Other && other.name == element.name)
                        fail(where + "a second '" + element.name + "' element");
                elements_.push_back(element);
            } else if (words[0] == "property") {
                if (elements_.empty()) fail(where + "a property before any element");
                Element& element = elements_.back();
                Property property;
                if (words.size() == 5 && words[1] == "list") {
                    property.isList = true;
                    property.countType = typeNamed(words[2]);
                    property.type = typeNamed(words[3]);
                    property.name = words[4];
                    if (property.countType == PlyType::Float32 || property.countType == PlyType::Float64)
                        fail(where + "a list count must have an integer type");
                } else if (words.size() == 3 && words[1] != "list") {
                    property.type = typeNamed(words[1]);
                    property.name = words[2];
                } else {
                    fail(where + "expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
                }
                for (const Property& other : element.properties)
                    if (other.name == property.name) fail(where + "property '" + property.name + "' appears twice");
                if (element.kind == ElementKind::Vertex && !property.isList)
                    property.role = property.name == "x" ? Role::X : property.name == "y" ? Role::Y
                                  : property.name == "z" ? Role::Z : Role::Ignored;
                if ((element.kind == ElementKind::Face || element.kind == ElementKind::Strips) && property.isList &&
                    (property.name == "vertex_indices" || property.name == "vertex_index"))
                    property.role = Role::Indices;
                element.properties.push_back(property);
            } else {
                fail(where + "unknown header keyword");
            }
        }
        if (!sawFormat) fail("the header has no format line");
        data_ = position;
        for (const Element& element : elements_) {
            auto has = [&](Role role) {
                return std::any_of(element.properties.begin(), element.properties.end(),
                                   [&](const Property& p) { return p.role == role; });
            };
            if (element.kind == ElementKind::Vertex)
                for (auto [role, axis] : {std::pair{Role::X, "x"}, std::pair{Role::Y, "y"}, std::pair{Role::Z, "z"}})
                    if (!has(role)) fail("the vertex element has no '" + std::string(axis) + "' property");
            if ((element.kind == ElementKind::Face || element.kind == ElementKind::Strips) && !has(Role::Indices))
                fail("the " + element.name + " element has no 'vertex_indices' list");
            if (element.count > 0 && element.properties.empty()) fail("element '" + element.name + "' has no properties");
        }
        if (std::none_of(elements_.begin(), elements_.end(), [](const Element& e) { return e.kind == ElementKind::Vertex; }))
            fail("no vertex element");
    }

    std::uint64_t remaining() const { return bytes_.size() - std::min<std::uint64_t>(bytes_.size(), data_); }

    // Binary: one value of `type` at the cursor, or Error if the data ends.
    double binaryValue(PlyType type, const Element& element, std::uint64_t item)
    {
        const int size = sizeOf(type);
        if (remaining() < std::uint64_t(size)) failItem(element, item, "the data ends early");
        unsigned char raw[8];
        std::memcpy(raw, bytes_.data() + data_, std::size_t(size));
        data_ += std::size_t(size);
        if (bigEndian_) std::reverse(raw, raw + size);
        auto as = [&](auto v) {
            std::memcpy(&v, raw, sizeof v);
            return double(v);
        };
        switch (type) {
        case PlyType::Int8: return as(std::int8_t{});
        case PlyType::Uint8: return as(std::uint8_t{});
        case PlyType::Int16: return as(std::int16_t{});
        case PlyType::Uint16: return as(std::uint16_t{});
        case PlyType::Int32: return as(std::int32_t{});
        case PlyType::Uint32: return as(std::uint32_t{});
        case PlyType::Float32: return as(float{});
        case PlyType::Float64: return as(double{});
        }
        return 0;
    }

    // Ascii: the item's line, split into numbers on demand.
    struct Line {
        const char* at;
        const char* end;
    };
    Line nextAsciiLine(const Element& element, std::uint64_t item)
    {
        for (;;) {
            if (data_ >= bytes_.size()) failItem(element, item, "the data ends early (fewer items than the header declares)");
            std::size_t end = bytes_.find('\n', data_);
            if (end == std::string_view::npos) end = bytes_.size();
            Line line{bytes_.data() + data_, bytes_.data() + end};
            data_ = end + 1;
            while (line.at < line.end && (*line.at == ' ' || *line.at == '\t' || *line.at == '\r')) ++line.at;
            if (line.at < line.end) return line;  // blank lines between items are skipped
        }
    }
    double asciiValue(Line& line, const Element& element, std::uint64_t item)
    {
        while (line.at < line.end && (*line.at == ' ' || *line.at == '\t' || *line.at == '\r')) ++line.at;
        if (line.at == line.end) failItem(element, item, "the line holds fewer values than the header declares");
        double v = 0;
        const char* start = line.at + (*line.at == '+' ? 1 : 0);
        const auto [stop, error] = std::from_chars(start, line.end, v);
        if (error != std::errc() || (stop < line.end && *stop != ' ' && *stop != '\t' && *stop != '\r'))
            failItem(element, item, "'" + printable(std::string_view(line.at, std::size_t(std::min<std::ptrdiff_t>(line.end - line.at, 20)))) +
                                        "' is not a number");
        line.at = stop;
        return v;
    }

    // A vertex index as read: a whole number in [0, 2^32 − 2]; in strips also −1 (a restart;
    // for unsigned index types the all-ones value is the restart). kRestart marks a restart.
    static constexpr std::int64_t kRestart = -1;
    std::int64_t vertexIndex(double v, const Property& property, const Element& element, std::uint64_t item) const
    {
        if (!std::isfinite(v) || v != std::floor(v)) failItem(element, item, "a vertex index is not a whole number");
        if (element.kind == ElementKind::Strips) {
            if (v == -1) return kRestart;
            if (isUnsigned(property.type) && v == std::ldexp(1.0, 8 * sizeOf(property.type)) - 1) return kRestart;
        }
        if (v < 0 || v > 4294967294.0) failItem(element, item, "vertex index " + formatNumber(v) + " is out of range");
        return static_cast<std::int64_t>(v);
    }

    void readElement(const Element& element)
    {
        // Refuse counts the data cannot hold before allocating or looping for them.
        std::uint64_t minimumBytes = 0;
        for (const Property& property : element.properties)
            minimumBytes += ascii_ ? 2 : std::uint64_t(sizeOf(property.isList ? property.countType : property.type));
        // (+1: the last ascii line needs no newline.)
        if (minimumBytes > 0 && element.count > (remaining() + (ascii_ ? 1 : 0)) / minimumBytes)
            fail("element '" + element.name + "' declares " + std::to_string(element.count) +
                 " items, more than the remaining " + std::to_string(remaining()) + " bytes can hold");
        if (element.kind == ElementKind::Vertex) {
            if (element.count >= 0xFFFFFFFFull) fail("too many vertices for 32-bit indices");
            reserveLarge(scene_.positions, element.count);
        }
        // Every face makes at least one triangle (a strip's count is known from its list).
        if (element.kind == ElementKind::Face) reserveLarge(scene_.triangles, scene_.triangles.size() + element.count);
        for (std::uint64_t item = 0; item < element.count; ++item) {
            Line line{nullptr, nullptr};
            if (ascii_) line = nextAsciiLine(element, item);
            auto value = [&](PlyType type) { return ascii_ ? asciiValue(line, element, item) : binaryValue(type, element, item); };
            glm::dvec3 position(0.0);
            for (const Property& property : element.properties) {
                if (!property.isList) {
                    const double v = value(property.type);
                    if (property.role == Role::X) position.x = v;
                    if (property.role == Role::Y) position.y = v;
                    if (property.role == Role::Z) position.z = v;
                    continue;
                }
                const double length = value(property.countType);
                // Ascii entries need a digit and a separator each on this line; binary ones their size.
                const std::uint64_t available = ascii_ ? std::uint64_t(line.end - line.at) / 2 + 1
                                                       : remaining() / std::uint64_t(sizeOf(property.type));
                if (!(length >= 0) || length != std::floor(length) || length > double(available))
                    failItem(element, item, "a list declares " + formatNumber(length) + " entries, more than the data holds");
                if (property.role == Role::Indices && element.kind == ElementKind::Strips && length > 2)
                    reserveLarge(scene_.triangles, scene_.triangles.size() + std::size_t(length) - 2);
                PrimitiveAssembler assemble(element.kind, scene_.triangles, stripJoins_);
                for (std::uint64_t k = 0; k < std::uint64_t(length); ++k) {
                    const double v = value(property.type);
                    if (property.role == Role::Indices) assemble.add(vertexIndex(v, property, element, item));
                }
                if (property.role == Role::Indices && element.kind == ElementKind::Face && length < 3)
                    failItem(element, item, "a face needs at least 3 vertices, this one has " + formatNumber(length));
                if (property.role == Role::Indices && element.kind == ElementKind::Face && length > 3)
                    fans_.emplace_back(scene_.triangles.size() - (std::size_t(length) - 2), std::size_t(length));
            }
            if (ascii_) {
                while (line.at < line.end && (*line.at == ' ' || *line.at == '\t' || *line.at == '\r')) ++line.at;
                if (line.at != line.end) failItem(element, item, "the line holds more values than the header declares");
            }
            if (element.kind == ElementKind::Vertex) {
                for (int axis = 0; axis < 3; ++axis)
                    if (!(std::abs(position[axis]) <= 3.4e38))
                        failItem(element, item, "coordinate " + formatNumber(position[axis]) + " is not a finite binary32 number");
                scene_.positions.push_back(scene_.rounding.store(position));
            }
        }
    }

    // Turns one face's or strip's index list into triangles as its indices arrive, so a strip
    // of millions of indices is never copied. Faces are fans, kept as the file gives them
    // (loadMesh judges degenerate ones). Strips alternate winding and restart at kRestart;
    // their triangles that repeat an index are the joins between strips, an artefact of the
    // encoding, and are skipped (and counted).
    class PrimitiveAssembler {
    public:
        PrimitiveAssembler(ElementKind kind, std::vector<glm::uvec3>& triangles, std::uint64_t& stripJoins)
            : strips_(kind == ElementKind::Strips), triangles_(triangles), stripJoins_(stripJoins) {}

        void add(std::int64_t index)
        {
            if (strips_ && index == kRestart) {
                count_ = 0;
                return;
            }
            const auto i = std::uint32_t(index);
            if (count_ == 0) first_ = i;
            if (count_ >= 2) {
                if (!strips_) triangles_.push_back({first_, previous_, i});
                else if (older_ == previous_ || previous_ == i || older_ == i) ++stripJoins_;
                else if (count_ % 2 == 0) triangles_.push_back({older_, previous_, i});
                else triangles_.push_back({previous_, older_, i});
            }
            older_ = previous_;
            previous_ = i;
            ++count_;
        }

    private:
        bool strips_;
        std::vector<glm::uvec3>& triangles_;
        std::uint64_t& stripJoins_;
        std::uint64_t count_ = 0;  // indices since the list's start or the last restart
        std::uint32_t first_ = 0, older_ = 0, previous_ = 0;
    };

    std::string path_;
    std::string_view bytes_;
    std::size_t data_ = 0;  // cursor into bytes_
    std::vector<Element> elements_;
    bool ascii_ = false, bigEndian_ = false;
    std::uint64_t stripJoins_ = 0;  // strip triangles skipped for repeating an index
    std::vector<std::pair<std::size_t, std::size_t>> fans_;  // (first triangle, corners) of faces of > 3 corners
    Scene scene_;
};

}  // namespace

Scene readPly(const std::string& path, std::string_view bytes) { return PlyReader(path, bytes).read(); }

}  // namespace zcheck
