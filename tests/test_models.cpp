// Projection models and views beyond the foundation: each against its defining formula.
#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/precision.h"

#include "matrix_assert.h"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

using namespace zcheck;
using nlohmann::json;

namespace {

CameraSpec parse(const std::string& text) { return cameraSpecFromJson(json::parse(text), "test"); }

const std::string kView = R"("view": {"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0]})";

glm::dmat4 rowsOf(const json& rows)
{
    double m[4][4];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[r][c] = rows[r][c].get<double>();
    return matrixFromRows(m);
}

// Image position (x right, y down from the top edge) of a world point.
glm::dvec2 imageOf(const Camera& camera, const glm::dvec3& pWorld)
{
    const glm::dvec3 w = windowFromWorld(camera, pWorld);
    return {w.x, camera.imageYFromWindowY(w.y)};
}

}  // namespace

TEST_CASE("a pinhole camera projects as OpenCV's u = fx·X/Z + cx, v = fy·Y/Z + cy in every convention", "[models]")
{
    // Camera at the origin looking down world −z with world +y up: OpenCV camera coordinates
    // of a world point are (x, −y, −z). OpenCV's pixel u has the centre of the leftmost
    // pixel at 0, zcheck's image x has it at 0.5.
    const double fx = 410.0, fy = 395.0, cx = 300.25, cy = 250.5;
    for (const auto& convention : Convention::presetNames())
        for (bool reversed : {false, true}) {
            CameraSpec spec = parse(R"({"image": {"width": 640, "height": 480}, "projection": {"type": "pinhole",
                "fx": 410, "fy": 395, "cx": 300.25, "cy": 250.5, "near": 0.1, "far": 50}, )" + kView + "}");
            spec.convention = Convention::preset(convention);
            spec.depth.reversed = reversed;
            const Camera camera(spec);
            for (const glm::dvec3 p : {glm::dvec3(0.3, -0.2, -2.0), glm::dvec3(-1.1, 0.7, -3.5), glm::dvec3(0, 0, -1)}) {
                const double X = p.x, Y = -p.y, Z = -p.z;
                const glm::dvec2 image = imageOf(camera, p);
                INFO(convention << (reversed ? " reversed" : "") << " point " << p.x << "," << p.y << "," << p.z);
                REQUIRE(image.x - 0.5 == Approx(fx * X / Z + cx).margin(1e-9));
                REQUIRE(image.y - 0.5 == Approx(fy * Y / Z + cy).margin(1e-9));
            }
            // A centred camera has cx = (width − 1)/2: the principal point is the image centre.
            CameraSpec centred = spec;
            centred.projection.cx = (640 - 1) / 2.0, centred.projection.cy = (480 - 1) / 2.0;
            const Camera c(centred);
            REQUIRE(c.left() == Approx(-c.right()).margin(1e-15));
            REQUIRE(c.top() == Approx(-c.bottom()).margin(1e-15));
        }
}

TEST_CASE("lens focal lengths give the textbook horizontal fields of view on a 36 mm sensor", "[models]")
{
    // 20 mm ≈ 84°, 50 mm ≈ 40°, 85 mm ≈ 24° (horizontal): hfov = 2·atan(18 / f).
    for (auto [focal, approx] : {std::pair{20.0, 84.0}, std::pair{50.0, 40.0}, std::pair{85.0, 24.0}}) {
        CameraSpec spec = parse(R"({"projection": {"type": "lens", "focal_mm": )" + std::to_string(focal) +
                                R"(, "near": 0.1, "far": 50}, )" + kView + "}");
        const Camera camera(spec);
        const double hfov = glm::degrees(2 * std::atan(camera.right() / camera.nearDistance()));
        INFO(focal << " mm: " << hfov << " degrees");
        REQUIRE(hfov == Approx(glm::degrees(2 * std::atan(18.0 / focal))).epsilon(1e-12));
        REQUIRE(std::abs(hfov - approx) < 0.5);
        // The image's aspect sets the vertical extent: square pixels.
        REQUIRE(camera.top() / camera.right() == Approx(480.0 / 640.0).epsilon(1e-12));
    }
    CameraSpec full = parse(R"({"projection": {"type": "lens", "focal_mm": 35, "sensor_width_mm": 23.5, "near": 0.1, "far": 50}, )" + kView + "}");
    REQUIRE(Camera(full).right() / 0.1 == Approx(23.5 / 70).epsilon(1e-12));
}

