// Depth buffers from a rasterizer no one here wrote: Mesa's llvmpipe, drawing through OpenGL
// and EGL (reference/gl_reference.h), in OpenGL's three depth set-ups — the classic [-1, 1]
// clip range into a 24-bit buffer, glClipControl's [0, 1] range, and reversed-Z into a float
// buffer. Each is verified as the camera declares it and must be consistent (no false alarm on
// a real renderer's snapping, fill rule, interpolation and quantization); declared with the
// other range or without the reversal, the diagnosis must name that mistake.
//
// The mesh and the clip-from-world matrix are the camera's own; what is independent is
// everything after them: Mesa's clipping, rasterization and depth buffer.
#include "zcheck/gl_reference.h"
#include "zcheck/map_verifier.h"
#include "zcheck/mesh_loader.h"

#include "diagnosis_helpers.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

using namespace zcheck;

namespace {

enum class GlDepth { MinusOneToOne, ZeroToOne, Reversed };

const char* nameOf(GlDepth setup)
{
    switch (setup) {
    case GlDepth::MinusOneToOne: return "[-1, 1], unorm24";
    case GlDepth::ZeroToOne: return "glClipControl [0, 1], unorm24";
    case GlDepth::Reversed: return "reversed-Z [0, 1], float32";
    }
    return "";
}

// The zcheck camera that describes what the OpenGL draw does: OpenGL's axes and window (y up,
// rows read back bottom-up and flipped), its clip range and depth buffer.
CameraSpec glCameraSpec(const Scene& scene, GlDepth setup, int width, int height)
{
    CameraSpec spec = scene.defaultCamera;
    spec.width = width, spec.height = height;
    spec.convention = Convention::preset("opengl");
    spec.depth.format = setup == GlDepth::Reversed ? DepthFormat::Float32 : DepthFormat::Unorm24;
    if (setup != GlDepth::MinusOneToOne) spec.convention.ndcDepth = NdcDepthRange::ZeroToOne;
    spec.depth.reversed = setup == GlDepth::Reversed;
    return spec;
}

// Mesa's draw of the scene with the camera's matrices in the OpenGL depth set-up `setup`
// (timeGlDepthDraw with `repeats`); with `samples` > 1 multisampled and resolved by a blit.
reference::GlDepthTiming glDraw(const Scene& scene, const Camera& camera, GlDepth setup, int samples, int repeats)
{
    std::vector<float> positions;
    for (const glm::vec3& p : scene.positions) positions.insert(positions.end(), {p.x, p.y, p.z});
    std::vector<std::uint32_t> indices;
    for (const glm::uvec3& t : scene.triangles) indices.insert(indices.end(), {t.x, t.y, t.z});
    reference::GlDepthInput input;
    input.positions = positions.data(), input.vertexCount = scene.positions.size();
    input.indices = indices.data(), input.triangleCount = scene.triangles.size();
    const glm::dmat4 clipFromWorld = camera.clipFromEye * camera.eyeFromWorld;
    std::memcpy(input.clipFromWorld.data(), &clipFromWorld[0][0], sizeof(double) * 16);
    input.width = camera.width(), input.height = camera.height();
    input.reversedZ = setup == GlDepth::Reversed;
    input.zeroToOne = setup != GlDepth::MinusOneToOne;
    input.threads = 2;
    input.samples = samples;
    return reference::timeGlDepthDraw(input, repeats);
}

// Mesa's depth buffer (glDraw, no timed repeats) as a window-depth map; the sample positions
// GL reports in `samplePositions`.
DepthMap glDepthMap(const Scene& scene, const Camera& camera, GlDepth setup, int samples = 0,
                    std::vector<std::array<float, 2>>* samplePositions = nullptr)
{
    const reference::GlDepthTiming drawn = glDraw(scene, camera, setup, samples, 0);
    if (samplePositions) *samplePositions = drawn.samplePositions;
    INFO("OpenGL renderer: " << drawn.renderer);
    REQUIRE(drawn.depth.size() == std::size_t(camera.width()) * camera.height());
    DepthMap map;
    map.width = camera.width(), map.height = camera.height(), map.quantity = DepthQuantity::Window;
    map.value.assign(drawn.depth.begin(), drawn.depth.end());
    return map;
}

// The map verified through the camera: consistent, with enough surface compared to mean it.
void requireConsistent(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    const ComparisonReport r = verifier.verify(camera, map).comparison.report;
    INFO("unexplained " << r.unexplained() << " of " << r.bothHit << " both hit, max error/tolerance " << r.maxErrorOverTolerance);
    REQUIRE(r.bothHit > 5000);
    REQUIRE(r.consistent());
}

std::vector<std::string> scenes()
{
    std::vector<std::string> out = {"builtin:default", "builtin:terrain?n=48", "builtin:near-crossing"};
    if (std::string(ZCHECK_MODELS_DIR).size() > 0) out.push_back(std::string(ZCHECK_MODELS_DIR) + "/stanford-bunny.obj");
    return out;
}

}  // namespace

