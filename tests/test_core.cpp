// Core: conventions, cameras and the inverse-projection module, against textbook matrices,
// GLM's independent implementations and round trips.
#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/clip.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/lane_mask.h"
#include "zcheck/large_buffer.h"
#include "zcheck/tile_grid.h"

#include "binary32_shapes.h"
#include "matrix_assert.h"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cfenv>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

using namespace zcheck;

namespace {

CameraSpec specWith(const std::string& convention, ProjectionType type, bool reversed = false)
{
    CameraSpec spec;
    spec.convention = Convention::preset(convention);
    spec.width = 640;
    spec.height = 480;
    spec.projection.type = type;
    spec.projection.fovyDeg = 60;
    spec.projection.left = -0.3, spec.projection.right = 0.5;
    spec.projection.bottom = -0.2, spec.projection.top = 0.25;
    spec.projection.near = 0.5;
    spec.projection.far = 80;
    if (type == ProjectionType::Orthographic) {
        spec.projection.left = -4, spec.projection.right = 5, spec.projection.bottom = -3, spec.projection.top = 3.5;
    }
    spec.view = View::lookAt({1.0, 2.0, 6.0}, {0.2, 0.1, -1.0}, {0.1, 1.0, 0.0});
    spec.depth.reversed = reversed;
    return spec;
}

std::vector<CameraSpec> everyConventionAndProjection()
{
    std::vector<CameraSpec> specs;
    for (const auto& convention : Convention::presetNames())
        for (auto type : {ProjectionType::Perspective, ProjectionType::Frustum, ProjectionType::Orthographic})
            for (bool reversed : {false, true}) {
                CameraSpec spec = specWith(convention, type, reversed);
                spec.depth.rangeMin = 0.1;  // a depth range other than [0,1] too
                spec.depth.rangeMax = 0.9;
                specs.push_back(specWith(convention, type, reversed));
                specs.push_back(spec);
            }
    return specs;
}

std::string describe(const CameraSpec& s)
{
    return s.convention.name + " " + toString(s.projection.type) + (s.depth.reversed ? " reversed" : "") + " range [" +
           std::to_string(s.depth.rangeMin) + "," + std::to_string(s.depth.rangeMax) + "]";
}

}  // namespace

TEST_CASE("clipFromEye of the opengl preset is the textbook gluPerspective matrix", "[core][textbook]")
{
    const Camera camera(specWith("opengl", ProjectionType::Perspective));
    const double n = 0.5, f = 80, aspect = 640.0 / 480.0, cot = 1.0 / std::tan(glm::radians(60.0) / 2);
    const double rows[4][4] = {
        {cot / aspect, 0, 0, 0},
        {0, cot, 0, 0},
        {0, 0, (f + n) / (n - f), 2 * f * n / (n - f)},
        {0, 0, -1, 0},
    };
    requireMatrixNear(camera.clipFromEye, matrixFromRows(rows));
}

TEST_CASE("clipFromEye of the opengl preset is the textbook glFrustum matrix", "[core][textbook]")
{
    const Camera camera(specWith("opengl", ProjectionType::Frustum));
    const double l = -0.3, r = 0.5, b = -0.2, t = 0.25, n = 0.5, f = 80;
    const double rows[4][4] = {
        {2 * n / (r - l), 0, (r + l) / (r - l), 0},
        {0, 2 * n / (t - b), (t + b) / (t - b), 0},
        {0, 0, -(f + n) / (f - n), -2 * f * n / (f - n)},
        {0, 0, -1, 0},
    };
    requireMatrixNear(camera.clipFromEye, matrixFromRows(rows));
}

TEST_CASE("clipFromEye of the opengl preset is the textbook glOrtho matrix", "[core][textbook]")
{
    const Camera camera(specWith("opengl", ProjectionType::Orthographic));
    const double l = -4, r = 5, b = -3, t = 3.5, n = 0.5, f = 80;
    const double rows[4][4] = {
        {2 / (r - l), 0, 0, -(r + l) / (r - l)},
        {0, 2 / (t - b), 0, -(t + b) / (t - b)},
        {0, 0, -2 / (f - n), -(f + n) / (f - n)},
        {0, 0, 0, 1},
    };
    requireMatrixNear(camera.clipFromEye, matrixFromRows(rows));
}

TEST_CASE("clipFromEye of the direct3d preset is the transposed D3DXMatrixPerspectiveFovLH", "[core][textbook]")
{
    // Row-vector form (p' = p·M), left-handed, depth [0,1]: d = 1/tan(α/2), A = f/(f−n), B = −nf/(f−n).
    const Camera camera(specWith("direct3d", ProjectionType::Perspective));
    const double n = 0.5, f = 80, aspect = 640.0 / 480.0, d = 1.0 / std::tan(glm::radians(60.0) / 2);
    const double rowVectorForm[4][4] = {
        {d / aspect, 0, 0, 0},
        {0, d, 0, 0},
        {0, 0, f / (f - n), 1},
        {0, 0, -n * f / (f - n), 0},
    };
    requireMatrixNear(camera.clipFromEye, glm::transpose(matrixFromRows(rowVectorForm)));
}

