// The pose and intrinsics rule (pose.h) against textbook rotations, hand-computed
// projections and the camera file, which must apply the same rule.
#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include "matrix_assert.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>

using namespace zcheck;

namespace {

// Projects a world point through a camera's matrices (the raster route's chain) to image
// coordinates: x right from the left edge, y down from the top edge, in pixels.
glm::dvec2 imagePointOf(const Camera& camera, const glm::dvec3& pWorld)
{
    const glm::dvec4 pClip = camera.clipFromWorld * glm::dvec4(pWorld, 1.0);
    const glm::dvec4 pWindow = camera.windowFromNdc * (pClip / pClip.w);
    return {pWindow.x, camera.imageYFromWindowY(pWindow.y)};
}

glm::dmat3 randomRotation(std::mt19937& random)
{
    std::normal_distribution<double> normal;
    const glm::dvec4 q = glm::normalize(glm::dvec4(normal(random), normal(random), normal(random), normal(random)));
    return rotationFromQuaternion(q.w, q.x, q.y, q.z, "q");
}

double rounded(double v, int decimals)
{
    const double scale = std::pow(10.0, decimals);
    return std::round(v * scale) / scale;
}

}  // namespace

TEST_CASE("rotationFromQuaternion is Hamilton's: 90 degrees about z turns x into y", "[pose]")
{
    const double h = std::sqrt(0.5);
    const glm::dmat3 r = rotationFromQuaternion(h, 0, 0, h, "q");  // w, x, y, z
    const glm::dvec3 x = r * glm::dvec3(1, 0, 0);
    REQUIRE(x.x == Approx(0).margin(1e-15));
    REQUIRE(x.y == Approx(1));
    REQUIRE(x.z == Approx(0).margin(1e-15));
    // 180 degrees about x (COLMAP's qvec 0 1 0 0): y → −y, z → −z.
    const glm::dmat3 flip = rotationFromQuaternion(0, 1, 0, 0, "q");
    REQUIRE(flip * glm::dvec3(0, 1, 0) == glm::dvec3(0, -1, 0));
    REQUIRE(flip * glm::dvec3(0, 0, 1) == glm::dvec3(0, 0, -1));
}

TEST_CASE("quaternionFromRotation inverts rotationFromQuaternion for random rotations", "[pose]")
{
    std::mt19937 random(7);
    for (int i = 0; i < 200; ++i) {
        const glm::dmat3 r = randomRotation(random);
        const glm::dvec4 q = quaternionFromRotation(r);
        REQUIRE(q.x >= 0);
        const glm::dmat3 back = rotationFromQuaternion(q.x, q.y, q.z, q.w, "q");
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k) REQUIRE(back[c][k] == Approx(r[c][k]).margin(1e-14));
    }
}

TEST_CASE("rotationFromQuaternion normalises a rounded quaternion and refuses a far one", "[pose]")
{
    double departure = -1;
    rotationFromQuaternion(0.70711, 0, 0, 0.70711, "qvec", &departure);
    REQUIRE(departure > 0);
    REQUIRE(departure < 1e-4);
    REQUIRE_THROWS_WITH(rotationFromQuaternion(1.1, 0, 0, 0, "images.txt line 5 qvec"),
                        Catch::StartsWith("'images.txt line 5 qvec' is not a unit quaternion: its norm is 1.1"));
    REQUIRE_THROWS_WITH(rotationFromQuaternion(0, 0, 0, 0, "q"), Catch::Contains("not a unit quaternion"));
    REQUIRE_THROWS_WITH(rotationFromQuaternion(NAN, 0, 0, 1, "q"), Catch::Contains("not finite"));
}