TEST_CASE("OpenGL depth buffers drawn by Mesa's llvmpipe verify as consistent", "[verify][real-renderer]")
{
    for (const std::string& path : scenes()) {
        const Scene scene = loadScene(path);
        const Checker checker(scene);
        const MapVerifier verifier(checker);
        for (GlDepth setup : {GlDepth::MinusOneToOne, GlDepth::ZeroToOne, GlDepth::Reversed}) {
            INFO(path << ", " << nameOf(setup));
            const Camera camera(glCameraSpec(scene, setup, 320, 240));
            requireConsistent(verifier, camera, glDepthMap(scene, camera, setup));
        }
    }
}

TEST_CASE("the llvmpipe yardstick times each repeat warm and into a new depth buffer, and reads back the first buffer",
          "[real-renderer]")
{
    // bench's cold yardstick: a depth buffer made per draw; the one read back is the buffer the
    // warm draws drew into, the same picture as with no repeats at all.
    const Scene scene = loadScene("builtin:terrain?n=48");
    for (GlDepth setup : {GlDepth::MinusOneToOne, GlDepth::Reversed}) {
        INFO(nameOf(setup));
        const Camera camera(glCameraSpec(scene, setup, 160, 120));
        const reference::GlDepthTiming once = glDraw(scene, camera, setup, 0, 0);
        const reference::GlDepthTiming timed = glDraw(scene, camera, setup, 0, 3);
        CHECK(once.drawMs.empty());
        CHECK(once.coldDrawMs.empty());
        REQUIRE(timed.drawMs.size() == 3);
        REQUIRE(timed.coldDrawMs.size() == 3);
        for (double ms : timed.coldDrawMs) CHECK(ms > 0);
        CHECK(timed.depth == once.depth);
        const float cleared = setup == GlDepth::Reversed ? 0.0f : 1.0f;
        CHECK(std::count(timed.depth.begin(), timed.depth.end(), cleared) < std::ptrdiff_t(timed.depth.size() / 2));
    }
}

TEST_CASE("OpenGL depth buffers verify as consistent in every projection model", "[verify][real-renderer]")
{
    // Off-axis frustum, orthographic box, cabinet oblique, an off-centre pinhole, a lens and an
    // infinite far plane: the matrices differ, Mesa's rasterization is the same.
    const Scene scene = loadScene("builtin:default");
    const Checker checker(scene);
    const MapVerifier verifier(checker);
    const CameraSpec base = glCameraSpec(scene, GlDepth::MinusOneToOne, 320, 240);
    const double n = base.projection.near, t = std::tan(glm::radians(base.projection.fovyDeg) / 2);
    const double sceneHalfHeight = glm::length(base.view.eye - base.view.target) * t;
    std::vector<std::pair<std::string, Projection>> projections;
    Projection p = base.projection;
    p.type = ProjectionType::Frustum, p.left = -0.6 * n * t * 4 / 3, p.right = 1.3 * n * t * 4 / 3, p.bottom = -0.8 * n * t, p.top = 1.1 * n * t;
    projections.emplace_back("off-axis frustum", p);
    p = base.projection;
    p.type = ProjectionType::Orthographic, p.left = -sceneHalfHeight * 4 / 3, p.right = sceneHalfHeight * 4 / 3,
    p.bottom = -sceneHalfHeight, p.top = sceneHalfHeight;
    projections.emplace_back("orthographic", p);
    Projection oblique = p;
    oblique.type = ProjectionType::Oblique, oblique.foreshortening = 0.5, oblique.angleDeg = 30;
    projections.emplace_back("cabinet oblique", oblique);
    p = base.projection;
    p.type = ProjectionType::Pinhole, p.fx = 240 / (2 * t) * 1.05, p.fy = 240 / (2 * t), p.cx = 159.5 + 17.3, p.cy = 119.5 - 9.6;
    projections.emplace_back("off-centre pinhole", p);
    p = base.projection;
    p.type = ProjectionType::Lens, p.focalMm = 35, p.sensorWidthMm = 36;
    projections.emplace_back("35 mm lens", p);
    p = base.projection;
    p.far = INFINITY;
    projections.emplace_back("infinite far plane", p);
    for (const auto& [name, projection] : projections)
        for (GlDepth setup : {GlDepth::MinusOneToOne, GlDepth::Reversed}) {
            INFO(name << ", " << nameOf(setup));
            CameraSpec spec = glCameraSpec(scene, setup, 320, 240);
            spec.projection = projection;
            const Camera camera(spec);
            requireConsistent(verifier, camera, glDepthMap(scene, camera, setup));
        }
}