TEST_CASE("a model's intrinsic parameters, changed by a focal scale, make the projection with eye x and y scaled", "[core]")
{
    // intrinsicParameters' changed values, written back into the camera, must give
    // clipFromEye · diag(k, k, 1, 1): eye x and y scaled before the projection.
    for (const ProjectionType type : {ProjectionType::Perspective, ProjectionType::Lens, ProjectionType::Pinhole}) {
        INFO(toString(type));
        CameraSpec spec = specWith("vulkan", type);
        spec.projection.fx = 600, spec.projection.fy = 560, spec.projection.cx = 300, spec.projection.cy = 250;
        const Camera declared(spec);
        const double k = 1.3;
        const std::vector<IntrinsicParameter> stated =
            intrinsicParameters(spec.projection, IntrinsicChange::FocalScale, {k, 0.5 /* not read */}, {7, 9});
        REQUIRE(stated.size() == (type == ProjectionType::Pinhole ? 2u : 1u));
        for (const IntrinsicParameter& parameter : stated) {
            const std::string key = parameter.key;
            double& value = key == "fovy_deg" ? spec.projection.fovyDeg
                            : key == "focal_mm" ? spec.projection.focalMm
                            : key == "fx"       ? spec.projection.fx
                                                : spec.projection.fy;
            REQUIRE(parameter.declared == value);
            value = parameter.changed;
        }
        requireMatrixNear(Camera(spec).clipFromEye, declared.clipFromEye * glm::dmat4(glm::dvec4(k, 0, 0, 0), glm::dvec4(0, k, 0, 0),
                                                                                      glm::dvec4(0, 0, 1, 0), glm::dvec4(0, 0, 0, 1)),
                          1e-12);
    }
    // Two scales and a moved principal point: only a pinhole states them, in fx, fy, cx, cy.
    Projection pinhole = specWith("opencv", ProjectionType::Pinhole).projection;
    pinhole.fx = 600, pinhole.fy = 560, pinhole.cx = 300, pinhole.cy = 250;
    const std::vector<IntrinsicParameter> stated =
        intrinsicParameters(pinhole, IntrinsicChange::FocalScalesAndPrincipalPoint, {1.5, 0.5}, {7, -9});
    REQUIRE(stated.size() == 4);
    CHECK(std::string(stated[0].key) + stated[1].key + stated[2].key + stated[3].key == "fxfycxcy");
    CHECK((stated[0].changed == 900 && stated[1].changed == 280 && stated[2].changed == 307 && stated[3].changed == 241));
    for (const ProjectionType type : {ProjectionType::Perspective, ProjectionType::Lens, ProjectionType::Frustum,
                                      ProjectionType::Orthographic, ProjectionType::Oblique, ProjectionType::Matrix}) {
        INFO(toString(type));
        const Projection p = specWith("opengl", type).projection;
        CHECK(intrinsicParameters(p, IntrinsicChange::FocalScalesAndPrincipalPoint, {1.5, 0.5}, {7, -9}).empty());
        if (type != ProjectionType::Perspective && type != ProjectionType::Lens)
            CHECK(intrinsicParameters(p, IntrinsicChange::FocalScale, {1.5, 1.5}, {0, 0}).empty());
    }
}

TEST_CASE("projection and view agree with GLM's independent implementations", "[core][glm]")
{
    const double fovy = glm::radians(60.0), aspect = 640.0 / 480.0, n = 0.5, f = 80;
    const glm::dvec3 eye(1.0, 2.0, 6.0), target(0.2, 0.1, -1.0), up(0.1, 1.0, 0.0);
    SECTION("opengl is perspectiveRH_NO and lookAtRH")
    {
        const Camera camera(specWith("opengl", ProjectionType::Perspective));
        requireMatrixNear(camera.clipFromEye, glm::perspectiveRH_NO(fovy, aspect, n, f));
        requireMatrixNear(camera.eyeFromWorld, glm::lookAtRH(eye, target, up));
    }
    SECTION("direct3d is perspectiveLH_ZO; its view is lookAtRH with eye z negated")
    {
        // zcheck's world is right-handed in every convention, so that one camera gives one
        // picture. GLM's lookAtLH (like D3DXMatrixLookAtLH) assumes a left-handed world and
        // takes x = up × forward: the mirror image, hence its x row negated here.
        const Camera camera(specWith("direct3d", ProjectionType::Perspective));
        requireMatrixNear(camera.clipFromEye, glm::perspectiveLH_ZO(fovy, aspect, n, f));
        const glm::dmat4 negateZ = glm::scale(glm::dmat4(1.0), glm::dvec3(1, 1, -1));
        const glm::dmat4 negateX = glm::scale(glm::dmat4(1.0), glm::dvec3(-1, 1, 1));
        requireMatrixNear(camera.eyeFromWorld, negateZ * glm::lookAtRH(eye, target, up));
        requireMatrixNear(camera.eyeFromWorld, negateX * glm::lookAtLH(eye, target, up));
    }
    SECTION("metal is perspectiveRH_ZO; vulkan is perspectiveRH_ZO with clip y negated")
    {
        requireMatrixNear(Camera(specWith("metal", ProjectionType::Perspective)).clipFromEye,
                          glm::perspectiveRH_ZO(fovy, aspect, n, f));
        glm::dmat4 flipped = glm::perspectiveRH_ZO(fovy, aspect, n, f);
        flipped[1][1] = -flipped[1][1];
        requireMatrixNear(Camera(specWith("vulkan", ProjectionType::Perspective)).clipFromEye, flipped);
    }
    SECTION("orthographic: orthoRH_NO for opengl, orthoLH_ZO for direct3d")
    {
        requireMatrixNear(Camera(specWith("opengl", ProjectionType::Orthographic)).clipFromEye,
                          glm::orthoRH_NO(-4.0, 5.0, -3.0, 3.5, n, f));
        requireMatrixNear(Camera(specWith("direct3d", ProjectionType::Orthographic)).clipFromEye,
                          glm::orthoLH_ZO(-4.0, 5.0, -3.0, 3.5, n, f));
    }
    SECTION("frustum: frustumRH_NO for opengl")
    {
        requireMatrixNear(Camera(specWith("opengl", ProjectionType::Frustum)).clipFromEye,
                          glm::frustumRH_NO(-0.3, 0.5, -0.2, 0.25, n, f));
    }
}

TEST_CASE("windowFromNdc is the textbook viewport for bottom-left and top-left origins", "[core][textbook]")
{
    SECTION("glViewport + glDepthRange(0,1): the [-1,1] depth remap T(0,0,1/2)·S(1,1,1/2)")
    {
        const Camera camera(specWith("opengl", ProjectionType::Perspective));
        const double rows[4][4] = {{320, 0, 0, 320}, {0, 240, 0, 240}, {0, 0, 0.5, 0.5}, {0, 0, 0, 1}};
        requireMatrixNear(camera.windowFromNdc, matrixFromRows(rows));
    }
    SECTION("Direct3D viewport, top-left origin, MinDepth 0.1 / MaxDepth 0.9")
    {
        CameraSpec spec = specWith("direct3d", ProjectionType::Perspective);
        spec.depth.rangeMin = 0.1, spec.depth.rangeMax = 0.9;
        const Camera camera(spec);
        const double rows[4][4] = {{320, 0, 0, 320}, {0, -240, 0, 240}, {0, 0, 0.8, 0.1}, {0, 0, 0, 1}};
        requireMatrixNear(camera.windowFromNdc, matrixFromRows(rows));
    }
}

