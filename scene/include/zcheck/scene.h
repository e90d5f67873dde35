#pragma once
// Scenes: a triangle soup in world space plus the camera it is best looked at with.
//
// Positions are binary32 (what a GPU and Embree consume); every route converts them to
// double before it transforms them. Scenes are addressed by name: `builtin:NAME[?k=v&…]`
// or a mesh file path (loaded by mesh_loader.h).
#include "zcheck/camera.h"
#include "zcheck/camera_import.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace zcheck {

// How far the polygons of more than 3 corners that a mesh file held lie from one plane. A
// reader splits such a polygon into a fan; a renderer may split it along other diagonals, and
// where the polygon is not planar its depth then depends on the split.
struct PolygonPlanarity {
    // Corners off the polygon's plane by more than this fraction of its size count as non-planar
    // (binary32 positions alone stay near 1e-7).
    static constexpr double kTolerance = 1e-5;
    std::uint64_t polygons = 0;   // polygons of more than 3 corners
    std::uint64_t nonPlanar = 0;  // of those, not planar
    double worst = 0;             // the largest corner distance from the plane, relative to the polygon's size

    // A polygon split by a reader into the fan of `cornerCount` − 2 consecutive triangles of
    // `scene` from `firstTriangle` (each sharing its first corner with the first triangle).
    void addFan(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                std::size_t firstTriangle, std::size_t cornerCount);
    // "" when every polygon is planar; else one sentence naming `mesh`, the count and the worst.
    std::string warning(const std::string& mesh) const;
};

// Bounding boxes of runs of consecutive triangles (meshes keep neighbours close), so that a
// question about the whole scene seen from a camera (camera_sources.h's sceneNearFar) can skip
// what cannot change its answer. Made once per scene (indexTriangleChunks).
struct TriangleChunks {
    static constexpr std::size_t kSize = 1024;  // triangles per chunk; the last may hold fewer
    std::vector<glm::vec3> lo, hi;              // per chunk, world space
};

struct Scene {
    Scene() = default;
    // A copy's positions and triangles lie on huge pages, as a loaded scene's do (a copy on small
    // pages made the comparison's slope lookups, which read them all over, ~1.8× as long).
    Scene(const Scene& other);
    Scene& operator=(const Scene& other);
    Scene(Scene&&) = default;
    Scene& operator=(Scene&&) = default;

    std::string name;                     // as addressed: "builtin:default", a file path
    std::vector<glm::vec3> positions;     // world space
    std::vector<glm::uvec3> triangles;    // indices into positions; the index is the primitive id
    CameraSpec defaultCamera;             // used when the user gives no camera file
    PolygonPlanarity planarity;           // of the file's polygons (mesh files; none built in)
    std::vector<ImportedCamera> cameras;  // the file's camera nodes (glTF), in file order; the
                                          // first is the default camera (camera_sources.h)
    std::shared_ptr<const TriangleChunks> chunks;  // made by indexTriangleChunks; none: made on use

    std::size_t triangleCount() const { return triangles.size(); }
    glm::dvec3 boundsMin() const;
    glm::dvec3 boundsMax() const;
    // Appends another soup (indices are offset).
    void append(const std::vector<glm::vec3>& morePositions, const std::vector<glm::uvec3>& moreTriangles);
};

// Throws Error for a scene with no triangles or an index out of range.
void validateScene(const Scene& scene);

// The scene's TriangleChunks (indices must be valid). loadScene and frameScene make them.
std::shared_ptr<const TriangleChunks> triangleChunksOf(const Scene& scene);

// Makes a triangle soup a scene to check: validates it (validateScene), refuses it when no
// triangle has a nonzero area (nothing to draw), and gives it a default camera that frames its
// bounding sphere (framingCameraSpec). Messages begin with `what` ("cannot load mesh 'a.obj'").
// The mesh loader and the Python module's Scene.from_arrays use it.
Scene frameScene(Scene scene, const std::string& what);

bool isBuiltinSceneName(const std::string& name);
const std::vector<std::string>& builtinSceneNames();  // "default", "terrain", "near-crossing"

// builtin:default      ground plane, boxes and spheres at several depths, a thin slanted
//                      panel and two nearly coplanar quads, asymmetric left/right and
//                      top/bottom so that flips change the picture.
// builtin:terrain?n=N  heightfield of N×N vertices, 2(N−1)² triangles (N = 708 ≈ 1 M), N in 2…4096,
//                      default 256.
// builtin:near-crossing geometry that crosses the near plane and lies partly behind the camera.
// Throws Error naming an unknown scene or parameter.
Scene builtinScene(const std::string& name);

}  // namespace zcheck