TEST_CASE("poseFromRotationTranslation is [R | t]: x_cam = R x_world + t, as OpenCV and COLMAP store a pose", "[pose]")
{
    std::mt19937 random(9);
    const glm::dmat3 r = randomRotation(random);
    const glm::dvec3 t(1, -2, 3), pWorld(0.5, 4, -7);
    const glm::dmat4 pose = poseFromRotationTranslation(r, t);
    REQUIRE(hasRigidLastRow(pose));
    const glm::dvec4 pCam = pose * glm::dvec4(pWorld, 1.0);
    const glm::dvec3 byHand = r * pWorld + t;
    for (int k = 0; k < 3; ++k) REQUIRE(pCam[k] == Approx(byHand[k]).margin(1e-12));
    REQUIRE(pCam.w == 1.0);
    // Not a rigid transform's last row: refused by the pose rule, whose first shape rule it is.
    glm::dmat4 projective = pose;
    projective[2][3] = 1e-9;
    REQUIRE_FALSE(hasRigidLastRow(projective));
    REQUIRE_THROWS_WITH(requireRigid(projective, +1, "P"),
                        "'P' must have the last row 0 0 0 1 (a rigid transform for column vectors)");
}

TEST_CASE("rigidInverse equals the general inverse of a rigid transform", "[pose]")
{
    std::mt19937 random(3);
    for (int i = 0; i < 50; ++i) {
        glm::dmat4 m(randomRotation(random));
        m[3] = glm::dvec4(1.5 * i, -2.0, 0.25 * i, 1.0);
        requireMatrixNear(rigidInverse(m), glm::inverse(m), 1e-13);
        requireMatrixNear(rigidInverse(m) * m, glm::dmat4(1.0), 1e-13);
    }
}

TEST_CASE("a pose rounded to 5 decimals is re-orthonormalised and noted, scale, shear and reflections are refused", "[pose]")
{
    std::mt19937 random(11);
    const glm::dmat3 exact = randomRotation(random);
    glm::dmat4 m(1.0);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) m[c][r] = rounded(exact[c][r], 5);
    m[3] = glm::dvec4(0.5, -1.25, 4.0, 1.0);

    const RigidTransform rigid = requireRigid(m, +1, "transform_matrix");
    REQUIRE(rigid.departure > kRotationExact);
    REQUIRE(rigid.departure < 3e-5);  // 5 decimals: each element off by ≤ 5e-6
    const glm::dmat3 repaired(rigid.matrix);
    const glm::dmat3 gram = glm::transpose(repaired) * repaired;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) {
            REQUIRE(gram[c][r] == Approx(c == r ? 1.0 : 0.0).margin(1e-15));
            REQUIRE(repaired[c][r] == Approx(exact[c][r]).margin(1e-5));  // the nearest rotation, not another
        }
    REQUIRE(glm::dvec3(rigid.matrix[3]) == glm::dvec3(m[3]));  // the translation is kept

    // An exact rotation is kept bit for bit.
    glm::dmat4 e(exact);
    REQUIRE(requireRigid(e, +1, "R").departure == 0);
    REQUIRE(requireRigid(e, +1, "R").matrix == e);

    glm::dmat4 scaled = m;
    for (int c = 0; c < 3; ++c) scaled[c] *= 1.001;
    scaled[3][3] = 1;
    REQUIRE_THROWS_WITH(requireRigid(scaled, +1, "R"),
                        Catch::StartsWith("'R' is not a rigid transform: its 3x3 rotation part is not orthonormal"));
    glm::dmat4 sheared(1.0);
    sheared[1][0] = 0.01;
    REQUIRE_THROWS_WITH(requireRigid(sheared, +1, "R"), Catch::Contains("scale or shear"));
    glm::dmat4 mirrored(1.0);
    mirrored[1][1] = -1;
    REQUIRE_THROWS_WITH(requireRigid(mirrored, +1, "R"),
                        Catch::StartsWith("the rotation of 'R' has determinant -1: a reflection"));
    REQUIRE_NOTHROW(requireRigid(mirrored, -1, "R"));  // direct3d's left-handed eye space
    glm::dmat4 projective(1.0);
    projective[2][3] = -1;
    REQUIRE_THROWS_WITH(requireRigid(projective, +1, "R"), Catch::Contains("last row 0 0 0 1"));
}

