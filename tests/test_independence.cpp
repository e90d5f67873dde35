// The two routes are independent: a wrong coefficient in any matrix a Camera builds from a
// projection model (the projection, the viewport, the look-at view) reaches only the raster
// route, which draws with the matrices; the ray route follows the camera's definition
// (camera_rays.h). Each coefficient of each model's matrices is perturbed in turn through
// the test hook (camera.h, zcheck::testing), and `check` must fail.
#include "zcheck/checker.h"
#include "zcheck/error.h"
#include "zcheck/suite.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace zcheck;

namespace {

// The perturbation the hook applies: one coefficient (row, col) of the matrix named `which`.
struct Perturbation {
    std::string which;
    int row = -1, col = -1;
    double relative = 0.01;  // 1 % of the coefficient, or of its row's largest for a zero
};
Perturbation current;

void perturb(const char* which, ProjectionType, glm::dmat4& m)
{
    if (current.which != which || current.row < 0) return;
    double scale = std::abs(m[current.col][current.row]);
    if (scale == 0)
        for (int c = 0; c < 4; ++c) scale = std::max(scale, std::abs(m[c][current.row]));
    m[current.col][current.row] += current.relative * scale;
}

// Sets the hook for the lifetime of the object.
struct HookGuard {
    HookGuard() { testing::setMatrixHook(perturb); }
    ~HookGuard()
    {
        testing::setMatrixHook(nullptr);
        current = {};
    }
};

}  // namespace

TEST_CASE("every coefficient of every projection model's matrices, perturbed, makes check fail", "[independence]")
{
    const Checker checker(builtinScene("builtin:default"));
    const std::vector<NamedCamera> models = cameraModels(checker.scene(), 160, 120);
    HookGuard guard;
    int perturbed = 0;
    for (const NamedCamera& model : models) {
        if (model.spec.projection.type == ProjectionType::Matrix) continue;  // a raw matrix is both routes' definition
        {
            current = {};
            INFO(model.name << ", unperturbed");
            REQUIRE(checker.check(Camera(model.spec)).report.comparison.consistent());
        }
        // The viewport and the view are applied to points (w is dropped): their last row is unused.
        for (const char* which : {"clip_from_eye", "window_from_ndc", "eye_from_world"})
            for (int row = 0; row < (std::string(which) == "clip_from_eye" ? 4 : 3); ++row)
                for (int col = 0; col < 4; ++col) {
                    current = {which, row, col};
                    INFO(model.name << ": " << which << " row " << row << " column " << col << " perturbed by 1%");
                    bool detected = false;
                    try {
                        detected = !checker.check(Camera(model.spec)).report.comparison.consistent();
                    } catch (const Error& e) {
                        detected = true;  // the perturbed camera is refused outright: also a failure
                        INFO(e.what());
                    }
                    REQUIRE(detected);
                    ++perturbed;
                }
    }
    REQUIRE(perturbed >= 11 * 40);
}

TEST_CASE("a raw-matrix camera follows its matrix in both routes, so the same perturbation is consistent",
          "[independence]")
{
    // The counterpart: the matrix is the definition. Perturbing the perspective camera's x scale
    // and pasting the result as a raw matrix leaves the chain self-consistent.
    const Checker checker(builtinScene("builtin:default"));
    CameraSpec spec = checker.scene().defaultCamera;
    spec.width = 160, spec.height = 120;
    glm::dmat4 clipFromEye;
    {
        HookGuard guard;
        current = {"clip_from_eye", 0, 0};
        clipFromEye = Camera(spec).clipFromEye;
        REQUIRE_FALSE(checker.check(Camera(spec)).report.comparison.consistent());
    }
    spec.projection.type = ProjectionType::Matrix;
    spec.projection.clipFromEye = clipFromEye;
    REQUIRE(checker.check(Camera(spec)).report.comparison.consistent());
}
