#include "zcheck/scene.h"

#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace zcheck {

Scene::Plane Scene::worldPlane(std::size_t t) const
{
    const glm::uvec3& corners = triangles[t];
    const glm::dvec3 a(positions[corners[0]]), b(positions[corners[1]]), c(positions[corners[2]]);
    return {glm::cross(b - a, c - a), worldPosition(corners[0])};
}

glm::dvec3 Scene::boundsMin() const
{
    glm::dvec3 lo(INFINITY);
    for (const auto& p : positions) lo = glm::min(lo, glm::dvec3(p));
    return lo;
}

glm::dvec3 Scene::boundsMax() const
{
    glm::dvec3 hi(-INFINITY);
    for (const auto& p : positions) hi = glm::max(hi, glm::dvec3(p));
    return hi;
}

void Scene::append(const std::vector<glm::vec3>& morePositions, const std::vector<glm::uvec3>& moreTriangles)
{
    const auto offset = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), morePositions.begin(), morePositions.end());
    for (const auto& t : moreTriangles) triangles.push_back(t + glm::uvec3(offset));
}

void PolygonPlanarity::addFan(const std::vector<glm::vec3>& positions, const PositionRounding& rounding,
                              const std::vector<glm::uvec3>& triangles, std::size_t firstTriangle,
                              std::size_t cornerCount)
{
    if (cornerCount <= 3) return;
    // The corners relative to the first (the distances below do not depend on where the polygon
    // lies, and UTM-sized coordinates would lose digits in Newell's sums).
    const glm::uvec3& first = triangles[firstTriangle];
    const glm::dvec3 firstCorner = rounding.fileCoordinates(positions, first[0]);
    std::vector<glm::dvec3> corners;
    for (int k = 0; k < 3; ++k) corners.push_back(rounding.fileCoordinates(positions, first[k]) - firstCorner);
    for (std::size_t t = firstTriangle + 1; t < firstTriangle + cornerCount - 2; ++t)
        corners.push_back(rounding.fileCoordinates(positions, triangles[t][2]) - firstCorner);
    ++polygons;
    // Newell's normal (robust for any simple polygon) through the centroid.
    glm::dvec3 normal(0.0), centroid(0.0);
    for (std::size_t k = 0; k < corners.size(); ++k) {
        const glm::dvec3& a = corners[k];
        const glm::dvec3& b = corners[(k + 1) % corners.size()];
        normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
        centroid += a;
    }
    centroid /= double(corners.size());
    double size = 0, off = 0;
    for (const glm::dvec3& a : corners)
        for (const glm::dvec3& b : corners) size = std::max(size, glm::length(a - b));
    if (!(glm::length(normal) > 0) || !(size > 0)) return;  // degenerate: no plane to be off
    normal = glm::normalize(normal);
    for (const glm::dvec3& a : corners) off = std::max(off, std::abs(glm::dot(normal, a - centroid)));
    const double relative = off / size;
    if (relative > kTolerance) {
        ++nonPlanar;
        worst = std::max(worst, relative);
    }
}

std::string PolygonPlanarity::warning(const std::string& mesh) const
{
    if (nonPlanar == 0) return "";
    char worstText[32];
    std::snprintf(worstText, sizeof worstText, "%.3g", 100 * worst);
    return "mesh '" + mesh + "': " + std::to_string(nonPlanar) + " of its " + std::to_string(polygons) +
           " polygons of more than 3 corners are not planar (corners up to " + worstText +
           " % of the polygon's size off its plane); renderers split such polygons along different diagonals, so "
           "their depth depends on the split: triangulate the mesh before rendering it";
}

glm::vec3 PositionRounding::store(const glm::dvec3& position)
{
    // (GCC 12's SLP vectoriser once made position − stored 0 in x and y here: roundedToBinary32.)
    const glm::dvec3 kept(roundedToBinary32(position.x), roundedToBinary32(position.y), roundedToBinary32(position.z));
    const glm::vec3 stored(kept);  // exact
    const glm::dvec3 left = position - kept;
    const double move = glm::length(left);
    if (move > largestMove) largestMove = move, movedVertex = position;
    if (move > 0 || !residual.empty()) {  // 12 bytes a vertex from the first that moved
        residual.resize(storedCount, glm::vec3(0.0f));  // the vertices before it moved nothing
        residual.push_back(glm::vec3(left));
    }
    ++storedCount;
    return stored;
}

