#pragma once
// Scenes: a triangle soup plus the camera it is best looked at with.
//
// Positions are binary32 (what a GPU and Embree consume), in the world or, for a mesh far from
// the world's origin, about a local origin (Scene::origin); every route converts them to double
// before it transforms them. Scenes are addressed by name: `builtin:NAME[?k=v&…]`
// or a mesh file path (loaded by mesh_loader.h).
#include "zcheck/camera.h"
#include "zcheck/camera_import.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

// How far binary32 (what zcheck, Embree and a GPU hold) would move a mesh's vertices at the file's
// own coordinates. A file may hold more digits (OBJ and PLY text, PLY doubles, a glTF node's
// transform applied in binary64, a Python float64 array). Near the origin the move is below 2^-24
// of the mesh's size and nobody draws anything else; far from it against the mesh's size (UTM or
// ECEF coordinates: binary32 steps by 0.5 at 4.2e6) the rounded mesh is another mesh. frameScene
// then holds the mesh about a local origin (Scene::origin), as large-world renderers do, and
// keeps the file's mesh to binary32 of its own size; what is recorded here is what a renderer
// holding the file's coordinates in binary32 draws instead, which reports name.
struct PositionRounding {
    // A move over this fraction of the mesh's size (its bounding box's diagonal) is material: the
    // coordinates lie some ten sizes or more from the origin. A camera that sees the mesh stands
    // about its size away, and a binary32 eye-z map is judged to ~2^-22 of its depth
    // (tolerance.md), so a move of 2^-20 of the size can already part such a map from the truth.
    static constexpr double kMaterial = 0x1p-20;
    double largestMove = 0;     // the longest distance a vertex moved, in the file's units
    glm::dvec3 movedVertex{0};  // that vertex as the file holds it
    double size = 0;            // the stored mesh's bounding-box diagonal (frameScene sets it)
    // What binary32 left of each vertex's file coordinates (file − stored, itself in binary32:
    // the file's value to ~2^-48 of it), by index from the first vertex that moved (empty while
    // none has), until frameScene has placed the mesh: what it rounds again about a local origin
    // when the move is material.
    std::vector<glm::vec3> residual;
    std::size_t storedCount = 0;  // store() calls since the last frameScene: the index of the next vertex

    // `position` as binary32 (the caller has checked it is within range), its move recorded.
    // A reader calls it once per vertex, in the order of Scene::positions.
    glm::vec3 store(const glm::dvec3& position);
    // Vertex v of `stored` (what store() returned, in order) as the file held it: its binary32
    // value and the residual, to ~2^-48 of it; until frameScene has placed the mesh.
    glm::dvec3 fileCoordinates(const std::vector<glm::vec3>& stored, std::size_t v) const
    {
        return v < residual.size() ? glm::dvec3(stored[v]) + glm::dvec3(residual[v]) : glm::dvec3(stored[v]);
    }
    bool material() const { return largestMove > kMaterial * size; }
    // "" unless material(); else one sentence naming `mesh`, the move, and where the mesh is held
    // (`origin`, Scene::origin; zero: at the file's coordinates, and the move is this check's own).
    std::string warning(const std::string& mesh, const glm::dvec3& origin = glm::dvec3(0.0)) const;
};

// How far the polygons of more than 3 corners that a mesh file held lie from one plane. A
// reader splits such a polygon into a fan; a renderer may split it along other diagonals, and
// where the polygon is not planar its depth then depends on the split.
struct PolygonPlanarity {
    // Corners off the polygon's plane by more than this fraction of its size count as non-planar
    // (a planar polygon's corners, as the file writes them, measure near 1e-7 or less when they
    // carry binary32's digits or more and lie within some of the polygon's sizes of the origin).
    static constexpr double kTolerance = 1e-5;
    std::uint64_t polygons = 0;   // polygons of more than 3 corners
    std::uint64_t nonPlanar = 0;  // of those, not planar
    double worst = 0;             // the largest corner distance from the plane, relative to the polygon's size

