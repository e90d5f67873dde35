// OpenCV FileStorage and ROS CameraInfo (format_opencv.cpp): the top-left pixel centre at 0, a
// world-to-camera pose, stereo and per-view files, the raw and rectified cameras, distortion and
// fisheyes as lens models (opencv, opencv_fisheye) and the writer.
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/error.h"
#include "zcheck/lens.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

using namespace zcheck;
using namespace zcheck::testing;

namespace {

// An !!opencv-matrix as FileStorage writes it in YAML.
std::string yamlMatrix(const std::string& name, int rows, int cols, const std::vector<double>& values)
{
    std::string data;
    for (double v : values) data += (data.empty() ? "" : ", ") + formatNumber(v);
    return name + ": !!opencv-matrix\n   rows: " + std::to_string(rows) + "\n   cols: " + std::to_string(cols) +
           "\n   dt: d\n   data: [ " + data + " ]\n";
}

// calib3d's projection of a point in the camera frame, as OpenCV's documentation writes it out
// ("Camera Calibration and 3D Reconstruction", detailed description; cv::projectPoints), by hand:
//   x' = x/z, y' = y/z, r² = x'² + y'²
//   x'' = x'·(1 + k1r² + k2r⁴ + k3r⁶)/(1 + k4r² + k5r⁴ + k6r⁶) + 2p1x'y' + p2(r² + 2x'²) + s1r² + s2r⁴
//   y'' = y'·(same) + p1(r² + 2y'²) + 2p2x'y' + s3r² + s4r⁴
//   s·(x''', y''', 1) = [[R33, 0, −R13], [0, R33, −R23], [0, 0, 1]]·R(τx, τy)·(x'', y'', 1), with
//   R(τx, τy) = [[cos τy, 0, −sin τy], [0, 1, 0], [sin τy, 0, cos τy]]·[[1, 0, 0], [0, cos τx, sin τx],
//   [0, −sin τx, cos τx]]; multiplied out by hand, the tilt's rows are (cos τx, 0, 0),
//   (−sin τx·sin τy, cos τy, 0) and (sin τy, −cos τy·sin τx, cos τy·cos τx)
//   u = fx·x''' + cx, v = fy·y''' + cy    (OpenCV's pixels: the top-left pixel's centre is (0, 0))
// `d` as the file gives it (4, 5, 8, 12 or 14 values; the rest 0).
glm::dvec2 calib3dPixel(const glm::dvec3& p, double fx, double fy, double cx, double cy, const std::vector<double>& d)
{
    double c[14] = {};
    for (std::size_t i = 0; i < d.size(); ++i) c[i] = d[i];
    const double k1 = c[0], k2 = c[1], p1 = c[2], p2 = c[3], k3 = c[4], k4 = c[5], k5 = c[6], k6 = c[7];
    const double s1 = c[8], s2 = c[9], s3 = c[10], s4 = c[11], tx = c[12], ty = c[13];
    const double x = p.x / p.z, y = p.y / p.z, r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
    const double radial = (1 + k1 * r2 + k2 * r4 + k3 * r6) / (1 + k4 * r2 + k5 * r4 + k6 * r6);
    const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x) + s1 * r2 + s2 * r4;
    const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y + s3 * r2 + s4 * r4;
    const double a = std::cos(tx) * xd;
    const double b = -std::sin(tx) * std::sin(ty) * xd + std::cos(ty) * yd;
    const double w = std::sin(ty) * xd - std::cos(ty) * std::sin(tx) * yd + std::cos(ty) * std::cos(tx);
    return {fx * a / w + cx, fy * b / w + cy};
}

// cv::fisheye's projection (OpenCV's fisheye documentation, by hand): a = x/z, b = y/z,
// r² = a² + b², θ = atan(r), θd = θ(1 + k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸), x' = (θd/r)·a, y' = (θd/r)·b,
// u = fx·x' + cx, v = fy·y' + cy (skew α = 0).
glm::dvec2 fisheyePixel(const glm::dvec3& p, double fx, double fy, double cx, double cy, const std::vector<double>& k)
{
    const double a = p.x / p.z, b = p.y / p.z, r = std::hypot(a, b), t = std::atan(r);
    const double t2 = t * t;
    const double td = t * (1 + k[0] * t2 + k[1] * t2 * t2 + k[2] * t2 * t2 * t2 + k[3] * t2 * t2 * t2 * t2);
    return {fx * td / r * a + cx, fy * td / r * b + cy};
}