TEST_CASE("an oblique projection shifts a point d behind the near plane by λ·d·(cos a, sin a)", "[models]")
{
    for (auto [lambda, angle] : {std::pair{1.0, 45.0}, std::pair{0.5, 63.4}, std::pair{0.5, -30.0}})
        for (const auto& convention : Convention::presetNames()) {
            CameraSpec spec = parse(R"({"image": {"width": 600, "height": 400}, "projection": {"type": "oblique",
                "left": -3, "right": 3, "bottom": -2, "top": 2, "near": 1, "far": 9, "angle_deg": )" +
                                    std::to_string(angle) + R"(, "foreshortening": )" + std::to_string(lambda) + "}, " +
                                    kView + "}");
            spec.convention = Convention::preset(convention);
            const Camera camera(spec);
            const double pixelsPerUnit = 100.0;  // 600 px over 6 units, 400 over 4
            const glm::dvec2 onNear = imageOf(camera, {0.4, -0.3, -1.0});
            for (double d : {0.5, 2.0, 7.5}) {
                const glm::dvec2 behind = imageOf(camera, {0.4, -0.3, -1.0 - d});
                INFO(convention << " λ " << lambda << " angle " << angle << " d " << d);
                REQUIRE((behind.x - onNear.x) / pixelsPerUnit ==
                        Approx(lambda * d * std::cos(glm::radians(angle))).margin(1e-9));
                REQUIRE(-(behind.y - onNear.y) / pixelsPerUnit ==  // image y grows downwards
                        Approx(lambda * d * std::sin(glm::radians(angle))).margin(1e-9));
            }
            // The near plane is unmoved: a point on it lands where the orthographic box says.
            REQUIRE(onNear.x == Approx(300 + 40).margin(1e-9));
            REQUIRE(onNear.y == Approx(200 + 30).margin(1e-9));
            // Rays are parallel to each other but not perpendicular to the image plane.
            const EyePlaneRay a = worldEyePlaneRayThroughWindow(camera, {10.5, 20.5});
            const EyePlaneRay b = worldEyePlaneRayThroughWindow(camera, {500.5, 300.5});
            REQUIRE(glm::length(a.direction - b.direction) < 1e-12);
            REQUIRE(std::abs(a.direction.z) < 1 - 1e-3);
        }
}

TEST_CASE("axonometric views foreshorten the world axes as their names say", "[models]")
{
    auto foreshortening = [](const std::string& view) {
        const CameraSpec spec = parse(R"({"projection": {"type": "orthographic", "left": -5, "right": 5,
            "bottom": -5, "top": 5, "near": 1, "far": 40}, "image": {"width": 500, "height": 500}, "view": )" + view + "}");
        const Camera camera(spec);
        const glm::dvec3 target(1, 2, 3);
        const glm::dvec2 origin = imageOf(camera, target);
        glm::dvec3 lengths;
        for (int axis = 0; axis < 3; ++axis) {
            glm::dvec3 unit(0.0);
            unit[axis] = 1.0;
            lengths[axis] = glm::length(imageOf(camera, target + unit) - origin);
        }
        return lengths;
    };
    const glm::dvec3 iso = foreshortening(R"({"axonometric": "isometric", "target": [1, 2, 3], "distance": 10})");
    REQUIRE(iso.x == Approx(iso.y).epsilon(1e-12));
    REQUIRE(iso.y == Approx(iso.z).epsilon(1e-12));
    REQUIRE(iso.x == Approx(50 * std::sqrt(2.0 / 3.0)).epsilon(1e-12));  // 50 px per unit × √(2/3)
    const glm::dvec3 di = foreshortening(R"({"axonometric": "dimetric", "target": [1, 2, 3], "distance": 10, "elevation_deg": 20})");
    REQUIRE(di.x == Approx(di.z).epsilon(1e-12));
    REQUIRE(std::abs(di.y - di.x) > 1.0);
    const glm::dvec3 tri = foreshortening(R"({"axonometric": "trimetric", "target": [1, 2, 3], "distance": 10, "azimuth_deg": 20, "elevation_deg": 25})");
    REQUIRE(std::abs(tri.x - tri.y) > 1.0);
    REQUIRE(std::abs(tri.y - tri.z) > 1.0);
    REQUIRE(std::abs(tri.x - tri.z) > 1.0);
    // Isometric: the eye looks along (−1, −1, −1) from the (+,+,+) octant, elevation 35.264°.
    const CameraSpec spec = parse(R"({"projection": {"type": "orthographic", "left": -5, "right": 5, "bottom": -5, "top": 5,
        "near": 1, "far": 40}, "view": {"axonometric": "isometric", "target": [0, 0, 0], "distance": 10}})");
    REQUIRE(glm::length(spec.view.eye - glm::dvec3(10 / std::sqrt(3.0))) < 1e-12);
    REQUIRE(spec.view.elevationDeg == Approx(35.2643896827547).epsilon(1e-12));
}