    // A polygon split by a reader into the fan of `cornerCount` − 2 consecutive triangles from
    // `firstTriangle` (each sharing its first corner with the first triangle), its corners
    // measured where the file put them (`rounding`'s fileCoordinates of `positions`), not where
    // binary32 moved them: far from the origin that move alone would bend a planar polygon. A
    // reader calls it before frameScene, while `rounding` still holds the residuals.
    void addFan(const std::vector<glm::vec3>& positions, const PositionRounding& rounding,
                const std::vector<glm::uvec3>& triangles, std::size_t firstTriangle, std::size_t cornerCount);
    // "" when every polygon is planar; else one sentence naming `mesh`, the count and the worst.
    std::string warning(const std::string& mesh) const;
};

// Bounding boxes of runs of consecutive triangles (meshes keep neighbours close), so that a
// question about the whole scene seen from a camera (camera_sources.h's sceneNearFar) can skip
// what cannot change its answer. Made once per scene (indexTriangleChunks).
struct TriangleChunks {
    static constexpr std::size_t kSize = 1024;  // triangles per chunk; the last may hold fewer
    std::vector<glm::vec3> lo, hi;              // per chunk, in the scene's frame
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
    // World = origin + position: zero but for a mesh whose file coordinates binary32 would have
    // moved materially (PositionRounding), which frameScene holds about the centre of its box.
    // Cameras stay in the world; whatever meets them with positions goes through worldPosition()
    // or a camera in the scene's frame (CameraInSceneFrame).
    glm::dvec3 origin{0.0};
    std::vector<glm::vec3> positions;     // the scene's frame: world − origin
    std::vector<glm::uvec3> triangles;    // indices into positions; the index is the primitive id
    CameraSpec defaultCamera;             // used when the user gives no camera file
    PolygonPlanarity planarity;           // of the file's polygons (mesh files; none built in)
    PositionRounding rounding;            // of the file's coordinates to binary32 (mesh files, arrays)
    std::vector<ImportedCamera> cameras;  // the file's camera nodes (glTF), in file order; the
                                          // first is the default camera (camera_sources.h)
    std::shared_ptr<const TriangleChunks> chunks;  // made by indexTriangleChunks; none: made on use

    std::size_t triangleCount() const { return triangles.size(); }
    bool heldAboutOrigin() const { return origin != glm::dvec3(0.0); }
    // A point of the scene's frame in the world, in binary64 (the same bits when origin is zero:
    // 0 + x would turn −0 into +0).
    glm::dvec3 worldFromScene(const glm::dvec3& pScene) const { return heldAboutOrigin() ? origin + pScene : pScene; }
    // Vertex v in the world.
    glm::dvec3 worldPosition(std::size_t v) const { return worldFromScene(glm::dvec3(positions[v])); }
    // Triangle t's plane in the world: `normal` = cross(b − a, c − a) of its positions (their
    // differences exact in binary64, wherever the scene is held) through `point`, its first
    // corner in the world (worldPosition).
    struct Plane {
        glm::dvec3 normal, point;
    };
    Plane worldPlane(std::size_t t) const;
    glm::dvec3 boundsMin() const;  // in the scene's frame (add origin for the world's)
    glm::dvec3 boundsMax() const;
    // Appends another soup (indices are offset).
    void append(const std::vector<glm::vec3>& morePositions, const std::vector<glm::uvec3>& moreTriangles);
};

// A world camera as the routes draw a scene with: moved by −scene.origin (cameraAboutOrigin), so
// that eye and vertices meet in the scene's frame; the camera itself when the origin is zero.
class CameraInSceneFrame {
public:
    CameraInSceneFrame(const Scene& scene, const Camera& camera)
        : given_(camera), moved_(scene.heldAboutOrigin() ? std::optional<Camera>(cameraAboutOrigin(camera, scene.origin))
                                                         : std::nullopt)
    {
    }
    const Camera& get() const { return moved_ ? *moved_ : given_; }

private:
    const Camera& given_;
    std::optional<Camera> moved_;
};

// Throws Error for a scene with no triangles or an index out of range.
void validateScene(const Scene& scene);

// The scene's TriangleChunks (indices must be valid). loadScene and frameScene make them.
std::shared_ptr<const TriangleChunks> triangleChunksOf(const Scene& scene);

// Makes a triangle soup a scene to check: validates it (validateScene), sets rounding.size, holds
// it about a local origin when binary32 at the file's coordinates moved it materially (its
// vertices then rounded again from rounding.residual, about the centre of its box), refuses it
// when no triangle has a nonzero area (nothing to draw), and gives it a default camera that frames its
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
