// Kalibr's camchain.yaml (format_kalibr.cpp) against Kalibr's own formulas, written out here from
// aslam_cv (ethz-asl/kalibr, aslam_cameras/implementation): DoubleSphereProjection (Usenko et al.
// 2018), PinholeProjection with RadialTangentialDistortion, OmniProjection, ExtendedUnifiedProjection.
// A keypoint there is in OpenCV's pixels (the top-left pixel's centre at (0, 0)): zcheck's image
// point is the keypoint + 0.5. Also: the chain of T_cn_cnm1, the mapping of every model, the
// refusals, and the writer's round trip.
#include "camera_test_support.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

using namespace zcheck;
using namespace zcheck::testing;

namespace {

std::string num(double value)
{
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

// A 4x4 (column vectors) as Kalibr writes T_cn_cnm1: a block list of flow rows at the key's indentation.
std::string matrixRows(const glm::dmat4& m)
{
    std::string out;
    for (int row = 0; row < 4; ++row)
        out += "  - [" + num(m[0][row]) + ", " + num(m[1][row]) + ", " + num(m[2][row]) + ", " + num(m[3][row]) + "]\n";
    return out;
}

glm::dmat4 rotationAboutY(double degrees)
{
    const double a = glm::radians(degrees);
    glm::dmat4 m(1.0);
    m[0][0] = std::cos(a), m[2][0] = std::sin(a), m[0][2] = -std::sin(a), m[2][2] = std::cos(a);
    return m;
}

glm::dmat4 rotationAboutX(double degrees)
{
    const double a = glm::radians(degrees);
    glm::dmat4 m(1.0);
    m[1][1] = std::cos(a), m[2][1] = -std::sin(a), m[1][2] = std::sin(a), m[2][2] = std::cos(a);
    return m;
}

glm::dmat4 withTranslation(glm::dmat4 m, const glm::dvec3& t)
{
    m[3] = glm::dvec4(t, 1.0);
    return m;
}

// cam1 from cam0: 3° about y after −1° about x, then t.
const glm::dmat4 kCam1FromCam0 = withTranslation(rotationAboutY(3) * rotationAboutX(-1), {-0.11, 0.0004, -0.0009});

// TUM-VI-like double sphere [xi, alpha, fu, fv, pu, pv] and EuRoC-like radtan pinhole.
const double kDs[6] = {-0.17724, 0.59163, 158.28, 158.27, 254.93, 256.87};
const double kPinhole[4] = {457.587, 456.134, 379.999, 255.238};
const double kRadtan[4] = {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05};

std::string camchain()
{
    return "cam0:\n"
           "  cam_overlaps: [1]\n"
           "  camera_model: ds\n"
           "  distortion_coeffs: []\n"
           "  distortion_model: none\n"
           "  intrinsics: [-0.17724, 0.59163, 158.28, 158.27, 254.93, 256.87]\n"
           "  resolution: [512, 512]\n"
           "  rostopic: /cam0/image_raw\n"
           "cam1:\n"
           "  T_cn_cnm1:\n" +
           matrixRows(kCam1FromCam0) +
           "  cam_overlaps: [0]\n"
           "  camera_model: pinhole\n"
           "  distortion_coeffs: [-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]\n"
           "  distortion_model: radtan\n"
           "  intrinsics: [457.587, 456.134, 379.999, 255.238]\n"
           "  resolution: [752, 480]\n"
           "  rostopic: /cam1/image_raw\n";
}

// DoubleSphereProjection::euclideanToKeypoint: d1 = |p|, k = ξ·d1 + z, d2 = √(x² + y² + k²),
// m = (x, y)/(α·d2 + (1 − α)·k), keypoint = (fu·mx + pu, fv·my + pv).
glm::dvec2 kalibrDoubleSphere(const double (&i)[6], const glm::dvec3& p)
{
    const double xi = i[0], alpha = i[1];
    const double d1 = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    const double k = xi * d1 + p.z;
    const double d2 = std::sqrt(p.x * p.x + p.y * p.y + k * k);
    const double norm = alpha * d2 + (1 - alpha) * k;
    return {i[2] * p.x / norm + i[4], i[3] * p.y / norm + i[5]};
}

// RadialTangentialDistortion::distort on m, then the pinhole's fu, fv, pu, pv.
glm::dvec2 kalibrRadtan(const double (&k)[4], const double (&d)[4], double mx, double my)
{
    const double mx2 = mx * mx, my2 = my * my, mxy = mx * my, rho2 = mx2 + my2;
    const double radial = d[0] * rho2 + d[1] * rho2 * rho2;
    const double x = mx + mx * radial + 2 * d[2] * mxy + d[3] * (rho2 + 2 * mx2);
    const double y = my + my * radial + 2 * d[3] * mxy + d[2] * (rho2 + 2 * my2);
    return {k[0] * x + k[2], k[1] * y + k[3]};
}

// The image point (pixel centres at +0.5) of a point of the world (cam0's frame) through an imported camera.
std::optional<glm::dvec2> imageOf(const CameraSpec& spec, const glm::dvec3& pWorld)
{
    const Camera camera(spec);
    REQUIRE(camera.lens());
    const glm::dvec3 pEye(camera.eyeFromWorld * glm::dvec4(pWorld, 1.0));
    return camera.lens()->imageFromDirection(camera.lensFrameFromEye(pEye));
}

void requireImage(const CameraSpec& spec, const glm::dvec3& pWorld, const glm::dvec2& keypoint)
{
    INFO("world point " << pWorld.x << ", " << pWorld.y << ", " << pWorld.z);
    const std::optional<glm::dvec2> pImage = imageOf(spec, pWorld);
    REQUIRE(pImage.has_value());
    requireNear(*pImage, keypoint + glm::dvec2(0.5));
}

std::string replaced(std::string text, const std::string& from, const std::string& to)
{
    const std::size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
}

std::string readError(const fs::path& path)
{
    try {
        (void)readCameraSet(path.string(), &cameraFormatNamed("kalibr"));
    } catch (const Error& e) {
        return e.what();
    }
    return "accepted";
}


}  // namespace

TEST_CASE("Kalibr camchain: a double-sphere cam0 and a radtan cam1 project as Kalibr's formulas, cam1 placed by T_cn_cnm1",
          "[import][kalibr]")
{
    const fs::path dir = scratch("kalibr");
    const fs::path path = dir / "camchain.yaml";
    writeText(path, camchain());
    // `zcheck camera camchain.yaml#cam1`: the format told by content, the frame by name, index or rostopic.
    REQUIRE(detectCameraFormat(path.string()).name == "kalibr");
    const CameraSet set = readCameraSet(path.string());
    REQUIRE(set.format == "kalibr");
    REQUIRE(set.cameras.size() == 2);
    REQUIRE(set.find("cam1") == 1);
    REQUIRE(set.find("1") == 1);
    REQUIRE(set.find("/cam1/image_raw") == 1);
    REQUIRE_THROWS_WITH(set.find(""), Catch::Contains("holds 2 cameras"));

    const CameraSpec& cam0 = set.cameras[0].spec;
    const CameraSpec& cam1 = set.cameras[1].spec;
    REQUIRE(set.cameras[0].refusal.empty());
    REQUIRE(set.cameras[1].refusal.empty());
    REQUIRE(cam0.width == 512);
    REQUIRE(cam1.width == 752);
    REQUIRE(cam1.height == 480);
    REQUIRE(cam0.convention.name == "opencv");
    // Kalibr's [xi, alpha, fu, fv, pu, pv] become double_sphere's fx, fy, cx, cy, xi, alpha; pu, pv
    // are already OpenCV's pixel coordinates.
    REQUIRE(cam0.projection.lens == LensSpec{"double_sphere", {158.28, 158.27, 254.93, 256.87, -0.17724, 0.59163}});
    REQUIRE(cam1.projection.lens ==
            LensSpec{"opencv", {457.587, 456.134, 379.999, 255.238, -0.28368365, 0.07451284, -0.00010473, -3.55590700e-05}});
    REQUIRE_THAT(cam0.notes.at(0), Catch::Contains("cam0's frame is the world"));

    // cam0 is the world; cam1's view is T_cn_cnm1 itself.
    const Camera camera1(cam1);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) REQUIRE(camera1.eyeFromWorld[c][r] == Approx(kCam1FromCam0[c][r]).margin(1e-15));
    REQUIRE(Camera(cam0).eyeFromWorld == glm::dmat4(1.0));

