// Lens models (core/include/zcheck/lens.h): each model's two directions against each other over
// random coefficient sets, against hand-computed projections, and the refusals. OpenCV's own
// implementation is the oracle in tests/python/test_lens_opencv.py.
#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/checker.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/lens.h"
#include "zcheck/lens_mistakes.h"
#include "zcheck/map_verifier.h"
#include "zcheck/pose.h"
#include "zcheck/remap.h"
#include "zcheck/scene.h"
#include "zcheck/verify_map.h"

#include <catch2/catch.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <functional>
#include <algorithm>
#include <random>

using namespace zcheck;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kWidth = 1280, kHeight = 960;

// A model's parameters drawn from realistic ranges.
using Draw = std::function<std::vector<double>(std::mt19937_64&)>;

double uniform(std::mt19937_64& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

std::vector<double> focal(std::mt19937_64& rng)
{
    const double f = uniform(rng, 350, 900);
    return {f, f * uniform(rng, 0.98, 1.02), kWidth / 2.0 - 0.5 + uniform(rng, -30, 30),
            kHeight / 2.0 - 0.5 + uniform(rng, -30, 30)};
}

std::vector<double> with(std::vector<double> head, std::initializer_list<double> tail)
{
    head.insert(head.end(), tail);
    return head;
}

struct ModelDraw {
    const char* model;
    Draw draw;
};

const std::vector<ModelDraw>& draws()
{
    static const std::vector<ModelDraw> table = {
        {"opencv",
         [](std::mt19937_64& r) {
             return with(focal(r), {uniform(r, -0.3, 0.1), uniform(r, -0.05, 0.1), uniform(r, -1e-3, 1e-3),
                                    uniform(r, -1e-3, 1e-3), uniform(r, -0.01, 0.01), uniform(r, -0.05, 0.05),
                                    uniform(r, -0.02, 0.02), uniform(r, -0.01, 0.01), uniform(r, -1e-3, 1e-3),
                                    uniform(r, -1e-4, 1e-4), uniform(r, -1e-3, 1e-3), uniform(r, -1e-4, 1e-4),
                                    uniform(r, -0.02, 0.02), uniform(r, -0.02, 0.02)});
         }},
        {"brown_conrady",
         [](std::mt19937_64& r) {
             return with(focal(r), {uniform(r, -0.3, 0.1), uniform(r, -0.05, 0.1), uniform(r, -0.01, 0.01),
                                    uniform(r, -0.002, 0.002), uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3)});
         }},
        {"opencv_fisheye",
         [](std::mt19937_64& r) {
             return with(focal(r), {uniform(r, -0.05, 0.05), uniform(r, -0.02, 0.02), uniform(r, -0.005, 0.005),
                                    uniform(r, -0.001, 0.001)});
         }},
        {"thin_prism_fisheye",
         [](std::mt19937_64& r) {
             return with(focal(r), {uniform(r, -0.05, 0.05), uniform(r, -0.02, 0.02), uniform(r, -1e-3, 1e-3),
                                    uniform(r, -1e-3, 1e-3), uniform(r, -0.005, 0.005), uniform(r, -0.001, 0.001),
                                    uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3)});
         }},
        {"fisheye624",
         [](std::mt19937_64& r) {
             return with(focal(r), {uniform(r, -0.05, 0.05), uniform(r, -0.02, 0.02), uniform(r, -0.005, 0.005),
                                    uniform(r, -0.001, 0.001), uniform(r, -1e-4, 1e-4), uniform(r, -1e-5, 1e-5),
                                    uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3),
                                    uniform(r, -1e-4, 1e-4), uniform(r, -1e-3, 1e-3), uniform(r, -1e-4, 1e-4)});
         }},
        {"fov", [](std::mt19937_64& r) { return with(focal(r), {uniform(r, 0.2, 1.6)}); }},
        {"division", [](std::mt19937_64& r) { return with(focal(r), {uniform(r, -0.4, 0.1)}); }},
        {"unified",
         [](std::mt19937_64& r) {
             return with(focal(r), {uniform(r, 0.0, 1.6), uniform(r, -0.1, 0.1), uniform(r, -0.02, 0.02),
                                    uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3)});
         }},
        {"eucm", [](std::mt19937_64& r) { return with(focal(r), {uniform(r, 0.3, 0.8), uniform(r, 0.6, 1.5)}); }},
        {"double_sphere", [](std::mt19937_64& r) { return with(focal(r), {uniform(r, -0.3, 0.3), uniform(r, 0.4, 0.7)}); }},
        {"metashape_frame",
         [](std::mt19937_64& r) {
             return std::vector<double>{uniform(r, 400, 900), kWidth / 2.0 - 0.5 + uniform(r, -30, 30), kHeight / 2.0 - 0.5 + uniform(r, -30, 30),
                     uniform(r, -5, 5), uniform(r, -1, 1), uniform(r, -0.3, 0.1), uniform(r, -0.05, 0.1),
                     uniform(r, -0.01, 0.01), uniform(r, -0.002, 0.002), uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3)};
         }},
        {"metashape_fisheye",
         [](std::mt19937_64& r) {
             return std::vector<double>{uniform(r, 300, 600), kWidth / 2.0 - 0.5 + uniform(r, -30, 30), kHeight / 2.0 - 0.5 + uniform(r, -30, 30),
                     uniform(r, -5, 5), uniform(r, -1, 1), uniform(r, -0.05, 0.05), uniform(r, -0.02, 0.02),
                     uniform(r, -0.005, 0.005), uniform(r, -0.001, 0.001), uniform(r, -1e-3, 1e-3), uniform(r, -1e-3, 1e-3)};
         }},
        {"equisolid", [](std::mt19937_64& r) { return focal(r); }},
        {"equirectangular",
         [](std::mt19937_64& r) {
             const double lon = uniform(r, 30, 360), lat = uniform(r, 20, 180);
             const double lonMin = uniform(r, -180, 180 - lon), latMin = uniform(r, -90, 90 - lat);
             return std::vector<double>{lonMin, lonMin + lon, latMin, latMin + lat};
         }},
        // Blender's panoramic cameras: fisheye_fov up to 2π, shift in image widths and heights,
        // sensors after the fit with pixels of aspect 0.9–1.1.
        {"blender_fisheye_equidistant",
         [](std::mt19937_64& r) { return std::vector<double>{uniform(r, 0.5, 2 * kPi), uniform(r, -0.2, 0.2), uniform(r, -0.2, 0.2)}; }},
        {"blender_fisheye_equisolid",
         [](std::mt19937_64& r) {
             const double width = uniform(r, 20, 40);
             return std::vector<double>{uniform(r, 6, 16), uniform(r, 1, 2 * kPi), width, width * kHeight / kWidth * uniform(r, 0.9, 1.1),
                                        uniform(r, -0.2, 0.2), uniform(r, -0.2, 0.2)};
         }},
        {"blender_fisheye_lens_polynomial",
         [](std::mt19937_64& r) {
             const double width = uniform(r, 20, 40);
             return std::vector<double>{0.0, uniform(r, -0.09, -0.04), uniform(r, -5e-4, 5e-4), uniform(r, -1e-5, 1e-5),
                                        uniform(r, -1e-7, 1e-7), uniform(r, 1.5, kPi), width,
                                        width * kHeight / kWidth * uniform(r, 0.9, 1.1), uniform(r, -0.2, 0.2), uniform(r, -0.2, 0.2)};
         }},
        {"blender_mirror_ball", [](std::mt19937_64& r) { return std::vector<double>{uniform(r, -0.2, 0.2), uniform(r, -0.2, 0.2)}; }},
        {"blender_equiangular_cubemap_face",
         [](std::mt19937_64& r) { return std::vector<double>{uniform(r, -0.5, 0.5), uniform(r, -0.5, 0.5)}; }},
    };
    return table;
}

