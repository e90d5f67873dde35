#pragma once
// PLY point clouds (x, y, z as float32), written to the given path with checked writes
// (a command makes it atomic with OutputFiles, atomic_file.h).
#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace zcheck {

// binary: binary_little_endian 1.0 (the default); otherwise ascii 1.0. `comment` lines
// go into the header (line breaks in them become spaces).
void writePointCloudPly(const std::string& path, const std::vector<glm::dvec3>& points, bool binary,
                        const std::vector<std::string>& comments = {});

}  // namespace zcheck
