// Every projection model and view is consistent through both routes, in every convention,
// float32 and unorm24, standard and reversed (and with an infinite far plane where it
// applies), on built-in scenes and the shared meshes.
#include "zcheck/checker.h"
#include "zcheck/suite.h"

#include "zcheck/mesh_loader.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace zcheck;

namespace {

const std::string kModels = ZCHECK_MODELS_DIR;

void requireEveryModelConsistent(const std::string& sceneName)
{
    const Scene scene = loadScene(sceneName);
    const Checker checker(scene);
    for (const NamedCamera& model : cameraModels(scene, 320, 240))
        for (const auto& convention : Convention::presetNames())
            for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24})
                for (bool reversed : {false, true}) {
                    DepthSettings depth;
                    depth.format = format, depth.reversed = reversed;
                    const CameraSpec spec = withDepthAndConvention(model.spec, scene, Convention::preset(convention), depth);
                    const ComparisonReport r = checker.check(Camera(spec)).report.comparison;
                    INFO(sceneName << ": " << model.name << ", " << convention << ", " << toString(format)
                                   << (reversed ? ", reversed" : "") << ": both hit " << r.bothHit << ", depth errors "
                                   << r.depthErrors << ", unexplained coverage " << r.coverageUnexplained
                                   << ", max/tol " << r.maxErrorOverTolerance);
                    REQUIRE(r.bothHit > 300);  // the model sees the scene
                    REQUIRE(r.consistent());
                }
}

}  // namespace

TEST_CASE("every model is consistent on builtin:default", "[e2e][models]") { requireEveryModelConsistent("builtin:default"); }
TEST_CASE("every model is consistent on builtin:terrain", "[e2e][models]") { requireEveryModelConsistent("builtin:terrain?n=96"); }
TEST_CASE("every model is consistent on builtin:near-crossing", "[e2e][models]") { requireEveryModelConsistent("builtin:near-crossing"); }
TEST_CASE("every model is consistent on stanford-bunny.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/stanford-bunny.obj"); }
TEST_CASE("every model is consistent on nefertiti.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/nefertiti.obj"); }
TEST_CASE("every model is consistent on fandisk.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/fandisk.obj"); }
TEST_CASE("every model is consistent on spot.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/spot.obj"); }
TEST_CASE("every model is consistent on cow.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/cow.obj"); }
TEST_CASE("every model is consistent on teapot.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/teapot.obj"); }
TEST_CASE("every model is consistent on suzanne.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/suzanne.obj"); }
TEST_CASE("every model is consistent on beast.obj", "[e2e][models]") { requireEveryModelConsistent(kModels + "/beast.obj"); }
TEST_CASE("every model is consistent on igea.ply", "[e2e][models]") { requireEveryModelConsistent(kModels + "/igea.ply"); }
