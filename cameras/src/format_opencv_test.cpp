// OpenCV FileStorage and ROS CameraInfo (format_opencv.cpp): the top-left pixel centre at 0, a
// world-to-camera pose, stereo and per-view files, the raw and rectified cameras.
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

TEST_CASE("OpenCV FileStorage YAML and XML put the top-left pixel centre at 0 and hold a world-to-camera pose", "[import][opencv]")
{
    const fs::path dir = scratch("opencv");
    // K with cx, cy in OpenCV coordinates: 329.5, 249.5 are the COLMAP test's 330, 250.
    writeText(dir / "calib.yml", "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                                 "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                                 "   data: [ 500., 0., 329.5, 0.,\n       400., 249.5, 0., 0., 1. ]\n"
                                 "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
                                 "   data: [ 0., 0., 0., 0., 0. ]\n"
                                 "R: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 0, 0, 1, 0, 1, 0, -1, 0, 0 ]\n"
                                 "T: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ 0.1, -0.2, 3. ]\n");
    REQUIRE(detectCameraFormat((dir / "calib.yml").string()).name == "opencv");
    const CameraSet yaml = readCameraSet((dir / "calib.yml").string(), &cameraFormatNamed("opencv"));
    requireProjectsKnownPoint(yaml.cameras.at(yaml.find("")).spec, 0.5);

    writeText(dir / "calib.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                 "<image_height>480</image_height>\n<camera_matrix type_id=\"opencv-matrix\">\n"
                                 "  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n  <data>\n"
                                 "    500. 0. 329.5 0. 400. 249.5 0. 0. 1.</data></camera_matrix>\n"
                                 "<rvec type_id=\"opencv-matrix\"><rows>3</rows><cols>1</cols><dt>d</dt><data>0 1.5707963267948966 0</data></rvec>\n"
                                 "<tvec type_id=\"opencv-matrix\"><rows>3</rows><cols>1</cols><dt>d</dt><data>0.1 -0.2 3</data></tvec>\n"
                                 "</opencv_storage>\n");
    REQUIRE(detectCameraFormat((dir / "calib.xml").string()).name == "opencv");
    const CameraSet xml = readCameraSet((dir / "calib.xml").string(), &cameraFormatNamed("opencv"));
    requireProjectsKnownPoint(xml.cameras.at(0).spec, 0.5);  // rvec: 90° about y, as the quaternion

    // A repeated element would let one value hide another: refused, as YAML's repeated keys are.
    writeText(dir / "twice.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                 "<image_width>320</image_width>\n</opencv_storage>\n");
    REQUIRE_THROWS_WITH(readCameraSet((dir / "twice.xml").string(), &cameraFormatNamed("opencv")),
                        Catch::Contains("line 4: the element <image_width> is repeated inside <opencv_storage>"));

    // Without a pose the camera's own frame is the world, and the report says so.
    writeText(dir / "intrinsics.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\n"
                                      "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                                      "   data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]\n");
    const CameraSet bare = readCameraSet((dir / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    requireNear(imagePointOf(bare.cameras[0].spec, {0, 0, 2}), glm::dvec2(320, 240));
    REQUIRE_THAT(bare.cameras[0].spec.notes.at(0), Catch::Contains("has no pose"));
}

TEST_CASE("OpenCV's stereo files: intrinsics.yml#left and #right, the right posed by R and T of extrinsics.yml beside it",
          "[import][opencv]")
{
    const fs::path dir = scratch("opencv_stereo");
    auto mat = [](const std::string& name, int rows, int cols, const std::string& data) {
        return name + ": !!opencv-matrix\n   rows: " + std::to_string(rows) + "\n   cols: " + std::to_string(cols) +
               "\n   dt: d\n   data: [ " + data + " ]\n";
    };
    // As stereo_calib.cpp writes them: no image size; D1 and D2 of 8 (here zero).
    writeText(dir / "intrinsics.yml", "%YAML:1.0\n" + mat("M1", 3, 3, "500, 0, 319.5, 0, 500, 239.5, 0, 0, 1") +
                                          mat("D1", 1, 8, "0, 0, 0, 0, 0, 0, 0, 0") +
                                          mat("M2", 3, 3, "510, 0, 330, 0, 505, 241, 0, 0, 1") +
                                          mat("D2", 1, 8, "0, 0, 0, 0, 0, 0, 0, 0"));
    // R: 5° about y; T: the right camera 0.12 to the right (x_right = R·x_left + T).
    const double a = glm::radians(5.0), c = std::cos(a), s = std::sin(a);
    writeText(dir / "extrinsics.yml", "%YAML:1.0\n" +
                                          mat("R", 3, 3, std::to_string(c) + ", 0, " + std::to_string(s) + ", 0, 1, 0, " +
                                                             std::to_string(-s) + ", 0, " + std::to_string(c)) +
                                          mat("T", 3, 1, "-0.12, 0, 0") + mat("R1", 3, 3, "1, 0, 0, 0, 1, 0, 0, 0, 1") +
                                          mat("P1", 3, 4, "500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0") +
                                          mat("Q", 4, 4, "1, 0, 0, -320, 0, 1, 0, -240, 0, 0, 0, 500, 0, 0, 8.3, 0"));
    const CameraSet set = readCameraSet((dir / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    const glm::dvec3 p(0.2, -0.1, 2.0);  // in the left camera's frame, the world
    const ImportedCamera& left = set.cameras.at(set.find("left"));
    REQUIRE(set.find("M1") == set.find("left"));
    REQUIRE_FALSE(left.hasImageSize);  // the depth map's size is taken (completeCamera)
    requireNear(imagePointOf(left.spec, p), glm::dvec2(500 * 0.1 + 319.5 + 0.5, 500 * -0.05 + 239.5 + 0.5));
    const ImportedCamera& right = set.cameras.at(set.find("right"));
    REQUIRE(set.find("M2") == set.find("right"));
    REQUIRE(right.refusal.empty());
    const glm::dvec3 q(c * p.x + s * p.z - 0.12, p.y, -s * p.x + c * p.z);  // R·p + T, by hand
    requireNear(imagePointOf(right.spec, p), glm::dvec2(510 * q.x / q.z + 330 + 0.5, 505 * q.y / q.z + 241 + 0.5));
    REQUIRE_THAT(right.spec.notes.at(0), Catch::Contains("extrinsics.yml") && Catch::Contains("R and T"));
    // A file without a #FRAME names neither: the reference must say which.
    REQUIRE_THROWS(set.find(""));
    // The extrinsics alone are no camera: refused, naming the intrinsics file's cameras.
    REQUIRE_THROWS_WITH(readCameraSet((dir / "extrinsics.yml").string(), &cameraFormatNamed("opencv")),
                        Catch::Contains("no camera matrix") && Catch::Contains("#left or FILE#right"));
    // Without extrinsics.yml beside it, the right camera has no pose: refused when asked for.
    const fs::path alone = scratch("opencv_stereo_alone");
    fs::copy_file(dir / "intrinsics.yml", alone / "intrinsics.yml");
    const CameraSet unposed = readCameraSet((alone / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    REQUIRE_THROWS_WITH(unposed.find("right"), Catch::Contains("has no pose"));
    REQUIRE_NOTHROW(unposed.find("left"));
}

TEST_CASE("OpenCV's calibration.cpp file: each view's extrinsic_parameters a camera (#view_N), the file's own the default",
          "[import][opencv]")
{
    const fs::path dir = scratch("opencv_views");
    writeText(dir / "out_camera_data.yml",
              "%YAML:1.0\n---\nnr_of_frames: 2\nimage_width: 640\nimage_height: 480\n"
              "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]\n"
              "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n"
              "extrinsic_parameters: !!opencv-matrix\n   rows: 2\n   cols: 6\n   dt: d\n"
              "   data: [ 0., 0., 0., 0., 0., 2., 0., 0.3, 0., 0.1, 0.2, 3. ]\n");
    const CameraSet set = readCameraSet((dir / "out_camera_data.yml").string(), &cameraFormatNamed("opencv"));
    REQUIRE(set.cameras.size() == 3);
    REQUIRE(set.find("") == 0);  // the file's own camera, no pose
    const glm::dvec3 p(0.1, 0.05, 1.0);
    // view_1: rvec (0, 0.3, 0) — 0.3 rad about y — and tvec (0.1, 0.2, 3): x = R·p + t by hand.
    const double c = std::cos(0.3), s = std::sin(0.3);
    const glm::dvec3 x(c * p.x + s * p.z + 0.1, p.y + 0.2, -s * p.x + c * p.z + 3);
    requireNear(imagePointOf(set.cameras.at(set.find("view_1")).spec, p),
                glm::dvec2(500 * x.x / x.z + 320, 500 * x.y / x.z + 240));
    const glm::dvec3 x0(p.x, p.y, p.z + 2);  // view_0: no rotation, tvec (0, 0, 2)
    requireNear(imagePointOf(set.cameras.at(set.find("view_0")).spec, p),
                glm::dvec2(500 * x0.x / x0.z + 320, 500 * x0.y / x0.z + 240));
}

TEST_CASE("ROS CameraInfo: the calibration file and the echoed message, raw (K) and rectified (P)", "[import][ros]")
{
    const fs::path dir = scratch("ros");
    writeText(dir / "camera.yaml", "image_width: 640\nimage_height: 480\ncamera_name: depth_optical\n"
                                   "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, 319.5, 0, 500, 239.5, 0, 0, 1]\n"
                                   "distortion_model: plumb_bob\n"
                                   "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n"
                                   "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                                   "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [500, 0, 319.5, -25, 0, 500, 239.5, 0, 0, 0, 1, 0]\n");
    REQUIRE(detectCameraFormat((dir / "camera.yaml").string()).name == "ros");
    const CameraSet set = readCameraSet((dir / "camera.yaml").string(), &cameraFormatNamed("ros"));
    const ImportedCamera& raw = set.cameras.at(set.find(""));
    REQUIRE(raw.name == "raw");
    requireNear(imagePointOf(raw.spec, {0, 0, 2}), glm::dvec2(320, 240));
    // The rectified camera of a stereo pair's second camera: u = (fx·X + cx·Z + Tx)/Z.
    const ImportedCamera& rectified = set.cameras.at(set.find("rectified"));
    REQUIRE(imagePointOf(rectified.spec, {0, 0, 2}).x == Approx((500 * 0 + 319.5 * 2 - 25) / 2 + 0.5));

    writeText(dir / "message.yaml", "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: camera_optical\n"
                                    "height: 480\nwidth: 640\ndistortion_model: plumb_bob\n"
                                    "d:\n- 0.1\n- 0.0\n- 0.0\n- 0.0\n- 0.0\n"
                                    "k:\n- 500.0\n- 0.0\n- 319.5\n- 0.0\n- 500.0\n- 239.5\n- 0.0\n- 0.0\n- 1.0\n"
                                    "r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
                                    "p: [480.0, 0.0, 320.0, 0.0, 0.0, 480.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0]\n"
                                    "binning_x: 0\nbinning_y: 0\nroi:\n  x_offset: 0\n  y_offset: 0\n  height: 0\n  width: 0\n"
                                    "  do_rectify: false\n---\n");
    const CameraSet message = readCameraSet((dir / "message.yaml").string(), &cameraFormatNamed("ros"));
    REQUIRE_THROWS_WITH(message.find(""), Catch::Contains("plumb_bob has lens distortion (k1 = 0.1") &&
                                              Catch::Contains("FILE#rectified"));
    requireNear(imagePointOf(message.cameras.at(message.find("rectified")).spec, {0, 0, 2}), glm::dvec2(320.5, 240.5));
}

