#include "zcheck/mesh_loader.h"

#include "zcheck/camera_sources.h"

#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/mesh_formats.h"

#include <algorithm>
#include <cmath>
#include <string_view>

namespace zcheck {

namespace {

Scene framed(Scene scene)
{
    if (scene.triangles.empty()) throw Error("cannot load mesh '" + scene.name + "': it holds no triangles");
    const std::string what = "cannot load mesh '" + scene.name + "'";
    return frameScene(std::move(scene), what);
}

}  // namespace

Scene loadMesh(const std::string& path)
{
    const LargeVector<char> file = readInputBytes(path, kMeshInput);
    const std::string_view bytes(file.data(), file.size());
    const std::string ext = lowerExtension(path);
    // The content decides where it can (a .ply renamed .obj is still a PLY); else the extension.
    if (bytes.rfind("ply\n", 0) == 0 || bytes.rfind("ply\r\n", 0) == 0 || ext == ".ply") return framed(readPly(path, bytes));
    if (ext == ".glb" && bytes.rfind("glTF", 0) != 0)
        throw Error("cannot load mesh '" + path + "': malformed GLB: it does not begin with the magic 'glTF'");
    if (bytes.rfind("glTF", 0) == 0 || ext == ".glb" || ext == ".gltf") {
        Scene scene = framed(readGltf(path, bytes));
        if (!scene.cameras.empty()) {  // the file's first camera is the scene's own
            ImportedCamera& first = scene.cameras.front();
            first.spec.notes.push_back("the camera is the glTF's first, '" + first.name + "'");
            scene.defaultCamera = completeCamera(first, &scene, {});
        }
        return scene;
    }
    if (ext == ".obj") return framed(readObj(path, bytes));
    if (ext == ".stl") return framed(readStl(path, bytes));
    throw Error("cannot load mesh '" + path + "': unsupported format '" + (ext.empty() ? "(no extension)" : ext) +
                "' (zcheck reads .obj, .ply, .stl, .gltf and .glb; convert other formats to one of these)");
}

Scene loadScene(const std::string& nameOrPath)
{
    if (nameOrPath.empty()) throw Error("the scene name is empty");
    if (isBuiltinSceneName(nameOrPath)) {
        Scene scene = builtinScene(nameOrPath);
        scene.chunks = triangleChunksOf(scene);
        return scene;
    }
    return loadMesh(nameOrPath);
}

}  // namespace zcheck