TEST_CASE("the near and far planes map to the ends of the depth range, swapped by reversed-Z", "[core]")
{
    for (const CameraSpec& spec : everyConventionAndProjection()) {
        INFO(describe(spec));
        const Camera camera(spec);
        const glm::dvec2 centre(320, 240);
        for (double eyeZ : {spec.projection.near, spec.projection.far}) {
            const double expected = (eyeZ == spec.projection.near) != spec.depth.reversed ? spec.depth.rangeMin
                                                                                            : spec.depth.rangeMax;
            REQUIRE(windowDepthFromEyeZ(camera, centre, eyeZ) == Approx(expected).margin(1e-12));
        }
    }
}

TEST_CASE("window depth of a perspective camera matches the analytic formula in every convention", "[core]")
{
    // Standard: d = f(z − n) / (z (f − n)); reversed: d = n(f − z) / (z (f − n)); then the range.
    for (const auto& convention : Convention::presetNames())
        for (bool reversed : {false, true}) {
            const CameraSpec spec = specWith(convention, ProjectionType::Perspective, reversed);
            const Camera camera(spec);
            const double n = spec.projection.near, f = spec.projection.far;
            for (double z : {0.5, 0.7, 3.0, 41.0, 80.0}) {
                const double d = reversed ? n * (f - z) / (z * (f - n)) : f * (z - n) / (z * (f - n));
                INFO(convention << (reversed ? " reversed" : "") << " eye-z " << z);
                REQUIRE(windowDepthFromEyeZ(camera, {100.5, 33.5}, z) == Approx(d).margin(1e-13));
            }
        }
}

TEST_CASE("every transform round-trips through its inverse in every convention", "[core][property]")
{
    std::mt19937_64 random(20261121);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const CameraSpec& spec : everyConventionAndProjection()) {
        INFO(describe(spec));
        const Camera camera(spec);
        const double lo = std::min(camera.windowDepthNear(), camera.windowDepthFar());
        const double hi = std::max(camera.windowDepthNear(), camera.windowDepthFar());
        for (int k = 0; k < 200; ++k) {
            const glm::dvec3 pWindow(unit(random) * 640, unit(random) * 480, lo + (hi - lo) * unit(random));
            // window → eye → window
            const glm::dvec3 pEye = eyeFromWindow(camera, pWindow);
            const glm::dvec3 back = windowFromEye(camera, pEye);
            REQUIRE(back.x == Approx(pWindow.x).margin(1e-7));
            REQUIRE(back.y == Approx(pWindow.y).margin(1e-7));
            REQUIRE(back.z == Approx(pWindow.z).margin(1e-9));
            // the eye point lies in front, between near and far
            const double eyeZ = camera.eyeZOf(pEye);
            REQUIRE(eyeZ >= spec.projection.near * (1 - 1e-9));
            REQUIRE(eyeZ <= spec.projection.far * (1 + 1e-9));
            // window depth ↔ eye-z ↔ distance
            const glm::dvec2 pXY(pWindow);
            REQUIRE(eyeZFromWindowDepth(camera, pXY, pWindow.z) == Approx(eyeZ).epsilon(1e-9));
            REQUIRE(windowDepthFromEyeZ(camera, pXY, eyeZ) == Approx(pWindow.z).margin(1e-9));
            const double distance = distanceFromEyeZ(camera, pXY, eyeZ);
            REQUIRE(distance >= eyeZ * (1 - 1e-12));
            REQUIRE(eyeZFromDistance(camera, pXY, distance) == Approx(eyeZ).epsilon(1e-9));
            // the world ray through the window point passes through the world point
            const glm::dvec3 pWorld(camera.worldFromEye * glm::dvec4(pEye, 1.0));
            const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera, pXY);
            const double t = glm::dot(pWorld - ray.origin, ray.direction);
            REQUIRE(glm::length(ray.origin + t * ray.direction - pWorld) <= 1e-9 * (1 + glm::length(pWorld)));
            REQUIRE(t >= ray.tNear * (1 - 1e-9));
            REQUIRE(t <= ray.tFar * (1 + 1e-9));
            REQUIRE(t == Approx(distance).epsilon(1e-9));  // t along the eye-plane ray is the distance
            // world ↔ eye ↔ clip
            const glm::dvec4 pClip = camera.clipFromWorld * glm::dvec4(pWorld, 1.0);
            const glm::dvec4 again = camera.worldFromClip * pClip;
            REQUIRE(glm::length(glm::dvec3(again) / again.w - pWorld) <= 1e-9 * (1 + glm::length(pWorld)));
        }
    }
}

TEST_CASE("the same camera sees the same picture in every convention", "[core][property]")
{
    // A world point lands on the same image position (row 0 at the top) and at the same
    // eye-z, whatever the convention: conventions change numbers, never the image.
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (auto type : {ProjectionType::Perspective, ProjectionType::Frustum, ProjectionType::Orthographic}) {
        const Camera reference(specWith("opengl", type));
        for (int k = 0; k < 100; ++k) {
            const glm::dvec3 pWorld(unit(random) * 2, unit(random) * 2, unit(random) * 2 - 1);
            const glm::dvec3 w0 = windowFromWorld(reference, pWorld);
            const glm::dvec3 pEye0(reference.eyeFromWorld * glm::dvec4(pWorld, 1.0));
            for (const auto& name : Convention::presetNames()) {
                const Camera camera(specWith(name, type));
                const glm::dvec3 w = windowFromWorld(camera, pWorld);
                INFO(name << " " << toString(type));
                REQUIRE(w.x == Approx(w0.x).margin(1e-9));
                REQUIRE(camera.imageYFromWindowY(w.y) == Approx(reference.imageYFromWindowY(w0.y)).margin(1e-9));
                const glm::dvec3 pEye(camera.eyeFromWorld * glm::dvec4(pWorld, 1.0));
                REQUIRE(camera.eyeZOf(pEye) == Approx(reference.eyeZOf(pEye0)).margin(1e-12));
            }
        }
    }
}

