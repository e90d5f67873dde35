// nerfstudio and instant-ngp transforms.json (format_nerfstudio.cpp): camera-to-world in OpenGL
// axes with centres at +0.5, and a file without an image size.
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <string>

using namespace zcheck;
using namespace zcheck::testing;

TEST_CASE("a nerfstudio transforms.json is camera-to-world in OpenGL axes with centres at +0.5", "[import][nerfstudio]")
{
    // The pose of the COLMAP test, stored as nerfstudio stores it: world-from-camera, OpenGL axes.
    const glm::dmat3 r = rotationFromQuaternion(kH, 0, kH, 0, "q");
    glm::dmat4 camFromWorld(r);
    camFromWorld[3] = glm::dvec4(0.1, -0.2, 3, 1);
    const glm::dmat4 c2w = rigidInverse(camFromWorld) * eyeFromEye(Convention::preset("opencv"), Convention::preset("opengl"));
    std::string rows;
    for (int row = 0; row < 4; ++row) {
        rows += row ? ", [" : "[";
        for (int c = 0; c < 4; ++c) {
            char v[40];
            std::snprintf(v, sizeof v, "%.17g", c2w[c][row]);
            rows += (c ? ", " : "") + std::string(v);
        }
        rows += "]";
    }
    const fs::path dir = scratch("nerfstudio");
    writeText(dir / "transforms.json",
              R"({"camera_model": "OPENCV", "fl_x": 500, "fl_y": 400, "cx": 330, "cy": 250, "w": 640.0, "h": 480,
                  "k1": 0, "k2": 0, "p1": 0, "p2": 0,
                  "frames": [{"file_path": "images/frame_00001.png", "depth_file_path": "depths/frame_00001.png",
                              "transform_matrix": [)" + rows + R"(]},
                             {"file_path": "images/frame_00002.png", "k1": 0.02, "transform_matrix": [)" + rows + R"(]}]})");
    REQUIRE(detectCameraFormat((dir / "transforms.json").string()).name == "nerfstudio");
    const CameraSet set = readCameraSet((dir / "transforms.json").string(), &cameraFormatNamed("nerfstudio"));
    REQUIRE(set.cameras.size() == 2);
    REQUIRE(set.cameras[0].spec.convention.name == "opengl");
    REQUIRE(set.cameras[0].depthPath == (dir / "depths/frame_00001.png").string());
    requireProjectsKnownPoint(set.cameras[0].spec, 0.5);
    REQUIRE(set.find("frame_00001") == 0);
    REQUIRE_THAT(set.cameras[1].refusal, Catch::Contains("camera model OPENCV has lens distortion (k1 = 0.02"));
}

TEST_CASE("an instant-ngp transforms.json without an image size takes the depth map's", "[import][nerfstudio]")
{
    const fs::path dir = scratch("ngp");
    writeText(dir / "transforms.json",
              R"({"camera_angle_x": 0.6911112070083618,
                  "frames": [{"file_path": "./train/r_0", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})");
    const CameraSet set = readCameraSet((dir / "transforms.json").string(), &cameraFormatNamed("nerfstudio"));
    const ImportedCamera& camera = set.cameras.at(set.find("r_0"));
    REQUIRE_FALSE(camera.hasImageSize);
    REQUIRE(camera.projectionForSize);
    // NeRF-synthetic's lego: 800x800, fl = 0.5·800/tan(0.5·0.6911112) = 1111.111 px, cx = 400.
    const Projection p = camera.projectionForSize(800, 800);
    REQUIRE(p.fx == Approx(1111.1110311937682).epsilon(1e-9));
    REQUIRE(p.fy == Approx(p.fx));
    REQUIRE(p.cx == Approx(399.5));  // OpenCV's coordinates: 400 − 0.5
}