TEST_CASE("raw matrices equal the cameras they were taken from, in every layout", "[models][matrix]")
{
    const double fovy = glm::radians(50.0), aspect = 640.0 / 480.0, n = 0.2, f = 30;
    const glm::dvec3 eye(1, 2, 5), target(0, 0.5, 0), up(0, 1, 0);
    auto flat = [](const glm::dmat4& m, bool rowMajor) {
        json v = json::array();
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) v.push_back(rowMajor ? m[j][i] : m[i][j]);
        return v;
    };
    SECTION("opengl: GLM's column-major arrays pasted as they are stored")
    {
        json doc = {{"convention", "opengl"},
                    {"projection", {{"type", "matrix"}, {"clip_from_eye", flat(glm::perspectiveRH_NO(fovy, aspect, n, f), false)},
                                    {"layout", "column-major"}, {"vectors", "column"}}},
                    {"view", {{"eye_from_world", flat(glm::lookAtRH(eye, target, up), false)}, {"layout", "column-major"}, {"vectors", "column"}}}};
        const Camera fromMatrix(cameraSpecFromJson(doc, "test"));
        CameraSpec reference;
        reference.projection = Projection::perspective(50.0, n, f);
        reference.view = View::lookAt(eye, target, up);
        const Camera expected(reference);
        requireMatrixNear(fromMatrix.clipFromWorld, expected.clipFromWorld);
        REQUIRE(fromMatrix.nearDistance() == Approx(n).epsilon(1e-12));
        REQUIRE(fromMatrix.farDistance() == Approx(f).epsilon(1e-12));
        REQUIRE(fromMatrix.spec().projection.isPerspective());
    }
    SECTION("direct3d: D3DXMatrixPerspectiveFovLH as written, row vectors, with world_from_eye")
    {
        const double d = 1 / std::tan(fovy / 2);
        const double rowVector[4][4] = {{d / aspect, 0, 0, 0}, {0, d, 0, 0}, {0, 0, f / (f - n), 1}, {0, 0, -n * f / (f - n), 0}};
        CameraSpec reference;
        reference.convention = Convention::preset("direct3d");
        reference.projection = Projection::perspective(50.0, n, f);
        reference.view = View::lookAt(eye, target, up);
        const Camera expected(reference);
        json doc = {{"convention", "direct3d"},
                    {"projection", {{"type", "matrix"}, {"clip_from_eye", flat(matrixFromRows(rowVector), true)},
                                    {"layout", "row-major"}, {"vectors", "row"}}},
                    {"view", {{"world_from_eye", flat(glm::transpose(expected.worldFromEye), true)}, {"layout", "row-major"}, {"vectors", "row"}}}};
        const Camera fromMatrix(cameraSpecFromJson(doc, "test"));
        requireMatrixNear(fromMatrix.clipFromWorld, expected.clipFromWorld);
        requireMatrixNear(fromMatrix.eyeFromWorld, expected.eyeFromWorld);
    }
    SECTION("an infinite-far matrix is recognised")
    {
        json doc = {{"projection", {{"type", "matrix"}, {"clip_from_eye", flat(glm::infinitePerspectiveRH(fovy, aspect, n), false)},
                                    {"layout", "column-major"}, {"vectors", "column"}}},
                    {"view", {{"eye", {0, 0, 0}}, {"target", {0, 0, -1}}}}};
        const Camera camera(cameraSpecFromJson(doc, "test"));
        REQUIRE(camera.farIsInfinite());
        REQUIRE(camera.nearDistance() == Approx(n).epsilon(1e-12));
    }
}

