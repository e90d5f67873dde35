// Cameras for a scene (camera_sources.h): glTF camera nodes, near and far from the scene, and
// round trips through every format's writer (camera_formats.h). Each format's own tests are
// beside its reader (cameras/src/format_NAME_test.cpp).
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/camera_sources.h"
#include "zcheck/error.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>

using namespace zcheck;
using namespace zcheck::testing;
namespace fs = std::filesystem;

TEST_CASE("glTF camera nodes: yfov and aspectRatio, the node's transform without its scale, zfar absent = infinite",
          "[import][gltf]")
{
    const fs::path dir = scratch("gltf");
    // A camera 5 units up +z looking down −z (its node's identity rotation), scaled by 2.
    writeText(dir / "cameras.gltf", R"({"asset": {"version": "2.0"},
        "cameras": [{"type": "perspective", "name": "main", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1}},
                    {"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 1, "znear": 0.5, "zfar": 50}}],
        "nodes": [{"name": "rig", "children": [1, 2], "translation": [0, 0, 5]},
                  {"name": "persp", "camera": 0, "scale": [2, 2, 2]},
                  {"camera": 1, "translation": [1, 0, 0]}],
        "scenes": [{"nodes": [0]}], "scene": 0})");
    REQUIRE(detectCameraFormat((dir / "cameras.gltf").string()).name == "gltf");
    const CameraSet set = readCameraSet((dir / "cameras.gltf").string());
    REQUIRE(set.cameras.size() == 2);
    REQUIRE(set.find("main") == 0);
    REQUIRE(set.find("persp") == 0);
    REQUIRE(set.find("nodes[2]") == 1);
    const ImportedCamera& persp = set.cameras[0];
    REQUIRE(persp.hasClipPlanes);
    REQUIRE_FALSE(persp.hasImageSize);
    REQUIRE(std::isinf(persp.spec.projection.far));
    CameraSpec spec = persp.spec;
    spec.width = 300, spec.height = 200;
    spec.projection = persp.projectionForSize(300, 200);
    // A point at (1, 0.5, 0): 5 in front. y_ndc = 0.5/(5·tan(0.35)), x_ndc = 1/(5·tan(0.35)·1.5).
    const glm::dvec2 p = imagePointOf(spec, {1, 0.5, 0});
    REQUIRE(p.x == Approx(150 + 150 * 1 / (5 * std::tan(0.35) * 1.5)));
    REQUIRE(p.y == Approx(100 - 100 * 0.5 / (5 * std::tan(0.35))));
    const ImportedCamera& ortho = set.cameras[1];
    CameraSpec o = ortho.spec;
    o.width = 400, o.height = 200;
    requireNear(imagePointOf(o, {2, 0.5, 0}), glm::dvec2(200 + 200 * 1.0 / 2, 100 - 100 * 0.5));
}

