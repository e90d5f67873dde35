// End to end: both routes on real scenes across the whole configuration matrix, and the
// check's sensitivity to deliberately broken chains.
#include "zcheck/checker.h"

#include "zcheck/mesh_loader.h"

#include "random_scenes.h"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

using namespace zcheck;

namespace {

const std::string kModels = ZCHECK_MODELS_DIR;

std::string describe(const CameraSpec& spec, const ComparisonReport& r)
{
    std::ostringstream out;
    out << spec.convention.name << " " << toString(spec.depth.format) << (spec.depth.reversed ? " reversed" : "")
        << " range [" << spec.depth.rangeMin << "," << spec.depth.rangeMax << "]: both hit " << r.bothHit
        << ", depth errors " << r.depthErrors << ", unexplained coverage " << r.coverageUnexplained << ", max/tol "
        << r.maxErrorOverTolerance;
    if (!r.unexplainedSamples.empty())
        out << ", first unexplained (" << r.unexplainedSamples[0].col << "," << r.unexplainedSamples[0].row << ") "
            << toString(r.unexplainedSamples[0].pixelClass);
    return out.str();
}

// Every convention × depth format × reversed-Z on/off, plus a narrowed depth range.
void requireConsistentEverywhere(const std::string& sceneName)
{
    const Scene scene = loadScene(sceneName);
    const Checker checker(scene);
    for (const auto& convention : Convention::presetNames())
        for (const auto& format : depthFormatNames())
            for (bool reversed : {false, true})
                for (auto range : {std::pair{0.0, 1.0}, std::pair{0.2, 0.7}}) {
                    if (range.first != 0.0 && format != "float32") continue;  // one narrowed range per convention
                    CameraSpec spec = scene.defaultCamera;
                    spec.convention = Convention::preset(convention);
                    spec.depth = {depthFormatFromName(format), reversed, range.first, range.second};
                    const CheckResult run = checker.check(Camera(spec));
                    const ComparisonReport& r = run.report.comparison;
                    INFO(sceneName << " " << describe(spec, r));
                    REQUIRE(r.bothHit > 1000);  // the camera actually sees the scene
                    REQUIRE(r.unexplained() == 0);
                    REQUIRE(r.consistent());
                }
}

ComparisonReport checkWithSampling(const Scene& scene, const CameraSpec& spec, const RayFaults& sampling)
{
    CheckOptions options;
    options.faults.ray = sampling;
    return Checker(scene).check(Camera(spec), options).report.comparison;
}

}  // namespace

TEST_CASE("builtin:default is consistent in every convention, depth format and Z direction", "[e2e]")
{
    requireConsistentEverywhere("builtin:default");
}

TEST_CASE("builtin:near-crossing is consistent in every convention, depth format and Z direction", "[e2e]")
{
    requireConsistentEverywhere("builtin:near-crossing");
}

TEST_CASE("builtin:terrain is consistent in every convention, depth format and Z direction", "[e2e]")
{
    requireConsistentEverywhere("builtin:terrain?n=160");
}

TEST_CASE("stanford-bunny.obj is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/stanford-bunny.obj"); }
TEST_CASE("nefertiti.obj is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/nefertiti.obj"); }
TEST_CASE("fandisk.obj is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/fandisk.obj"); }
TEST_CASE("spot.obj is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/spot.obj"); }
TEST_CASE("cow.obj is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/cow.obj"); }
TEST_CASE("teapot.obj is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/teapot.obj"); }
TEST_CASE("suzanne.obj (quads) is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/suzanne.obj"); }
TEST_CASE("beast.obj (quads) is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/beast.obj"); }
TEST_CASE("igea.ply (triangle strips) is consistent everywhere", "[e2e][mesh]") { requireConsistentEverywhere(kModels + "/igea.ply"); }

TEST_CASE("every shared mesh loads with its documented face count", "[mesh]")
{
    // Triangles after triangulation: quads become two triangles each.
    const std::pair<const char*, std::size_t> expected[] = {
        {"stanford-bunny.obj", 69451}, {"nefertiti.obj", 99938}, {"fandisk.obj", 12946},
        {"spot.obj", 5856},            {"cow.obj", 5804},        {"teapot.obj", 6320},
    };
    for (const auto& [file, triangles] : expected) {
        INFO(file);
        REQUIRE(loadMesh(kModels + "/" + file).triangleCount() == triangles);
    }
    REQUIRE(loadMesh(kModels + "/suzanne.obj").triangleCount() == 468 * 2 + 32);
}