TEST_CASE("bad matrices and models are refused with a message naming them", "[models][validation]")
{
    const std::string lookAt = R"("view": {"eye": [0, 0, 3], "target": [0, 0, 0]})";
    auto refuses = [](const std::string& text, const std::string& what) {
        INFO("expected a complaint about " << what);
        REQUIRE_THROWS_WITH(Camera(cameraSpecFromJson(json::parse(text), "test")), Catch::Contains(what));
    };
    const std::string identity = "[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]";
    const std::string zero = "[0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,0]";
    refuses(R"({"projection": {"type": "matrix", "clip_from_eye": )" + zero + R"(, "layout": "row-major", "vectors": "column"}, )" + lookAt + "}",
            "singular");
    refuses(R"({"projection": {"type": "matrix", "clip_from_eye": )" + identity + R"(, "layout": "row-major", "vectors": "column"}, )" + lookAt + "}",
            "clip_from_eye");  // orthographic identity: near at eye-z −1 for opengl, behind the eye
    refuses(R"({"projection": {"type": "matrix", "clip_from_eye": )" + identity + R"(, "layout": "diagonal", "vectors": "column"}, )" + lookAt + "}",
            "projection.layout");
    refuses(R"({"projection": {"type": "matrix", "clip_from_eye": [1,2,3], "layout": "row-major", "vectors": "column"}, )" + lookAt + "}",
            "16 numbers");
    refuses(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 9}, "view": {"eye_from_world": [2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,0,1], "layout": "row-major", "vectors": "column"}})",
            "not a rigid transform");
    refuses(R"({"projection": {"type": "pinhole", "fx": 0, "fy": 400, "cx": 1, "cy": 1, "near": 0.1, "far": 9}, )" + lookAt + "}", "projection.fx");
    refuses(R"({"projection": {"type": "lens", "focal_mm": -5, "near": 0.1, "far": 9}, )" + lookAt + "}", "projection.focal_mm");
    refuses(R"({"projection": {"type": "oblique", "left": -1, "right": 1, "bottom": -1, "top": 1, "near": 1, "far": 9, "angle_deg": 45, "foreshortening": -1}, )" + lookAt + "}",
            "projection.foreshortening");
    refuses(R"({"projection": {"type": "orthographic", "left": -1, "right": 1, "bottom": -1, "top": 1, "near": 1, "far": "inf"}, )" + lookAt + "}",
            "projection.far");
    refuses(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": "infinity"}, )" + lookAt + "}", "projection.far");
    refuses(R"({"projection": {"type": "orthographic", "left": -1, "right": 1, "bottom": -1, "top": 1, "near": 1, "far": 9}, "view": {"axonometric": "isometric", "target": [0,0,0], "distance": 10, "elevation_deg": 20}})",
            "view.elevation_deg");
    refuses(R"({"projection": {"type": "orthographic", "left": -1, "right": 1, "bottom": -1, "top": 1, "near": 1, "far": 9}, "view": {"axonometric": "planometric", "target": [0,0,0], "distance": 10}})",
            "view.axonometric");
}

TEST_CASE("far \"inf\" reads, builds an infinite-far camera and prints back", "[models]")
{
    const CameraSpec spec = parse(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": "inf"}, )" + kView + "}");
    REQUIRE(std::isinf(spec.projection.far));
    for (bool reversed : {false, true}) {
        CameraSpec s = spec;
        s.depth.reversed = reversed;
        const Camera camera(s);
        REQUIRE(camera.farIsInfinite());
        REQUIRE(camera.windowDepthFar() == (reversed ? 0.0 : 1.0));
        const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera, {320, 240});
        REQUIRE(std::isinf(ray.tFar));
        REQUIRE(windowDepthFromEyeZ(camera, {320, 240}, 1e9) == Approx(reversed ? 0.1 / 1e9 : 1 - 0.1 / 1e9).margin(1e-15));
    }
    REQUIRE(toJson(spec)["projection"]["far"] == "inf");
    REQUIRE(std::isinf(cameraSpecFromJson(toJson(spec), "round trip").projection.far));
}