TEST_CASE("the camera applies the pose rule and reports the repair", "[pose][camera]")
{
    CameraSpec spec;
    spec.projection = Projection::perspective(50, 0.1, 50);
    spec.view.hasMatrix = true;
    spec.view.eyeFromWorld = glm::dmat4(1.0);
    spec.view.eyeFromWorld[0][0] = 0.999995;  // a rotation rounded to 5 decimals
    spec.view.eyeFromWorld[3] = glm::dvec4(0, 0, -5, 1);
    const Camera camera(spec);
    REQUIRE(camera.spec().view.rotationDeparture > 0);
    REQUIRE(camera.eyeFromWorld[0][0] == 1.0);
    const auto notes = cameraNotes(camera.spec());
    REQUIRE(notes.size() == 1);
    REQUIRE_THAT(notes[0], Catch::Contains("re-orthonormalised"));

    spec.convention = Convention::preset("direct3d");  // det +1 in a left-handed eye space: a mirror
    spec.view.eyeFromWorld[0][0] = 1;
    REQUIRE_THROWS_WITH(Camera(spec), Catch::Contains("the rotation of 'view.eye_from_world' has determinant 1"));
}

TEST_CASE("eyeFromEye turns OpenCV camera axes into OpenGL ones by 180 degrees about x", "[pose]")
{
    const Convention opencv = Convention::preset("opencv"), opengl = Convention::preset("opengl");
    glm::dmat4 expected(1.0);
    expected[1][1] = expected[2][2] = -1;
    REQUIRE(eyeFromEye(opengl, opencv) == expected);
    REQUIRE(eyeFromEye(opencv, opengl) == expected);
    REQUIRE(eyeFromEye(opengl, opengl) == glm::dmat4(1.0));
    glm::dmat4 zOnly(1.0);
    zOnly[2][2] = -1;
    REQUIRE(eyeFromEye(Convention::preset("direct3d"), opengl) == zOnly);
    REQUIRE(eyeHandedness(opengl) == 1);
    REQUIRE(eyeHandedness(opencv) == 1);
    REQUIRE(eyeHandedness(Convention::preset("direct3d")) == -1);
}

TEST_CASE("a COLMAP-style camera projects a known point where a hand computation puts it", "[pose]")
{
    // cam_from_world: the world turned 90° about y, then moved; K in COLMAP's pixel
    // coordinates (centre of the top-left pixel at 0.5).
    const double h = std::sqrt(0.5);
    const glm::dmat3 r = rotationFromQuaternion(h, 0, h, 0, "qvec");  // x → −z, z → x
    glm::dmat4 camFromWorld(r);
    camFromWorld[3] = glm::dvec4(0.1, -0.2, 3.0, 1.0);
    const PinholeIntrinsics k{500, 400, 330, 250, 0.5};
    CameraSpec spec;
    spec.width = 640, spec.height = 480;
    spec.projection = k.projection(0.1, 100, "cameras.txt");
    for (const std::string convention : {"opengl", "opencv", "direct3d", "vulkan"}) {
        spec.convention = Convention::preset(convention);
        spec.view = viewFromPose(camFromWorld, PoseDirection::CameraFromWorld, Convention::preset("opencv"),
                                 spec.convention, "qvec");
        const Camera camera(spec);
        // By hand: pCam = R·p + t. For p = (−0.4, 0.3, 0.2): R·p = (0.2, 0.3, 0.4), plus t =
        // (0.3, 0.1, 3.4); u = 500·0.3/3.4 + 330, v = 400·0.1/3.4 + 250 in corner coordinates,
        // which are image coordinates.
        const glm::dvec2 pImage = imagePointOf(camera, {-0.4, 0.3, 0.2});
        INFO(convention);
        REQUIRE(pImage.x == Approx(500 * 0.3 / 3.4 + 330).epsilon(1e-12));
        REQUIRE(pImage.y == Approx(400 * 0.1 / 3.4 + 250).epsilon(1e-12));
    }
    // The same pose stored camera-to-world in OpenGL axes (nerfstudio) is the same camera.
    glm::dmat4 worldFromCamGl = rigidInverse(camFromWorld) * eyeFromEye(Convention::preset("opencv"), Convention::preset("opengl"));
    spec.convention = Convention::preset("opengl");
    spec.view = viewFromPose(worldFromCamGl, PoseDirection::WorldFromCamera, Convention::preset("opengl"), spec.convention,
                             "transform_matrix");
    const glm::dvec2 pImage = imagePointOf(Camera(spec), {-0.4, 0.3, 0.2});
    REQUIRE(pImage.x == Approx(500 * 0.3 / 3.4 + 330).epsilon(1e-12));
    REQUIRE(pImage.y == Approx(400 * 0.1 / 3.4 + 250).epsilon(1e-12));
}

