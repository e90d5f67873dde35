#pragma once
// What the camera-format tests share (tests/test_camera_import.cpp and cameras/src/format_*_test.cpp):
// a scratch folder, files written as given, a point's image position, and the known point every
// format's test projects (its hand computation in tests/test_pose.cpp). Test code only.
#include "zcheck/camera.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace zcheck::testing {

namespace fs = std::filesystem;

inline fs::path scratch(const std::string& name)
{
    const fs::path dir = fs::temp_directory_path() / ("zcheck_import_" + std::to_string(::getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

inline void writeText(const fs::path& path, const std::string& text)
{
    std::ofstream(path, std::ios::binary) << text;
}

inline glm::dvec2 imagePointOf(const CameraSpec& spec, const glm::dvec3& pWorld)
{
    const Camera camera(spec);
    const glm::dvec4 pClip = camera.clipFromWorld * glm::dvec4(pWorld, 1.0);
    const glm::dvec4 pWindow = camera.windowFromNdc * (pClip / pClip.w);
    return {pWindow.x, camera.imageYFromWindowY(pWindow.y)};
}

// The test's world point and a COLMAP-style pose: qvec 90° about y, tvec (0.1, −0.2, 3), so the
// point lands at p_cam = (0.3, 0.1, 3.4) (test_pose.cpp does the arithmetic).
inline const glm::dvec3 kPoint{-0.4, 0.3, 0.2};
inline const double kH = std::sqrt(0.5);

inline void requireNear(const glm::dvec2& actual, const glm::dvec2& expected)
{
    REQUIRE(actual.x == Approx(expected.x).margin(1e-9));
    REQUIRE(actual.y == Approx(expected.y).margin(1e-9));
}

inline void requireProjectsKnownPoint(const CameraSpec& spec, double pixelCenter)
{
    // K = (fx 500, fy 400, cx 330, cy 250) in coordinates whose top-left pixel centre is
    // `pixelCenter`: u = 500·0.3/3.4 + 330, v = 400·0.1/3.4 + 250 there, image x = u + 0.5 − pixelCenter.
    const glm::dvec2 pImage = imagePointOf(spec, kPoint);
    REQUIRE(pImage.x == Approx(500 * 0.3 / 3.4 + 330 + 0.5 - pixelCenter).epsilon(1e-12));
    REQUIRE(pImage.y == Approx(400 * 0.1 / 3.4 + 250 + 0.5 - pixelCenter).epsilon(1e-12));
}

}  // namespace zcheck::testing