TEST_CASE("pixel rays of a perspective camera pass through the hand-computed points", "[core]")
{
    // opengl, eye at the origin looking down −z, fovy 90°, square 2×2 image: the centre of
    // pixel (1,0) (top-right) sits at NDC (0.5, 0.5), so its ray points along (0.5, 0.5, −1).
    CameraSpec spec = specWith("opengl", ProjectionType::Perspective);
    spec.width = spec.height = 2;
    spec.projection.fovyDeg = 90;
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    for (const auto& name : {"opengl", "direct3d", "vulkan", "metal", "opencv"}) {
        spec.convention = Convention::preset(name);
        const Camera camera(spec);
        const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera, windowFromPixelCentre(camera, 1, 0));
        INFO(name);
        REQUIRE(glm::length(ray.origin) <= 1e-15);
        REQUIRE(glm::length(ray.direction - glm::normalize(glm::dvec3(0.5, 0.5, -1))) <= 1e-12);
        REQUIRE(ray.tNear == Approx(0.5 * std::sqrt(1.5)).epsilon(1e-12));
    }
}

TEST_CASE("storage quanta and quantization follow the formats' definitions", "[core]")
{
    REQUIRE(storageQuantum(DepthFormat::Unorm16, 0.3) == 1.0 / 65535);
    REQUIRE(storageQuantum(DepthFormat::Unorm24, 0.3) == 1.0 / 16777215);
    REQUIRE(storageQuantum(DepthFormat::Float32, 1.0) == std::ldexp(1.0, -23));
    REQUIRE(storageQuantum(DepthFormat::Float32, 0.75) == std::ldexp(1.0, -24));
    // float32's ulp above |value| is std::nextafter's step (the inline form adds one to the bits):
    // at zero, a subnormal, the largest normal's neighbours, negative and random values.
    const auto ulpAbove = [](double value) {
        const float magnitude = std::fabs(float(value));
        return double(std::nextafter(magnitude, INFINITY)) - double(magnitude);
    };
    std::mt19937_64 random(11);
    std::vector<double> values = {0.0, -0.0, 1e-45, -3e-39, 1.1754942e-38, 3.4028233e38, double(FLT_MAX), -0.3, 1e30};
    for (int k = 0; k < 100000; ++k) values.push_back(std::ldexp(double(random() % 100000 + 1), int(random() % 200) - 140));
    for (const double value : values) {
        INFO(value);
        REQUIRE(storageQuantum(DepthFormat::Float32, value) == ulpAbove(value));
    }
    REQUIRE(storageQuantum(DepthFormat::Float32, double(FLT_MAX)) == INFINITY);
    REQUIRE(std::isnan(storageQuantum(DepthFormat::Float32, INFINITY)));
    REQUIRE(std::isnan(storageQuantum(DepthFormat::Float32, NAN)));
    REQUIRE(quantizeDepth(DepthFormat::Unorm16, 0.5) == 32768.0 / 65535);  // round(0.5·65535) = 32768
    REQUIRE(quantizeDepth(DepthFormat::Unorm16, 1.2) == 1.0);
    REQUIRE(quantizeDepth(DepthFormat::Float32, 0.1) == double(0.1f));
}

namespace {
struct PlainRound {  // as zcheck's own sources may write it
    static double of(double x) { return double(float(x)); }
};
}  // namespace

TEST_CASE("regression: GCC 12's SLP vectoriser took double(float(x)) for x", "[core]")
{
    binary32_shapes::requireBothShapesRound<PlainRound>();
}

TEST_CASE("a unorm code's value without a division is the quotient code / (2^N - 1), every code of both formats", "[core]")
{
    // unormValue's claim, checked exhaustively: bit for bit the division's result (the divisor
    // read through a volatile, so that the division stays one).
    for (const DepthFormat format : {DepthFormat::Unorm24, DepthFormat::Unorm16}) {
        volatile double divisor = unormMax(format);
        const double maxCode = divisor;
        std::uint64_t differing = 0;
        double firstDiffering = -1;
        for (double code = 0; code <= maxCode; ++code) {
            const double quotient = code / divisor, value = unormValue(format, code);
            if (std::memcmp(&quotient, &value, sizeof value) != 0 && differing++ == 0) firstDiffering = code;
        }
        INFO(toString(format) << ": first differing code " << firstDiffering);
        REQUIRE(differing == 0);
        REQUIRE(unormValue(format, maxCode) == 1.0);
        REQUIRE(quantizeDepth(format, 0.25) == unormCode(format, 0.25) / divisor);
    }
}

TEST_CASE("the inline rounding to a depth code is std::nearbyint, halves to even, in every rounding mode", "[core]")
{
    // Halves round to even (0.5 -> 0, 1.5 -> 2, 2.5 -> 2), as nearbyint does in the default mode;
    // the largest unorm24 code and the values just below a half stay where nearbyint puts them.
    const double exact[][2] = {{0.0, 0.0}, {0.5, 0.0}, {1.5, 2.0}, {2.5, 2.0}, {16777214.5, 16777214.0},
                               {16777215.0, 16777215.0}, {std::nextafter(0.5, 0.0), 0.0}, {0.5000000000000001, 1.0}};
    for (const auto& [x, rounded] : exact) REQUIRE(nearbyintNonNegative(x) == rounded);
    REQUIRE(std::isnan(nearbyintNonNegative(NAN)));
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> depth(0.0, 1.0);
    for (const int mode : {FE_TONEAREST, FE_DOWNWARD, FE_UPWARD, FE_TOWARDZERO}) {
        std::fesetround(mode);
        for (int k = 0; k < 100000; ++k) {
            const double x = depth(random) * unormMax(DepthFormat::Unorm24);
            if (nearbyintNonNegative(x) != std::nearbyint(x)) FAIL("mode " << mode << ": " << x);
        }
        for (const auto& [x, rounded] : exact) REQUIRE(nearbyintNonNegative(x) == std::nearbyint(x));
    }
    std::fesetround(FE_TONEAREST);
}

TEST_CASE("clipping a triangle keeps what is inside the near and far planes", "[core]")
{
    // ZO volume: 0 ≤ z ≤ w. One vertex behind the near plane.
    const ClipPlanes planes = depthClipPlanes(0.0);
    const ClipPolygon polygon = clipTriangle({0, 0, -1, 1}, {1, 0, 0.5, 1}, {0, 1, 0.5, 1}, planes);
    REQUIRE(polygon.size == 4);
    for (int i = 0; i < polygon.size; ++i) {
        REQUIRE(polygon.pClip[i].z >= -1e-15);
        REQUIRE(polygon.pClip[i].z <= polygon.pClip[i].w);
    }
    REQUIRE(clipTriangle({0, 0, -1, 1}, {1, 0, -2, 1}, {0, 1, -0.5, 1}, planes).size == 0);
}

