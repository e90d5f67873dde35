#include "zcheck/point_cloud.h"

#include "zcheck/atomic_file.h"
#include "zcheck/convention.h"
#include "zcheck/error.h"

#include <cstdint>
#include <cstring>
#include <cstdio>

namespace zcheck {

void writePointCloudPly(const std::string& path, const std::vector<glm::dvec3>& points, bool binary,
                        const std::vector<std::string>& comments)
{
    std::string bytes = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") + " 1.0\n";
    for (std::string comment : comments) {
        for (char& c : comment)
            if (c == '\n' || c == '\r') c = ' ';  // a file name may hold anything
        bytes += "comment " + comment + "\n";
    }
    bytes += "element vertex " + std::to_string(points.size()) +
             "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    if (binary) {
        const std::size_t header = bytes.size();
        bytes.resize(header + points.size() * 12);
        for (std::size_t i = 0; i < points.size(); ++i) {
            const float xyz[3] = {float(points[i].x), float(points[i].y), float(points[i].z)};
            std::memcpy(bytes.data() + header + 12 * i, xyz, 12);  // x86-64 is little-endian
        }
    } else {
        char line[64];
        for (const auto& p : points) {
            const int n = std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", roundedToBinary32(p.x),
                                        roundedToBinary32(p.y), roundedToBinary32(p.z));
            bytes.append(line, std::size_t(n));
        }
    }
    writeFileBytes(path, bytes);
}

}  // namespace zcheck