TEST_CASE("regression: assimp read igea.ply's triangle strips as a single triangle", "[mesh][regression]")
{
    // igea.ply holds 134,345 vertices and one `tristrips` element; assimp 5.2 returned one
    // triangle without an error. A closed-ish scan of V vertices has about 2V triangles.
    const Scene igea = loadMesh(kModels + "/igea.ply");
    REQUIRE(igea.positions.size() == 134345);
    REQUIRE(igea.triangleCount() > 260000);
    REQUIRE(igea.triangleCount() < 270000);
}

namespace {
// The check must call a ray route that samples the wrong place inconsistent, loudly.
void requireCaught(const std::string& sceneName, const RayFaults& fault, std::int64_t minimumUnexplained)
{
    const Scene scene = loadScene(sceneName);
    for (const auto& format : depthFormatNames()) {
        CameraSpec spec = scene.defaultCamera;
        spec.depth.format = depthFormatFromName(format);
        const ComparisonReport r = checkWithSampling(scene, spec, fault);
        INFO(sceneName << " shift " << fault.shiftPixels.x << "," << fault.shiftPixels.y
                       << (fault.flipRows ? " flipped" : "") << " " << describe(spec, r));
        REQUIRE_FALSE(r.consistent());
        REQUIRE(r.unexplained() > minimumUnexplained);
    }
}
}  // namespace

TEST_CASE("a y-flipped ray route is reported inconsistent", "[sensitivity]")
{
    RayFaults flipped;
    flipped.flipRows = true;
    for (const std::string& name : {std::string("builtin:default"), kModels + "/stanford-bunny.obj"})
        requireCaught(name, flipped, 1000);
}

TEST_CASE("a ray route missing the half-pixel offset is reported inconsistent", "[sensitivity]")
{
    for (const std::string& name : {std::string("builtin:default"), std::string("builtin:terrain?n=64"),
                                    kModels + "/stanford-bunny.obj"})
        for (const glm::dvec2 shift : {glm::dvec2(-0.5, 0.0), glm::dvec2(0.0, -0.5), glm::dvec2(-0.5, -0.5)}) {
            RayFaults shifted;
            shifted.shiftPixels = shift;
            requireCaught(name, shifted, 100);
        }
}

TEST_CASE("a ray route shifted by a tenth of a pixel is still caught", "[sensitivity]")
{
    const Scene scene = builtinScene("builtin:default");
    RayFaults shifted;
    shifted.shiftPixels = {0.1, 0.0};
    const ComparisonReport r = checkWithSampling(scene, scene.defaultCamera, shifted);
    INFO(describe(scene.defaultCamera, r));
    REQUIRE_FALSE(r.consistent());
}

TEST_CASE("regression: unorm16 with a tiny near plane flagged surfaces at the clear value as unexplained", "[e2e][regression]")
{
    // near = 1e-4: beyond ~6.5 units unorm16 rounds every depth to the clear value, so the
    // strict depth test cannot pass and a correct raster draws nothing there. That is a
    // precision limit, explained and counted, not a chain error.
    const Scene scene = builtinScene("builtin:default");
    for (bool reversed : {false, true}) {
        CameraSpec spec = scene.defaultCamera;
        spec.projection.near = 1e-4, spec.projection.far = 1e4;
        spec.depth.format = DepthFormat::Unorm16;
        spec.depth.reversed = reversed;
        const ComparisonReport r = Checker(scene).check(Camera(spec)).report.comparison;
        INFO(describe(spec, r));
        REQUIRE(r.lostAtClearValue > 10000);
        REQUIRE(r.consistent());
    }
}

