#include "zcheck/point_cloud.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"

#include <cstdint>
#include <cstring>
#include <fstream>

namespace zcheck {

void writePointCloudPly(const std::string& path, const std::vector<glm::dvec3>& points, bool binary,
                        const std::vector<std::string>& comments)
{
    writeAtomically(path, [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n";
        for (const auto& comment : comments) out << "comment " << comment << "\n";
        out << "element vertex " << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        if (binary) {
            std::vector<char> bytes(points.size() * 12);
            for (std::size_t i = 0; i < points.size(); ++i) {
                const float xyz[3] = {float(points[i].x), float(points[i].y), float(points[i].z)};
                std::memcpy(bytes.data() + 12 * i, xyz, 12);  // x86-64 is little-endian
            }
            out.write(bytes.data(), std::streamsize(bytes.size()));
        } else {
            out.precision(9);
            for (const auto& p : points) out << float(p.x) << ' ' << float(p.y) << ' ' << float(p.z) << '\n';
        }
        out.flush();
        if (!out) throw Error("cannot write '" + path + "': write failed");
    });
}

}  // namespace zcheck