// A lens camera of builtin:default's kind: OpenCV axes, near 0.05, far 100 (distances), the view given.
CameraSpec lensSpec(LensSpec lens, int width = 200, int height = 150, const View& view = View::lookAt({1.2, 2.4, 5.5}, {-0.3, 0.9, -4.0}, {0, 1, 0}))
{
    CameraSpec spec;
    spec.convention = Convention::preset("opencv");
    spec.width = width, spec.height = height;
    spec.projection.type = ProjectionType::NonLinear;
    spec.projection.lens = std::move(lens);
    spec.projection.near = 0.05, spec.projection.far = 100;
    spec.view = view;
    return spec;
}

glm::dvec3 direction(double theta, double phi) { return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)}; }

}  // namespace

TEST_CASE("every lens model is in the table, and the table's tests cover every model", "[lens]")
{
    REQUIRE(draws().size() == lensModels().size());
    for (const LensModelInfo& info : lensModels()) {
        bool drawn = false;
        for (const ModelDraw& d : draws()) drawn = drawn || std::string(d.model) == info.name;
        INFO(info.name);
        REQUIRE(drawn);
    }
}

TEST_CASE("each lens model's two directions agree over its field, 100 coefficient sets each", "[lens]")
{
    std::mt19937_64 rng(20261129);
    for (const ModelDraw& d : draws()) {
        INFO("model " << d.model);
        int accepted = 0, attempts = 0, pixelsWithRays = 0;
        while (accepted < 100) {
            REQUIRE(++attempts < 400);  // realistic ranges: nearly every set makes a lens
            std::vector<double> params = d.draw(rng);
            std::optional<LensModel> lens;
            try {
                lens.emplace(LensSpec{d.model, params}, kWidth, kHeight);
            } catch (const Error&) {
                continue;  // folds inside the image: refused (tested below)
            }
            ++accepted;
            // Pixels: a 33×25 grid of points spread over the image; where there is a ray, it
            // projects back onto the point.
            for (int j = 0; j <= 24; ++j)
                for (int i = 0; i <= 32; ++i) {
                    const glm::dvec2 p(kWidth * (i + 0.5) / 33.0, kHeight * (j + 0.5) / 25.0);
                    const std::optional<glm::dvec3> ray = lens->directionFromImage(p);
                    if (!ray) continue;
                    ++pixelsWithRays;
                    REQUIRE(std::abs(glm::length(*ray) - 1) <= 1e-14);
                    const std::optional<glm::dvec2> back = lens->imageFromDirection(*ray);
                    REQUIRE(back.has_value());
                    INFO("pixel " << p.x << ", " << p.y << " back at " << back->x << ", " << back->y);
                    REQUIRE(glm::length(*back - p) <= 1e-9);
                }
            // Directions within the field (short of a fold's end, where the inverse is ill-posed):
            // to a pixel and back to themselves.
            const double field = lens->isPanorama() ? kPi : 0.98 * lens->fieldAngle();
            for (int k = 0; k < 200; ++k) {
                const glm::dvec3 dCam = direction(uniform(rng, 0, field), uniform(rng, -kPi, kPi));
                const std::optional<glm::dvec2> pImage = lens->imageFromDirection(dCam);
                if (!pImage) {
                    REQUIRE(lens->isPanorama());  // a panorama's field is its ranges
                    continue;
                }
                const std::optional<glm::dvec3> back = lens->directionFromImage(*pImage);
                INFO("direction " << dCam.x << ", " << dCam.y << ", " << dCam.z << " at " << pImage->x << ", " << pImage->y
                                  << "; field " << lens->fieldAngle() << "; parameters " << [&] {
                                         std::string text;
                                         for (double v : params) text += std::to_string(v) + " ";
                                         return text;
                                     }());
                REQUIRE(back.has_value());
                REQUIRE(glm::length(*back - dCam) <= 1e-9);
            }
        }
        REQUIRE(pixelsWithRays > 100 * 33 * 25 / 4);
    }
}

TEST_CASE("lens models project as their authors' formulas say, by hand", "[lens]")
{
    const double fx = 500, fy = 480, cx = 639.5, cy = 479.5;
    const auto at = [](const char* model, std::vector<double> params, glm::dvec3 d) {
        return LensModel({model, std::move(params)}, kWidth, kHeight).imageFromDirection(d).value();
    };
    const glm::dvec3 d = direction(0.5, 0.0);  // 0.5 rad towards +x
    // Kannala–Brandt without coefficients: equidistant, m = θ. Image x = fx·θ + cx + ½.
    REQUIRE(at("opencv_fisheye", {fx, fy, cx, cy}, d).x == Approx(fx * 0.5 + cx + 0.5).epsilon(1e-14));
    // θd = θ(1 + k1θ²): θ = 0.5, k1 = 0.1 → 0.5125.
    REQUIRE(at("opencv_fisheye", {fx, fy, cx, cy, 0.1}, d).x == Approx(fx * 0.5125 + cx + 0.5).epsilon(1e-14));
    // OpenCV: tan 0.5 = 0.5463024898; m' = m(1 + k1 m²), k1 = −0.1.
    const double m = std::tan(0.5);
    REQUIRE(at("opencv", {fx, fy, cx, cy, -0.1}, d).x == Approx(fx * m * (1 - 0.1 * m * m) + cx + 0.5).epsilon(1e-14));
    // Tangential alone at a point on +y: m = (0, t): x' = 2·p1·0 + p2·t², y' = t + p1·3t².
    const double t = std::tan(0.5);
    const glm::dvec2 tangential = at("opencv", {fx, fy, cx, cy, 0, 0, 0.01, 0.02}, direction(0.5, kPi / 2));
    REQUIRE(tangential.x == Approx(fx * 0.02 * t * t + cx + 0.5).epsilon(1e-14));
    REQUIRE(tangential.y == Approx(fy * (t + 0.01 * 3 * t * t) + cy + 0.5).epsilon(1e-14));
    // Metashape's P1 goes with r² + 2x² (OpenCV's p2): the same point along +x moves by P1·3r².
    REQUIRE(at("metashape_frame", {fx, cx, cy, 0, 0, 0, 0, 0, 0, 0.01, 0}, d).x ==
            Approx(fx * (m + 0.01 * 3 * m * m) + cx + 0.5).epsilon(1e-14));
    // Equisolid: 2 sin(θ/2); at 60°, 1.
    REQUIRE(at("equisolid", {fx, fy, cx, cy}, direction(kPi / 3, 0)).x == Approx(fx + cx + 0.5).epsilon(1e-14));
    // Unified with ξ = 1 is the stereographic projection: tan(θ/2).
    REQUIRE(at("unified", {fx, fy, cx, cy, 1.0}, d).x == Approx(fx * std::tan(0.25) + cx + 0.5).epsilon(1e-14));
    // EUCM with α = 0 and double sphere with ξ = α = 0 are the pinhole.
    REQUIRE(at("eucm", {fx, fy, cx, cy, 0.0, 1.0}, d).x == Approx(fx * m + cx + 0.5).epsilon(1e-14));
    REQUIRE(at("double_sphere", {fx, fy, cx, cy, 0.0, 0.0}, d).x == Approx(fx * m + cx + 0.5).epsilon(1e-14));
    // FOV: atan(2·tan θ·tan(ω/2))/ω.
    const double omega = 0.9;
    REQUIRE(at("fov", {fx, fy, cx, cy, omega}, d).x ==
            Approx(fx * std::atan(2 * m * std::tan(omega / 2)) / omega + cx + 0.5).epsilon(1e-14));
    // Division: the ray through m is (m, 1 + k|m|²); at m = 0.4 with k = −0.2 the ray's slope is 0.4/0.968.
    const glm::dvec3 divisionRay(0.4, 0, 1 - 0.2 * 0.16);
    REQUIRE(at("division", {fx, fy, cx, cy, -0.2}, divisionRay).x == Approx(fx * 0.4 + cx + 0.5).epsilon(1e-14));
    // Equirectangular over the sphere: +x is longitude 90°, three quarters across; up is the top row.
    const glm::dvec2 east = at("equirectangular", {-180, 180, -90, 90}, {1, 0, 0});
    REQUIRE(east.x == Approx(0.75 * kWidth).epsilon(1e-14));
    REQUIRE(east.y == Approx(0.5 * kHeight).epsilon(1e-14));
    REQUIRE(at("equirectangular", {-180, 180, -90, 90}, {0, -1, 1e-300}).y == Approx(0.0).margin(1e-9));
}

