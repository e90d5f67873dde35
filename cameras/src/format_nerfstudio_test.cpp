// nerfstudio and instant-ngp transforms.json (format_nerfstudio.cpp): camera-to-world in OpenGL
// axes with centres at +0.5, a file without an image size, each camera_model's lens against the
// source's formula written out by hand, instant-ngp's lens keys as its loader reads them, the
// writer's round trips and refusals.
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <cmath>
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
    // nerfstudio takes every frame's distortion from the top level when the top level gives any
    // (nerfstudio_dataparser.py): the second frame's own k1 is not used, and the camera says so.
    REQUIRE(set.cameras[1].refusal.empty());
    REQUIRE(set.cameras[1].spec.projection.type == ProjectionType::Pinhole);
    REQUIRE_THAT(set.cameras[1].spec.notes.at(0), Catch::Contains("frames[1].k1 is not used"));
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


namespace {

// A transforms.json of one frame at the world origin whose camera-to-world is the identity
// (OpenGL axes): the camera frame of lens.h (x right, y down, z forward) is world (x, −y, −z).
std::string oneFrame(const std::string& keys, const std::string& frameKeys = "")
{
    return "{" + keys + (keys.empty() ? "" : ", ") + "\"frames\": [{\"file_path\": \"f.png\"" +
           (frameKeys.empty() ? "" : ", " + frameKeys) +
           ", \"transform_matrix\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}]}";
}

glm::dvec3 worldOf(const glm::dvec3& dCamera) { return {dCamera.x, -dCamera.y, -dCamera.z}; }

ImportedCamera readOne(const std::string& name, const std::string& text)
{
    const fs::path dir = scratch("nerfstudio_lens");
    writeText(dir / name, text);
    return readCameraSet((dir / name).string(), &cameraFormatNamed("nerfstudio")).cameras.at(0);
}

std::string refusalOf(const std::string& name, const std::string& text)
{
    const fs::path dir = scratch("nerfstudio_lens");
    writeText(dir / name, text);
    try {
        return readCameraSet((dir / name).string(), &cameraFormatNamed("nerfstudio")).cameras.at(0).refusal;
    } catch (const Error& e) {
        return e.what();
    }
}

// Where a world point lands in a lens camera's image (pixel centres at +0.5, as nerfstudio's).
glm::dvec2 imagePointOfLens(const CameraSpec& spec, const glm::dvec3& world)
{
    const Camera camera(spec);
    REQUIRE(camera.lens());
    const glm::dvec3 eye(camera.eyeFromWorld * glm::dvec4(world, 1.0));
    const std::optional<glm::dvec2> pixel = camera.lens()->imageFromDirection(camera.lensFrameFromEye(eye));
    REQUIRE(pixel);
    return *pixel;
}

// The same for a direction in the camera frame of the frames oneFrame() writes.
glm::dvec2 pixelOf(const CameraSpec& spec, const glm::dvec3& dCamera) { return imagePointOfLens(spec, worldOf(dCamera)); }

glm::dvec3 direction(double thetaDeg, double phiDeg)
{
    const double t = thetaDeg * M_PI / 180, p = phiDeg * M_PI / 180;
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

const char* const kIntrinsics = R"("fl_x": 300, "fl_y": 280, "cx": 322.5, "cy": 237.25, "w": 640, "h": 480)";

}  // namespace

TEST_CASE("nerfstudio OPENCV is brown_conrady: k4 an r⁸ term, OpenCV's tangential pairing", "[import][nerfstudio]")
{
    const ImportedCamera camera =
        readOne("opencv.json", oneFrame(std::string(R"("camera_model": "OPENCV", )") + kIntrinsics +
                                        R"(, "k1": -0.12, "k2": 0.031, "k3": -0.004, "k4": 0.0006, "p1": 0.0011, "p2": -0.0007)"));
    REQUIRE(camera.refusal.empty());
    REQUIRE(camera.spec.projection.lens ==
            LensSpec{"brown_conrady", {300, 280, 322, 236.75, -0.12, 0.031, -0.004, 0.0006, 0.0011, -0.0007}});
    // camera_utils._compute_residual_and_jacobian, the forward map nerfstudio inverts:
    // d = 1 + k1·r² + k2·r⁴ + k3·r⁶ + k4·r⁸, xd = d·x + 2·p1·x·y + p2·(r² + 2x²),
    // yd = d·y + 2·p2·x·y + p1·(r² + 2y²); pixel = (fl_x·xd + cx, fl_y·yd + cy).
    for (const glm::dvec3 d : {direction(0, 0), direction(15, 40), direction(30, 200), direction(38, -70)}) {
        const double x = d.x / d.z, y = d.y / d.z, r2 = x * x + y * y;
        const double k = 1 + r2 * (-0.12 + r2 * (0.031 + r2 * (-0.004 + r2 * 0.0006)));
        const double xd = k * x + 2 * 0.0011 * x * y + -0.0007 * (r2 + 2 * x * x);
        const double yd = k * y + 2 * -0.0007 * x * y + 0.0011 * (r2 + 2 * y * y);
        requireNear(pixelOf(camera.spec, d), {300 * xd + 322.5, 280 * yd + 237.25});
    }
    // distortion_params gives the same six in nerfstudio's order [k1 k2 k3 k4 p1 p2].
    const ImportedCamera listed =
        readOne("list.json", oneFrame(std::string(R"("camera_model": "OPENCV", )") + kIntrinsics +
                                      R"(, "distortion_params": [-0.12, 0.031, -0.004, 0.0006, 0.0011, -0.0007])"));
    REQUIRE(listed.spec.projection.lens == camera.spec.projection.lens);
    // All zero: a pinhole, the raster route's.
    const ImportedCamera zero = readOne(
        "zero.json", oneFrame(std::string(R"("camera_model": "OPENCV", )") + kIntrinsics + R"(, "k1": 0, "p2": 0)"));
    REQUIRE(zero.spec.projection.type == ProjectionType::Pinhole);
}

TEST_CASE("nerfstudio OPENCV_FISHEYE is opencv_fisheye, to θ past 90°, with p1, p2 thin_prism_fisheye", "[import][nerfstudio]")
{
    const ImportedCamera camera = readOne(
        "fisheye.json", oneFrame(std::string(R"("camera_model": "OPENCV_FISHEYE", )") + kIntrinsics +
                                 R"(, "k1": 0.021, "k2": -0.004, "k3": 0.0007, "k4": -0.0001)"));
    REQUIRE(camera.spec.projection.lens == LensSpec{"opencv_fisheye", {300, 280, 322, 236.75, 0.021, -0.004, 0.0007, -0.0001}});
    // cameras.py (FISHEYE): the undistorted point's length is θ, the angle from the axis, and the
    // distortion undone is the same polynomial: θd = θ·(1 + k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸) along φ.
    for (const auto& [t, p] : {std::pair{10.0, 30.0}, {45.0, 160.0}, {80.0, -100.0}, {100.0, 10.0}}) {
        const double theta = t * M_PI / 180, phi = p * M_PI / 180, t2 = theta * theta;
        const double thetaD = theta * (1 + t2 * (0.021 + t2 * (-0.004 + t2 * (0.0007 + t2 * -0.0001))));
        requireNear(pixelOf(camera.spec, direction(t, p)),
                    {300 * thetaD * std::cos(phi) + 322.5, 280 * thetaD * std::sin(phi) + 237.25});
    }
    // A zero fisheye is still a fisheye: equidistant.
    const ImportedCamera zero =
        readOne("fisheye0.json", oneFrame(std::string(R"("camera_model": "OPENCV_FISHEYE", )") + kIntrinsics));
    REQUIRE(zero.spec.projection.lens == LensSpec{"opencv_fisheye", {300, 280, 322, 236.75, 0, 0, 0, 0}});
    // p1, p2: nerfstudio applies them on the θ-plane before the radial factor.
    const ImportedCamera tangential = readOne(
        "fisheye_p.json", oneFrame(std::string(R"("camera_model": "OPENCV_FISHEYE", )") + kIntrinsics +
                                   R"(, "k1": 0.021, "k2": -0.004, "p1": 0.002, "p2": -0.001)"));
    REQUIRE(tangential.spec.projection.lens ==
            LensSpec{"thin_prism_fisheye", {300, 280, 322, 236.75, 0.021, -0.004, 0.002, -0.001, 0, 0, 0, 0}});
    const double theta = 50 * M_PI / 180, phi = 20 * M_PI / 180;
    const double x = theta * std::cos(phi), y = theta * std::sin(phi), r2 = x * x + y * y;
    const double k = 1 + r2 * (0.021 + r2 * -0.004);
    const double xd = k * x + 2 * 0.002 * x * y + -0.001 * (r2 + 2 * x * x);
    const double yd = k * y + 2 * -0.001 * x * y + 0.002 * (r2 + 2 * y * y);
    requireNear(pixelOf(tangential.spec, direction(50, 20)), {300 * xd + 322.5, 280 * yd + 237.25});
}

TEST_CASE("nerfstudio FISHEYE624 is fisheye624 from distortion_params [k0..k5 p0 p1 s0..s3]", "[import][nerfstudio]")
{
    const double q[12] = {0.01, -0.003, 0.0004, -0.00002, 0.000001, 0, 0.0009, -0.0006, 0.0003, -0.0001, -0.0002, 0.00005};
    std::string list;
    for (double v : q) list += (list.empty() ? "" : ", ") + formatNumber(v);
    const ImportedCamera camera = readOne(
        "624.json", oneFrame(std::string(R"("camera_model": "FISHEYE624", )") + kIntrinsics + ", \"distortion_params\": [" +
                             list + "]"));
    REQUIRE(camera.spec.projection.lens.model == "fisheye624");
    REQUIRE(camera.spec.projection.lens.params ==
            std::vector<double>{300, 280, 322, 236.75, q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8], q[9], q[10], q[11]});
    // camera_utils.fisheye624_project: a = x/z, b = y/z, r = |(a, b)|, θ = atan(r),
    // θk = θ + Σ k_i·θ^(3+2i), (xr, yr) = θk·(a, b)/r, rd² = xr² + yr²;
    // u = xr + (2xr² + rd²)·p0 + 2·xr·yr·p1 + s0·rd² + s1·rd⁴, v likewise with p1, p0, s2, s3.
    for (const glm::dvec3 d : {direction(12, 50), direction(40, -120), direction(70, 200)}) {
        const double a = d.x / d.z, b = d.y / d.z, r = std::hypot(a, b), theta = std::atan(r);
        double thetaK = theta;
        for (int i = 0; i < 6; ++i) thetaK += q[i] * std::pow(theta, 3 + 2 * i);
        const double xr = thetaK * a / r, yr = thetaK * b / r, rd2 = xr * xr + yr * yr;
        const double u = xr + (2 * xr * xr + rd2) * q[6] + 2 * xr * yr * q[7] + q[8] * rd2 + q[9] * rd2 * rd2;
        const double v = yr + (2 * yr * yr + rd2) * q[7] + 2 * xr * yr * q[6] + q[10] * rd2 + q[11] * rd2 * rd2;
        requireNear(pixelOf(camera.spec, d), {300 * u + 322.5, 280 * v + 237.25});
    }
    REQUIRE_THAT(refusalOf("624_short.json", oneFrame(std::string(R"("camera_model": "FISHEYE624", )") + kIntrinsics +
                                                      R"(, "distortion_params": [0.1, 0, 0])")),
                 Catch::Contains("'distortion_params' holds 3 numbers; camera_model FISHEYE624 takes 12 (k0..k5, p0, p1, s0..s3)"));
    REQUIRE_THAT(refusalOf("624_named.json",
                           oneFrame(std::string(R"("camera_model": "FISHEYE624", )") + kIntrinsics + R"(, "k1": 0.1)")),
                 Catch::Contains("camera_model FISHEYE624 takes distortion_params, 12 numbers"));
    REQUIRE_THAT(refusalOf("opencv_short.json", oneFrame(std::string(R"("camera_model": "OPENCV", )") + kIntrinsics +
                                                         R"(, "distortion_params": [0.1, 0, 0, 0])")),
                 Catch::Contains("holds 4 numbers; camera_model OPENCV takes 6 (k1, k2, k3, k4, p1, p2)"));
    REQUIRE_THAT(refusalOf("nan.json", oneFrame(std::string(R"("camera_model": "OPENCV", )") + kIntrinsics,
                                                R"("distortion_params": [0.1, 0, "x", 0, 0, 0])")),
                 Catch::Contains("'frames[0].distortion_params[2]' must be a finite number"));
}

