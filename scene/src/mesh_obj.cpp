// Wavefront OBJ, the geometry statements that matter to depth: `v` and `f`. Texture
// coordinates, normals, groups, materials and smoothing are read past; free-form curves and
// surfaces are not geometry zcheck can draw and are ignored. A statement zcheck does not
// know is refused, so that a file of some other kind is not read as an empty mesh.
#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_formats.h"

#include <charconv>
#include <cmath>
#include <cstring>

namespace zcheck {

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

class ObjReader {
public:
    ObjReader(const std::string& path, std::string_view bytes) : path_(path), bytes_(bytes) {}

    Scene read()
    {
        scene_.name = path_;
        // Capacity for typical lines (a vertex takes about 30 bytes, a face about 20): reserved
        // address space costs no memory until touched, and the arrays need not move while they
        // grow (beyond it they grow as usual).
        reserveLarge(scene_.positions, bytes_.size() / 24);
        reserveLarge(scene_.triangles, bytes_.size() / 16);
        std::size_t position = 0;
        std::string joined;  // a statement continued over several lines with a trailing backslash
        while (position < bytes_.size()) {
            std::size_t end = bytes_.find('\n', position);
            if (end == std::string_view::npos) end = bytes_.size();
            ++lineNumber_;
            std::string_view line = bytes_.substr(position, end - position);
            position = end + 1;
            while (!line.empty() && isBlank(line.back())) line.remove_suffix(1);
            if (!line.empty() && line.back() == '\\') {
                joined.append(line.substr(0, line.size() - 1)).push_back(' ');
                continue;
            }
            if (!joined.empty()) {
                joined.append(line);
                statement(joined);
                joined.clear();
            } else {
                statement(line);
            }
        }
        if (!joined.empty()) statement(joined);
        for (const auto& t : scene_.triangles)
            for (int k = 0; k < 3; ++k)
                if (t[k] >= scene_.positions.size())
                    throw Error("cannot load mesh '" + path_ + "': malformed OBJ: a face refers to vertex " +
                                std::to_string(t[k] + 1) + " but the file defines " +
                                std::to_string(scene_.positions.size()));
        for (const auto& [firstTriangle, corners] : fans_)
            scene_.planarity.addFan(scene_.positions, scene_.rounding, scene_.triangles, firstTriangle, corners);
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(const std::string& why) const
    {
        throw Error("cannot load mesh '" + path_ + "': malformed OBJ: line " + std::to_string(lineNumber_) + ": " + why);
    }

    static std::string printable(std::string_view text) { return printableExcerpt(text, 40); }

    static std::string_view nextWord(std::string_view& rest)
    {
        std::size_t i = 0;
        while (i < rest.size() && isBlank(rest[i])) ++i;
        std::size_t j = i;
        while (j < rest.size() && !isBlank(rest[j])) ++j;
        const std::string_view word = rest.substr(i, j - i);
        rest.remove_prefix(j);
        return word;
    }

    void statement(std::string_view line)
    {
        std::string_view rest = line;
        const std::string_view keyword = nextWord(rest);
        if (keyword.empty() || keyword[0] == '#') return;
        if (keyword == "v") return vertex(rest);
        if (keyword == "f" || keyword == "fo") return face(rest);
        static const char* const ignored[] = {
            "vt", "vn", "vp", "l", "p", "o", "g", "s", "mg", "usemtl", "mtllib", "usemap", "maplib", "lod", "bevel",
            "c_interp", "d_interp", "shadow_obj", "trace_obj", "ctech", "stech", "cstype", "deg", "bmat", "step",
            "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "call", "csh", "vc"};
        for (const char* name : ignored)
            if (keyword == name) return;
        fail("unknown statement '" + printable(keyword) + "' (is this an OBJ file?)");
    }

    double number(std::string_view word) const
    {
        double v = 0;
        const char* start = word.data() + (word.size() > 1 && word[0] == '+' ? 1 : 0);
        const auto [stop, error] = std::from_chars(start, word.data() + word.size(), v);
        if (error == std::errc::result_out_of_range) fail("'" + printable(word) + "' is beyond the range of a number");
        if (error != std::errc() || stop != word.data() + word.size()) fail("'" + printable(word) + "' is not a number");
        return v;
    }

    // v x y z [w] or v x y z r g b: the position is x, y, z.
    void vertex(std::string_view rest)
    {
        double v[7];
        int count = 0;
        for (std::string_view word = nextWord(rest); !word.empty(); word = nextWord(rest)) {
            if (count == 7) fail("a vertex has more than 7 values");
            v[count++] = number(word);
        }
        if (count < 3) fail("a vertex needs x, y and z, this one has " + std::to_string(count) + " values");
        for (int axis = 0; axis < 3; ++axis)
            if (!(std::abs(v[axis]) <= 3.4e38))
                fail("vertex coordinate " + formatNumber(v[axis]) + " is not a finite binary32 number");
        if (scene_.positions.size() >= 0xFFFFFFFEu) fail("too many vertices for 32-bit indices");
        scene_.positions.push_back(scene_.rounding.store({v[0], v[1], v[2]}));
    }

    // One face corner: v, v/vt, v/vt/vn or v//vn; the position index, 0-based.
    std::uint32_t corner(std::string_view word) const
    {
        const std::string_view index = word.substr(0, word.find('/'));
        long long v = 0;
        const auto [stop, error] = std::from_chars(index.data(), index.data() + index.size(), v);
        if (error != std::errc() || stop != index.data() + index.size() || index.empty())
            fail("face corner '" + printable(word) + "' does not start with a vertex index");
        // Relative indices count back from the last vertex defined so far.
        const long long defined = static_cast<long long>(scene_.positions.size());
        const long long resolved = v > 0 ? v - 1 : defined + v;
        if (v == 0 || resolved < 0 || resolved >= 0xFFFFFFFFll)
            fail("vertex index " + std::to_string(v) + " is out of range (" + std::to_string(defined) + " vertices defined)");
        return static_cast<std::uint32_t>(resolved);
    }

    // Polygons as fans from the first corner, except that a concave quad is split at its
    // reflex corner (what assimp and most exporters do, and the only split that stays inside it).
    void face(std::string_view rest)
    {
        corners_.clear();
        for (std::string_view word = nextWord(rest); !word.empty(); word = nextWord(rest)) corners_.push_back(corner(word));
        if (corners_.size() < 3) fail("a face needs at least 3 vertices, this one has " + std::to_string(corners_.size()));
        std::size_t first = 0;
        if (corners_.size() == 4) first = reflexCorner();
        const std::size_t n = corners_.size();
        if (n > 3) fans_.emplace_back(scene_.triangles.size(), n);
        for (std::size_t i = 1; i + 1 < n; ++i)
            scene_.triangles.push_back({corners_[first], corners_[(first + i) % n], corners_[(first + i + 1) % n]});
    }

    // The corner of a quad whose interior angle exceeds 180°, or 0 if it is convex (or its
    // corners are not all defined yet, or it is not planar enough to tell).
    std::size_t reflexCorner() const
    {
        glm::dvec3 p[4];
        for (int k = 0; k < 4; ++k) {
            if (corners_[std::size_t(k)] >= scene_.positions.size()) return 0;
            p[k] = glm::dvec3(scene_.positions[corners_[std::size_t(k)]]);
        }
        const glm::dvec3 normal = glm::cross(p[2] - p[0], p[3] - p[1]);  // Newell-like: the diagonals' cross product
        for (int k = 0; k < 4; ++k) {
            const glm::dvec3 turn = glm::cross(p[k] - p[(k + 3) % 4], p[(k + 1) % 4] - p[k]);
            if (glm::dot(turn, normal) < 0) return std::size_t(k);
        }
        return 0;
    }

    std::string path_;
    std::string_view bytes_;
    std::size_t lineNumber_ = 0;
    std::vector<std::uint32_t> corners_;
    std::vector<std::pair<std::size_t, std::size_t>> fans_;  // (first triangle, corners) of polygons of > 3 corners
    Scene scene_;
};

}  // namespace

Scene readObj(const std::string& path, std::string_view bytes) { return ObjReader(path, bytes).read(); }

}  // namespace zcheck