TEST_CASE("invalid cameras are refused with a message naming the parameter", "[core][validation]")
{
    auto refuses = [](CameraSpec spec, const std::string& key) {
        INFO("expected a complaint about " << key);
        REQUIRE_THROWS_WITH(Camera(spec), Catch::Contains(key));
    };
    CameraSpec good = specWith("opengl", ProjectionType::Perspective);
    REQUIRE_NOTHROW(Camera(good));
    CameraSpec s = good;
    s.projection.near = 0;
    refuses(s, "projection.near");
    s = good, s.projection.near = -1;
    refuses(s, "projection.near");
    s = good, s.projection.far = 0.5;
    refuses(s, "projection.far");
    s = good, s.projection.far = NAN;
    refuses(s, "projection.far");
    s = good, s.projection.fovyDeg = NAN;
    refuses(s, "projection.fovy_deg");
    s = good, s.projection.fovyDeg = 180;
    refuses(s, "projection.fovy_deg");
    s = good, s.width = 0;
    refuses(s, "image.width");
    s = good, s.height = 100000;
    refuses(s, "image.height");
    s = good, s.view.target = s.view.eye;
    refuses(s, "view.target");
    s = good, s.view.up = s.view.target - s.view.eye;
    refuses(s, "view.up");
    s = good, s.view.eye.x = NAN;
    refuses(s, "view.eye");
    s = good, s.depth.rangeMin = 0.8, s.depth.rangeMax = 0.2;
    refuses(s, "depth.range");
    s = specWith("opengl", ProjectionType::Frustum), s.projection.right = s.projection.left;
    refuses(s, "projection.right");
    s = specWith("opengl", ProjectionType::Orthographic), s.projection.far = INFINITY;
    refuses(s, "projection.far");
}

TEST_CASE("regression: a far/near ratio of exactly 1e12 was refused as exceeding 1e12", "[core][validation][regression]")
{
    // docs/camera.md: far/near <= 10^12. 1e8 / 1e-4 is 1e12 exactly in binary64.
    CameraSpec s = specWith("opengl", ProjectionType::Perspective);
    s.projection.near = 1e-4, s.projection.far = 1e8;
    REQUIRE(s.projection.far / s.projection.near == 1e12);
    REQUIRE_NOTHROW(Camera(s));
    s.projection.far = std::nextafter(1e8, INFINITY);
    REQUIRE_THROWS_WITH(Camera(s), Catch::Contains("'projection.far' / 'projection.near'") &&
                                       Catch::Contains("exceeds 1e12"));
}

TEST_CASE("an image side is a whole 1..16384 pixels and an image at most 2^25 pixels, at the bounds exactly", "[core][validation]")
{
    // Camera's rule, which the camera constructor and every importer and depth-map reader ask.
    for (const double side : {1.0, 2.0, 16383.0, 16384.0}) REQUIRE(Camera::isImageSide(side));
    for (const double side : {0.0, -1.0, 1.5, 16384.5, 16385.0, 1e300, double(NAN), double(INFINITY)})
        REQUIRE_FALSE(Camera::isImageSide(side));
    REQUIRE(Camera::isImageSize(8192, 4096));
    REQUIRE(Camera::isImageSize(16384, 2048));
    REQUIRE_FALSE(Camera::isImageSize(8192, 4097));
    REQUIRE_FALSE(Camera::isImageSize(16385, 1));
    REQUIRE_FALSE(Camera::isImageSize(0, 480));
    CameraSpec spec = specWith("opengl", ProjectionType::Perspective);
    spec.width = 16384, spec.height = 2;
    REQUIRE_NOTHROW(Camera(spec));
    spec.width = 16385;
    REQUIRE_THROWS_WITH(Camera(spec), "'image.width' must be in 1..16384 pixels, got 16385");
    spec.width = 8192, spec.height = 4097;
    REQUIRE_THROWS_WITH(Camera(spec), "image 8192x4097 has more than 33554432 pixels (8192x4096)");
}

TEST_CASE("the camera file is read strictly", "[core][validation]")
{
    const auto parse = [](const std::string& text) { return cameraSpecFromJson(nlohmann::json::parse(text), "test"); };
    const std::string projection = R"("projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100})";
    const std::string view = R"("view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]})";
    const CameraSpec spec = parse("{" + projection + "," + view + "}");
    REQUIRE(spec.convention.name == "opengl");
    REQUIRE(spec.width == 640);
    REQUIRE(spec.height == 480);
    REQUIRE(spec.depth.format == DepthFormat::Float32);
    REQUIRE_FALSE(spec.depth.reversed);
    REQUIRE(spec.depth.rangeMin == 0);
    REQUIRE(spec.depth.rangeMax == 1);
    // Round trip through toJson.
    const CameraSpec again = cameraSpecFromJson(toJson(spec), "round trip");
    REQUIRE(again.view.eye == spec.view.eye);
    REQUIRE(again.projection.far == spec.projection.far);

    REQUIRE_THROWS_WITH(parse("{" + view + "}"), Catch::Contains("'projection' is missing"));
    REQUIRE_THROWS_WITH(parse("{" + projection + "," + view + R"(, "colour": 1})"), Catch::Contains("unknown key 'colour'"));
    REQUIRE_THROWS_WITH(parse(R"({"projection": {"type": "perspective", "fovy_deg": "60", "near": 0.1, "far": 100},)" + view + "}"),
                        Catch::Contains("'projection.fovy_deg' must be a number"));
    REQUIRE_THROWS_WITH(parse(R"({"projection": {"type": "perspective", "fov": 60, "near": 0.1, "far": 100},)" + view + "}"),
                        Catch::Contains("projection.fovy_deg"));
    REQUIRE_THROWS_WITH(parse(R"({"projection": {"type": "fisheye", "near": 0.1, "far": 100},)" + view + "}"),
                        Catch::Contains("'projection.type'"));
    REQUIRE_THROWS_WITH(parse("{" + projection + "," + view + R"(, "convention": "glide"})"),
                        Catch::Contains("'convention'"));
    REQUIRE_THROWS_WITH(parse("{" + projection + "," + view + R"(, "depth": {"format": "unorm8"}})"),
                        Catch::Contains("'depth.format'"));
    REQUIRE_THROWS_WITH(parse("{" + projection + "," + view + R"(, "image": {"width": 64.5}})"),
                        Catch::Contains("'image.width' must be an integer"));
    REQUIRE_THROWS_WITH(parse(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 0, "far": 100},)" + view + "}"),
                        Catch::Contains("projection.near"));
    REQUIRE_THROWS_WITH(parse(R"({"projection": {"type": "perspective", "fovy_deg": 60, "near": 1, "far": 1},)" + view + "}"),
                        Catch::Contains("projection.far"));
    REQUIRE_THROWS_WITH(readCameraFile("/nonexistent/camera.json"), Catch::Contains("cannot read camera file"));
}