TEST_CASE("nerfstudio EQUIRECTANGULAR: the longitudes and latitudes its fl_x, cx, fl_y, cy span", "[import][nerfstudio]")
{
    // metashape_utils.py and camera_paths.py write fl_x = w/2, cx = w/2, fl_y = h, cy = h/2: the sphere.
    const ImportedCamera sphere = readOne(
        "equirect.json",
        oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 100, "fl_y": 100, "cx": 100, "cy": 50, "w": 200, "h": 100)"));
    REQUIRE(sphere.refusal.empty());
    REQUIRE(sphere.spec.projection.lens == LensSpec{"equirectangular", {-180, 180, -90, 90}});
    // cameras.py, _generate_rays_from_coords (EQUIRECTANGULAR), pixel → direction in OpenGL axes:
    // θ = −π·(x − cx)/fx, φ = π·(0.5 + (y − cy)/fy), d = (−sin θ·sin φ, cos φ, −cos θ·sin φ).
    // The identity camera-to-world makes d the world point; it must land back on (x, y).
    const auto nerfstudioRay = [](double x, double y, double fx, double fy, double cx, double cy) {
        const double theta = -M_PI * (x - cx) / fx, phi = M_PI * (0.5 + (y - cy) / fy);
        return glm::dvec3(-std::sin(theta) * std::sin(phi), std::cos(phi), -std::cos(theta) * std::sin(phi));
    };
    for (const glm::dvec2 pixel : {glm::dvec2(100, 50), glm::dvec2(100.5, 50.5), glm::dvec2(150, 25), glm::dvec2(3.25, 90),
                                   glm::dvec2(199, 10)}) {
        const glm::dvec3 world = nerfstudioRay(pixel.x, pixel.y, 100, 100, 100, 50);
        requireNear(imagePointOfLens(sphere.spec, world), pixel);
    }
    // Any other fl_x, cx, fl_y, cy: the part of the sphere they span, the same formula.
    const ImportedCamera part = readOne(
        "part.json",
        oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 150, "fl_y": 150, "cx": 80, "cy": 70, "w": 200, "h": 100)"));
    REQUIRE(part.spec.projection.lens ==
            LensSpec{"equirectangular", {-180.0 * 80 / 150, 180.0 * 120 / 150, 180.0 * (70 - 100) / 150, 180.0 * 70 / 150}});
    for (const glm::dvec2 pixel : {glm::dvec2(80, 70), glm::dvec2(10, 5), glm::dvec2(190, 95)})
        requireNear(imagePointOfLens(part.spec, nerfstudioRay(pixel.x, pixel.y, 150, 150, 80, 70)), pixel);
    // A span past a pole is no sphere: refused.
    REQUIRE_THROWS_WITH(readOne("pole.json", oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 150, "fl_y": 120, "cx": 80, "cy": 70, "w": 200, "h": 100)")),
                        Catch::Contains("latitudes end at ±90°"));
    // nerfstudio skips distortion for EQUIRECTANGULAR: a coefficient is noted, not used.
    const ImportedCamera noted = readOne(
        "equirect_k.json",
        oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 100, "fl_y": 100, "cx": 100, "cy": 50, "w": 200, "h": 100, "k1": 0.1)"));
    REQUIRE_THAT(noted.spec.notes.at(0), Catch::Contains("'k1' is not used"));
    // More than the sphere is refused, naming the keys and the rule.
    REQUIRE_THAT(refusalOf("wide.json", oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 90, "fl_y": 100, "cx": 100, "cy": 50, "w": 200, "h": 100)")),
                 Catch::Contains("frames[0]: camera_model EQUIRECTANGULAR: fl_x = 90, cx = 100 over w = 200 span longitudes -200° to 200°") &&
                     Catch::Contains("at most 360°"));
    REQUIRE_THAT(refusalOf("tall.json", oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 100, "fl_y": 100, "cx": 100, "cy": 60, "w": 200, "h": 100)")),
                 Catch::Contains("span latitudes -72° to 108°") && Catch::Contains("±90°"));
}