TEST_CASE("OpenGL depth buffers read under the wrong depth set-up are diagnosed by name", "[verify][diagnose][real-renderer]")
{
    const Scene scene = loadScene("builtin:default");
    const Checker checker(scene);
    const MapVerifier verifier(checker);
    // A [0, 1] (Direct3D-style) projection matrix drawn without glClipControl: OpenGL takes its
    // clip z for the classic [-1, 1] range, and the buffer holds depths in [0.5, 1].
    const Camera zeroToOne(glCameraSpec(scene, GlDepth::ZeroToOne, 320, 240));
    const Camera classic(glCameraSpec(scene, GlDepth::MinusOneToOne, 320, 240));
    const DepthMap zeroToOneMap = glDepthMap(scene, zeroToOne, GlDepth::MinusOneToOne);
    REQUIRE_FALSE(verifier.verify(classic, zeroToOneMap).comparison.report.consistent());
    REQUIRE(testing::diagnosedAs(verifier, classic, zeroToOneMap, "ndc-range"));
    // A reversed-Z buffer declared as standard [0, 1] depth.
    CameraSpec standardSpec = glCameraSpec(scene, GlDepth::Reversed, 320, 240);
    standardSpec.depth.reversed = false;
    const Camera reversed(glCameraSpec(scene, GlDepth::Reversed, 320, 240)), standard(standardSpec);
    const DepthMap reversedMap = glDepthMap(scene, reversed, GlDepth::Reversed);
    REQUIRE_FALSE(verifier.verify(standard, reversedMap).comparison.report.consistent());
    REQUIRE(testing::diagnosedAs(verifier, standard, reversedMap, "reversed-as-standard"));
    // glReadPixels' rows taken as they come, bottom row first, for an image's top-down rows.
    const DepthMap classicMap = glDepthMap(scene, classic, GlDepth::MinusOneToOne);
    DepthMap bottomUp = classicMap;
    for (int row = 0; row < bottomUp.height; ++row)
        std::copy_n(classicMap.value.begin() + std::ptrdiff_t(row) * bottomUp.width, bottomUp.width,
                    bottomUp.value.begin() + std::ptrdiff_t(bottomUp.height - 1 - row) * bottomUp.width);
    REQUIRE_FALSE(verifier.verify(classic, bottomUp).comparison.report.consistent());
    REQUIRE(testing::diagnosedAs(verifier, classic, bottomUp, "y-flip"));
}

TEST_CASE("a depth buffer resolved from Mesa's multisampling is diagnosed with the sample GL reports", "[verify][diagnose][real-renderer]")
{
    // 4× MSAA depth (llvmpipe's most), resolved into a single-sample buffer by glBlitFramebuffer as an
    // application reading it back would: the resolve keeps one sample's depth, so the map is a
    // map sampled off the pixel centre, and the fit must find one of the positions GL reports
    // (glGetMultisamplefv: x right, y up from the pixel's lower-left corner).
    const Scene scene = loadScene("builtin:default");
    const Checker checker(scene);
    const MapVerifier verifier(checker);
    const Camera camera(glCameraSpec(scene, GlDepth::MinusOneToOne, 320, 240));
    for (int samples : {4}) {
        INFO(samples << "× MSAA");
        std::vector<std::array<float, 2>> positions;
        const DepthMap map = glDepthMap(scene, camera, GlDepth::MinusOneToOne, samples, &positions);
        REQUIRE(positions.size() == std::size_t(samples));
        const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, map);
        REQUIRE_FALSE(diagnosis.empty());
        const Hypothesis& best = diagnosis.front();
        INFO(best.name << ": " << best.explanation << ", unexplained " << best.unexplained);
        REQUIRE(best.consistent);
        REQUIRE(best.name == "sample-offset");
        double dx = NAN, dy = NAN;
        for (const FittedValue& v : best.fitted) {
            if (v.name == "sample_dx_px") dx = v.value;
            if (v.name == "sample_dy_px") dy = v.value;
        }
        const bool reported = std::any_of(positions.begin(), positions.end(), [&](const std::array<float, 2>& p) {
            return std::abs(dx - (p[0] - 0.5)) <= 1.0 / 256 && std::abs(dy - (0.5 - p[1])) <= 1.0 / 256;
        });
        REQUIRE(reported);
        // llvmpipe's positions are the standard pattern's, from the lower-left corner: the
        // diagnosis names the sample in the framebuffer's own axes (y up in OpenGL).
        const std::vector<std::array<float, 2>> standard = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f}};
        if (positions == standard) REQUIRE(best.explanation.find("of 4× MSAA's standard pattern") != std::string::npos);
        // The same buffer with glReadPixels' bottom-up rows taken as top-down: two mistakes, a
        // re-reading and a fitted departure, named together.
        DepthMap bottomUp = map;
        for (int row = 0; row < map.height; ++row)
            std::copy_n(map.value.begin() + std::ptrdiff_t(row) * map.width, map.width,
                        bottomUp.value.begin() + std::ptrdiff_t(map.height - 1 - row) * map.width);
        const std::vector<Hypothesis> both = verifier.diagnose(camera, bottomUp);
        REQUIRE_FALSE(both.empty());
        INFO("flipped: " << both.front().name << ": " << both.front().explanation << ", unexplained " << both.front().unexplained);
        REQUIRE(both.front().consistent);
        REQUIRE(both.front().name == "y-flip + sample-offset");
        for (const FittedValue& v : both.front().fitted) {
            if (v.name == "sample_dx_px") REQUIRE(std::abs(v.value - dx) <= 1.0 / 256);
            if (v.name == "sample_dy_px") REQUIRE(std::abs(v.value - dy) <= 1.0 / 256);
        }
    }
}