// Where the imported camera's lens puts a direction of its frame, in OpenCV's pixels (zcheck's
// image coordinates less ½).
glm::dvec2 lensPixel(const CameraSpec& spec, const glm::dvec3& dCam)
{
    const Camera camera(spec);
    REQUIRE(camera.lens());
    const std::optional<glm::dvec2> pImage = camera.lens()->imageFromDirection(dCam);
    REQUIRE(pImage);
    return *pImage - glm::dvec2(0.5);
}

void requirePixel(const glm::dvec2& actual, const glm::dvec2& expected)
{
    REQUIRE(actual.x == Approx(expected.x).epsilon(1e-12).margin(1e-9));
    REQUIRE(actual.y == Approx(expected.y).epsilon(1e-12).margin(1e-9));
}

const std::vector<double> kCoefficients = {-0.12, 0.03,   1e-3, -5e-4, -0.004, 0.02, -0.01,
                                           0.003, 1e-3,  -2e-4, 5e-4,  1e-4,   0.01, -0.02};  // k1 … τy
const glm::dvec3 kDirections[] = {{0.3, -0.2, 1.0}, {-0.5, 0.35, 1.2}, {0.05, 0.02, 1.0}};

}  // namespace

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
    REQUIRE(yaml.cameras.at(0).spec.projection.type == ProjectionType::Pinhole);  // zero distortion: linear
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
    // plumb_bob with k1 = 0.1: the raw camera is lens opencv (ROS's D is OpenCV's 5).
    const CameraSpec& distorted = message.cameras.at(message.find("")).spec;
    REQUIRE(distorted.projection.lens == LensSpec{"opencv", {500, 500, 319.5, 239.5, 0.1, 0, 0, 0, 0}});
    requirePixel(lensPixel(distorted, {0.4, -0.3, 2}), calib3dPixel({0.4, -0.3, 2}, 500, 500, 319.5, 239.5, {0.1}));
    // The rectified camera (P) is a pinhole, as the rectified image is.
    const CameraSpec& rectifiedMessage = message.cameras.at(message.find("rectified")).spec;
    REQUIRE(rectifiedMessage.projection.type == ProjectionType::Pinhole);
    requireNear(imagePointOf(rectifiedMessage, {0, 0, 2}), glm::dvec2(320.5, 240.5));
}