TEST_CASE("a lens is refused with one line naming the model, the parameter and the rule", "[lens]")
{
    const auto refusal = [](const char* model, std::vector<double> params) {
        try {
            LensModel({model, std::move(params)}, 640, 480);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    REQUIRE(refusal("brown", {1, 1, 1, 1}).find("unknown lens model 'brown'") != std::string::npos);
    REQUIRE(refusal("opencv_fisheye", {300, 300, 319.5}) == "lens model opencv_fisheye takes 4 to 8 parameters, got 3");
    REQUIRE(refusal("opencv_fisheye", {300, 300, 319.5, 239.5, 0, 0, 0, 0, 0}) ==
            "lens model opencv_fisheye takes 4 to 8 parameters, got 9");
    REQUIRE(refusal("opencv", {300, 300, 319.5, 239.5, NAN}) == "lens model opencv: 'k1' must be a finite number, got nan");
    REQUIRE(refusal("opencv", {-300, 300, 319.5, 239.5}) == "lens model opencv: 'fx' must be > 0, got -300");
    REQUIRE(refusal("fov", {300, 300, 319.5, 239.5, 4}).find("'omega' must lie in (0, π)") != std::string::npos);
    REQUIRE(refusal("eucm", {300, 300, 319.5, 239.5, 1.5, 1}).find("'alpha' must lie in [0, 1]") != std::string::npos);
    REQUIRE(refusal("equirectangular", {-180, 270, -90, 90}).find("'lon_max_deg' must be at most 360°") != std::string::npos);
    REQUIRE(refusal("equirectangular", {-180, 180, -100, 90}).find("'lat_min_deg' must be at least -90") != std::string::npos);
    // k1 = −1 folds at r = 1/√3 ≈ 0.577 (r·(1 − r²) stops increasing): 173 px from the centre at
    // fx = 300, inside a 480-pixel-high image.
    const std::string fold = refusal("opencv", {300, 300, 319.5, 239.5, -1});
    REQUIRE(fold.find("lens model opencv folds (is no longer one-to-one) 30") != std::string::npos);
    REQUIRE(fold.find("inside the image") != std::string::npos);
    // A huge coefficient folds at once.
    REQUIRE(refusal("opencv", {300, 300, 319.5, 239.5, -1e300}).find("lens model opencv") != std::string::npos);
}

TEST_CASE("pixels beyond a fold outside the image's inscribed disc have no ray: their own class", "[lens]")
{
    // k1 = −0.2 at fx = 300: the fold at r = 1/√(3·0.2) = 1.29, where the image radius is
    // 300·1.29·(1 − 0.2·1.29²) = 258 px: beyond the nearest edge (240 px), inside the corners (400 px).
    const LensModel lens({"opencv", {300, 300, 319.5, 239.5, -0.2}}, 640, 480);
    REQUIRE(lens.fieldAngle() == Approx(std::atan(1 / std::sqrt(3 * 0.2))).epsilon(1e-6));
    REQUIRE(lens.directionFromImage({320, 240}).has_value());
    REQUIRE(!lens.directionFromImage({0.5, 0.5}).has_value());  // a corner: beyond the fold
    REQUIRE(!lens.imageFromDirection(direction(lens.fieldAngle() + 1e-6, 0.3)).has_value());
}

TEST_CASE("a lens spec without its trailing zero parameters is written and re-read by the mistakes in full", "[lens]")
{
    // Regression (found by AddressSanitizer in the suite's lens part): an opencv lens of 5
    // coefficients (9 parameters of 18) was written to JSON, and re-read by the lens mistakes, by
    // the model's 18 indices, reading past the end of its parameters.
    const CameraSpec spec = lensSpec({"opencv", {140, 140, 99.5, 74.5, -0.2, 0.05, 0.003, -0.002, -0.01}});
    const Camera camera(spec);
    const CameraSpec back = cameraSpecFromJsonText(cameraJsonText(spec), "written");
    REQUIRE(Camera(back).lens()->terms().numerator[0] == -0.2);
    REQUIRE(Camera(back).lens()->terms().tauX == 0);
    bool flipped = false;
    for (const LensMistake& m : lensMistakes(camera, DepthQuantity::Distance))
        if (m.name == "distortion-signs-flipped") {
            flipped = true;
            REQUIRE(m.camera->projection.lens.params[4] == 0.2);
            REQUIRE(m.camera->projection.lens.params[8] == 0.01);
            for (std::size_t i = 9; i < m.camera->projection.lens.params.size(); ++i) REQUIRE(m.camera->projection.lens.params[i] == 0);
        }
    REQUIRE(flipped);
}

TEST_CASE("metashape fisheye's field ends at 90 degrees, where the manual's formula stops", "[lens]")
{
    // The manual's x0 = X/Z divides by Z: a direction 100° off the axis has no pixel, and the
    // image's corners beyond 90° (θ = r/f for this equidistant lens: 90° at r = 300·π/2 = 471 px,
    // the corner 500 px away) have no ray, where the same lens as OpenCV's fisheye has both.
    const LensModel metashape({"metashape_fisheye", {300, 399.5, 299.5, 0, 0, 0, 0, 0, 0, 0, 0}}, 800, 600);
    const LensModel kannalaBrandt({"opencv_fisheye", {300, 300, 399.5, 299.5}}, 800, 600);
    REQUIRE(metashape.fieldAngle() == Approx(kPi / 2).epsilon(1e-12));
    REQUIRE(!metashape.imageFromDirection(direction(kPi * 100 / 180, 0.3)).has_value());
    REQUIRE(kannalaBrandt.imageFromDirection(direction(kPi * 100 / 180, 0.3)).has_value());
    REQUIRE(!metashape.directionFromImage({0.5, 0.5}).has_value());
    REQUIRE(kannalaBrandt.directionFromImage({0.5, 0.5}).has_value());
    // Inside 90° both are the equidistant lens.
    const glm::dvec2 both = metashape.imageFromDirection(direction(1.2, 0.3)).value();
    REQUIRE(glm::length(both - kannalaBrandt.imageFromDirection(direction(1.2, 0.3)).value()) < 1e-9);
}

TEST_CASE("a camera file's lens object reads and writes back as itself", "[lens]")
{
    const std::string text = R"({"convention": "opencv", "image": {"width": 640, "height": 480},
        "projection": {"type": "pinhole", "fx": 200, "fy": 210, "cx": 319.5, "cy": 239.5, "near": 0.1, "far": 100},
        "lens": {"model": "opencv_fisheye", "k1": 0.02, "k2": -0.005},
        "view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, -1, 0]}})";
    const CameraSpec spec = cameraSpecFromJsonText(text, "test");
    REQUIRE(spec.projection.type == ProjectionType::NonLinear);
    REQUIRE(spec.projection.lens == LensSpec{"opencv_fisheye", {200, 210, 319.5, 239.5, 0.02, -0.005, 0, 0}});
    REQUIRE(cameraSpecFromJsonText(cameraJsonText(spec), "again").projection.lens == spec.projection.lens);
    // A panorama: near and far only in the projection, every parameter in the lens.
    const std::string panorama = R"({"image": {"width": 512, "height": 256}, "projection": {"near": 0.1, "far": 50},
        "lens": {"model": "equirectangular", "lon_min_deg": -180, "lon_max_deg": 180, "lat_min_deg": -90, "lat_max_deg": 90},
        "view": {"eye": [0, 0, 0], "target": [0, 0, -1]}})";
    const CameraSpec pano = cameraSpecFromJsonText(panorama, "pano");
    REQUIRE(pano.projection.lens.model == "equirectangular");
    REQUIRE(cameraSpecFromJsonText(cameraJsonText(pano), "again").projection.lens == pano.projection.lens);
    const auto refusal = [](const std::string& json) {
        try {
            cameraSpecFromJsonText(json, "cam.json");
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    const std::string head = R"({"projection": {"type": "pinhole", "fx": 200, "fy": 200, "cx": 319.5, "cy": 239.5, "near": 0.1, "far": 100}, "view": {"eye": [0, 1, 3], "target": [0, 0, 0]}, )";
    REQUIRE(refusal(head + R"("lens": {"model": "opencv_fisheye", "k9": 1}})") == "cam.json: unknown key 'lens.k9'");
    REQUIRE(refusal(head + R"("lens": {"model": "opencv_fisheye", "fx": 1}})") ==
            "cam.json: 'lens.fx' is the pinhole projection's: give it there only");
    REQUIRE(refusal(head + R"("lens": {"model": "fov"}})") == "cam.json: 'lens.omega' is missing");
    REQUIRE(refusal(head + R"("lens": {"model": "equirectangular"}})").find("does not take a pinhole's fx") != std::string::npos);
}

TEST_CASE("check of a lens camera: the two directions and the trace agree, a shifted ray does not", "[lens]")
{
    const Checker checker(builtinScene("default"));
    for (const LensSpec& lens : {LensSpec{"opencv_fisheye", {200, 200, 319.5, 239.5, 0.02, -0.005, 0.001}},
                                 LensSpec{"opencv", {500, 500, 319.5, 239.5, -0.2, 0.05, 1e-3, -1e-3}},
                                 LensSpec{"double_sphere", {150, 150, 319.5, 239.5, -0.2, 0.6}},
                                 LensSpec{"equirectangular", {-180, 180, -90, 90}}}) {
        INFO(lens.model);
        CameraSpec spec;
        spec.convention = Convention::preset("vulkan");
        spec.width = 640, spec.height = lens.model == "equirectangular" ? 320 : 480;
        spec.projection.type = ProjectionType::NonLinear;
        spec.projection.lens = lens;
        spec.projection.near = 0.05, spec.projection.far = 100;
        spec.view = View::lookAt({0.3, 0.8, 2.5}, {0, 0, 0}, {0, 1, 0});
        const Camera camera(spec);
        const CheckResult clean = checker.check(camera);
        REQUIRE(clean.report.lens.has_value());
        REQUIRE(clean.report.lens->hits > 10000);
        REQUIRE(clean.report.lens->roundTripMaxPx <= 1e-9);
        REQUIRE(clean.report.lens->forwardMaxPx <= 1e-6);
        REQUIRE(clean.report.comparison.consistent());
        CheckOptions shifted;
        shifted.faults.ray.shiftPixels = {0.01, 0.0};
        const CheckResult wrong = checker.check(camera, shifted);
        REQUIRE(!wrong.report.comparison.consistent());
        REQUIRE(wrong.report.lens->forwardMaxPx == Approx(0.01).epsilon(1e-3));
    }
}

TEST_CASE("regression: a lens camera far from the world origin failed its forward test on rounding alone", "[lens][regression]")
{
    // The hit point is eye + t·d in world coordinates, so its direction from the eye is rounded by
    // ~2^-53·|eye|/t radians: a camera in UTM coordinates (5·10⁶ m out) 0.2 m from a wall moved its
    // hits ~2·10⁻⁶ px at f = 1000, and near a lens's fold the lens magnifies that a thousandfold;
    // the bare bound of 10⁻⁶ px called such chains inconsistent. The wall: the plane z = 20, exact
    // in binary32, two triangles of 2 km.
    auto wallAround = [](const glm::dvec3& centre) {
        Scene scene;
        scene.name = "wall";
        for (const glm::dvec2 corner : {glm::dvec2(-1, -1), glm::dvec2(1, -1), glm::dvec2(1, 1), glm::dvec2(-1, 1)})
            scene.positions.push_back(glm::vec3(glm::dvec3(centre.x + 1000 * corner.x, centre.y + 1000 * corner.y, 20)));
        scene.triangles = {{0, 1, 2}, {0, 2, 3}};
        return scene;
    };
    struct Case {
        const char* what;
        glm::dvec3 eye;
        LensSpec lens;
        int width, height;
    };
    // The division lens folds at |m|² = 1/k = 2.004: its image corners (|m|² = 2) sit just inside.
    for (const Case& c : {Case{"UTM", {300000, 5000000, 20.2}, {"opencv", {1000, 1000, 319.5, 239.5, -0.1, 0.02, 1e-3, -5e-4}}, 640, 480},
                          Case{"near a fold", {1000000, 1000, 20.5}, {"division", {100, 100, 99.5, 99.5, 0.499}}, 200, 200}}) {
        INFO(c.what);
        const Checker checker(wallAround(c.eye));
        const Camera camera(lensSpec(c.lens, c.width, c.height, View::lookAt(c.eye, c.eye - glm::dvec3(0, 0, 1), {0, 1, 0})));
        const CheckResult clean = checker.check(camera);
        const LensCheck& lens = *clean.report.lens;
        REQUIRE(lens.hits == std::int64_t(c.width) * c.height);
        REQUIRE(lens.forwardMaxPx > LensCheck::kForwardBoundPx);  // the rounding is there to allow
        REQUIRE(lens.forwardFailures == 0);
        REQUIRE(lens.forwardWidestBoundPx < 1e-4);
        REQUIRE(clean.report.comparison.consistent());
        // A ray shifted by 10⁻⁴ px is still caught at every pixel.
        CheckOptions shifted;
        shifted.faults.ray.shiftPixels = {1e-4, 0.0};
        const CheckResult wrong = checker.check(camera, shifted);
        REQUIRE(!wrong.report.comparison.consistent());
        REQUIRE(wrong.report.lens->forwardFailures == lens.hits);
    }
}

TEST_CASE("regression: quantityImage of a lens camera's render without eye points read its distances as window depths", "[lens][regression]")
{
    // A lens camera's route holds the distance along each pixel's ray, not a window depth; from a
    // render that kept no eye points, quantityImage unprojected it through the camera's matrices
    // (which a lens has none of) and wrote wrong eye-z, distances and positions without a word.
    // Found by the property test of verify (test_verify.cpp).
    const Checker checker(builtinScene("default"));
    const Camera camera(lensSpec({"opencv_fisheye", {120, 120, 99.5, 74.5, 0.02, -0.004}}, 200, 150,
                                 View::lookAt({0.3, 0.8, 2.5}, {0, 0, 0}, {0, 1, 0})));
    const RenderResult withoutEyePoints = checker.renderRay(camera);
    REQUIRE(withoutEyePoints.pEye.empty());
    for (const ExportQuantity q : {ExportQuantity::EyeZ, ExportQuantity::Distance, ExportQuantity::PositionEye, ExportQuantity::PositionWorld}) {
        INFO(toString(q));
        const QuantityImage fromDepth = quantityImage(checker.scene(), camera, withoutEyePoints, q);
        const QuantityImage exact = checker.render(camera, q, Route::Ray);
        REQUIRE(fromDepth.value.size() == exact.value.size());
        std::size_t compared = 0;
        for (std::size_t i = 0; i < exact.value.size(); ++i) {
            if (!std::isfinite(exact.value[i])) {
                REQUIRE_FALSE(std::isfinite(fromDepth.value[i]));
                continue;
            }
            REQUIRE(fromDepth.value[i] == Approx(exact.value[i]).epsilon(1e-12).margin(1e-12));
            ++compared;
        }
        REQUIRE(compared > 10000);
    }
}

TEST_CASE("verify of a lens camera's map: the truth passes, a distortion mistake or a scale does not", "[lens]")
{
    const Checker checker(builtinScene("default"));
    const MapVerifier verifier(checker);
    const CameraSpec spec = lensSpec({"opencv", {210, 210, 159.5, 119.5, -0.25, 0.08, 1e-3, -5e-4}}, 320, 240,
                                     View::lookAt({0.3, 0.8, 2.5}, {0, 0, 0}, {0, 1, 0}));
    const Camera camera(spec);
    for (const DepthQuantity quantity : {DepthQuantity::Distance, DepthQuantity::EyeZ}) {
        INFO(toString(quantity));
        const DepthMap exact = renderedMap(checker, camera, quantity);
        const VerifyResult clean = verifier.verify(camera, exact);
        REQUIRE(clean.report.comparison.consistent());
        REQUIRE(clean.report.comparison.agree > 40000);
        REQUIRE(clean.report.mapErrors.maxRel < 1e-6);
        // One part in 10⁴ too far: every pixel beyond its tolerance.
        DepthMap scaled = exact;
        for (double& v : scaled.value) v *= 1.0001;
        REQUIRE(!verifier.verify(camera, scaled).report.comparison.consistent());
        // Distortion ignored: the same map verified with the pinhole that has the lens's K.
        CameraSpec pinhole = spec;
        pinhole.projection = PinholeIntrinsics{210, 210, 159.5, 119.5, 0}.projection(0.05, 100, "K");
        const VerifyResult ignored = verifier.verify(Camera(pinhole), exact);
        REQUIRE(!ignored.report.comparison.consistent());
        REQUIRE(ignored.report.comparison.unexplained() > 10000);
        // k1 off by 1 %.
        CameraSpec off = spec;
        off.projection.lens.params[4] *= 1.01;
        REQUIRE(!verifier.verify(Camera(off), exact).report.comparison.consistent());
    }
    // A window map cannot come from a lens: refused.
    REQUIRE_THROWS_WITH(verifyMap(verifier, camera, DepthMap::exact(320, 240, DepthQuantity::Window, std::vector<double>(320 * 240, 0.5)), false, "map.exr"),
                        Catch::Contains("a window map cannot come from a lens model (opencv)"));
}

TEST_CASE("verify of a lens camera's map: declared accuracies are judged as a linear camera's, and accept no wrong map", "[lens]")
{
    // Regression: a lens map's --quantum widened each pixel's tolerance, but nothing judged the
    // declaration as a whole — a grid as coarse as the depths (--quantum 5) accepted any map —
    // and --rel-tolerance, --abs-tolerance and noise were refused outright.
    const Checker checker(builtinScene("default"));
    const MapVerifier verifier(checker);
    const Camera camera(lensSpec({"opencv_fisheye", {180, 180, 159.5, 119.5, 0.02, -0.004}}, 320, 240,
                                 View::lookAt({0.3, 0.8, 2.5}, {0, 0, 0}, {0, 1, 0})));
    const auto verdict = [&](DepthMap map, MapAccuracy accuracy) {
        map.accuracy = accuracy;
        return verifier.verify(camera, map).report.comparison;
    };
    for (const DepthQuantity quantity : {DepthQuantity::Distance, DepthQuantity::EyeZ}) {
        INFO(toString(quantity));
        const DepthMap exact = renderedMap(checker, camera, quantity);
        // Unbiased relative noise of up to ±5·10⁻⁴: rejected as exact, accepted under --rel-tolerance 1e-3.
        std::mt19937 random(7);
        std::uniform_real_distribution<double> noise(-5e-4, 5e-4);
        DepthMap noisy = exact;
        for (double& v : noisy.value) v = v > 0 ? v * (1 + noise(random)) : v;
        MapAccuracy relative;
        relative.relative = 1e-3;
        REQUIRE(!verdict(noisy, {}).consistent());
        const ComparisonReport accepted = verdict(noisy, relative);
        REQUIRE(accepted.consistent());
        REQUIRE(accepted.agree > 40000);
        // The same tolerance absorbs no scale: 4·10⁻⁴ long everywhere is within each pixel's
        // ±10⁻³, and refused as systematic.
        DepthMap scaled = exact;
        for (double& v : scaled.value) v *= 1.0004;
        const ComparisonReport biased = verdict(scaled, relative);
        REQUIRE(!biased.consistent());
        REQUIRE_THAT(biased.declaredAccuracyRefused, Catch::Contains("systematic"));
        // An absolute tolerance likewise: a map 2 mm far with --abs-tolerance 0.005.
        DepthMap offset = exact;
        for (double& v : offset.value) v = v > 0 ? v + 0.002 : v;
        MapAccuracy absolute;
        absolute.absolute = 0.005;
        REQUIRE_THAT(verdict(offset, absolute).declaredAccuracyRefused, Catch::Contains("systematic"));
        // Millimetres: the values rounded to 0.001 pass with --quantum 0.001, not without it; the
        // exact map with --quantum 0.001 is not on that grid; --quantum 5 is as coarse as the depths.
        DepthMap millimetres = exact;
        for (double& v : millimetres.value) v = std::round(v * 1000) / 1000;
        MapAccuracy grid;
        grid.quantum = 0.001;
        REQUIRE(!verdict(millimetres, {}).consistent());
        REQUIRE(verdict(millimetres, grid).consistent());
        REQUIRE_THAT(verdict(exact, grid).declaredAccuracyRefused, Catch::Contains("not the map's grid"));
        MapAccuracy coarse;
        coarse.quantum = 5;
        DepthMap fives = exact;
        for (double& v : fives.value) v = v > 0 ? 5.0 : v;
        REQUIRE_THAT(verdict(fives, coarse).declaredAccuracyRefused, Catch::Contains("as coarse as the depths"));
    }
}

TEST_CASE("verify of a lens camera's map: a depth outside the lens's field is the map's invention", "[lens]")
{
    const Checker checker(builtinScene("default"));
    const MapVerifier verifier(checker);
    // The fold at r = 1/√(3·0.2): 130 px from the centre at fx = 150, beyond the nearest edge
    // (120 px) but not the corners.
    const CameraSpec spec = lensSpec({"opencv", {150, 150, 159.5, 119.5, -0.2}}, 320, 240,
                                     View::lookAt({0.3, 0.8, 2.5}, {0, 0, 0}, {0, 1, 0}));
    const Camera camera(spec);
    REQUIRE(!camera.lens()->directionFromImage({0.5, 0.5}).has_value());
    const QuantityImage truth = checker.render(camera, ExportQuantity::Distance, Route::Ray);
    std::vector<double> values(truth.value.size());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::isinf(truth.value[i]) ? 0.0 : truth.value[i];
    DepthMap map = DepthMap::exact(320, 240, DepthQuantity::Distance, values);
    REQUIRE(verifier.verify(camera, map).report.comparison.consistent());
    map.value[0] = 3.0;  // pixel (0, 0): outside the field
    const VerifyResult invented = verifier.verify(camera, map);
    REQUIRE(!invented.report.comparison.consistent());
    REQUIRE(invented.comparison.pixelClass[0] == PixelClass::RasterOnly);
}

TEST_CASE("remap: a map moved to another camera with the same centre is the other camera's render", "[lens][remap]")
{
    const Checker checker(builtinScene("default"));
    CameraSpec fisheyeSpec;
    fisheyeSpec.convention = Convention::preset("opencv");
    fisheyeSpec.width = 400, fisheyeSpec.height = 400;
    fisheyeSpec.projection.type = ProjectionType::NonLinear;
    fisheyeSpec.projection.lens = {"opencv_fisheye", {120, 120, 199.5, 199.5, 0.021, -0.004, 7e-4, -1e-4}};
    fisheyeSpec.projection.near = 0.05, fisheyeSpec.projection.far = 100;
    fisheyeSpec.view = View::lookAt({1.2, 2.4, 5.5}, {-0.3, 0.9, -4.0}, {0, 1, 0});
    const Camera fisheye(fisheyeSpec);
    CameraSpec pinholeSpec = fisheyeSpec;  // the same centre, turned a little, another convention
    pinholeSpec.convention = Convention::preset("opengl");
    pinholeSpec.width = 320, pinholeSpec.height = 240;
    pinholeSpec.projection = PinholeIntrinsics{260, 260, 159.5, 119.5, 0}.projection(0.05, 100, "K");
    pinholeSpec.view = View::lookAt({1.2, 2.4, 5.5}, {-0.1, 0.7, -4.0}, {0, 1, 0});
    const Camera pinhole(pinholeSpec);
    const auto values = [&](const Camera& camera, ExportQuantity q) { return checker.render(camera, q, Route::Ray).value; };

    // The same camera: every value comes back (nearest samples the pixel's own centre).
    const std::vector<double> distance = values(fisheye, ExportQuantity::Distance);
    const RemappedMap same = remapDepthMap(fisheye, distance, DepthQuantity::Distance, fisheye, DepthQuantity::Distance,
                                           RemapSampling::Nearest);
    for (std::size_t i = 0; i < distance.size(); ++i)
        if (std::isfinite(distance[i])) REQUIRE(same.values[i] == Approx(distance[i]).epsilon(1e-12));

    // Fisheye distance → pinhole eye-z, on planes: the pinhole's own render, to binary64 rounding.
    const RemappedMap moved = remapDepthMap(fisheye, distance, DepthQuantity::Distance, pinhole, DepthQuantity::EyeZ,
                                            RemapSampling::Plane);
    const std::vector<double> truth = values(pinhole, ExportQuantity::EyeZ);
    std::size_t compared = 0, exact = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
        if (!std::isfinite(truth[i]) || !std::isfinite(moved.values[i])) continue;
        ++compared;
        exact += std::abs(moved.values[i] - truth[i]) <= 1e-9 * truth[i];
    }
    REQUIRE(moved.unseen == 0);
    REQUIRE(compared > 40000);
    REQUIRE(exact > compared / 2);  // all but the pixels whose 2×2 samples straddle an edge or a facet's crease
    // Nearest instead: never across an edge, but off by the sample's offset on slanted surfaces.
    const RemappedMap nearest = remapDepthMap(fisheye, distance, DepthQuantity::Distance, pinhole, DepthQuantity::EyeZ,
                                              RemapSampling::Nearest);
    std::size_t nearestExact = 0;
    for (std::size_t i = 0; i < truth.size(); ++i)
        if (std::isfinite(truth[i]) && std::isfinite(nearest.values[i]))
            nearestExact += std::abs(nearest.values[i] - truth[i]) <= 1e-9 * truth[i];
    REQUIRE(nearestExact < exact / 10);

    // The quantity converted per ray: a pinhole's eye-z map moved to itself as distance is its distance render.
    const RemappedMap asDistance = remapDepthMap(pinhole, truth, DepthQuantity::EyeZ, pinhole, DepthQuantity::Distance,
                                                 RemapSampling::Nearest);
    const std::vector<double> pinholeDistance = values(pinhole, ExportQuantity::Distance);
    for (std::size_t i = 0; i < truth.size(); ++i)
        if (std::isfinite(truth[i])) REQUIRE(asDistance.values[i] == Approx(pinholeDistance[i]).epsilon(1e-12));

    // Another centre: refused.
    CameraSpec moved2 = pinholeSpec;
    moved2.view = View::lookAt({1.2, 2.5, 5.5}, {-0.3, 0.9, -4.0}, {0, 1, 0});
    REQUIRE_THROWS_WITH(remapDepthMap(fisheye, distance, DepthQuantity::Distance, Camera(moved2), DepthQuantity::EyeZ,
                                      RemapSampling::Plane),
                        Catch::Contains("the two cameras' centres differ"));
}

namespace {

// A map of `quantity` rendered by the ray route through `made`, as a renderer would store it (binary32, 0 a miss).
DepthMap mapThrough(const Checker& checker, const CameraSpec& made, DepthQuantity quantity)
{
    return renderedMap(checker, Camera(made), quantity);
}


}  // namespace

TEST_CASE("the diagnosis names the lens family's mistakes", "[lens][diagnose]")
{
    const Checker checker(builtinScene("default"));
    const MapVerifier verifier(checker);
    const LensSpec declared{"opencv", {140, 140, 99.5, 74.5, -0.2, 0.05, 0.003, -0.002, -0.01}};
    const CameraSpec declaredSpec = lensSpec(declared);
    const Camera camera(declaredSpec);
    struct Case {
        const char* name;
        CameraSpec made;
        DepthQuantity quantity = DepthQuantity::Distance;
        DepthQuantity declaredQuantity = DepthQuantity::Distance;
    };
    CameraSpec pinhole = declaredSpec;
    pinhole.projection = PinholeIntrinsics{140, 140, 99.5, 74.5, 0}.projection(0.05, 100, "K");
    std::vector<Case> cases = {
        {"distortion-ignored", pinhole},
        {"undistorted-new-k", undistortedCameraSpec(camera, 0.0)},
        {"coefficient-order", lensSpec({"opencv", {140, 140, 99.5, 74.5, -0.2, 0.05, -0.01, 0.003, -0.002}})},
        {"tangential-swapped", lensSpec({"opencv", {140, 140, 99.5, 74.5, -0.2, 0.05, -0.002, 0.003, -0.01}})},
        {"distortion-signs-flipped", lensSpec({"opencv", {140, 140, 99.5, 74.5, 0.2, -0.05, -0.003, 0.002, 0.01}})},
        {"eye-z-as-distance", declaredSpec, DepthQuantity::EyeZ, DepthQuantity::Distance},
        {"half-pixel", lensSpec({"opencv", {140, 140, 100, 75, -0.2, 0.05, 0.003, -0.002, -0.01}})},
        {"fitted-radial-distortion", lensSpec({"opencv", {140, 140, 99.5, 74.5, -0.23, 0.065, 0.003, -0.002, -0.01}})},
    };
    for (const Case& c : cases) {
        INFO(c.name);
        DepthMap map = mapThrough(checker, c.made, c.quantity);
        map.quantity = c.declaredQuantity;
        REQUIRE(!verifier.verify(camera, map).report.comparison.consistent());
        const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, map);
        REQUIRE(!diagnosis.empty());
        INFO("first: " << diagnosis.front().name << " (" << diagnosis.front().variant << "), unexplained "
                       << diagnosis.front().unexplained);
        REQUIRE(diagnosis.front().name == c.name);
        REQUIRE(diagnosis.front().explains());
        if (std::string(c.name) == "fitted-radial-distortion") {
            REQUIRE(diagnosis.front().fitted.at(0).value == Approx(-0.23).margin(2e-3));
            REQUIRE(diagnosis.front().fitted.at(1).value == Approx(0.065).margin(1e-2));
        }
    }
    // The map's rows bottom to top.
    DepthMap upsideDown = mapThrough(checker, declaredSpec, DepthQuantity::Distance);
    for (int row = 0; row < upsideDown.height / 2; ++row)
        for (int col = 0; col < upsideDown.width; ++col)
            std::swap(upsideDown.value[std::size_t(row) * upsideDown.width + col],
                      upsideDown.value[std::size_t(upsideDown.height - 1 - row) * upsideDown.width + col]);
    REQUIRE(verifier.diagnose(camera, upsideDown).front().name == "y-flip");
    // A fisheye read as another fisheye.
    const Camera fisheye(lensSpec({"opencv_fisheye", {70, 70, 99.5, 74.5, 0.01, -0.002}}));
    DepthMap equisolidMap = mapThrough(checker, lensSpec({"equisolid", {70, 70, 99.5, 74.5}}), DepthQuantity::Distance);
    const std::vector<Hypothesis> fisheyeDiagnosis = verifier.diagnose(fisheye, equisolidMap);
    REQUIRE(fisheyeDiagnosis.front().name == "fisheye-model");
    REQUIRE(fisheyeDiagnosis.front().variant == "equisolid");
    REQUIRE(fisheyeDiagnosis.front().explains());
}