TEST_CASE("odd image sizes and extreme near/far ratios are consistent", "[e2e]")
{
    const Scene scene = builtinScene("builtin:default");
    const Checker checker(scene);
    for (auto size : {std::pair{333, 257}, std::pair{1, 1}, std::pair{2, 3}, std::pair{1001, 17}, std::pair{17, 999}})
        for (auto nearFar : {std::pair{0.1, 100.0}, std::pair{1e-4, 1e4}, std::pair{4.5, 12.0}, std::pair{1e-3, 1e7}})
            for (const auto& format : depthFormatNames())
                for (bool reversed : {false, true}) {
                    CameraSpec spec = scene.defaultCamera;
                    spec.width = size.first, spec.height = size.second;
                    spec.projection.near = nearFar.first, spec.projection.far = nearFar.second;
                    spec.depth.format = depthFormatFromName(format);
                    spec.depth.reversed = reversed;
                    const ComparisonReport r = checker.check(Camera(spec)).report.comparison;
                    INFO(size.first << "x" << size.second << " near " << nearFar.first << " far " << nearFar.second
                                    << " " << describe(spec, r));
                    REQUIRE(r.consistent());
                }
}

TEST_CASE("glTF files load with their node transforms applied", "[mesh]")
{
    // tests/data_quad.gltf: a 2×2 quad (two triangles) in x ∈ [−1,1], y ∈ [0,2], z = 0,
    // placed by its node at translation (10, 0, −5).
    const Scene quad = loadMesh(std::string(ZCHECK_TESTS_DIR) + "/data_quad.gltf");
    REQUIRE(quad.triangleCount() == 2);
    REQUIRE(quad.boundsMin() == glm::dvec3(9, 0, -5));
    REQUIRE(quad.boundsMax() == glm::dvec3(11, 2, -5));
    REQUIRE(Checker(quad).check(Camera(quad.defaultCamera)).report.comparison.consistent());
}

TEST_CASE("regression: surfaces lying exactly on the near or far plane gave unexplained mismatches", "[e2e][regression]")
{
    // Quads at exactly eye-z = near and eye-z = far (a common test set-up): binary32
    // tNear/tFar in Embree and the rasterizer's clipping round differently there, and with
    // reversed-Z float32 the window depth at far is ~0, below the double chain's rounding.
    const double n = 0.5, f = 20;
    Scene planes;
    planes.name = "near and far quads";
    auto quad = [&](double z, double x0, double x1) {
        planes.append({{float(x0), -30, float(-z)}, {float(x1), -30, float(-z)}, {float(x1), 30, float(-z)}, {float(x0), 30, float(-z)}},
                      {{0, 1, 2}, {0, 2, 3}});
    };
    quad(f, -30, 30);      // the far plane, behind everything
    quad(n, -0.1, 0.05);   // a strip on the near plane
    for (const auto& convention : Convention::presetNames())
        for (const auto& format : depthFormatNames())
            for (bool reversed : {false, true}) {
                CameraSpec spec;
                spec.convention = Convention::preset(convention);
                spec.width = 160, spec.height = 120;
                spec.projection.near = n, spec.projection.far = f;
                spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
                spec.depth.format = depthFormatFromName(format);
                spec.depth.reversed = reversed;
                const ComparisonReport r = Checker(planes).check(Camera(spec)).report.comparison;
                INFO(describe(spec, r));
                REQUIRE(r.consistent());
            }
}

TEST_CASE("regression: a mesh far from the world origin lost its edges to binary32 ray origins", "[e2e][regression]")
{
    // The bunny moved to x = 1000: rounding the ray origin to binary32 in world coordinates
    // moved every silhouette by a sizeable fraction of a pixel. Embree now traces in a frame
    // centred on the scene.
    Scene bunny = loadMesh(kModels + "/stanford-bunny.obj");
    for (auto& p : bunny.positions) p += glm::vec3(1000.0f, -400.0f, 700.0f);
    const glm::dvec3 lo = bunny.boundsMin(), hi = bunny.boundsMax();
    bunny.defaultCamera = framingCameraSpec((lo + hi) / 2.0, glm::length(hi - lo) / 2);
    CameraSpec spec = bunny.defaultCamera;
    spec.width = 1280, spec.height = 960;
    const ComparisonReport r = Checker(bunny).check(Camera(spec)).report.comparison;
    INFO(describe(spec, r));
    REQUIRE(r.consistent());
}

