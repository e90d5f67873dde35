#pragma once
// The mesh readers zcheck vouches for (library zcheck_scene). Each reads a whole file held
// in memory, bounds every count, offset and index by the bytes actually present before it
// allocates or loops, and throws Error with one line naming the file, the place (element and
// item, line, JSON path) and the rule. None recurses on input structure; all are fuzzed
// (fuzz/). They return the triangles as stored, degenerate ones included; loadMesh
// (mesh_loader.h) validates and frames the result.
//
//   PLY   ascii, binary little/big endian; `face` lists (polygons as fans) and `tristrips`
//         (−1 or the unsigned all-ones value restarts a strip); any property order, extra
//         properties and elements read past; vertex x, y, z required.
//   OBJ   `v` and `f` (v, v/vt, v/vt/vn, v//vn, negative indices; polygons as fans, a
//         concave quad split at its reflex corner); other statements ignored, unknown ones refused.
//   STL   binary (size must be 84 + 50·n) and ascii.
//   glTF  .gltf and .glb 2.0: triangle, strip and fan primitives of the default scene,
//         node transforms applied; buffers in the GLB, data: URIs or files beside it.
#include "zcheck/camera_import.h"
#include "zcheck/scene.h"

#include <string>
#include <string_view>
#include <vector>

namespace zcheck {

Scene readPly(const std::string& path, std::string_view bytes);
Scene readObj(const std::string& path, std::string_view bytes);
Scene readStl(const std::string& path, std::string_view bytes);
Scene readGltf(const std::string& path, std::string_view bytes);
// The camera nodes of a glTF's default scene, without reading its buffers (camera_sources.h).
std::vector<ImportedCamera> readGltfCameraNodes(const std::string& path, std::string_view bytes);

}  // namespace zcheck
