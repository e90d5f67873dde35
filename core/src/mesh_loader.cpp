#include "zcheck/mesh_loader.h"

#include "zcheck/error.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <filesystem>

namespace zcheck {

Scene loadMesh(const std::string& path)
{
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error("cannot read mesh '" + path + "': no such file");
    if (std::filesystem::is_directory(path, ec)) throw Error("cannot read mesh '" + path + "': it is a directory");

    Assimp::Importer importer;
    // Keep every triangle: no degenerate removal, no validation that drops faces.
    const aiScene* imported = importer.ReadFile(
        path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!imported || !imported->mRootNode || (imported->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        std::string reason = importer.GetErrorString();
        if (reason.empty()) reason = "unsupported or malformed file";
        for (char& c : reason)
            if (c == '\n' || c == '\r') c = ' ';
        throw Error("cannot load mesh '" + path + "': " + reason);
    }

    Scene scene;
    scene.name = path;
    for (unsigned m = 0; m < imported->mNumMeshes; ++m) {
        const aiMesh* mesh = imported->mMeshes[m];
        if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        std::vector<glm::vec3> positions(mesh->mNumVertices);
        for (unsigned v = 0; v < mesh->mNumVertices; ++v)
            positions[v] = {mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z};
        std::vector<glm::uvec3> triangles;
        triangles.reserve(mesh->mNumFaces);
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices == 3) triangles.push_back({face.mIndices[0], face.mIndices[1], face.mIndices[2]});
        }
        scene.append(positions, triangles);
    }
    if (scene.triangles.empty()) throw Error("cannot load mesh '" + path + "': it holds no triangles");
    validateScene(scene);

    const glm::dvec3 lo = scene.boundsMin(), hi = scene.boundsMax();
    const double radius = std::max(glm::length(hi - lo) / 2, 1e-6);
    scene.defaultCamera = framingCameraSpec((lo + hi) / 2.0, radius);
    return scene;
}

Scene loadScene(const std::string& nameOrPath)
{
    if (nameOrPath.empty()) throw Error("the scene name is empty");
    if (isBuiltinSceneName(nameOrPath)) return builtinScene(nameOrPath);
    return loadMesh(nameOrPath);
}

}  // namespace zcheck