TEST_CASE("the diagnosis of a lens map names what its reading should declare and the pose's mistakes", "[lens][diagnose]")
{
    // Regression: the lens diagnosis knew only the lens family, so a fisheye map holding Cycles'
    // 1e10 where nothing is hit, one rounded to millimetres, or one of a mesh turned Y-up to Z-up
    // had no name at all.
    const Checker checker(builtinScene("default"));
    const MapVerifier verifier(checker);
    const CameraSpec spec = lensSpec({"opencv_fisheye", {120, 120, 159.5, 119.5, 0.02, -0.004}}, 320, 240,
                                     View::lookAt({0.3, 0.8, 2.5}, {0, 0, 0}, {0, 1, 0}));
    const Camera camera(spec);
    const DepthMap exact = renderedMap(checker, camera, DepthQuantity::Distance);
    const auto best = [&](const DepthMap& map) {
        const VerifyResult run = verifier.verify(camera, map);
        REQUIRE(!run.report.comparison.consistent());
        const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, map);
        REQUIRE(!diagnosis.empty());
        REQUIRE(diagnosis.front().explains());
        return diagnosis.front();
    };
    DepthMap background = exact;  // Cycles' Z pass: 1e10 where no surface is
    for (double& v : background.value) v = v > 0 ? v : 1e10;
    const Hypothesis miss = best(background);
    REQUIRE(miss.name == "miss-value");
    REQUIRE_THAT(miss.explanation, Catch::Contains(">=1e9"));
    DepthMap millimetres = exact;
    for (double& v : millimetres.value) v = std::round(v * 1000) / 1000;
    REQUIRE(best(millimetres).name == "quantum");
    // The renderer's mesh turned −90° about x (Blender's OBJ import: Y-up read as Z-up).
    CameraSpec turned = spec;
    turned.view.hasMatrix = true;
    turned.view.eyeFromWorld = camera.eyeFromWorld * glm::rotate(glm::dmat4(1.0), glm::radians(-90.0), glm::dvec3(1, 0, 0));
    const Hypothesis upAxis = best(renderedMap(checker, Camera(turned), DepthQuantity::Distance));
    REQUIRE(upAxis.name == "mesh-up-axis");
    REQUIRE(upAxis.variant == "−90° about x");
}