namespace {

// What binary32 made of the coordinates: "held in binary32 (...), its vertices moved by up to 0.2344 (...)".
std::string roundingText(const PositionRounding& r)
{
    const float farthest = float(std::max({std::abs(r.movedVertex.x), std::abs(r.movedVertex.y), std::abs(r.movedVertex.z)}));
    const double step = double(std::nextafter(farthest, INFINITY)) - double(farthest);
    std::string text = "its vertices moved by up to " + fourSignificantDigits(r.largestMove) + " (";
    if (r.size > 0) text += fourSignificantDigits(100 * r.largestMove / r.size) + " % of its size; ";
    return text + "coordinates up to " + fourSignificantDigits(farthest) + ", where binary32 steps by " +
           fourSignificantDigits(step) + ")";
}

}  // namespace

std::string PositionRounding::warning(const std::string& mesh, const glm::dvec3& origin) const
{
    if (!material()) return "";
    if (origin == glm::dvec3(0.0))
        return "mesh '" + mesh + "': held in binary32 (as Embree and GPUs hold positions), " + roundingText(*this) +
               ": a map rendered from the file's own digits (in binary64, or around a local origin as large-world "
               "renderers do) shows another mesh than this check's truth, by up to that much; move the mesh and its "
               "cameras near the origin";
    char about[96];
    std::snprintf(about, sizeof about, "(%.10g, %.10g, %.10g)", origin.x, origin.y, origin.z);
    return "mesh '" + mesh + "': far from the origin, held about " + about +
           " as large-world renderers hold it; held at the file's own coordinates in binary32, as a renderer without "
           "a local origin holds them, " +
           roundingText(*this) + ": a map rendered so shows another mesh, off by up to that much";
}

Scene::Scene(const Scene& other)
    : name(other.name),
      origin(other.origin),
      defaultCamera(other.defaultCamera),
      planarity(other.planarity),
      rounding(other.rounding),
      cameras(other.cameras),
      chunks(other.chunks)
{
    reserveLarge(positions, other.positions.size());
    positions.assign(other.positions.begin(), other.positions.end());
    reserveLarge(triangles, other.triangles.size());
    triangles.assign(other.triangles.begin(), other.triangles.end());
}

Scene& Scene::operator=(const Scene& other)
{
    if (this != &other) *this = Scene(other);
    return *this;
}

