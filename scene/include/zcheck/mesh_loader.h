#pragma once
// Scene loading by name (library zcheck::scene).
#include "zcheck/scene.h"

#include <string>

namespace zcheck {

// Reads a mesh file with zcheck's own readers (mesh_formats.h): OBJ, PLY (including
// triangle strips), STL, glTF/glb; polygons become triangles, node transforms are applied,
// points and lines ignored. Other formats are refused. The file must be a regular file of at
// most 4 GiB (input_file.h). The default camera frames the bounding sphere. Throws Error
// naming the file for a missing, unreadable, malformed or empty mesh, or one whose
// triangles all have zero area.
Scene loadMesh(const std::string& path);

// `builtin:NAME[?k=v]` or a mesh file path.
Scene loadScene(const std::string& nameOrPath);

}  // namespace zcheck
