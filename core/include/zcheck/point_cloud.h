#pragma once
// PLY point clouds (x, y, z as float32), written atomically.
#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace zcheck {

// binary: binary_little_endian 1.0 (the default); otherwise ascii 1.0. `comment` lines
// (no newlines) go into the header.
void writePointCloudPly(const std::string& path, const std::vector<glm::dvec3>& points, bool binary,
                        const std::vector<std::string>& comments = {});

}  // namespace zcheck