TEST_CASE("the diagnosis of a pinhole's map made through a lens fits the lens it left out", "[lens][diagnose]")
{
    const Checker checker(builtinScene("default"));
    const MapVerifier verifier(checker);
    CameraSpec pinhole = lensSpec({"opencv", {140, 140, 99.5, 74.5}});
    pinhole.projection = PinholeIntrinsics{140, 140, 99.5, 74.5, 0}.projection(0.05, 100, "K");
    const DepthMap map = mapThrough(checker, lensSpec({"opencv", {140, 140, 99.5, 74.5, -0.15, 0.03}}), DepthQuantity::EyeZ);
    const Camera camera(pinhole);
    REQUIRE(!verifier.verify(camera, map).report.comparison.consistent());
    const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, map);
    const auto fit = std::find_if(diagnosis.begin(), diagnosis.end(), [](const Hypothesis& h) { return h.name == "fitted-radial-distortion"; });
    REQUIRE(fit != diagnosis.end());
    REQUIRE(fit->explains());
    REQUIRE(fit == diagnosis.begin());
    REQUIRE(fit->fitted.at(0).value == Approx(-0.15).margin(2e-3));
}

// Blender Cycles 3.4's panoramic cameras, by hand from the formulas of its kernel
// (kernel/camera/projection.h, *_to_direction) in zcheck's axes: x right, y down, z forward;
// u = x/W + shift_x, v = 1 − y/H + shift_y (Blender's v grows upwards).
TEST_CASE("Blender's panoramic cameras project as Cycles renders them, by hand", "[lens][blender]")
{
    const double W = kWidth, H = kHeight;
    const auto lens = [&](const char* model, std::vector<double> params) { return LensModel({model, std::move(params)}, kWidth, kHeight); };
    const auto near = [](const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b) <= 1e-12; };
    const glm::dvec3 ahead(0, 0, 1);
    // The image's centre looks straight ahead, for every type.
    for (const LensModel& l : {lens("blender_fisheye_equidistant", {3.0}), lens("blender_fisheye_equisolid", {10.5, kPi, 36, 27}),
                               lens("blender_fisheye_lens_polynomial", {0, -0.05, 1e-4, 0, 0, 3.0, 36, 27}),
                               lens("blender_mirror_ball", {}), lens("blender_equiangular_cubemap_face", {})}) {
        INFO(l.spec().model);
        REQUIRE(near(l.directionFromImage({W / 2, H / 2}).value(), ahead));
        const glm::dvec2 centre = l.imageFromDirection(ahead).value();
        REQUIRE(std::abs(centre.x - W / 2) <= 1e-9);
        REQUIRE(std::abs(centre.y - H / 2) <= 1e-9);
    }

    // Equidistant, fov 3 rad: r = 2|(u − ½, v − ½)|, θ = r·fov/2; the right edge's middle is the
    // ellipse's edge, 1.5 rad to the right; the bottom edge's middle 1.5 rad down.
    const LensModel equidistant = lens("blender_fisheye_equidistant", {3.0});
    REQUIRE(near(equidistant.directionFromImage({W, H / 2}).value(), {std::sin(1.5), 0, std::cos(1.5)}));
    REQUIRE(near(equidistant.directionFromImage({W / 2, H}).value(), {0, std::sin(1.5), std::cos(1.5)}));
    // Halfway to the right edge: θ = 0.75.
    REQUIRE(near(equidistant.directionFromImage({0.75 * W, H / 2}).value(), {std::sin(0.75), 0, std::cos(0.75)}));
    // Outside the ellipse (the corners) no ray; past fov/2 no pixel.
    REQUIRE(!equidistant.directionFromImage({0.95 * W, 0.95 * H}).has_value());
    REQUIRE(!equidistant.imageFromDirection({std::sin(1.51), 0, std::cos(1.51)}).has_value());
    // fov π: camera right (90°) lands on the right edge.
    REQUIRE(lens("blender_fisheye_equidistant", {kPi}).imageFromDirection({1, 0, 0}).value().x == Approx(W).epsilon(1e-14));

    // Equisolid, f = 10.5 mm on a 36 × 27 mm fitted sensor: R = 2f·sin(θ/2) mm from the centre, 90°
    // right at x = W·(½ + 21·sin 45° / 36).
    const LensModel equisolid = lens("blender_fisheye_equisolid", {10.5, kPi, 36, 27});
    REQUIRE(equisolid.imageFromDirection({1, 0, 0}).value().x == Approx(W * (0.5 + 21 * std::sin(kPi / 4) / 36)).epsilon(1e-14));
    // Straight down at 60°: R = 21·sin 30° = 10.5 mm on the 27 mm height.
    REQUIRE(equisolid.imageFromDirection({0, std::sin(kPi / 3), std::cos(kPi / 3)}).value().y ==
            Approx(H * (0.5 + 10.5 / 27)).epsilon(1e-14));
    // fov 2 rad: the circle's rim at R = 21·sin(½) mm; just inside a ray at 1 rad, just outside none.
    const LensModel equisolidNarrow = lens("blender_fisheye_equisolid", {10.5, 2.0, 36, 27});
    const double rim = 21 * std::sin(0.5) / 36 * W;
    REQUIRE(std::acos(equisolidNarrow.directionFromImage({W / 2 + rim - 1e-6, H / 2}).value().z) == Approx(1.0).epsilon(1e-6));
    REQUIRE(!equisolidNarrow.directionFromImage({W / 2 + rim + 1e-6, H / 2}).has_value());

    // Lens polynomial θ = −(k0 + k1R + k2R²): k1 = −0.05, k2 = 1e-4, R = 8 mm → θ = 0.3936 rad.
    const LensModel polynomial = lens("blender_fisheye_lens_polynomial", {0, -0.05, 1e-4, 0, 0, 3.0, 36, 27});
    const double theta = 0.05 * 8 - 1e-4 * 64;
    REQUIRE(near(polynomial.directionFromImage({W / 2 + 8.0 / 36 * W, H / 2}).value(), {std::sin(theta), 0, std::cos(theta)}));
    const glm::dvec2 p = polynomial.imageFromDirection({0, std::sin(theta), std::cos(theta)}).value();
    REQUIRE(std::abs(p.x - W / 2) <= 1e-9);
    REQUIRE(std::abs(p.y - (H / 2 + 8.0 / 27 * H)) <= 1e-9);
    // k0 = −0.01: θ = 0.01 at the centre, so the directions within 0.01 rad of the axis have no pixel.
    const LensModel biased = lens("blender_fisheye_lens_polynomial", {-0.01, -0.05, 0, 0, 0, 3.0, 36, 27});
    REQUIRE(!biased.imageFromDirection({std::sin(0.005), 0, std::cos(0.005)}).has_value());
    REQUIRE(biased.imageFromDirection({std::sin(0.06), 0, std::cos(0.06)}).value().x == Approx(W / 2 + 1.0 / 36 * W).epsilon(1e-12));

    // Mirror ball: camera right at u = ½ + ½/√2; straight back no pixel; past the disc no ray.
    const LensModel ball = lens("blender_mirror_ball", {});
    REQUIRE(ball.imageFromDirection({1, 0, 0}).value().x == Approx(W * (0.5 + 0.5 / std::sqrt(2.0))).epsilon(1e-14));
    REQUIRE(near(ball.directionFromImage({W * (0.5 + 0.5 / std::sqrt(2.0)), H / 2}).value(), {1, 0, 0}));
    REQUIRE(!ball.imageFromDirection({0, 0, -1}).has_value());
    REQUIRE(!ball.directionFromImage({0.5, 0.5}).has_value());

    // Cubemap face: 45° right at the right edge; tan(22.5°) down at three quarters of the height.
    const LensModel face = lens("blender_equiangular_cubemap_face", {});
    REQUIRE(face.imageFromDirection({1, 0, 1}).value().x == Approx(W).epsilon(1e-14));
    REQUIRE(face.imageFromDirection({0, std::tan(kPi / 8), 1}).value().y == Approx(0.75 * H).epsilon(1e-14));
    REQUIRE(!face.imageFromDirection({1, 0, -0.1}).has_value());
    // Shift (whole widths and heights): shift_x = 0.1 moves the view right, the axis to u − shift_x
    // = 0.4 of the width; shift_y = 0.1 moves it up, the axis 0.1 of the height lower.
    const glm::dvec2 shifted = lens("blender_equiangular_cubemap_face", {0.1, 0.1}).imageFromDirection(ahead).value();
    REQUIRE(shifted.x == Approx(0.4 * W).epsilon(1e-14));
    REQUIRE(shifted.y == Approx(0.6 * H).epsilon(1e-14));
}