TEST_CASE("PLY triangle strips: restarts, alternating winding, unsigned restarts, ascii and binary", "[mesh]")
{
    // Four vertices of a unit square, one strip 0 1 2 3 → triangles (0,1,2), (2,1,3); then a
    // restart and a strip that only repeats an index (no area, skipped).
    const std::string dir = std::string(ZCHECK_TESTS_DIR);
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                               "property float z\nelement tristrips 1\n";
    const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n";
    auto load = [&](const std::string& listType, const std::string& strip, bool binary) {
        const std::string path = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") + "/zcheck_strip_test.ply";
        std::ofstream out(path, std::ios::binary);
        if (!binary) {
            out << header << "property list int " << listType << " vertex_indices\nend_header\n" << vertices << strip << "\n";
        } else {
            out << "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                   "property float z\nelement tristrips 1\nproperty list int uint vertex_indices\nend_header\n";
            const float xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
            out.write(reinterpret_cast<const char*>(xyz), sizeof xyz);
            const std::int32_t count = 7;
            const std::uint32_t indices[7] = {0, 1, 2, 3, 0xFFFFFFFFu, 3, 3};
            out.write(reinterpret_cast<const char*>(&count), sizeof count);
            out.write(reinterpret_cast<const char*>(indices), sizeof indices);
        }
        out.close();
        return loadMesh(path);
    };
    for (const Scene& scene : {load("int", "7 0 1 2 3 -1 3 3", false), load("uint", "7 0 1 2 3 4294967295 3 3", false),
                               load("uint", "", true)}) {
        REQUIRE(scene.triangleCount() == 2);
        REQUIRE(scene.triangles[0] == glm::uvec3(0, 1, 2));
        REQUIRE(scene.triangles[1] == glm::uvec3(2, 1, 3));  // odd triangles swap to keep the winding
    }
    (void)dir;
}

TEST_CASE("regression: with an infinite far plane every coverage mismatch was explained as lying on the far plane", "[e2e][regression]")
{
    // |t − tFar| ≤ ε·tFar with tFar = +inf is inf ≤ inf: every ray-only pixel counted as
    // "on the far plane". Found by the suite: with far = inf, a raster that draws nothing at
    // all looked consistent.
    const Scene scene = builtinScene("builtin:default");
    CameraSpec spec = scene.defaultCamera;
    spec.projection.far = INFINITY;
    for (bool reversed : {false, true}) {
        spec.depth.reversed = reversed;
        const Camera camera(spec);
        const RenderResult ray = RayRenderer(scene).render(camera);
        RenderResult empty = ray;  // the same size, nothing drawn
        std::fill(empty.primitiveId.begin(), empty.primitiveId.end(), kNoPrimitive);
        std::fill(empty.windowDepth.value.begin(), empty.windowDepth.value.end(), camera.clearDepth());
        const ComparisonReport r = compareRoutes(scene, camera, ray, empty).report;
        INFO(describe(spec, r));
        REQUIRE(r.coverageUnexplained > 10000);
        REQUIRE_FALSE(r.consistent());
    }
}

TEST_CASE("property: random triangle soups through random cameras raise no false alarm", "[e2e][property]")
{
    // Scenes no mesh file holds (triangles through one another, coplanar overlaps, slivers seen
    // edge-on, triangles across the near, far and eye planes, sub-pixel ones), as far from the
    // world origin as georeferenced data (UTM: 5·10⁶ m), through cameras of every convention,
    // format, projection and range, some through lens models: a correct chain must never be
    // called inconsistent. (Runs of this kind, ~35,000 cases, found four lens cameras far from the
    // origin whose forward test did not allow for the rounding of their hits: the regression test
    // in test_lens.cpp. Nothing else in them.)
    std::mt19937_64 random(20261201);
    int checked = 0, seenNothing = 0, refused = 0, lensChecks = 0;
    for (int k = 0; k < 2000; ++k) {
        const testing::RandomCase c = testing::randomCase(random, k);
        INFO("case " << k << ", scene kind " << k % 6 << ", camera " << c.cameraJson);
        if (!c.camera) {
            ++refused;
            continue;
        }
        const CheckResult run = Checker(c.scene).check(*c.camera);
        const ComparisonReport& r = run.report.comparison;
        INFO(describe(c.camera->spec(), r));
        REQUIRE(r.consistent());
        if (r.bothHit + r.rayOnly + r.rasterOnly == 0) {  // `zcheck check` would say "nothing to compare"
            ++seenNothing;
            continue;
        }
        ++checked;
        lensChecks += run.report.lens.has_value();
    }
    INFO(checked << " checked, " << seenNothing << " saw nothing, " << refused << " refused or collapsed, " << lensChecks << " through lenses");
    REQUIRE(checked >= 1000);
    REQUIRE(lensChecks >= 50);
}