TEST_CASE("zcheck matrices prints the textbook matrices", "[models][matrices]")
{
    SECTION("opengl: gluPerspective, the bottom-left viewport and the [-1,1] → [0,1] remap T(0,0,½)·S(1,1,½)")
    {
        const Camera camera(parse(R"({"convention": "opengl", "projection": {"type": "perspective", "fovy_deg": 60, "near": 0.5, "far": 80}, )" + kView + "}"));
        const json m = matricesJson(camera);
        const double n = 0.5, f = 80, a = 640.0 / 480, cot = 1 / std::tan(glm::radians(30.0));
        const double glu[4][4] = {{cot / a, 0, 0, 0}, {0, cot, 0, 0}, {0, 0, (f + n) / (n - f), 2 * f * n / (n - f)}, {0, 0, -1, 0}};
        requireMatrixNear(rowsOf(m["clip_from_eye"]), matrixFromRows(glu));
        requireMatrixNear(rowsOf(m["native"]["clip_from_eye"]), matrixFromRows(glu));
        const glm::dmat4 remap = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 0.5)) * glm::scale(glm::dmat4(1.0), glm::dvec3(1, 1, 0.5));
        const glm::dmat4 viewport = glm::translate(glm::dmat4(1.0), glm::dvec3(320, 240, 0)) * glm::scale(glm::dmat4(1.0), glm::dvec3(320, 240, 1));
        requireMatrixNear(rowsOf(m["window_from_ndc"]), viewport * remap);
        requireMatrixNear(rowsOf(m["ndc_from_window"]) * rowsOf(m["window_from_ndc"]), glm::dmat4(1.0));
        requireMatrixNear(rowsOf(m["eye_from_clip"]) * rowsOf(m["clip_from_eye"]), glm::dmat4(1.0));
        requireMatrixNear(rowsOf(m["world_from_eye"]) * rowsOf(m["eye_from_world"]), glm::dmat4(1.0));
    }
    SECTION("direct3d: the native block is D3DXMatrixPerspectiveFovLH in row-vector form, top-left viewport")
    {
        const Camera camera(parse(R"({"convention": "direct3d", "projection": {"type": "perspective", "fovy_deg": 60, "near": 0.5, "far": 80}, )" + kView + "}"));
        const json m = matricesJson(camera);
        const double n = 0.5, f = 80, a = 640.0 / 480, d = 1 / std::tan(glm::radians(30.0));
        const double lh[4][4] = {{d / a, 0, 0, 0}, {0, d, 0, 0}, {0, 0, f / (f - n), 1}, {0, 0, -n * f / (f - n), 0}};
        requireMatrixNear(rowsOf(m["native"]["clip_from_eye"]), matrixFromRows(lh));
        requireMatrixNear(rowsOf(m["clip_from_eye"]), glm::transpose(matrixFromRows(lh)));
        // D3D viewport (row vectors): x' = (x+1)·W/2, y' = (1−y)·H/2, z' = MinZ + z·(MaxZ − MinZ).
        const double viewport[4][4] = {{320, 0, 0, 0}, {0, -240, 0, 0}, {0, 0, 1, 0}, {320, 240, 0, 1}};
        requireMatrixNear(rowsOf(m["native"]["window_from_ndc"]), matrixFromRows(viewport));
    }
}