TEST_CASE("regression: messages printed 180 as 1.8e+02", "[core][regression]")
{
    REQUIRE(formatNumber(180) == "180");
    REQUIRE(formatNumber(0.1) == "0.1");
    REQUIRE(formatNumber(1e-4) == "0.0001");
    REQUIRE(formatNumber(123456789012345.0) == "123456789012345");
    REQUIRE(formatNumber(1e15) == "1e+15");
    REQUIRE(formatNumber(1.5e-5) == "1.5e-05");
    REQUIRE(formatNumber(-2.5) == "-2.5");
    for (double v : {180.0, 1.0 / 3.0, 6.02214076e23, -1e-300, 0.0})
        REQUIRE(std::strtod(formatNumber(v).c_str(), nullptr) == v);  // every form reads back exactly
}

TEST_CASE("a camera file with a key twice in one object is refused, naming the key by its path", "[core][camera-file]")
{
    const std::string view = R"("view": {"eye": [0, 1, 3], "target": [0, 0, 0]})";
    REQUIRE_THROWS_WITH(
        parseJsonStrictly(R"({"convention": "opengl", "convention": "vulkan"})", "camera file 'c.json'"),
        Catch::Equals("camera file 'c.json': key 'convention' appears twice in one object"));
    REQUIRE_THROWS_WITH(parseJsonStrictly(R"({"projection": {"near": 1, "far": 9, "near": 2}, )" + view + "}", "f"),
                        Catch::Contains("key 'projection.near' appears twice"));
    // The same key in two different objects is fine.
    REQUIRE_NOTHROW(parseJsonStrictly(R"({"a": {"x": 1}, "b": {"x": 2}, "c": [{"x": 1}, {"x": 2}]})", "f"));
}

TEST_CASE("cameras beyond what binary32 ray tracing can represent are refused, naming the bound", "[core]")
{
    CameraSpec spec;
    spec.projection = Projection::perspective(60, 0.1, 100);
    spec.view = View::lookAt({1e16, 0, 0}, {0, 0, 0}, {0, 1, 0});
    REQUIRE_THROWS_WITH(Camera(spec), Catch::Contains("eye") && Catch::Contains("1e+16") && Catch::Contains("1e15"));
    spec.view = View::lookAt({0, 0, 3}, {0, 0, 0}, {0, 1, 0});
    spec.projection.type = ProjectionType::Orthographic;
    spec.projection.left = -1e19, spec.projection.right = 1, spec.projection.bottom = -1, spec.projection.top = 1;
    REQUIRE_THROWS_WITH(Camera(spec), Catch::Contains("near-plane window") && Catch::Contains("1e15"));
    spec.projection.left = -1e14;  // within the bound
    REQUIRE_NOTHROW(Camera(spec));
}

TEST_CASE("a matrix written for row vectors is the transpose, in the camera file as in matrixForVectors", "[core][camera-file]")
{
    REQUIRE(matrixVectorsFromName("column") == MatrixVectors::Column);
    REQUIRE(matrixVectorsFromName("row") == MatrixVectors::Row);
    REQUIRE_FALSE(matrixVectorsFromName("columns"));
    const double rows[4][4] = {{1.2, 0, 0.3, 0}, {0, 1.5, -0.2, 0}, {0, 0, -1.002, -0.2002}, {0, 0, -1, 0}};
    const glm::dmat4 m = matrixFromRows(rows);
    REQUIRE(matrixForVectors(m, MatrixVectors::Column) == m);
    REQUIRE(matrixForVectors(m, MatrixVectors::Row) == glm::transpose(m));
    REQUIRE(matrixForVectors(matrixForVectors(m, MatrixVectors::Row), MatrixVectors::Row) == m);
    // p' = p·M for row vectors is p' = Mᵀ·p: the same point either way.
    const glm::dvec4 p(0.3, -0.2, -2, 1);
    const glm::dmat4 written = matrixForVectors(m, MatrixVectors::Row);
    glm::dvec4 rowTimesMatrix(0.0);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k) rowTimesMatrix[c] += p[k] * written[c][k];  // (p·W)_c = Σ_k p_k W[k][c]
    REQUIRE(rowTimesMatrix == m * p);
    // The camera file reads 16 numbers written for row vectors as their transpose.
    auto numbers = [](const glm::dmat4& matrix) {
        std::string out;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) out += (out.empty() ? "" : ", ") + formatNumber(matrix[c][r]);
        return out;
    };
    auto read = [&](const glm::dmat4& matrix, const std::string& vectors) {
        return cameraSpecFromJsonText(R"({"projection": {"type": "matrix", "clip_from_eye": [)" + numbers(matrix) +
                                          R"(], "layout": "row-major", "vectors": ")" + vectors +
                                          R"("}, "view": {"eye": [0, 0, 3], "target": [0, 0, 0]}})",
                                      "test")
            .projection.clipFromEye;
    };
    REQUIRE(read(written, "row") == read(m, "column"));
    REQUIRE_THROWS_WITH(read(m, "columns"), std::string("test: 'projection.vectors' must be ") + kMatrixVectorsNames);
}

TEST_CASE("each depth quantity is stored as the export quantity of its name", "[core][quantity]")
{
    REQUIRE(depthQuantityNames() == std::vector<std::string>{"window", "ndc", "eye-z", "distance"});
    for (const std::string& name : depthQuantityNames()) {
        const ExportQuantity stored = exportQuantityOf(depthQuantityFromName(name));
        REQUIRE(toString(stored) == name);
        REQUIRE(exportQuantityFromName(name) == stored);
    }
    REQUIRE(channelNameOf(exportQuantityOf(DepthQuantity::EyeZ)) == "Z");
    REQUIRE(exportQuantityFromName("primitive-id") == ExportQuantity::PrimitiveId);
    REQUIRE_THROWS_WITH(exportQuantityFromName("depth"),
                        "unknown quantity 'depth' (expected one of window, ndc, eye-z, distance, position-eye, "
                        "position-world, normal, primitive-id)");
}