TEST_CASE("instant-ngp's lens keys as its loader reads them, where they mean what they say", "[import][nerfstudio]")
{
    // colmap2nerf's OPENCV: k1, k2, p1, p2 (k3 = k4 = 0), no camera_model: both programs read
    // brown_conrady; common_device.cuh opencv_lens_distortion_delta is the same polynomial.
    const ImportedCamera opencv = readOne(
        "ngp.json", oneFrame(std::string(kIntrinsics) + R"(, "k1": -0.1, "k2": 0.02, "k3": 0, "k4": 0, "p1": 0.001, "p2": -0.002, "is_fisheye": false)"));
    REQUIRE(opencv.refusal.empty());
    REQUIRE(opencv.spec.projection.lens == LensSpec{"brown_conrady", {300, 280, 322, 236.75, -0.1, 0.02, 0, 0, 0.001, -0.002}});
    const glm::dvec3 d = direction(25, 60);
    const double u = d.x / d.z, v = d.y / d.z, r2 = u * u + v * v, radial = -0.1 * r2 + 0.02 * r2 * r2;
    const double du = u * radial + 2 * 0.001 * u * v + -0.002 * (r2 + 2 * u * u);
    const double dv = v * radial + 2 * -0.002 * u * v + 0.001 * (r2 + 2 * v * v);
    requireNear(pixelOf(opencv.spec, d), {300 * (u + du) + 322.5, 280 * (v + dv) + 237.25});

    // is_fisheye: opencv_fisheye_lens_distortion_delta, Kannala–Brandt k1..k4.
    const ImportedCamera fisheye = readOne(
        "ngp_fisheye.json", oneFrame(std::string(kIntrinsics) + R"(, "is_fisheye": true, "k1": 0.02, "k2": -0.003, "k3": 0.0004, "k4": -0.00005)"));
    REQUIRE(fisheye.spec.projection.lens == LensSpec{"opencv_fisheye", {300, 280, 322, 236.75, 0.02, -0.003, 0.0004, -0.00005}});

    // colmap2nerf's OPENCV_FISHEYE writes "p1": 0, "p2": 0, which read_lens puts where k3, k4 were.
    REQUIRE_THAT(refusalOf("ngp_lost.json", oneFrame(std::string(kIntrinsics) +
                                                     R"(, "is_fisheye": true, "k1": 0.02, "k2": -0.003, "k3": 0.0004, "k4": -0.00005, "p1": 0, "p2": 0)")),
                 Catch::Contains("instant-ngp's loader (nerf_loader.cu read_lens) reads its lens as lens model opencv_fisheye "
                                 "(k1 = 0.02, k2 = -0.003, k3 = 0, k4 = 0)") &&
                     Catch::Contains("puts p1, p2 in the places of k3, k4"));
    // is_fisheye with every coefficient 0: instant-ngp keeps a pinhole.
    REQUIRE_THAT(refusalOf("ngp_flat.json", oneFrame(std::string(kIntrinsics) + R"(, "is_fisheye": true, "k1": 0)")),
                 Catch::Contains("reads its lens as a pinhole, though its keys name lens model opencv_fisheye"));
    REQUIRE_THAT(refusalOf("ngp_flag.json", oneFrame(std::string(kIntrinsics) + R"(, "is_fisheye": 1)")),
                 Catch::Contains("'is_fisheye' must be true or false"));
    // k3 without any program's own key: nerfstudio reads an r⁶ term, instant-ngp p1.
    REQUIRE_THAT(refusalOf("both.json", oneFrame(std::string(kIntrinsics) + R"(, "k1": 0.1, "k3": 0.01)")),
                 Catch::Contains("nerfstudio and instant-ngp read its lens differently") &&
                     Catch::Contains("k3 = 0.01") && Catch::Contains("p1 = 0.01"));

    // latlong: latlong_to_dir, uv ∈ [0, 1]²: lat = (v − ½)π, lon = (u − ½)2π,
    // d = (sin lon·cos lat, sin lat, cos lon·cos lat) in x right, y down, z forward.
    const ImportedCamera latlong = readOne("ngp_latlong.json", oneFrame(R"("fl_x": 100, "w": 200, "h": 100, "latlong": true)"));
    REQUIRE(latlong.spec.projection.lens == LensSpec{"equirectangular", {-180, 180, -90, 90}});
    for (const glm::dvec2 uv : {glm::dvec2(0.5, 0.5), glm::dvec2(0.8, 0.3), glm::dvec2(0.05, 0.9)}) {
        const double lat = (uv.y - 0.5) * M_PI, lon = (uv.x - 0.5) * 2 * M_PI;
        const glm::dvec3 dNgp(std::sin(lon) * std::cos(lat), std::sin(lat), std::cos(lon) * std::cos(lat));
        requireNear(pixelOf(latlong.spec, dNgp), {uv.x * 200, uv.y * 100});
    }
    REQUIRE_THAT(refusalOf("ngp_equal_area.json", oneFrame(R"("fl_x": 100, "w": 200, "h": 100, "equirectangular": true)")),
                 Catch::Contains("cylindrical equal-area panorama"));
    REQUIRE_THAT(refusalOf("ngp_ortho.json", oneFrame(R"("fl_x": 100, "w": 200, "h": 100, "orthographic": true)")),
                 Catch::Contains("'orthographic' lens has parallel rays"));
    REQUIRE_THAT(refusalOf("ngp_ftheta.json", oneFrame(R"("fl_x": 100, "w": 200, "h": 100, "ftheta_p0": 0, "ftheta_p1": 0.01)")),
                 Catch::Contains("f-theta lens"));
    REQUIRE_THAT(refusalOf("mixed.json",
                           oneFrame(R"("camera_model": "EQUIRECTANGULAR", "fl_x": 100, "fl_y": 100, "w": 200, "h": 100, "latlong": true)")),
                 Catch::Contains("read its lens differently"));
}