namespace {

// The first i < n, in order, for which bad(i), or n if none: each thread a part of the range (a
// ten-million-triangle scene is checked by every renderer made for it).
template <class Bad>
std::size_t firstWhere(std::size_t n, Bad bad)
{
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 1 << 16), n,
        [&](const tbb::blocked_range<std::size_t>& r, std::size_t first) {
            for (std::size_t i = r.begin(); i != r.end() && i < first; ++i)
                if (bad(i)) return i;
            return first;
        },
        [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

// validateScene's rule for a vertex coordinate: finite and within ±Camera::kMaxWorldCoordinate
// (binary32 ray tracing needs headroom: Embree fails beyond ~1e19; the camera's bound too).
bool coordinateValid(float x) { return std::abs(x) <= Camera::kMaxWorldCoordinate; }  // false for NaN

}  // namespace

void validateScene(const Scene& scene)
{
    const std::string what = "scene '" + scene.name + "'";
    if (scene.triangles.empty()) throw Error(what + " has no triangles");
    if (scene.triangles.size() >= 0xFFFFFFFFu) throw Error(what + " has more triangles than 32-bit primitive ids can name");
    const std::size_t vertices = scene.positions.size();
    const std::size_t badVertex = firstWhere(vertices, [&](std::size_t i) {
        const glm::vec3& p = scene.positions[i];
        return !(coordinateValid(p.x) && coordinateValid(p.y) && coordinateValid(p.z));
    });
    if (badVertex < vertices)
        for (int axis = 0; axis < 3; ++axis) {
            const float x = scene.positions[badVertex][axis];
            if (coordinateValid(x)) continue;
            if (!std::isfinite(x)) throw Error(what + " has a vertex that is not finite");
            throw Error(what + " has a vertex coordinate " + formatNumber(x) +
                        ", beyond the ±1e15 that the ray tracer can represent");
        }
    const std::size_t badTriangle = firstWhere(scene.triangles.size(), [&](std::size_t i) {
        const glm::uvec3& t = scene.triangles[i];
        return t[0] >= vertices || t[1] >= vertices || t[2] >= vertices;
    });
    if (badTriangle < scene.triangles.size())
        for (int corner = 0; corner < 3; ++corner)
            if (const std::uint32_t index = scene.triangles[badTriangle][corner]; index >= vertices)
                throw Error(what + " has a vertex index out of range (" + std::to_string(index) + ")");
}

namespace {

// A local origin for a mesh spanning [lo, hi]: the centre of its box on a grid of the power of two
// at or below its size, so that it prints short and its coordinates about it stay under its size.
glm::dvec3 localOrigin(const glm::dvec3& lo, const glm::dvec3& hi)
{
    const double size = glm::length(hi - lo);
    const double grid = size > 0 ? std::exp2(std::floor(std::log2(size))) : 1.0;
    return glm::round((lo + hi) / 2.0 / grid) * grid;
}

// Holds `scene`, spanning [lo, hi], about a local origin: each vertex from the file's coordinates
// (its binary32 value and what binary32 left, rounding.residual), less the origin, rounded once.
void holdAboutLocalOrigin(Scene& scene, const glm::dvec3& lo, const glm::dvec3& hi)
{
    scene.origin = localOrigin(lo, hi);
    for (std::size_t v = 0; v < scene.positions.size(); ++v)
        scene.positions[v] = glm::vec3(scene.rounding.fileCoordinates(scene.positions, v) - scene.origin);
}

}  // namespace

Scene frameScene(Scene scene, const std::string& what)
{
    validateScene(scene);
    glm::dvec3 lo = scene.boundsMin(), hi = scene.boundsMax();
    scene.rounding.size = glm::length(hi - lo);
    // Whatever stored the vertices, once each, in order (a reader, Scene.from_arrays: a residual
    // for each vertex, once one moved): their file coordinates are at hand, and a material move is
    // undone about a local origin (once: a scene framed again keeps its origin).
    PositionRounding& rounding = scene.rounding;
    if (rounding.material() && !scene.heldAboutOrigin() && rounding.residual.size() == scene.positions.size()) {
        holdAboutLocalOrigin(scene, lo, hi);
        lo = scene.boundsMin(), hi = scene.boundsMax();
    }
    rounding.residual = {};
    rounding.storedCount = 0;
    const bool anyArea = std::any_of(scene.triangles.begin(), scene.triangles.end(), [&](const glm::uvec3& t) {
        const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
        return glm::length(glm::cross(b - a, c - a)) > 0;
    });
    if (!anyArea)
        throw Error(what + ": all its " + std::to_string(scene.triangles.size()) +
                    " triangles are degenerate (zero area): nothing to draw" +
                    (scene.rounding.material() && !scene.heldAboutOrigin()
                         ? ": held in binary32, " + roundingText(scene.rounding) + ": move the mesh near the origin"
                         : ""));
    const double radius = std::max(glm::length(hi - lo) / 2, 1e-6);
    scene.defaultCamera = framingCameraSpec(scene.worldFromScene((lo + hi) / 2.0), radius);  // in the world
    scene.chunks = triangleChunksOf(scene);
    return scene;
}

std::shared_ptr<const TriangleChunks> triangleChunksOf(const Scene& scene)
{
    auto chunks = std::make_shared<TriangleChunks>();
    const std::size_t count = (scene.triangles.size() + TriangleChunks::kSize - 1) / TriangleChunks::kSize;
    chunks->lo.assign(count, glm::vec3(INFINITY));
    chunks->hi.assign(count, glm::vec3(-INFINITY));
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t c) {  // chunk by chunk, each thread its own
        glm::vec3 &lo = chunks->lo[c], &hi = chunks->hi[c];
        const std::size_t end = std::min(scene.triangles.size(), (c + 1) * TriangleChunks::kSize);
        for (std::size_t t = c * TriangleChunks::kSize; t < end; ++t)
            for (int k = 0; k < 3; ++k) {
                const glm::vec3& p = scene.positions[scene.triangles[t][k]];
                lo = glm::min(lo, p), hi = glm::max(hi, p);
            }
    });
    return chunks;
}

}  // namespace zcheck