TEST_CASE("regression: prettyJson rewrote number lists inside strings", "[json]")
{
    const nlohmann::json document = {{"explanation", "maps depth to [-1,1] instead of [0,1]"},
                                     {"file", "a[1,2].exr"},
                                     {"quoted", "say \"[3,4]\" twice"},
                                     {"row", {1, 2.5, -3}}};
    const std::string text = prettyJson(document);
    REQUIRE(text.find("\"maps depth to [-1,1] instead of [0,1]\"") != std::string::npos);
    REQUIRE(text.find("\"a[1,2].exr\"") != std::string::npos);
    REQUIRE(text.find("[3,4]") != std::string::npos);
    REQUIRE(text.find("[1, 2.5, -3]") != std::string::npos);  // numbers still fold onto one line
    REQUIRE(nlohmann::json::parse(text) == document);
}

TEST_CASE("a tile grid cuts the image into row-major tiles, the last ones cut by its edges", "[core][tiles]")
{
    // 203×131 pixels in 64-pixel tiles: 4 columns (64, 64, 64, 11 wide), 3 rows (64, 64, 3 high).
    const zcheck::TileGrid grid(203, 131, 64);
    CHECK(grid.tilesX() == 4);
    CHECK(grid.tilesY() == 3);
    CHECK(grid.count() == 12);
    auto same = [](const zcheck::PixelRect& r, int col0, int row0, int col1, int row1) {
        return r.col0 == col0 && r.row0 == row0 && r.col1 == col1 && r.row1 == row1;
    };
    CHECK(same(grid.rect(0), 0, 0, 64, 64));
    CHECK(same(grid.rect(3), 192, 0, 203, 64));
    CHECK(same(grid.rect(5), 64, 64, 128, 128));
    CHECK(same(grid.rect(11), 192, 128, 203, 131));
    CHECK(grid.rect(11).width() == 11);
    CHECK(grid.rect(11).height() == 3);
    CHECK(grid.firstPixel(5) == 64u * 203u + 64u);
    CHECK(grid.firstPixel(11) == 128u * 203u + 192u);

    // Every pixel lies in exactly one tile: tile (col / 64) + 4·(row / 64).
    std::vector<int> owner(203 * 131, -1);
    for (int tile = 0; tile < grid.count(); ++tile) {
        const zcheck::PixelRect r = grid.rect(tile);
        for (int row = r.row0; row < r.row1; ++row)
            for (int col = r.col0; col < r.col1; ++col) {
                REQUIRE(owner[std::size_t(row) * 203 + col] == -1);
                owner[std::size_t(row) * 203 + col] = tile;
            }
    }
    for (int row = 0; row < 131; ++row)
        for (int col = 0; col < 203; ++col) REQUIRE(owner[std::size_t(row) * 203 + col] == col / 64 + 4 * (row / 64));

    // An image smaller than one tile is one tile.
    const zcheck::TileGrid small(5, 3, 64);
    CHECK(small.count() == 1);
    CHECK(same(small.rect(0), 0, 0, 5, 3));
}

constexpr std::size_t kHugePage = std::size_t(2) << 20;  // the large buffers' page (large_buffer.h)

TEST_CASE("a LargeVector sits on 2 MiB boundaries and leaves elements made without a value as they were",
          "[core][large_buffer]")
{
    // A 1080p window-depth buffer: on a huge-page boundary, where the advice can take effect.
    LargeVector<double> depth;
    depth.resize(1920 * 1080);
    REQUIRE(reinterpret_cast<std::uintptr_t>(depth.data()) % kHugePage == 0);
    // resize() default-initialises: within the capacity, elements made again keep what the
    // memory held (std::vector's value-initialisation would have zeroed them; a renderer
    // writes every pixel and must not pay for a clear first).
    std::fill(depth.begin(), depth.end(), 0.25);
    depth.resize(10);
    depth.resize(1920 * 1080);
    REQUIRE(depth.back() == 0.25);
    REQUIRE(depth[1000] == 0.25);
    // Values given are values kept; small buffers come from operator new.
    const LargeVector<std::uint32_t> small(5, 7u);
    REQUIRE(std::vector<std::uint32_t>(small.begin(), small.end()) == std::vector<std::uint32_t>{7, 7, 7, 7, 7});
    LargeVector<float> filled;
    filled.assign(kHugePage, 1.5f);
    REQUIRE(filled.size() == kHugePage);
    REQUIRE(reinterpret_cast<std::uintptr_t>(filled.data()) % kHugePage == 0);
    REQUIRE(std::all_of(filled.begin(), filled.end(), [](float v) { return v == 1.5f; }));
}

TEST_CASE("a released large buffer is handed back, faulted in, to the next one of its size, and given up for any other",
          "[core][large_buffer]")
{
    constexpr std::size_t kPixels = 1920 * 1080;  // 16,588,800 bytes of double: 8 huge pages
    constexpr std::size_t kRounded = std::size_t(16) << 20;
    releaseCachedLargeBuffers();
    REQUIRE(cachedLargeBufferBytes() == 0);
    const void* first = nullptr;
    {
        LargeVector<double> depth(kPixels, 0.75);
        first = depth.data();
    }
    REQUIRE(cachedLargeBufferBytes() == kRounded);
    // The next buffer of the same rounded size (another type) is the same memory, as it was left.
    LargeVector<std::uint64_t> codes;
    codes.resize(kPixels - 1000);
    REQUIRE(static_cast<const void*>(codes.data()) == first);
    REQUIRE(cachedLargeBufferBytes() == 0);
    double value;
    std::memcpy(&value, &codes[12345], sizeof value);
    REQUIRE(value == 0.75);
    LargeVector<std::uint64_t>().swap(codes);  // released
    REQUIRE(cachedLargeBufferBytes() == kRounded);
    // A buffer of another size finds nothing to reuse: everything kept is given back before
    // new memory is mapped, so the cache never adds to the peak.
    LargeVector<double> larger(2 * kPixels);
    REQUIRE(cachedLargeBufferBytes() == 0);
    // Small buffers are not kept.
    { LargeVector<double> small(1000, 1.0); }
    REQUIRE(cachedLargeBufferBytes() == 0);
}

