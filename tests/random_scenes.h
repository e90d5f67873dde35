#pragma once
// For the property tests that no correct chain is called inconsistent (test_end_to_end.cpp: check;
// test_verify.cpp: verify): random scenes no mesh file holds and random cameras of every kind.
#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/error.h"
#include "zcheck/scene.h"

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace zcheck::testing {

// A random scene of one kind for the property tests: 1 to 300 triangles in front of an eye at
// `offset` looking down −z, as binary32 positions (so far from the origin they lie on a coarse
// grid, as a georeferenced mesh's do).
inline Scene randomSoup(std::mt19937_64& random, int kind, const glm::dvec3& offset)
{
    auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
    auto point = [&](double spread, double zLo, double zHi) { return glm::dvec3(uniform(-spread, spread), uniform(-spread, spread), uniform(zLo, zHi)); };
    std::vector<glm::dvec3> corners;
    const int count = int(uniform(1, 300));
    for (int k = 0; k < count; ++k) {
        switch (kind) {
        case 0: {  // large triangles through one another
            const glm::dvec3 centre = point(1, -6, -2);
            const double size = uniform(0.5, 3);
            for (int v = 0; v < 3; ++v) corners.push_back(centre + point(size, -size, size));
            break;
        }
        case 1: {  // overlapping triangles in a few shared planes, two of them a hair apart
            const double planes[] = {-2.0, -3.0, -3.0000001, -4.5};
            const double z = planes[int(uniform(0, 4)) % 4];
            for (int v = 0; v < 3; ++v) corners.push_back(point(2, z, z));
            break;
        }
        case 2: {  // slivers nearly containing their line of sight
            const glm::dvec3 c = point(1, -6, -1), d = glm::normalize(c);
            const glm::dvec3 side = glm::normalize(glm::cross(d, glm::dvec3(0, 1, 0)));
            const double length = uniform(0.05, 1);
            corners.insert(corners.end(), {c, c + d * length + side * uniform(-1e-4, 1e-4), c + side * length * uniform(0.5, 2)});
            break;
        }
        case 3:  // crossing the near and the far plane, and the eye's plane
            for (int v = 0; v < 3; ++v) corners.push_back(point(3, -30, 0.5));
            break;
        case 4: {  // a fan: shared vertices, every pixel inside it covered once
            const glm::dvec3 c = point(1, -5, -2);
            const double radius = uniform(0.1, 2), start = uniform(0, 6.3);
            const int spokes = int(uniform(3, 40));
            auto rim = [&](int i) {
                const double a = start + 2 * 3.14159265358979 * i / spokes;
                return c + glm::dvec3(radius * std::cos(a), radius * std::sin(a), 0.3 * std::sin(3.0 * i));
            };
            for (int i = 0; i < spokes; ++i) corners.insert(corners.end(), {c, rim(i), rim(i + 1)});
            k += spokes - 1;
            break;
        }
        default: {  // sub-pixel triangles
            const glm::dvec3 centre = point(1, -5, -1);
            const double size = std::pow(10.0, uniform(-5, -2));
            for (int v = 0; v < 3; ++v) corners.push_back(centre + point(size, -size, size));
        }
        }
    }
    Scene scene;
    scene.name = "random soup";
    for (const glm::dvec3& corner : corners) scene.positions.push_back(glm::vec3(corner + offset));
    for (std::uint32_t i = 0; i + 2 < corners.size(); i += 3) scene.triangles.push_back({i, i + 1, i + 2});
    return scene;
}

// A random camera at `eye` looking down −z (nearly): any convention, depth format and direction,
// projection and depth range; every sixth a lens model.
inline std::string randomCameraJson(std::mt19937_64& random, const glm::dvec3& eye)
{
    auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
    auto pick = [&](std::initializer_list<const char*> names) { return names.begin()[int(uniform(0, double(names.size()))) % names.size()]; };
    const int width = int(uniform(1, 200)), height = int(uniform(1, 150));
    const double near = std::pow(10.0, uniform(-3, 0));
    const bool infiniteFar = uniform(0, 1) < 0.15;
    const double far = near * std::pow(10.0, uniform(0.3, 5));
    const std::string type = pick({"perspective", "perspective", "frustum", "orthographic", "oblique", "pinhole", "lens"});
    std::ostringstream projection;
    projection.precision(17);
    projection << R"({"type": ")" << type << R"(", )";
    if (type == "perspective") {
        projection << R"("fovy_deg": )" << uniform(10, 120);
    } else if (type == "frustum") {
        const double l = uniform(-1, 0.2) * near, b = uniform(-1, 0.2) * near;
        projection << R"("left": )" << l << R"(, "right": )" << l + uniform(0.2, 2) * near << R"(, "bottom": )" << b
                   << R"(, "top": )" << b + uniform(0.2, 2) * near;
    } else if (type == "orthographic" || type == "oblique") {
        const double half = uniform(0.5, 5), l = -half * uniform(0.5, 1.5), b = -half * uniform(0.5, 1.5);
        projection << R"("left": )" << l << R"(, "right": )" << l + 2 * half << R"(, "bottom": )" << b << R"(, "top": )"
                   << b + 2 * half;
        if (type == "oblique") projection << R"(, "angle_deg": )" << uniform(0, 90) << R"(, "foreshortening": )" << uniform(0, 1);
    } else if (type == "pinhole") {
        const double fx = uniform(20, 400);
        projection << R"("fx": )" << fx << R"(, "fy": )" << fx * uniform(0.8, 1.25) << R"(, "cx": )" << uniform(-0.5, width)
                   << R"(, "cy": )" << uniform(-0.5, height);
    } else {
        projection << R"("focal_mm": )" << uniform(10, 100) << R"(, "sensor_width_mm": 36)";
    }
    const bool parallel = type == "orthographic" || type == "oblique";
    projection << R"(, "near": )" << near << R"(, "far": )";
    if (infiniteFar && !parallel) projection << R"("inf")";
    else projection << far;
    projection << "}";
    std::ostringstream text;
    text.precision(17);
    text << R"({"convention": ")" << pick({"opengl", "direct3d", "vulkan", "metal", "opencv"}) << R"(", "image": {"width": )"
         << width << R"(, "height": )" << height << R"(}, "projection": )" << projection.str() << R"(, "view": {"eye": [)"
         << eye.x << ", " << eye.y << ", " << eye.z << R"(], "target": [)" << eye.x + uniform(-0.3, 0.3) << ", "
         << eye.y + uniform(-0.3, 0.3) << ", " << eye.z - 1 << R"(], "up": [0, 1, 0]})";
    if (type == "pinhole" && uniform(0, 1) < 0.5) {
        const std::string model = pick({"opencv", "opencv_fisheye", "division"});
        text << R"(, "lens": {"model": ")" << model << R"(", )";
        if (model == "opencv")
            text << R"("k1": )" << uniform(-0.3, 0.3) << R"(, "k2": )" << uniform(-0.1, 0.1) << R"(, "p1": )"
                 << uniform(-0.01, 0.01) << R"(, "p2": )" << uniform(-0.01, 0.01) << "}";
        else if (model == "opencv_fisheye")
            text << R"("k1": )" << uniform(-0.05, 0.05) << R"(, "k2": )" << uniform(-0.01, 0.01) << "}";
        else
            text << R"("k": )" << uniform(-0.3, 0.3) << "}";
    } else {
        text << R"(, "depth": {"format": ")" << pick({"unorm16", "unorm24", "float32"}) << R"(", "reversed": )"
             << (uniform(0, 1) < 0.5 ? "true" : "false");
        if (uniform(0, 1) < 0.2) {
            const double lo = uniform(0, 0.5);
            text << R"(, "range": [)" << lo << ", " << lo + uniform(0.1, 0.5) << "]";
        }
        text << "}";
    }
    text << "}";
    return text.str();
}

// Case k of a property run: a scene of kind k % 6 and a camera looking at it, both as far from the
// world origin as one of 0 to 5·10⁶ m per axis; no camera where its file is refused (a lens that
// folds inside its image) or every triangle collapsed on binary32's grid.
struct RandomCase {
    Scene scene;
    std::string cameraJson;
    std::optional<Camera> camera;
};
inline RandomCase randomCase(std::mt19937_64& random, int k)
{
    constexpr double kOffsets[] = {0, 0, 1e3, 1e5, -3e4, 1e6, 5e6, -4e6};
    const glm::dvec3 offset(kOffsets[random() % 8], kOffsets[random() % 8], kOffsets[random() % 8]);
    RandomCase c{randomSoup(random, k % 6, offset), randomCameraJson(random, offset), std::nullopt};
    bool drawable = false;
    for (const glm::uvec3& t : c.scene.triangles)
        drawable |= glm::length(glm::cross(glm::dvec3(c.scene.positions[t[1]]) - glm::dvec3(c.scene.positions[t[0]]),
                                           glm::dvec3(c.scene.positions[t[2]]) - glm::dvec3(c.scene.positions[t[0]]))) > 0;
    try {
        if (drawable) c.camera.emplace(cameraSpecFromJsonText(c.cameraJson, "random camera"));
    } catch (const Error&) {
    }
    return c;
}

}  // namespace zcheck::testing
