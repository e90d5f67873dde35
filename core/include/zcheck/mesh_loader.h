#pragma once
// Scene loading by name (library zcheck_meshio, the only place assimp is used).
#include "zcheck/scene.h"

#include <string>

namespace zcheck {

// Reads a mesh file through assimp (OBJ, PLY including triangle strips, glTF/glb, and the
// other formats assimp reads); polygons are triangulated, node transforms applied, point
// and line primitives ignored. The default camera frames the bounding sphere.
// Throws Error naming the file for a missing, unreadable or empty mesh.
Scene loadMesh(const std::string& path);

// `builtin:NAME[?k=v]` or a mesh file path.
Scene loadScene(const std::string& nameOrPath);

}  // namespace zcheck