    const double s100 = std::sin(glm::radians(100.0)), c100 = std::cos(glm::radians(100.0));
    for (const glm::dvec3& p : {glm::dvec3(0.3, -0.2, 1.5), glm::dvec3(-1.2, 0.8, 0.9), glm::dvec3(0.05, 0.4, 2.0),
                                glm::dvec3(2.0, -1.1, 0.4),
                                // 100° from the axis: the double sphere sees behind its image plane
                                glm::dvec3(s100 * std::cos(0.5), s100 * std::sin(0.5), c100)}) {
        requireImage(cam0, p, kalibrDoubleSphere(kDs, p));
        const glm::dvec3 p1(kCam1FromCam0 * glm::dvec4(p, 1.0));
        if (p1.z > 0.5 && std::abs(p1.x / p1.z) < 0.8 && std::abs(p1.y / p1.z) < 0.6)  // inside cam1's image
            requireImage(cam1, p, kalibrRadtan(kPinhole, kRadtan, p1.x / p1.z, p1.y / p1.z));
    }
}

TEST_CASE("Kalibr camchain: the chain composes camN_from_cam0 = T_cN_cN-1 ... T_c1_c0, read by number not file order",
          "[import][kalibr]")
{
    const fs::path dir = scratch("kalibr_chain");
    const auto pinhole = [](const std::string& t) {
        return t + "  camera_model: pinhole\n  distortion_coeffs: []\n  distortion_model: none\n"
                   "  intrinsics: [400.0, 400.0, 319.5, 239.5]\n  resolution: [640, 480]\n";
    };
    const glm::dmat4 t1 = withTranslation(rotationAboutY(20), {-0.2, 0.01, 0.03});
    const glm::dmat4 t2 = withTranslation(rotationAboutX(-15) * rotationAboutY(5), {0.05, -0.3, 0.1});
    // As a hand-edited file may hold them: cam2 first; T as a nested flow list, wrapped.
    const auto flow = [](const glm::dmat4& m) {
        std::string out = "  T_cn_cnm1: [";
        for (int row = 0; row < 4; ++row)
            out += std::string(row ? ",\n    " : "") + "[" + num(m[0][row]) + ", " + num(m[1][row]) + ", " + num(m[2][row]) +
                   ", " + num(m[3][row]) + "]";
        return out + "]\n";
    };
    writeText(dir / "camchain.yaml", "cam2:\n" + pinhole(flow(t2)) + "cam0:\n" + pinhole("") + "cam1:\n" + pinhole(flow(t1)));
    const CameraSet set = readCameraSet((dir / "camchain.yaml").string(), &cameraFormatNamed("kalibr"));
    REQUIRE(set.cameras.at(2).name == "cam2");
    const glm::dvec3 p(0.4, -0.3, 2.5);
    const glm::dvec3 expected = glm::dvec3(t2 * glm::dvec4(glm::dvec3(t1 * glm::dvec4(p, 1.0)), 1.0));
    const glm::dvec3 pEye(Camera(set.cameras[2].spec).eyeFromWorld * glm::dvec4(p, 1.0));
    for (int i = 0; i < 3; ++i) REQUIRE(pEye[i] == Approx(expected[i]).margin(1e-14));
    REQUIRE(set.cameras[2].spec.projection.type == ProjectionType::Pinhole);  // pinhole + none: linear

    // PyYAML sorts the keys as text: cam10 comes before cam2, and is still the eleventh camera.
    std::string sorted;
    std::vector<std::string> keys;
    for (int n = 0; n <= 10; ++n) keys.push_back("cam" + std::to_string(n));
    std::sort(keys.begin(), keys.end());
    for (const std::string& key : keys) {
        const int n = std::stoi(key.substr(3));
        sorted += key + ":\n" + pinhole(n ? "  T_cn_cnm1:\n" + matrixRows(withTranslation(glm::dmat4(1.0), {-0.01 * n, 0, 0})) : "");
    }
    writeText(dir / "eleven.yaml", sorted);
    const CameraSet eleven = readCameraSet((dir / "eleven.yaml").string());
    REQUIRE(eleven.cameras.size() == 11);
    REQUIRE(eleven.cameras[10].name == "cam10");
    REQUIRE(Camera(eleven.cameras[10].spec).eyeFromWorld[3][0] == Approx(-0.55).margin(1e-14));  // 0.01·(1 + ... + 10)

    // A camera without T_cn_cnm1 is kept with its refusal, and so is every camera placed through it.
    writeText(dir / "gap.yaml", "cam0:\n" + pinhole("") + "cam1:\n" + pinhole("") + "cam2:\n" + pinhole(flow(t2)));
    const CameraSet gap = readCameraSet((dir / "gap.yaml").string());
    REQUIRE(gap.cameras[0].refusal.empty());
    REQUIRE_THAT(gap.cameras[1].refusal, Catch::Contains("cam1 has no T_cn_cnm1"));
    REQUIRE_THAT(gap.cameras[2].refusal, Catch::Contains("cam2 is placed through cam1"));
    REQUIRE_THROWS_WITH(gap.find("cam2"), Catch::Contains("placed through cam1"));
}

