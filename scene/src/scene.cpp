#include "zcheck/scene.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

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

void validateScene(const Scene& scene)
{
    if (scene.triangles.empty()) throw Error("scene '" + scene.name + "' has no triangles");
    if (scene.triangles.size() >= 0xFFFFFFFFu)
        throw Error("scene '" + scene.name + "' has more triangles than 32-bit primitive ids can name");
    for (const auto& p : scene.positions)
        for (int i = 0; i < 3; ++i) {
            if (!std::isfinite(p[i])) throw Error("scene '" + scene.name + "' has a vertex that is not finite");
            // binary32 ray tracing needs headroom (Embree fails beyond ~1e19); the same bound
            // as the camera's (Camera::kMaxWorldCoordinate).
            if (std::abs(p[i]) > Camera::kMaxWorldCoordinate)
                throw Error("scene '" + scene.name + "' has a vertex coordinate " + formatNumber(p[i]) +
                            ", beyond the ±1e15 that the ray tracer can represent");
        }
    for (const auto& t : scene.triangles)
        for (int i = 0; i < 3; ++i)
            if (t[i] >= scene.positions.size())
                throw Error("scene '" + scene.name + "' has a vertex index out of range (" + std::to_string(t[i]) + ")");
}

Scene frameScene(Scene scene, const std::string& what)
{
    validateScene(scene);
    const bool anyArea = std::any_of(scene.triangles.begin(), scene.triangles.end(), [&](const glm::uvec3& t) {
        const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
        return glm::length(glm::cross(b - a, c - a)) > 0;
    });
    if (!anyArea)
        throw Error(what + ": all its " + std::to_string(scene.triangles.size()) +
                    " triangles are degenerate (zero area): nothing to draw");
    const glm::dvec3 lo = scene.boundsMin(), hi = scene.boundsMax();
    const double radius = std::max(glm::length(hi - lo) / 2, 1e-6);
    scene.defaultCamera = framingCameraSpec((lo + hi) / 2.0, radius);
    return scene;
}

}  // namespace zcheck