TEST_CASE("near and far hug the scene as the camera sees it", "[import][clip]")
{
    // Two squares across the view: at eye-z 4 (0.5 wide) and at eye-z 9; a third far behind the
    // camera and one off to the side do not count.
    Scene scene;
    scene.name = "squares";
    auto square = [&](double z, double half, double x = 0) {
        const auto base = std::uint32_t(scene.positions.size());
        for (auto [dx, dy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
            scene.positions.emplace_back(float(x + dx * half), float(dy * half), float(z));
        scene.triangles.emplace_back(base, base + 1, base + 2);
        scene.triangles.emplace_back(base, base + 2, base + 3);
    };
    square(-4, 0.5), square(-9, 20), square(30, 1), square(-2, 0.5, 50);
    CameraSpec spec;
    spec.projection = Projection::perspective(60, kPlaceholderNear, kPlaceholderFar);
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const SceneNearFar planes = sceneNearFar(scene, spec);
    REQUIRE(planes.near == Approx(4 * 0.99));
    REQUIRE(planes.far == Approx(9 * 1.01));

    ImportedCamera imported;
    imported.name = "test";
    imported.spec = spec;
    const CameraSpec completed = completeCamera(imported, &scene, {});
    REQUIRE(completed.projection.near == Approx(3.96));
    REQUIRE_THAT(completed.notes.back(), Catch::Contains("near and far are not in the camera file"));
    const CameraSpec given = completeCamera(imported, &scene, {1.0, 50.0, std::nullopt, std::nullopt, std::nullopt});
    REQUIRE(given.projection.near == 1.0);
    REQUIRE(given.projection.far == 50.0);

    spec.view = View::lookAt({0, 0, 40}, {0, 0, 41}, {0, 1, 0});  // beyond them all, looking away
    REQUIRE_THROWS_WITH(sceneNearFar(scene, spec), Catch::Contains("sees none of scene 'squares'"));
}

TEST_CASE("a camera written as COLMAP, nerfstudio, OpenCV or zcheck reads back as the same camera", "[import][roundtrip]")
{
    CameraSpec spec;
    spec.convention = Convention::preset("vulkan");
    spec.width = 333, spec.height = 257;
    spec.projection.type = ProjectionType::Frustum;
    spec.projection.left = -0.03, spec.projection.right = 0.05, spec.projection.bottom = -0.02, spec.projection.top = 0.035;
    spec.projection.near = 0.1, spec.projection.far = 40;
    spec.view = View::lookAt({1.5, 2, 4}, {0.1, 0.2, -0.5}, {0.1, 1, 0});
    const Camera camera(spec);
    const fs::path dir = scratch("roundtrip");
    int written = 0;
    for (const CameraFormat* format : cameraFormats()) {  // every format with a writer, from the table
        if (!format->write) continue;
        ++written;
        INFO(format->name);
        const fs::path out = dir / format->name;
        fs::create_directories(out);
        const auto files = cameraInFormat(camera, *format, "frame_7.png");
        for (const CameraFileText& f : files) writeText(out / f.fileName, f.text);
        const std::string path = format->writesFolder ? out.string() : (out / files.front().fileName).string();
        REQUIRE(&detectCameraFormat(path) == format);
        const CameraSet set = readCameraSet(path, format);
        CameraSpec back = set.cameras.at(0).spec;
        back.projection.near = 0.1, back.projection.far = 40;
        REQUIRE(back.width == 333);
        for (const glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(0.5, -0.3, 1), glm::dvec3(-1, 1, -2)}) {
            const glm::dvec2 expected = imagePointOf(spec, p), got = imagePointOf(back, p);
            REQUIRE(got.x == Approx(expected.x).margin(1e-9));
            REQUIRE(got.y == Approx(expected.y).margin(1e-9));
        }
    }
    REQUIRE(written == 4);  // zcheck, colmap, nerfstudio, opencv
    spec.projection.type = ProjectionType::Orthographic;
    REQUIRE_THROWS_WITH(cameraInFormat(Camera(spec), cameraFormatNamed("colmap"), "x"), Catch::Contains("orthographic projection has no pinhole"));
}

namespace {

// The eye-z range of the scene's triangles clipped to a perspective camera's view, by brute force
// in eye space: every triangle, Sutherland–Hodgman against the four side planes through the eye
// and the near-window edges (left/right/top/bottom at eye-z = near) and the eye plane.
std::pair<double, double> bruteForceEyeZRange(const Scene& scene, const Camera& camera)
{
    const double n = camera.nearDistance();
    // Planes through the eye, ≥ 0 inside, in (image right, image up, forward) coordinates.
    auto inside = [&](const glm::dvec3& q, int plane) {
        switch (plane) {
        case 0: return q.x * n - camera.left() * q.z;
        case 1: return camera.right() * q.z - q.x * n;
        case 2: return q.y * n - camera.bottom() * q.z;
        case 3: return camera.top() * q.z - q.y * n;
        default: return q.z;
        }
    };
    const Convention& c = camera.convention();
    double lo = INFINITY, hi = -INFINITY;
    for (const glm::uvec3& t : scene.triangles) {
        std::vector<glm::dvec3> polygon;
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 e(camera.eyeFromWorld * glm::dvec4(glm::dvec3(scene.positions[t[k]]), 1.0));
            polygon.push_back({e.x, c.eyeUpY * e.y, c.eyeForwardZ * e.z});
        }
        for (int plane = 0; plane < 5 && !polygon.empty(); ++plane) {
            std::vector<glm::dvec3> next;
            for (std::size_t i = 0; i < polygon.size(); ++i) {
                const glm::dvec3 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
                const double fa = inside(a, plane), fb = inside(b, plane);
                if (fa >= 0) next.push_back(a);
                if ((fa >= 0) != (fb >= 0)) next.push_back(a + (fa / (fa - fb)) * (b - a));
            }
            polygon = next;
        }
        for (const glm::dvec3& q : polygon) lo = std::min(lo, q.z), hi = std::max(hi, q.z);
    }
    return {lo, hi};
}

}  // namespace

TEST_CASE("near and far from the scene's triangle chunks equal a clip of every triangle", "[import][clip]")
{
    // A terrain seen from random places around and inside its bounds, in several conventions:
    // the chunk pruning must never change the answer.
    const Scene scene = loadScene("builtin:terrain?n=90");
    REQUIRE(scene.chunks);
    std::mt19937 random(17);
    std::uniform_real_distribution<double> along(-80, 80), up(2, 60);
    int seen = 0;
    for (int i = 0; i < 40; ++i) {
        CameraSpec spec;
        spec.convention = Convention::preset(Convention::presetNames()[std::size_t(i) % Convention::presetNames().size()]);
        spec.width = 160, spec.height = 120;
        spec.projection = Projection::perspective(30 + i, kPlaceholderNear, kPlaceholderFar);
        spec.view = View::lookAt({along(random), up(random), along(random)}, {along(random) / 4, 0, along(random) / 4}, {0, 1, 0});
        const auto [lo, hi] = bruteForceEyeZRange(scene, Camera(spec));
        if (!(hi > 0)) {
            REQUIRE_THROWS_WITH(sceneNearFar(scene, spec), Catch::Contains("sees none of scene"));
            continue;
        }
        ++seen;
        const SceneNearFar planes = sceneNearFar(scene, spec);
        INFO("camera " << i);
        REQUIRE(planes.far == Approx(hi * 1.01).epsilon(1e-9));
        REQUIRE(planes.near == Approx(std::max(lo * 0.99, planes.far * 1e-7)).epsilon(1e-9));
    }
    REQUIRE(seen > 30);
}