TEST_CASE("Kalibr camchain-imucam.yaml: T_cam_imu and timeshift beside the chain, flow lists wrapped as PyYAML wraps them",
          "[import][kalibr]")
{
    const fs::path dir = scratch("kalibr_imucam");
    const std::string text = "cam0:\n"
                             "  T_cam_imu:\n" +
                             matrixRows(withTranslation(rotationAboutX(90), {0.02, -0.07, 0.01})) +
                             "  cam_overlaps: []\n"
                             "  camera_model: omni\n"
                             "  distortion_coeffs: [-0.33518750, 0.13211436, 0.00055967,\n"
                             "    0.00057686]\n"
                             "  distortion_model: radtan\n"
                             "  intrinsics: [0.80065662, 833.006, 830.345, 373.850, 253.749]\n"
                             "  resolution: [752, 480]\n"
                             "  rostopic: /cam0/image_raw\n"
                             "  timeshift_cam_imu: -8.121e-05\n";
    writeText(dir / "camchain-imucam.yaml", text);
    REQUIRE(detectCameraFormat((dir / "camchain-imucam.yaml").string()).name == "kalibr");
    const CameraSpec spec = readCameraSet((dir / "camchain-imucam.yaml").string()).cameras.at(0).spec;
    REQUIRE(spec.projection.lens ==
            LensSpec{"unified", {833.006, 830.345, 373.850, 253.749, 0.80065662, -0.33518750, 0.13211436, 0.00055967, 0.00057686}});
    // OmniProjection::euclideanToKeypoint: m = (x, y)/(z + ξ|p|), radtan on m, then fu, fv, pu, pv.
    const double k[4] = {833.006, 830.345, 373.850, 253.749}, d[4] = {-0.33518750, 0.13211436, 0.00055967, 0.00057686};
    for (const glm::dvec3& p : {glm::dvec3(0.3, -0.2, 1.5), glm::dvec3(-0.4, 0.25, 1.0)}) {
        const double norm = p.z + 0.80065662 * glm::length(p);
        requireImage(spec, p, kalibrRadtan(k, d, p.x / norm, p.y / norm));
    }
    // The IMU's transform is checked by the pose rule, though not used.
    writeText(dir / "bad_imu.yaml", replaced(text, "  T_cam_imu:\n", "  T_cam_imu:\n  - [2, 0, 0, 0]\n  - [0, 1, 0, 0]\n"
                                                                      "  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n  X_unused:\n"));
    REQUIRE_THAT(readError(dir / "bad_imu.yaml"), Catch::Contains("'cam0.T_cam_imu' is not a rigid transform"));
}

