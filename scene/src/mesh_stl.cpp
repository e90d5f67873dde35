// STL: binary (an 80-byte header, a uint32 triangle count, 50 bytes a triangle: normal,
// three vertices as binary32, a 16-bit attribute) or ascii (solid … facet … outer loop,
// three `vertex x y z`, endloop, endfacet … endsolid). Vertices are not shared.
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

[[noreturn]] void fail(const std::string& path, const std::string& why)
{
    throw Error("cannot load mesh '" + path + "': malformed STL: " + why);
}

void addVertex(Scene& scene, const std::string& path, const double v[3])
{
    for (int axis = 0; axis < 3; ++axis)
        if (!(std::abs(v[axis]) <= 3.4e38))
            fail(path, "vertex coordinate " + formatNumber(v[axis]) + " is not a finite binary32 number");
    scene.positions.push_back(scene.rounding.store({v[0], v[1], v[2]}));
}

void addTriangle(Scene& scene)
{
    const auto n = static_cast<std::uint32_t>(scene.positions.size());
    scene.triangles.push_back({n - 3, n - 2, n - 1});
}

Scene readBinary(const std::string& path, std::string_view bytes)
{
    if (bytes.size() < 84) fail(path, "a binary STL needs at least 84 bytes, this file has " + std::to_string(bytes.size()));
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);  // little-endian, as the format defines
    const std::uint64_t expected = 84 + 50 * std::uint64_t(count);
    if (bytes.size() != expected)
        fail(path, "the header declares " + std::to_string(count) + " triangles (" + std::to_string(expected) +
                       " bytes) but the file has " + std::to_string(bytes.size()) + " bytes");
    if (count > 0x55555554u) fail(path, "too many triangles for 32-bit vertex indices");
    Scene scene;
    scene.name = path;
    reserveLarge(scene.positions, std::size_t(count) * 3);
    reserveLarge(scene.triangles, count);
    for (std::uint32_t t = 0; t < count; ++t) {
        const char* record = bytes.data() + 84 + 50 * std::size_t(t);
        for (int k = 0; k < 3; ++k) {
            float xyz[3];
            std::memcpy(xyz, record + 12 + 12 * k, 12);
            const double v[3] = {xyz[0], xyz[1], xyz[2]};
            addVertex(scene, path, v);
        }
        addTriangle(scene);
    }
    return scene;
}

Scene readAscii(const std::string& path, std::string_view bytes)
{
    Scene scene;
    scene.name = path;
    std::size_t lineNumber = 0, position = 0, corners = 0;
    bool inLoop = false, ended = false;
    while (position < bytes.size()) {
        std::size_t end = bytes.find('\n', position);
        if (end == std::string_view::npos) end = bytes.size();
        std::string_view line = bytes.substr(position, end - position);
        position = end + 1;
        ++lineNumber;
        const std::string where = "line " + std::to_string(lineNumber) + ": ";
        auto word = [&]() {
            std::size_t i = 0;
            while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
            std::size_t j = i;
            while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
            const std::string_view w = line.substr(i, j - i);
            line.remove_prefix(j);
            return w;
        };
        const std::string_view keyword = word();
        if (keyword.empty()) continue;
        if (ended) fail(path, where + "text after endsolid");
        if (keyword == "solid" || keyword == "facet" || keyword == "endfacet") continue;  // names and normals: not needed
        if (keyword == "endsolid") {
            ended = true;
            continue;
        }
        if (keyword == "outer") {
            if (inLoop) fail(path, where + "'outer loop' inside a loop");
            inLoop = true, corners = 0;
        } else if (keyword == "endloop") {
            if (!inLoop || corners != 3) fail(path, where + "a loop must hold exactly 3 vertices");
            inLoop = false;
            addTriangle(scene);
        } else if (keyword == "vertex") {
            if (!inLoop || corners == 3) fail(path, where + "a vertex outside a loop, or a fourth one");
            double v[3];
            for (double& component : v) {
                const std::string_view w = word();
                const auto [stop, error] = std::from_chars(w.data(), w.data() + w.size(), component);
                if (w.empty() || error != std::errc() || stop != w.data() + w.size())
                    fail(path, where + "a vertex needs three numbers");
            }
            if (!word().empty()) fail(path, where + "a vertex has more than three numbers");
            if (scene.positions.size() >= 0xFFFFFFF0u) fail(path, "too many vertices for 32-bit indices");
            addVertex(scene, path, v);
            ++corners;
        } else {
            fail(path, where + "unknown keyword (is this an STL file?)");
        }
    }
    if (inLoop) fail(path, "the file ends inside a loop");
    return scene;
}

}  // namespace

Scene readStl(const std::string& path, std::string_view bytes)
{
    // Binary files may begin with "solid" too: ascii means "solid", no control bytes in the
    // first 512 (a binary header and count nearly always hold some), and not the exact size
    // of a binary file.
    bool binarySize = false;
    if (bytes.size() >= 84) {
        std::uint32_t count = 0;
        std::memcpy(&count, bytes.data() + 80, 4);
        binarySize = bytes.size() == 84 + 50 * std::uint64_t(count);
    }
    const std::string_view head = bytes.substr(0, 512);
    const bool text = std::all_of(head.begin(), head.end(), [](char c) {
        return c == '\n' || c == '\r' || c == '\t' || static_cast<unsigned char>(c) >= 32;
    });
    const bool looksAscii = bytes.substr(0, 5) == "solid" && text && !binarySize;
    return looksAscii ? readAscii(path, bytes) : readBinary(path, bytes);
}

}  // namespace zcheck