TEST_CASE("OpenCV distortion_coefficients of 4, 5, 8, 12 and 14 values are lens opencv: points land where calib3d's formula puts them",
          "[import][opencv][lens]")
{
    const fs::path dir = scratch("opencv_lens");
    for (const std::size_t n : {4, 5, 8, 12, 14}) {
        INFO(n << " coefficients");
        const std::vector<double> d(kCoefficients.begin(), kCoefficients.begin() + std::ptrdiff_t(n));
        // YAML as calibration.cpp writes it (a column), XML as a row.
        writeText(dir / "calib.yml", "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n" +
                                         yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                         yamlMatrix("distortion_coefficients", int(n), 1, d));
        std::string row;
        for (double v : d) row += formatNumber(v) + " ";
        writeText(dir / "calib.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                     "<image_height>480</image_height>\n<camera_matrix type_id=\"opencv-matrix\"><rows>3</rows>"
                                     "<cols>3</cols><dt>d</dt><data>500. 0. 319.5 0. 480. 239.5 0. 0. 1.</data></camera_matrix>\n"
                                     "<distortion_coefficients type_id=\"opencv-matrix\"><rows>1</rows><cols>" +
                                         std::to_string(n) + "</cols><dt>d</dt><data>" + row +
                                         "</data></distortion_coefficients>\n</opencv_storage>\n");
        for (const char* file : {"calib.yml", "calib.xml"}) {
            INFO(file);
            const CameraSet set = readCameraSet((dir / file).string(), &cameraFormatNamed("opencv"));
            const CameraSpec& spec = set.cameras.at(0).spec;
            REQUIRE(spec.projection.type == ProjectionType::NonLinear);
            std::vector<double> params = {500, 480, 319.5, 239.5};  // cx, cy: OpenCV's pixels, as the lens's
            params.insert(params.end(), d.begin(), d.end());
            REQUIRE(spec.projection.lens == LensSpec{"opencv", params});
            for (const glm::dvec3& p : kDirections) requirePixel(lensPixel(spec, p), calib3dPixel(p, 500, 480, 319.5, 239.5, d));
        }
    }
    // The tilt: 14 values with τx = τy = 0 are the 12-value camera; with the tilt, one value
    // cv2.projectPoints gave (OpenCV 4.6.0) beside the formula.
    std::vector<double> untilted(kCoefficients.begin(), kCoefficients.begin() + 12);
    const std::vector<double> twelve = untilted;
    untilted.insert(untilted.end(), {0.0, 0.0});
    writeText(dir / "untilted.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\n" +
                                        yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                        yamlMatrix("distortion_coefficients", 14, 1, untilted));
    const CameraSpec flat = readCameraSet((dir / "untilted.yml").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec;
    for (const glm::dvec3& p : kDirections) requirePixel(lensPixel(flat, p), calib3dPixel(p, 500, 480, 319.5, 239.5, twelve));
    // calib.yml: the loop's last, all 14 values.
    const CameraSpec tilted = readCameraSet((dir / "calib.yml").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec;
    requirePixel(lensPixel(tilted, kDirections[0]), {467.4122721579414, 144.99332951745066});

    // All zero, any count OpenCV takes (or an empty list): a linear pinhole.
    writeText(dir / "zero.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\n" +
                                    yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                    yamlMatrix("D", 1, 8, std::vector<double>(8, 0.0)));
    REQUIRE(readCameraSet((dir / "zero.yml").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec.projection.type ==
            ProjectionType::Pinhole);
    writeText(dir / "empty.yml", "%YAML:1.0\nimage_width: 640\nimage_height: 480\n" +
                                     yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) + "dist_coeffs: []\n");
    REQUIRE(readCameraSet((dir / "empty.yml").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec.projection.type ==
            ProjectionType::Pinhole);

    // Every view of calibration.cpp's file shares the lens; without an image size too (the
    // depth map's size is taken later: the lens is in pixels, as K is).
    writeText(dir / "views.yml", "%YAML:1.0\n---\nnr_of_frames: 2\n" +
                                     yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                     yamlMatrix("distortion_coefficients", 5, 1, {-0.12, 0.03, 1e-3, -5e-4, -0.004}) +
                                     yamlMatrix("extrinsic_parameters", 2, 6, {0, 0, 0, 0, 0, 2, 0, 0.3, 0, 0.1, 0.2, 3}));
    const CameraSet views = readCameraSet((dir / "views.yml").string(), &cameraFormatNamed("opencv"));
    REQUIRE(views.cameras.size() == 3);
    for (const ImportedCamera& view : views.cameras) {
        INFO(view.name);
        REQUIRE_FALSE(view.hasImageSize);
        REQUIRE(view.spec.projection.lens.model == "opencv");
        REQUIRE(view.projectionForSize(1280, 960).lens == view.spec.projection.lens);
    }
    // stereo_calib.cpp's intrinsics.yml: D1 and D2 each their camera's (8 values, as it writes them).
    writeText(dir / "intrinsics.yml", "%YAML:1.0\n" + yamlMatrix("M1", 3, 3, {500, 0, 319.5, 0, 500, 239.5, 0, 0, 1}) +
                                          yamlMatrix("D1", 1, 8, {-0.1, 0.02, 0, 0, 0, 0.01, 0, 0}) +
                                          yamlMatrix("M2", 3, 3, {510, 0, 330, 0, 505, 241, 0, 0, 1}) +
                                          yamlMatrix("D2", 1, 8, std::vector<double>(8, 0.0)) +
                                          yamlMatrix("R", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1}) + yamlMatrix("T", 3, 1, {-0.12, 0, 0}));
    const CameraSet stereo = readCameraSet((dir / "intrinsics.yml").string(), &cameraFormatNamed("opencv"));
    const CameraSpec& left = stereo.cameras.at(stereo.find("left")).spec;
    REQUIRE(left.projection.lens == LensSpec{"opencv", {500, 500, 319.5, 239.5, -0.1, 0.02, 0, 0, 0, 0.01, 0, 0}});
    requirePixel(lensPixel(left, {0.2, 0.1, 1}), calib3dPixel({0.2, 0.1, 1}, 500, 500, 319.5, 239.5, {-0.1, 0.02, 0, 0, 0, 0.01}));
    REQUIRE(stereo.cameras.at(stereo.find("right")).spec.projection.type == ProjectionType::Pinhole);
}

TEST_CASE("OpenCV's fisheye calibration (fisheye_model: 1, as camera_calibration.cpp writes it) is lens opencv_fisheye",
          "[import][opencv][lens]")
{
    const fs::path dir = scratch("opencv_fisheye");
    const std::vector<double> k = {0.05, -0.01, 0.002, -0.0005};
    // saveCameraParams of the calibration tutorial's sample, its fisheye flags (fix_skew,
    // recompute_extrinsic) and the bool it writes as 0 or 1.
    const std::string head = "%YAML:1.0\n---\ncalibration_time: \"Sun Nov 29 05:00:00 2026\"\nnr_of_frames: 12\n"
                             "image_width: 640\nimage_height: 480\nboard_width: 9\nboard_height: 6\nsquare_size: 25.\n"
                             "# flags: +fix_skew +recompute_extrinsic\nflags: 10\n";
    writeText(dir / "fisheye.yml", head + "fisheye_model: 1\n" +
                                       yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                       yamlMatrix("distortion_coefficients", 4, 1, k) + "avg_reprojection_error: 0.31\n");
    const CameraSpec spec = readCameraSet((dir / "fisheye.yml").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec;
    REQUIRE(spec.projection.lens == LensSpec{"opencv_fisheye", {500, 480, 319.5, 239.5, 0.05, -0.01, 0.002, -0.0005}});
    // In front, out to 73° from the axis (cv::fisheye projects the front half only).
    for (const glm::dvec3& p : {glm::dvec3(0.3, -0.2, 1.0), glm::dvec3(-1.5, 0.9, 0.6), glm::dvec3(0.8, 0.6, 0.3)})
        requirePixel(lensPixel(spec, p), fisheyePixel(p, 500, 480, 319.5, 239.5, k));
    requirePixel(lensPixel(spec, {0.3, -0.2, 1.0}), {464.30603577852503, 146.824137101744});  // cv2.fisheye.projectPoints, 4.6.0

    // Zero coefficients are still a fisheye: equidistant, 60° off the axis at fx·π/3, not fx·tan 60°.
    writeText(dir / "zero.yml", head + "fisheye_model: 1\n" + yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                    yamlMatrix("distortion_coefficients", 4, 1, {0, 0, 0, 0}));
    const CameraSpec zero = readCameraSet((dir / "zero.yml").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec;
    REQUIRE(zero.projection.lens.model == "opencv_fisheye");
    const double pi = std::acos(-1.0);
    requirePixel(lensPixel(zero, {std::sin(pi / 3), 0, std::cos(pi / 3)}), {500 * pi / 3 + 319.5, 239.5});

    // XML; FileStorage's JSON (as cv2.FileStorage writes it); a hand-written JSON with a JSON
    // bool and the matrices as lists of rows.
    writeText(dir / "fisheye.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                   "<image_height>480</image_height>\n<flags>10</flags>\n<fisheye_model>1</fisheye_model>\n"
                                   "<camera_matrix type_id=\"opencv-matrix\"><rows>3</rows><cols>3</cols><dt>d</dt>"
                                   "<data>500. 0. 319.5 0. 480. 239.5 0. 0. 1.</data></camera_matrix>\n"
                                   "<distortion_coefficients type_id=\"opencv-matrix\"><rows>4</rows><cols>1</cols><dt>d</dt>"
                                   "<data>0.05 -0.01 0.002 -0.0005</data></distortion_coefficients>\n</opencv_storage>\n");
    writeText(dir / "storage.json",
              "{\n    \"image_width\": 640,\n    \"image_height\": 480,\n    \"fisheye_model\": 1,\n"
              "    \"camera_matrix\": {\n        \"type_id\": \"opencv-matrix\",\n        \"rows\": 3,\n        \"cols\": 3,\n"
              "        \"dt\": \"d\",\n        \"data\": [ 500.0, 0.0, 3.1950000000000000e+02, 0.0, 480.0,\n"
              "            2.3950000000000000e+02, 0.0, 0.0, 1.0 ]\n    },\n"
              "    \"distortion_coefficients\": {\n        \"type_id\": \"opencv-matrix\",\n        \"rows\": 4,\n"
              "        \"cols\": 1,\n        \"dt\": \"d\",\n        \"data\": [ 5.0000000000000003e-02, -1.0000000000000000e-02,\n"
              "            2.0000000000000000e-03, -5.0000000000000001e-04 ]\n    }\n}\n");
    writeText(dir / "fisheye.json", "{\"image_width\": 640, \"image_height\": 480, \"flags\": 10, \"fisheye_model\": true,\n"
                                    " \"camera_matrix\": [[500.0, 0.0, 319.5], [0.0, 480.0, 239.5], [0.0, 0.0, 1.0]],\n"
                                    " \"distortion_coefficients\": [[0.05], [-0.01], [0.002], [-0.0005]]}\n");
    for (const char* file : {"fisheye.xml", "storage.json", "fisheye.json"}) {
        INFO(file);
        const CameraSpec other = readCameraSet((dir / file).string(), &cameraFormatNamed("opencv")).cameras.at(0).spec;
        REQUIRE(other.projection.lens == spec.projection.lens);
    }
    // fisheye_model 0 (false): calib3d's 4 values (k1 k2 p1 p2).
    writeText(dir / "not.json", "{\"image_width\": 640, \"image_height\": 480, \"fisheye_model\": false,\n"
                                " \"camera_matrix\": [[500.0, 0.0, 319.5], [0.0, 480.0, 239.5], [0.0, 0.0, 1.0]],\n"
                                " \"distortion_coefficients\": [[0.05], [-0.01], [0.002], [-0.0005]]}\n");
    REQUIRE(readCameraSet((dir / "not.json").string(), &cameraFormatNamed("opencv")).cameras.at(0).spec.projection.lens.model ==
            "opencv");
}

TEST_CASE("OpenCV distortion that is no lens is refused naming the file, the key and the rule", "[import][opencv][lens]")
{
    const fs::path dir = scratch("opencv_lens_refused");
    const std::string K = yamlMatrix("camera_matrix", 3, 3, {500, 0, 319.5, 0, 480, 239.5, 0, 0, 1});
    auto refusal = [&](const std::string& name, const std::string& text) {
        writeText(dir / name, text);
        try {
            readCameraSet((dir / name).string(), &cameraFormatNamed("opencv"));
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(read)");
    };
    const std::string head = "%YAML:1.0\nimage_width: 640\nimage_height: 480\n";
    REQUIRE_THAT(refusal("six.yml", head + K + yamlMatrix("distortion_coefficients", 6, 1, {0.1, 0, 0, 0, 0, 0})),
                 Catch::StartsWith("OpenCV calibration file '") &&
                     Catch::EndsWith("six.yml': 'distortion_coefficients' holds 6 coefficients; OpenCV's calib3d takes 4, 5, 8, "
                                     "12 or 14: k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tau_x tau_y]]]]"));
    REQUIRE_THAT(refusal("three.yml", head + K + yamlMatrix("D", 1, 3, {0, 0, 0})),
                 Catch::Contains("'D' holds 3 coefficients; OpenCV's calib3d takes 4, 5, 8, 12 or 14"));
    REQUIRE_THAT(refusal("fisheye5.yml", head + "fisheye_model: 1\n" + K + yamlMatrix("distortion_coefficients", 5, 1, {0, 0, 0, 0, 0})),
                 Catch::Contains("'distortion_coefficients' holds 5 coefficients; with fisheye_model 1 (cv::fisheye) it takes 4: "
                                 "k1, k2, k3, k4"));
    REQUIRE_THAT(refusal("fisheye2.yml", head + "fisheye_model: 2\n" + K + yamlMatrix("distortion_coefficients", 4, 1, {0, 0, 0, 0})),
                 Catch::Contains("'fisheye_model' (line 4) must be 0 or 1 (whether cv::fisheye calibrated the camera), got '2'"));
    REQUIRE_THAT(refusal("fisheyeNoD.yml", head + "fisheye_model: 1\n" + K),
                 Catch::Contains("fisheye_model is 1 but there are no distortion_coefficients"));
    REQUIRE_THAT(refusal("matrix.yml", head + K + yamlMatrix("distortion_coefficients", 2, 3, {0, 0, 0, 0, 0, 0})),
                 Catch::Contains("'distortion_coefficients' is 2x3: distortion coefficients are one row or one column"));
    REQUIRE_THAT(refusal("nan.yml", head + K + "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
                                               "   data: [ 0.1, .nan, 0., 0., 0. ]\n"),
                 Catch::Contains("'distortion_coefficients' (line") && Catch::Contains("must be a finite number"));
    // The lens's own refusals, prefixed with the file and the key: k1 = −1 folds 30° from the
    // axis, before the image's edge; a tilt of 1 rad is no tilt.
    REQUIRE_THAT(refusal("fold.yml", head + K + yamlMatrix("distortion_coefficients", 5, 1, {-1, 0, 0, 0, 0})),
                 Catch::StartsWith("OpenCV calibration file '") &&
                     Catch::Contains("fold.yml': distortion_coefficients: lens model opencv folds (is no longer one-to-one)"));
    std::vector<double> tilt(14, 0.0);
    tilt[12] = 1;
    REQUIRE_THAT(refusal("tilt.yml", head + K + yamlMatrix("distortion_coefficients", 14, 1, tilt)),
                 Catch::Contains("tilt.yml': distortion_coefficients: lens model opencv: 'tau_x' must lie within ±π/4"));
    // Skew in K stays refused: calib3d's model has none (projectPoints ignores K[0][1]).
    REQUIRE_THAT(refusal("skew.yml", head + yamlMatrix("camera_matrix", 3, 3, {500, 2, 319.5, 0, 480, 239.5, 0, 0, 1}) +
                                         yamlMatrix("distortion_coefficients", 5, 1, {0.1, 0, 0, 0, 0})),
                 Catch::Contains("camera_matrix[0, 1] (skew) must be 0"));
}

TEST_CASE("ROS CameraInfo: plumb_bob and rational_polynomial are lens opencv, equidistant lens opencv_fisheye, P stays a pinhole",
          "[import][ros][lens]")
{
    const fs::path dir = scratch("ros_lens");
    // camera_calibration_parsers' file: rows, cols, data.
    auto file = [](const std::string& model, const std::vector<double>& d) {
        std::string data;
        for (double v : d) data += (data.empty() ? "" : ", ") + formatNumber(v);
        return "image_width: 640\nimage_height: 480\ncamera_name: cam\n"
               "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [520, 0, 320.5, 0, 515, 240.5, 0, 0, 1]\n" +
               (model.empty() ? "" : "distortion_model: " + model + "\n") + "distortion_coefficients:\n  rows: 1\n  cols: " +
               std::to_string(d.size()) + "\n  data: [" + data + "]\n" +
               "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
               "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [480, 0, 321, 0, 0, 480, 241, 0, 0, 0, 1, 0]\n";
    };
    const glm::dvec3 p(0.4, 0.3, 1);
    const std::vector<double> plumbBob = {-0.2, 0.05, 1e-3, -2e-3, -0.01};
    const std::vector<double> rational = {0.4, -0.05, 1e-3, 2e-3, 0.01, 0.75, -0.02, 0.03};
    for (const auto& [model, d] : {std::pair{std::string("plumb_bob"), plumbBob}, std::pair{std::string("rational_polynomial"), rational},
                                   std::pair{std::string(""), plumbBob}}) {  // no distortion_model key: plumb_bob
        INFO(model);
        writeText(dir / "camera.yaml", file(model, d));
        const CameraSet set = readCameraSet((dir / "camera.yaml").string(), &cameraFormatNamed("ros"));
        const CameraSpec& raw = set.cameras.at(set.find("")).spec;
        std::vector<double> params = {520, 515, 320.5, 240.5};
        params.insert(params.end(), d.begin(), d.end());
        REQUIRE(raw.projection.lens == LensSpec{"opencv", params});
        requirePixel(lensPixel(raw, p), calib3dPixel(p, 520, 515, 320.5, 240.5, d));
        const CameraSpec& rectified = set.cameras.at(set.find("rectified")).spec;
        REQUIRE(rectified.projection.type == ProjectionType::Pinhole);
        requireNear(imagePointOf(rectified, p), glm::dvec2(480 * 0.4 + 321 + 0.5, 480 * 0.3 + 241 + 0.5));
    }
    // ROS 2's echoed message, equidistant: cv::fisheye's k1..k4.
    const std::vector<double> k = {0.05, -0.01, 0.002, -0.0005};
    auto message = [](const std::string& model, const std::string& d) {
        return "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: fisheye_optical\nheight: 480\nwidth: 640\n"
               "distortion_model: " + model + "\nd: " + d + "\n"
               "k: [400.0, 0.0, 319.5, 0.0, 400.0, 239.5, 0.0, 0.0, 1.0]\n"
               "r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
               "p: [300.0, 0.0, 320.0, 0.0, 0.0, 300.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0]\n"
               "binning_x: 0\nbinning_y: 0\n---\n";
    };
    writeText(dir / "fisheye.yaml", message("equidistant", "[0.05, -0.01, 0.002, -0.0005]"));
    const CameraSet fisheye = readCameraSet((dir / "fisheye.yaml").string(), &cameraFormatNamed("ros"));
    const CameraSpec& raw = fisheye.cameras.at(fisheye.find("")).spec;
    REQUIRE(raw.projection.lens == LensSpec{"opencv_fisheye", {400, 400, 319.5, 239.5, 0.05, -0.01, 0.002, -0.0005}});
    for (const glm::dvec3& q : {glm::dvec3(0.4, 0.3, 1), glm::dvec3(-1.5, 0.9, 0.6)})
        requirePixel(lensPixel(raw, q), fisheyePixel(q, 400, 400, 319.5, 239.5, k));
    REQUIRE(fisheye.cameras.at(fisheye.find("rectified")).spec.projection.type == ProjectionType::Pinhole);
    // equidistant with zero coefficients: still a fisheye.
    writeText(dir / "fisheye0.yaml", message("equidistant", "[0.0, 0.0, 0.0, 0.0]"));
    const CameraSet zero = readCameraSet((dir / "fisheye0.yaml").string(), &cameraFormatNamed("ros"));
    REQUIRE(zero.cameras.at(zero.find("")).spec.projection.lens.model == "opencv_fisheye");
    // plumb_bob with d empty or all zero, whatever its length (drivers with no distortion): a
    // pinhole, as image_geometry reads it.
    for (const char* d : {"[]", "[0.0, 0.0]", "[0.0, 0.0, 0.0, 0.0, 0.0]"}) {
        INFO(d);
        writeText(dir / "empty.yaml", message("plumb_bob", d));
        const CameraSet empty = readCameraSet((dir / "empty.yaml").string(), &cameraFormatNamed("ros"));
        REQUIRE(empty.cameras.at(empty.find("")).spec.projection.type == ProjectionType::Pinhole);
    }
    writeText(dir / "unset.yaml", message("''", "[]"));  // the message's defaults: no model, no D
    const CameraSet unset = readCameraSet((dir / "unset.yaml").string(), &cameraFormatNamed("ros"));
    REQUIRE(unset.cameras.at(unset.find("")).spec.projection.type == ProjectionType::Pinhole);

    // The raw camera refused, naming the key, the count and the rule; the rectified one stays.
    auto refusedRaw = [&](const std::string& name, const std::string& text) {
        writeText(dir / name, text);
        const CameraSet set = readCameraSet((dir / name).string(), &cameraFormatNamed("ros"));
        REQUIRE_NOTHROW(set.find("rectified"));
        try {
            set.find("");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(usable)");
    };
    REQUIRE_THAT(refusedRaw("four.yaml", file("plumb_bob", {0.1, 0, 0, 0})),
                 Catch::StartsWith("ROS CameraInfo '") &&
                     Catch::Contains("four.yaml': distortion_coefficients holds 4 coefficients; distortion_model plumb_bob takes 5 "
                                     "(k1, k2, t1, t2, k3) (a rectified image's camera is P: FILE#rectified)"));
    REQUIRE_THAT(refusedRaw("five.yaml", file("rational_polynomial", plumbBob)),
                 Catch::Contains("holds 5 coefficients; distortion_model rational_polynomial takes 8 (k1, k2, t1, t2, k3, k4, k5, k6)"));
    REQUIRE_THAT(refusedRaw("fisheye5.yaml", message("equidistant", "[0.0, 0.0, 0.0, 0.0, 0.0]")),
                 Catch::Contains("D holds 5 coefficients; distortion_model equidistant takes 4 (k1, k2, k3, k4)"));
    REQUIRE_THAT(refusedRaw("fisheyeEmpty.yaml", message("equidistant", "[]")),
                 Catch::Contains("D holds 0 coefficients; distortion_model equidistant takes 4"));
    REQUIRE_THAT(refusedRaw("unknown.yaml", message("kannala_brandt", "[0.05, -0.01, 0.002, -0.0005]")),
                 Catch::Contains("distortion_model 'kannala_brandt' is unknown: zcheck reads plumb_bob (5: k1, k2, t1, t2, k3), "
                                 "rational_polynomial (8: k1, k2, t1, t2, k3, k4, k5, k6) or equidistant (4: k1, k2, k3, k4)"));
    REQUIRE_THAT(refusedRaw("unnamed.yaml", message("''", "[0.1, 0.0, 0.0, 0.0, 0.0]")),
                 Catch::Contains("distortion_model is empty: zcheck reads plumb_bob"));
    REQUIRE_THAT(refusedRaw("fold.yaml", file("plumb_bob", {-1, 0, 0, 0, 0})),
                 Catch::Contains("fold.yaml': distortion_coefficients: lens model opencv folds") &&
                     Catch::Contains("FILE#rectified"));
}

TEST_CASE("zcheck camera --to opencv writes lens opencv in the shortest of OpenCV's counts and opencv_fisheye with fisheye_model",
          "[import][opencv][lens][roundtrip]")
{
    const fs::path dir = scratch("opencv_lens_write");
    auto lensCamera = [](const std::string& model, const std::vector<double>& coefficients) {
        CameraSpec spec;
        spec.convention = Convention::preset("opencv");
        spec.width = 640, spec.height = 480;
        spec.projection = PinholeIntrinsics{500, 480, 319.5, 239.5, 0.0}.lensProjection(model, coefficients, 0.1, 100, "test");
        spec.view = View::lookAt({0.2, -0.1, -3}, {0, 0, 0}, {0, -1, 0});
        return Camera(spec);
    };
    struct Case {
        std::vector<double> coefficients;  // as given
        int written;                       // how many the file holds
    };
    const Case cases[] = {{{-0.12, 0.03, 1e-3, -5e-4}, 4},
                          {{-0.12, 0.03, 0, 0, -0.004}, 5},
                          {{-0.12, 0, 0, 0, 0, 0, 0, 0.003, 0, 0, 0, 0, 0, 0}, 8},  // trailing zeros are not written
                          {{-0.12, 0.03, 1e-3, -5e-4, -0.004, 0.02, -0.01, 0.003, 0, 0, 0, 1e-4}, 12},
                          {kCoefficients, 14}};
    const CameraFormat& opencv = cameraFormatNamed("opencv");
    for (const Case& c : cases) {
        INFO(c.written << " coefficients");
        const Camera camera = lensCamera("opencv", c.coefficients);
        const std::vector<CameraFileText> files = cameraInFormat(camera, opencv, "frame");
        REQUIRE_THAT(files.at(0).text, Catch::Contains("distortion_coefficients: !!opencv-matrix\n   rows: " + std::to_string(c.written) +
                                                       "\n   cols: 1\n") &&
                                           !Catch::Contains("fisheye_model"));
        writeText(dir / "camera.yml", files.at(0).text);
        const CameraSpec back = readCameraSet((dir / "camera.yml").string(), &opencv).cameras.at(0).spec;
        REQUIRE(back.projection.lens.params.size() == std::size_t(4 + c.written));
        const Camera read(back);
        REQUIRE(read.lens()->spec() == camera.lens()->spec());  // every parameter, the defaults written out
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row) REQUIRE(read.eyeFromWorld[col][row] == Approx(camera.eyeFromWorld[col][row]).margin(1e-12));
    }
    const Camera fisheye = lensCamera("opencv_fisheye", {0.05, -0.01, 0, 0});
    const std::string text = cameraInFormat(fisheye, opencv, "frame").at(0).text;
    REQUIRE_THAT(text, Catch::Contains("fisheye_model: 1\n") &&
                           Catch::Contains("distortion_coefficients: !!opencv-matrix\n   rows: 4\n   cols: 1\n"));
    writeText(dir / "fisheye.yml", text);
    const Camera fisheyeBack(readCameraSet((dir / "fisheye.yml").string(), &opencv).cameras.at(0).spec);
    REQUIRE(fisheyeBack.lens()->spec() == fisheye.lens()->spec());
    // A pinhole keeps calibration.cpp's five zeros and reads back a pinhole.
    CameraSpec pinhole;
    pinhole.convention = Convention::preset("opencv");
    pinhole.width = 640, pinhole.height = 480;
    pinhole.projection = PinholeIntrinsics{500, 480, 319.5, 239.5, 0.0}.projection(0.1, 100, "test");
    const std::string pinholeText = cameraInFormat(Camera(pinhole), opencv, "frame").at(0).text;
    REQUIRE_THAT(pinholeText, Catch::Contains("data: [ 0, 0, 0, 0, 0 ]") && !Catch::Contains("fisheye_model"));
    // Every other model: OpenCV has none of it.
    REQUIRE_THROWS_WITH(cameraInFormat(lensCamera("brown_conrady", {-0.1, 0.01, 0, 0.001}), opencv, "frame"),
                        Catch::StartsWith("OpenCV has no brown_conrady lens model"));
    REQUIRE_THROWS_WITH(cameraInFormat(lensCamera("equisolid", {}), opencv, "frame"), Catch::StartsWith("OpenCV has no equisolid lens model"));
    CameraSpec panorama;
    panorama.convention = Convention::preset("opencv");
    panorama.width = 1024, panorama.height = 512;
    panorama.projection.type = ProjectionType::NonLinear;
    panorama.projection.near = 0.1, panorama.projection.far = 100;
    panorama.projection.lens = {"equirectangular", {-180, 180, -90, 90}};
    REQUIRE_THROWS_WITH(cameraInFormat(Camera(panorama), opencv, "frame"), Catch::StartsWith("OpenCV has no equirectangular lens model"));
}