TEST_CASE("precision steps equal direct evaluation of neighbouring representable values", "[precision]")
{
    // Steps are differences of nearly equal eye-z values (a 2e-6 step at z = 80), so double
    // cancellation limits agreement to ~1e-6 relative: compared at 1e-5.
    // Perspective, near n, far f. Standard: w = f(z − n)/(z(f − n)), so z(w) = f·n/(f − w(f − n)).
    // Reversed: w = n(f − z)/(z(f − n)), so z(w) = n·f/(n + w(f − n)).
    const double n = 0.1, f = 100;
    const CameraSpec base = parse(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100}, )" + kView + "}");
    for (double z : {0.3, 2.0, 17.0, 80.0}) {
        const double wStandard = f * (z - n) / (z * (f - n)), wReversed = n * (f - z) / (z * (f - n));
        auto zStandard = [&](double w) { return f * n / (f - w * (f - n)); };
        auto zReversed = [&](double w) { return n * f / (n + w * (f - n)); };
        for (auto [format, bits] : {std::pair{DepthFormat::Unorm16, 16}, std::pair{DepthFormat::Unorm24, 24}}) {
            const double maxCode = std::ldexp(1.0, bits) - 1;
            const double s = std::round(wStandard * maxCode) / maxCode, r = std::round(wReversed * maxCode) / maxCode;
            CameraSpec standard = base, reversed = base;
            standard.depth.format = reversed.depth.format = format;
            reversed.depth.reversed = true;
            INFO("eye-z " << z << " unorm" << bits);
            REQUIRE(resolvableEyeZStep(Camera(standard), z) ==
                    Approx(zStandard(s + 1 / maxCode) - zStandard(s)).epsilon(1e-5));
            REQUIRE(resolvableEyeZStep(Camera(reversed), z) ==
                    Approx(zReversed(r - 1 / maxCode) - zReversed(r)).epsilon(1e-5));
        }
        CameraSpec standard = base, reversed = base;
        reversed.depth.reversed = true;
        const float s = float(wStandard), r = float(wReversed);
        INFO("eye-z " << z << " float32");
        REQUIRE(resolvableEyeZStep(Camera(standard), z) ==
                Approx(zStandard(std::nextafter(s, 2.0f)) - zStandard(s)).epsilon(1e-5));
        REQUIRE(resolvableEyeZStep(Camera(reversed), z) ==
                Approx(zReversed(std::nextafter(r, -1.0f)) - zReversed(r)).epsilon(1e-5));
    }
    // Beyond what unorm16 resolves near the far plane, the step is unresolvable.
    CameraSpec coarse = base;
    coarse.depth.format = DepthFormat::Unorm16;
    REQUIRE(std::isinf(resolvableEyeZStep(Camera(coarse), 99.99)));
}

TEST_CASE("the precision table recommends reversed float32 for a deep perspective camera", "[precision]")
{
    const CameraSpec spec = parse(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.01, "far": 10000}, )" + kView + "}");
    const PrecisionTable table = depthPrecision(spec);
    REQUIRE(table.layouts.size() == 12);  // 3 formats × standard, reversed, infinite, infinite reversed
    REQUIRE(table.distances.size() == 9);
    REQUIRE(table.distances.front() == Approx(0.01));
    const PrecisionLayout& best = table.layouts[table.best];
    REQUIRE(best.format == DepthFormat::Float32);
    REQUIRE((best.mapping == DepthMapping::Reversed || best.mapping == DepthMapping::InfiniteReversed));
    // Standard float32 is far worse than reversed at the far end: the lesson of reversed-Z.
    std::size_t standard = 0, reversed = 0;
    for (std::size_t k = 0; k < table.layouts.size(); ++k) {
        if (table.layouts[k].format != DepthFormat::Float32) continue;
        if (table.layouts[k].mapping == DepthMapping::Standard) standard = k;
        if (table.layouts[k].mapping == DepthMapping::Reversed) reversed = k;
    }
    REQUIRE(table.step[standard].back() > 100 * table.step[reversed].back());
    // Parallel projections have no infinite-far layouts; a distance outside [near, far] is refused.
    const CameraSpec ortho = parse(R"({"projection": {"type": "orthographic", "left": -1, "right": 1, "bottom": -1, "top": 1, "near": 1, "far": 50}, )" + kView + "}");
    REQUIRE(depthPrecision(ortho).layouts.size() == 6);
    REQUIRE_THROWS_WITH(depthPrecision(ortho, {0.5}), Catch::Contains("outside the camera's depth range"));
}