TEST_CASE("nerfstudio camera models without one centre of projection, and unknown ones, are refused", "[import][nerfstudio]")
{
    REQUIRE_THAT(refusalOf("vr.json", oneFrame(std::string(R"("camera_model": "VR180_L", )") + kIntrinsics)),
                 Catch::Contains("camera_model VR180_L starts its rays 32 mm beside the camera's centre"));
    REQUIRE_THAT(refusalOf("ods.json", oneFrame(std::string(R"("camera_model": "OMNIDIRECTIONALSTEREO_R", )") + kIntrinsics)),
                 Catch::Contains("camera_model OMNIDIRECTIONALSTEREO_R starts its rays"));
    REQUIRE_THAT(refusalOf("ortho.json", oneFrame(std::string(R"("camera_model": "ORTHOPHOTO", )") + kIntrinsics)),
                 Catch::Contains("camera_model ORTHOPHOTO has parallel rays"));
    REQUIRE_THAT(refusalOf("kb.json", oneFrame(std::string(R"("camera_model": "KANNALA", )") + kIntrinsics)),
                 Catch::Contains("transforms file '") && Catch::Contains("frames[0]: camera_model KANNALA is not one of nerfstudio's (SIMPLE_PINHOLE"));
}

TEST_CASE("a lens camera written as nerfstudio's transforms.json reads back as the same lens, the rest is refused", "[import][nerfstudio][roundtrip]")
{
    const fs::path dir = scratch("nerfstudio_write");
    const auto specWith = [](const std::string& model, const std::vector<double>& coefficients, int width = 640, int height = 480) {
        CameraSpec spec;
        spec.convention = Convention::preset("opencv");
        spec.width = width, spec.height = height;
        spec.projection = PinholeIntrinsics{310, 290, 319.5, 241.25, 0}.lensProjection(model, coefficients, 0.1, 50, "test");
        spec.view = View::lookAt({1.5, 2, 4}, {0.1, 0.2, -0.5}, {0.1, 1, 0});
        return spec;
    };
    const auto roundTrip = [&](const CameraSpec& spec, const std::string& name) {
        const auto files = cameraInFormat(Camera(spec), cameraFormatNamed("nerfstudio"), "frame_7.png");
        writeText(dir / name, files.at(0).text);
        const CameraSet set = readCameraSet((dir / name).string(), &cameraFormatNamed("nerfstudio"));
        REQUIRE(set.cameras.at(0).refusal.empty());
        CameraSpec back = set.cameras.at(0).spec;
        back.projection.near = spec.projection.near, back.projection.far = spec.projection.far;
        const Camera a(spec), b(back);
        for (const glm::dvec3 p : {glm::dvec3(0.1, 0.2, -0.5), glm::dvec3(0.6, -0.1, -1), glm::dvec3(-0.4, 0.7, 0.2)}) {
            const auto pa = a.lens()->imageFromDirection(a.lensFrameFromEye(glm::dvec3(a.eyeFromWorld * glm::dvec4(p, 1))));
            const auto pb = b.lens()->imageFromDirection(b.lensFrameFromEye(glm::dvec3(b.eyeFromWorld * glm::dvec4(p, 1))));
            REQUIRE(pa.has_value() == pb.has_value());
            if (pa) requireNear(*pb, *pa);
        }
        return back.projection.lens;
    };
    const CameraSpec brown = specWith("brown_conrady", {-0.1, 0.02, -0.003, 0.0004, 0.001, -0.0005});
    REQUIRE(roundTrip(brown, "brown.json") == brown.projection.lens);
    const CameraSpec fisheye = specWith("opencv_fisheye", {0.02, -0.003, 0.0004, -0.00005});
    REQUIRE(roundTrip(fisheye, "fisheye.json") == fisheye.projection.lens);
    const CameraSpec prism = specWith("thin_prism_fisheye", {0.02, -0.003, 0.001, -0.002, 0.0004, -0.00005, 0, 0});
    REQUIRE(roundTrip(prism, "prism.json") == prism.projection.lens);
    const CameraSpec aria =
        specWith("fisheye624", {0.01, -0.003, 0.0004, -0.00002, 0.000001, 0, 0.0009, -0.0006, 0.0003, -0.0001, -0.0002, 0.00005});
    REQUIRE(roundTrip(aria, "aria.json") == aria.projection.lens);
    // OpenCV's k1, k2, p1, p2, k3 are brown_conrady's (k4 = 0).
    const CameraSpec opencv = specWith("opencv", {-0.1, 0.02, 0.001, -0.0005, -0.003});
    REQUIRE(roundTrip(opencv, "opencv.json") ==
            LensSpec{"brown_conrady", {310, 290, 319.5, 241.25, -0.1, 0.02, -0.003, 0, 0.001, -0.0005}});
    // Metashape's frame without skew: fx = f + b1, and its P1 is OpenCV's p2.
    CameraSpec metashape = specWith("brown_conrady", {});
    metashape.projection.lens = {"metashape_frame", {300, 319.5, 241.25, 2.5, 0, -0.1, 0.02, -0.003, 0.0004, 0.001, -0.0005}};
    REQUIRE(roundTrip(metashape, "metashape.json") ==
            LensSpec{"brown_conrady", {302.5, 300, 319.5, 241.25, -0.1, 0.02, -0.003, 0.0004, -0.0005, 0.001}});
    // The sphere, and a part of it.
    CameraSpec panorama = specWith("brown_conrady", {}, 2048, 1024);
    panorama.projection.lens = {"equirectangular", {-180, 180, -90, 90}};
    REQUIRE(roundTrip(panorama, "sphere.json") == panorama.projection.lens);
    panorama.projection.lens = {"equirectangular", {-100, 60, -45, 75}};
    const LensSpec part = roundTrip(panorama, "part.json");
    for (std::size_t i = 0; i < 4; ++i) REQUIRE(part.params[i] == Approx(panorama.projection.lens.params[i]).epsilon(1e-14));

    // What nerfstudio has no place for, by name.
    const auto refused = [&](const CameraSpec& spec) {
        try {
            cameraInFormat(Camera(spec), cameraFormatNamed("nerfstudio"), "x");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    REQUIRE_THAT(refused(specWith("opencv", {-0.1, 0.02, 0, 0, 0, 0.01})),
                 Catch::Contains("lens model opencv cannot be written as nerfstudio's transforms.json: k4 = 0.01, which "
                                 "camera_model OPENCV has no place for"));
    REQUIRE_THAT(refused(specWith("opencv", {0, 0, 0, 0, 0, 0, 0, 0, 0.001})),
                 Catch::Contains("s1 = 0.001"));
    REQUIRE_THAT(refused(specWith("thin_prism_fisheye", {0, 0, 0, 0, 0, 0, 0.001, 0})), Catch::Contains("sx1 = 0.001"));
    REQUIRE_THAT(refused(specWith("eucm", {0.6, 1.1})), Catch::Contains("lens model eucm cannot be written"));
    metashape.projection.lens.params[4] = 0.3;
    REQUIRE_THAT(refused(metashape), Catch::Contains("lens model metashape_frame cannot be written") &&
                                         Catch::Contains("b2 = 0.3"));
}