TEST_CASE("Blender's panoramic cameras refuse what Cycles' formulas cannot hold one-to-one", "[lens][blender]")
{
    const auto make = [](const char* model, std::vector<double> params) { return LensModel({model, std::move(params)}, kWidth, kHeight); };
    REQUIRE_THROWS_WITH(make("blender_fisheye_equidistant", {7.0}), Catch::Contains("'fisheye_fov' must lie in (0, 2π]"));
    REQUIRE_THROWS_WITH(make("blender_fisheye_equisolid", {0.0, 3.0, 36, 27}), Catch::Contains("'fisheye_lens' must be > 0"));
    REQUIRE_THROWS_WITH(make("blender_fisheye_equisolid", {10.5, 3.0, 36, 0}), Catch::Contains("'fitted_sensor_height' must be > 0"));
    REQUIRE_THROWS_WITH(make("blender_equiangular_cubemap_face", {0.6, 0}), Catch::Contains("'shift_x' must lie within ±0.5"));
    REQUIRE_THROWS_WITH(make("blender_fisheye_lens_polynomial", {0.01, -0.05, 0, 0, 0, 3.0, 36, 27}),
                        Catch::Contains("'fisheye_polynomial_k0' must be ≤ 0"));
    REQUIRE_THROWS_WITH(make("blender_fisheye_lens_polynomial", {0, 0.05, 0, 0, 0, 3.0, 36, 27}),
                        Catch::Contains("'fisheye_polynomial_k1' must be < 0"));
    // θ' = 0.05 − 2·0.005·R vanishes at R = 5 mm, well inside a 36 × 27 mm image, at θ = 0.125 < 1.5.
    REQUIRE_THROWS_WITH(make("blender_fisheye_lens_polynomial", {0, -0.05, 0.005, 0, 0, 3.0, 36, 27}),
                        Catch::Contains("stops increasing at R = 5 mm"));
    REQUIRE_THROWS_WITH(make("blender_fisheye_equidistant", {}), Catch::Contains("takes 1 to 3 parameters, got 0"));
}