TEST_CASE("Kalibr camchain: every camera_model and distortion_model pairing Kalibr builds is its lens model", "[import][kalibr]")
{
    const fs::path dir = scratch("kalibr_models");
    struct Case {
        const char* model;
        const char* intrinsics;
        const char* distortion;
        const char* coefficients;
        LensSpec lens;  // model "" for the linear pinhole
    };
    const Case cases[] = {
        {"pinhole", "[190.97, 190.98, 254.93, 256.89]", "equidistant", "[0.0034824, 0.000715, -0.0020532, 0.00020294]",
         {"opencv_fisheye", {190.97, 190.98, 254.93, 256.89, 0.0034824, 0.000715, -0.0020532, 0.00020294}}},
        {"pinhole", "[300.0, 300.0, 255.5, 255.5]", "equidistant", "[0.0, 0.0, 0.0, 0.0]",  // still a fisheye
         {"opencv_fisheye", {300, 300, 255.5, 255.5, 0, 0, 0, 0}}},
        {"pinhole", "[300.0, 301.0, 255.5, 250.5]", "fov", "[0.92]", {"fov", {300, 301, 255.5, 250.5, 0.92}}},
        {"pinhole", "[300.0, 301.0, 255.5, 250.5]", "fov", "[0.0]", {}},
        {"pinhole", "[300.0, 301.0, 255.5, 250.5]", "radtan", "[0.0, 0.0, 0.0, 0.0]", {}},
        {"pinhole", "[300.0, 301.0, 255.5, 250.5]", "none", "[]", {}},
        {"omni", "[0.9, 300.0, 301.0, 255.5, 250.5]", "none", "[]", {"unified", {300, 301, 255.5, 250.5, 0.9}}},
        {"eucm", "[0.59, 1.12, 160.0, 161.0, 255.5, 250.5]", "none", "[]", {"eucm", {160, 161, 255.5, 250.5, 0.59, 1.12}}},
    };
    for (const Case& c : cases) {
        INFO(c.model << " + " << c.distortion << " " << c.coefficients);
        writeText(dir / "c.yaml", std::string("cam0:\n  camera_model: ") + c.model + "\n  distortion_coeffs: " + c.coefficients +
                                      "\n  distortion_model: " + c.distortion + "\n  intrinsics: " + c.intrinsics +
                                      "\n  resolution: [512, 512]\n");
        const CameraSpec spec = readCameraSet((dir / "c.yaml").string()).cameras.at(0).spec;
        if (c.lens.model.empty()) {
            REQUIRE(spec.projection.type == ProjectionType::Pinhole);
            REQUIRE(spec.projection.fx == 300);
            REQUIRE(spec.projection.cy == 250.5);  // pixel centre 0: cy as written
        } else {
            REQUIRE(spec.projection.lens == c.lens);
        }
    }
    // ExtendedUnifiedProjection::euclideanToKeypoint: d = √(β(x² + y²) + z²), m = (x, y)/(α·d + (1 − α)·z).
    const CameraSpec eucm = readCameraSet((dir / "c.yaml").string()).cameras.at(0).spec;
    const glm::dvec3 p(0.7, -0.4, 0.6);
    const double dist = std::sqrt(1.12 * (p.x * p.x + p.y * p.y) + p.z * p.z), norm = 0.59 * dist + 0.41 * p.z;
    requireImage(eucm, p, {160 * p.x / norm + 255.5, 161 * p.y / norm + 250.5});
    // The absent distortion_coeffs of a model without distortion read as [].
    writeText(dir / "bare.yaml", "cam0:\n  camera_model: ds\n  distortion_model: none\n"
                                 "  intrinsics: [-0.2, 0.6, 150.0, 150.0, 255.5, 255.5]\n  resolution: [512, 512]\n");
    REQUIRE(readCameraSet((dir / "bare.yaml").string()).cameras.at(0).spec.projection.lens.model == "double_sphere");
}

