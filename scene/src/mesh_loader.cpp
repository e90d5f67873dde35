#include "zcheck/mesh_loader.h"

#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/mesh_formats.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

namespace {

// Refuses a mesh with no triangle of nonzero area (nothing for either route to draw), then
// validates it and gives it a camera that frames its bounding sphere.
Scene framed(Scene scene)
{
    if (scene.triangles.empty()) throw Error("cannot load mesh '" + scene.name + "': it holds no triangles");
    validateScene(scene);
    const bool anyArea = std::any_of(scene.triangles.begin(), scene.triangles.end(), [&](const glm::uvec3& t) {
        const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
        return glm::length(glm::cross(b - a, c - a)) > 0;
    });
    if (!anyArea)
        throw Error("cannot load mesh '" + scene.name + "': all its " + std::to_string(scene.triangles.size()) +
                    " triangles are degenerate (zero area): nothing to draw");
    const glm::dvec3 lo = scene.boundsMin(), hi = scene.boundsMax();
    const double radius = std::max(glm::length(hi - lo) / 2, 1e-6);
    scene.defaultCamera = framingCameraSpec((lo + hi) / 2.0, radius);
    return scene;
}

}  // namespace

Scene loadMesh(const std::string& path)
{
    const std::string bytes = readInputFile(path, kMeshInput);
    const std::string ext = lowerExtension(path);
    // The content decides where it can (a .ply renamed .obj is still a PLY); else the extension.
    if (bytes.rfind("ply\n", 0) == 0 || bytes.rfind("ply\r\n", 0) == 0 || ext == ".ply") return framed(readPly(path, bytes));
    if (ext == ".glb" && bytes.rfind("glTF", 0) != 0)
        throw Error("cannot load mesh '" + path + "': malformed GLB: it does not begin with the magic 'glTF'");
    if (bytes.rfind("glTF", 0) == 0 || ext == ".glb" || ext == ".gltf") return framed(readGltf(path, bytes));
    if (ext == ".obj") return framed(readObj(path, bytes));
    if (ext == ".stl") return framed(readStl(path, bytes));
    throw Error("cannot load mesh '" + path + "': unsupported format '" + (ext.empty() ? "(no extension)" : ext) +
                "' (zcheck reads .obj, .ply, .stl, .gltf and .glb; convert other formats to one of these)");
}

Scene loadScene(const std::string& nameOrPath)
{
    if (nameOrPath.empty()) throw Error("the scene name is empty");
    if (isBuiltinSceneName(nameOrPath)) return builtinScene(nameOrPath);
    return loadMesh(nameOrPath);
}

}  // namespace zcheck