// A comparison's per-pixel class (one byte a pixel, 2,073,600 bytes at 1080p, just under one
// huge page) came from operator new, mostly a fresh mmap faulted in 4 KiB at a time: ~480
// faults in a cold comparison. From 1 MiB up a buffer is whole huge pages, kept for reuse.
TEST_CASE("a 1080p byte-per-pixel buffer gets a huge page of its own and is kept for the next one",
          "[core][large_buffer]")
{
    releaseCachedLargeBuffers();
    {
        LargeVector<std::uint8_t> pixelClass(1920 * 1080);
        REQUIRE(reinterpret_cast<std::uintptr_t>(pixelClass.data()) % kHugePage == 0);
    }
    REQUIRE(cachedLargeBufferBytes() == kHugePage);
    {
        LargeVector<std::uint8_t> halfPage(kHugePage / 2);  // the least that gets a huge page
        REQUIRE(reinterpret_cast<std::uintptr_t>(halfPage.data()) % kHugePage == 0);
        REQUIRE(cachedLargeBufferBytes() == 0);  // it took the kept page
    }
    REQUIRE(cachedLargeBufferBytes() == kHugePage);
    releaseCachedLargeBuffers();
    { LargeVector<std::uint8_t> below(kHugePage / 2 - 1); }  // pages of its own, not a huge one: kept too
    REQUIRE(cachedLargeBufferBytes() == kHugePage / 2);
    releaseCachedLargeBuffers();
    REQUIRE(cachedLargeBufferBytes() == 0);
}

// A frame's scratch of tens to hundreds of KiB (the comparison's keepers) was freed to glibc,
// which gave it back to the system at once, and faulted in again the next frame (~150 faults
// a warm 1080p comparison). From 64 KiB a buffer is pages of its own, kept as the large ones.
TEST_CASE("a released buffer of 64 KiB to 1 MiB is kept for the next one of its size, and given back with the rest",
          "[core][large_buffer]")
{
    constexpr std::size_t kStep = std::size_t(64) << 10;
    releaseCachedLargeBuffers();
    { LargeVector<std::uint8_t> tooSmall(kStep - 1); }  // from operator new, not kept
    REQUIRE(cachedLargeBufferBytes() == 0);
    const void* first = nullptr;
    {
        LargeVector<std::uint32_t> keeper;
        keeper.reserve(41'480);  // a 1080p keeper's 2·keep: 165,920 bytes, three steps
        REQUIRE(reinterpret_cast<std::uintptr_t>(keeper.data()) % 4096 == 0);
        keeper.assign(41'480, 9u);
        first = keeper.data();
    }
    REQUIRE(cachedLargeBufferBytes() == 3 * kStep);
    {
        LargeVector<float> sameSteps(3 * kStep / sizeof(float));  // another type, the same rounded size
        REQUIRE(static_cast<const void*>(sameSteps.data()) == first);
        REQUIRE(cachedLargeBufferBytes() == 0);
    }
    REQUIRE(cachedLargeBufferBytes() == 3 * kStep);
    {
        // A buffer of a size none is kept for, of either class, finds nothing: everything kept, of
        // both classes, is given back before new memory is mapped (the peak never grows).
        LargeVector<double> depth(kHugePage / sizeof(double));
        REQUIRE(cachedLargeBufferBytes() == 0);
    }
    REQUIRE(cachedLargeBufferBytes() == kHugePage);
    { LargeVector<std::uint8_t> otherSize(5 * kStep); }
    REQUIRE(cachedLargeBufferBytes() == 5 * kStep);
    {
        LargeVector<std::uint8_t> again(5 * kStep - 1);  // the same rounded size: the kept block
        REQUIRE(cachedLargeBufferBytes() == 0);
    }
    REQUIRE(cachedLargeBufferBytes() == 5 * kStep);
    releaseCachedLargeBuffers();
    REQUIRE(cachedLargeBufferBytes() == 0);
}

// Regression: releaseCachedLargeBuffers handed its blocks to free(), and glibc, whose mmap
// threshold rises to the size of the last large block freed, kept them in its heap and gave
// them to the next allocations already faulted in, values and all: a "cold" render or
// comparison in `zcheck bench` (which releases the cache first to time fresh buffers) then
// often took no page fault at all. Memory given back must be the system's again: the next
// large buffers are fresh, zero-filled memory.
TEST_CASE("large buffers given back are the system's again: the next ones are fresh memory", "[core][large_buffer]")
{
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer's allocator fills new blocks with its own byte and keeps freed ones in
    // quarantine: what the memory holds is its choice, not the system's.
    WARN("not under AddressSanitizer");
#else
    constexpr std::size_t kValues = std::size_t(8) << 20 >> 3;  // 8 MiB of double
    for (int round = 0; round < 4; ++round) {
        releaseCachedLargeBuffers();
        std::vector<LargeVector<double>> buffers;
        for (std::size_t size : {kValues, 2 * kValues, kValues / 2, kValues, std::size_t(20'000), std::size_t(100'000)}) {
            buffers.emplace_back();
            buffers.back().resize(size);  // uninitialised: what the memory held
            INFO("round " << round << ", " << size << " values");
            REQUIRE(std::all_of(buffers.back().begin(), buffers.back().end(), [](double v) { return v == 0.0; }));
        }
        for (LargeVector<double>& buffer : buffers) std::fill(buffer.begin(), buffer.end(), 0.75);
    }
    releaseCachedLargeBuffers();
#endif
}

// The lane loops' sparse walks (forEachSetLane) must visit exactly the set lanes below n, in
// order: against a plain loop, over masks dense and sparse, lengths not a multiple of eight
// and longer than the 64 lanes packed at a time, and set bytes past n that must be ignored.
TEST_CASE("forEachSetLane visits the set lanes below n in order", "[core]")
{
    std::mt19937 random(3);
    for (const int percentSet : {0, 3, 50, 100})
        for (std::size_t n = 0; n <= 200; ++n) {
            alignas(64) std::uint8_t mask[208];
            for (std::size_t j = 0; j < 208; ++j) mask[j] = std::uint8_t(j >= n || int(random() % 100) < percentSet);
            std::vector<std::size_t> expected, visited;
            for (std::size_t j = 0; j < n; ++j)
                if (mask[j]) expected.push_back(j);
            forEachSetLane(mask, n, [&](std::size_t j) { visited.push_back(j); });
            INFO(percentSet << " % set, n " << n);
            REQUIRE(visited == expected);
        }
}