TEST_CASE("Kalibr camchain: what Kalibr refuses, or zcheck cannot read, is refused naming the line, key and rule",
          "[import][kalibr]")
{
    const fs::path dir = scratch("kalibr_refusals");
    const std::string base = camchain();
    const std::string ds = "  intrinsics: [-0.17724, 0.59163, 158.28, 158.27, 254.93, 256.87]\n";
    const std::string radtan = "  distortion_coeffs: [-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]\n";
    const std::string t0 = "  - [" + num(kCam1FromCam0[0][0]) + ", ";
    const struct {
        const char* name;
        std::string text;
        std::string message;
    } cases[] = {
        {"unknown-model", replaced(base, "camera_model: ds", "camera_model: kannala_brandt"),
         "'cam0.camera_model' is 'kannala_brandt', not one of Kalibr's camera models (pinhole, omni, eucm, ds)"},
        {"intrinsics-count", replaced(base, ds, "  intrinsics: [158.28, 158.27, 254.93, 256.87]\n"),
         "'cam0.intrinsics' holds 4 numbers; ds takes 6: [xi, alpha, fu, fv, pu, pv]"},
        {"non-rigid", replaced(base, t0, "  - [" + num(2 * kCam1FromCam0[0][0]) + ", "),
         "'cam1.T_cn_cnm1' is not a rigid transform"},
        {"reflection", replaced(base, "cam1:\n  T_cn_cnm1:\n", "cam1:\n  T_cn_cnm1: [[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n  X:\n"),
         "the rotation of 'cam1.T_cn_cnm1' has determinant -1"},
        {"no-resolution", replaced(base, "  resolution: [512, 512]\n", ""),
         "cam0 has no 'resolution' ([width, height]), which Kalibr requires"},
        {"bad-resolution", replaced(base, "[512, 512]", "[512.5, 512]"), "'cam0.resolution' must be [width, height]"},
        {"coefficient-count", replaced(base, radtan, "  distortion_coeffs: [-0.28, 0.07, 0.0, 0.0, 0.01]\n"),
         "'cam1.distortion_coeffs' holds 5 numbers; radtan takes 4: [k1, k2, p1, p2]"},
        {"unknown-distortion", replaced(base, "distortion_model: radtan", "distortion_model: rational"),
         "'cam1.distortion_model' is 'rational', not one of Kalibr's distortion models"},
        {"ds-radtan", replaced(replaced(base, "distortion_model: none", "distortion_model: radtan"), "distortion_coeffs: []",
                               "distortion_coeffs: [0.1, 0.0, 0.0, 0.0]"),
         "cam0: camera_model ds with distortion_model radtan is not a camera Kalibr builds"},
        {"fov-range", replaced(replaced(base, "distortion_model: radtan", "distortion_model: fov"), radtan,
                               "  distortion_coeffs: [0.3]\n"),
         "w is 0.3: Kalibr's fov distortion takes w in [0.5, 1.5], or 0"},
        {"ds-alpha", replaced(base, ds, "  intrinsics: [-0.17724, 1.0, 158.28, 158.27, 254.93, 256.87]\n"),
         "alpha is 1; ds takes 0 ≤ alpha < 1"},
        {"negative-principal-point", replaced(base, "255.238]", "-255.238]"), "must not be negative"},
        {"not-finite", replaced(base, "158.27, 254.93", ".nan, 254.93"), "'cam0.intrinsics' must hold finite numbers, found '.nan'"},
        {"quoted-number", replaced(base, "158.27, 254.93", "'158.27', 254.93"), "must hold finite numbers, found '158.27'"},
        {"lens-model-range", replaced(base, ds, "  intrinsics: [-1.5, 0.5, 158.28, 158.27, 254.93, 256.87]\n"),
         "cam0: lens model double_sphere: 'xi' must lie in (-1, 1), got -1.5"},
        {"not-a-camera", base + "imu0:\n  rostopic: /imu0\n", "the top-level key 'imu0' is not a camera cam0, cam1, ..."},
        {"gap", replaced(base, "cam1:\n", "cam2:\n"), "'cam2' in a chain of 2 cameras: Kalibr numbers them cam0 to cam1"},
        {"t-shape", replaced(base, "  T_cn_cnm1:\n", "  T_cn_cnm1:\n  - [0, 0, 0, 1]\n  X:\n"),
         "'cam1.T_cn_cnm1' must be a 4x4 matrix: a list of 4 rows of 4 numbers"},
        {"cam0-t", replaced(base, "  cam_overlaps: [1]\n", "  T_cn_cnm1: [[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"),
         "'cam0.T_cn_cnm1' is not the identity"},
        {"block-scalar", replaced(base, "rostopic: /cam0/image_raw", "rostopic: |"), "block scalars"},
    };
    for (const auto& c : cases) {
        INFO(c.name);
        const fs::path path = dir / (std::string(c.name) + ".yaml");
        writeText(path, c.text);
        const std::string error = readError(path);
        REQUIRE_THAT(error, Catch::StartsWith("Kalibr camchain '" + path.string() + "': line "));
        REQUIRE_THAT(error, Catch::Contains(c.message));
    }
}

TEST_CASE("Kalibr camchain: detection takes a cam0 key with a camera_model and leaves ROS's files alone", "[import][kalibr]")
{
    const fs::path dir = scratch("kalibr_detect");
    // Some camera_calibration_parsers files carry a camera_model key beside camera_matrix.
    writeText(dir / "ros.yaml", "image_width: 640\nimage_height: 480\ncamera_name: cam0\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
                                "  data: [500, 0, 319.5, 0, 500, 239.5, 0, 0, 1]\ncamera_model: plumb_bob\n");
    REQUIRE(detectCameraFormat((dir / "ros.yaml").string()).name == "ros");
    writeText(dir / "camchain.yaml", "# from kalibr_calibrate_cameras\n" + camchain());
    REQUIRE(detectCameraFormat((dir / "camchain.yaml").string()).name == "kalibr");
    REQUIRE(&cameraFormatNamed("camchain") == &cameraFormatNamed("kalibr"));
}