TEST_CASE("pinholeIntrinsicsOf gives the textbook focal lengths and principal points", "[pose]")
{
    CameraSpec spec;
    spec.width = 640, spec.height = 480;
    spec.projection = Projection::perspective(60, 0.1, 100);
    const PinholeIntrinsics colmap = pinholeIntrinsicsOf(Camera(spec), 0.5);
    REQUIRE(colmap.fy == Approx(240 / std::tan(glm::radians(30.0))));
    REQUIRE(colmap.fx == Approx(colmap.fy));
    REQUIRE(colmap.cx == Approx(320));
    REQUIRE(colmap.cy == Approx(240));
    const PinholeIntrinsics opencv = pinholeIntrinsicsOf(Camera(spec), 0.0);
    REQUIRE(opencv.cx == Approx(319.5));
    REQUIRE(opencv.cy == Approx(239.5));

    spec.projection.type = ProjectionType::Frustum;  // off-axis: the principal point moves
    spec.projection.left = -0.02, spec.projection.right = 0.06, spec.projection.bottom = -0.03, spec.projection.top = 0.03;
    const PinholeIntrinsics off = pinholeIntrinsicsOf(Camera(spec), 0.5);
    REQUIRE(off.fx == Approx(640 * 0.1 / 0.08));
    REQUIRE(off.cx == Approx(640 * 0.25));  // the axis a quarter of the way from the left edge
    REQUIRE(off.cy == Approx(240));
    spec.projection.type = ProjectionType::Orthographic;
    REQUIRE_THROWS_WITH(pinholeIntrinsicsOf(Camera(spec), 0.5), Catch::Contains("orthographic projection has no pinhole"));
}

TEST_CASE("the camera file inverts world_from_eye rigidly, as Python and the importers do", "[pose][camera]")
{
    // Regression: the camera file inverted world_from_eye with a general inverse while
    // Camera.from_opencv transposed; both now go through the pose rule.
    std::mt19937 random(5);
    glm::dmat4 worldFromEye(randomRotation(random));
    worldFromEye[3] = glm::dvec4(2, 3, 4, 1);
    std::string numbers;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            char text[40];
            std::snprintf(text, sizeof text, "%.17g", worldFromEye[c][r]);
            numbers += (numbers.empty() ? "" : ", ") + std::string(text);
        }
    const CameraSpec spec = cameraSpecFromJsonText(
        R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 9},
            "view": {"world_from_eye": [)" + numbers + R"(], "layout": "row-major", "vectors": "column"}})",
        "test");
    REQUIRE(spec.view.eyeFromWorld == rigidInverse(worldFromEye));
    // Rounded to 5 decimals it is accepted, re-orthonormalised, and noted.
    const CameraSpec rounded5 = cameraSpecFromJsonText(
        R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 9},
            "view": {"world_from_eye": [0.70711, -0.70711, 0, 1,  0.70711, 0.70711, 0, 2,  0, 0, 1, 3,  0, 0, 0, 1],
                     "layout": "row-major", "vectors": "column"}})",
        "test");
    REQUIRE(rounded5.view.rotationDeparture > 0);
    REQUIRE(Camera(rounded5).spec().view.rotationDeparture == rounded5.view.rotationDeparture);
    REQUIRE_THROWS_WITH(cameraSpecFromJsonText(
                            R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 9},
            "view": {"world_from_eye": [1, 0, 0, 0,  0, -1, 0, 0,  0, 0, 1, 3,  0, 0, 0, 1], "layout": "row-major", "vectors": "column"}})",
                            "camera file 'c.json'"),
                        Catch::StartsWith("camera file 'c.json': the rotation of 'view.world_from_eye' has determinant -1"));
}
