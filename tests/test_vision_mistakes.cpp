// The mistakes vision pipelines make with cameras from files (COLMAP, TUM-style trajectories,
// Blender, NeRF-style data): each renderer's camera below is built here from the textbook
// formulas (Hamilton quaternions, [R | t] in OpenCV axes, a principal point in pixels), the map
// rendered through it, and the diagnosis, given the camera the mistake made, must name the
// mistake — at several magnitudes, on two scenes and in several conventions.
#include "zcheck/fit.h"
#include "zcheck/map_verifier.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/verify.h"

#include "diagnosis_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace zcheck;
using testing::mapOf;

namespace {

const Scene& bunny()
{
    static const Scene scene = loadScene(std::string(ZCHECK_MODELS_DIR) + "/stanford-bunny.obj");
    return scene;
}

// The scene's own camera, smaller, in `convention`.
CameraSpec smallSpec(const Scene& scene, const std::string& convention, int width = 200, int height = 150)
{
    CameraSpec spec = scene.defaultCamera;
    spec.width = width, spec.height = height;
    spec.convention = Convention::preset(convention);
    return spec;
}

// Textbook rotation of a Hamilton quaternion w + xi + yj + zk (normalised here).
glm::dmat3 rotationOf(double w, double x, double y, double z)
{
    const double n = std::sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    const double rows[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                               {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                               {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    glm::dmat3 m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m[c][r] = rows[r][c];
    return m;
}

// OpenCV axes (x right, y down, z forward) from the convention's eye axes.
glm::dmat4 cvFromEyeAxes(const Convention& convention)
{
    glm::dmat4 f(1.0);
    f[1][1] = -convention.eyeUpY, f[2][2] = convention.eyeForwardZ;
    return f;
}

// The scene's camera as pinhole intrinsics (pixels; the top-left pixel's centre is 0).
CameraSpec pinholeSpec(const Scene& scene, const std::string& convention, int width, int height, double f, double cx, double cy)
{
    CameraSpec spec = smallSpec(scene, convention, width, height);
    spec.projection.type = ProjectionType::Pinhole;
    spec.projection.fx = spec.projection.fy = f;
    spec.projection.cx = cx, spec.projection.cy = cy;
    return spec;
}

// A camera whose world-to-camera pose, in OpenCV axes, is [R | t].
CameraSpec withPose(CameraSpec spec, const glm::dmat3& r, const glm::dvec3& t)
{
    glm::dmat4 cv(r);
    cv[3] = glm::dvec4(t, 1.0);
    spec.view.hasMatrix = true;
    spec.view.eyeFromWorld = cvFromEyeAxes(spec.convention) * cv;  // F is its own inverse
    return spec;
}

// A camera with rotation R (world-to-camera, OpenCV axes) looking at the scene's default target
// from the default distance: the scene is in view whatever R is.
CameraSpec aimed(const CameraSpec& base, const glm::dmat3& r)
{
    const glm::dvec3 target = base.view.target, forward = glm::transpose(r) * glm::dvec3(0, 0, 1);
    const glm::dvec3 eye = target - glm::length(base.view.eye - base.view.target) * forward;
    return withPose(base, r, -(r * eye));
}

struct Named {
    std::string mistake, variant;
};

// Whether the diagnosis of `map` under the declared camera holds a consistent hypothesis of that
// name (and variant, when given); the diagnosis's first lines when not, for the log.
bool names(const MapVerifier& verifier, const Camera& declared, const DepthMap& map, const Named& wanted, std::string& seen)
{
    for (const Hypothesis& h : verifier.diagnose(declared, map)) {
        if (h.consistent && h.name == wanted.mistake && (wanted.variant.empty() || h.variant == wanted.variant)) return true;
        if (seen.size() < 600)
            seen += h.name + " [" + h.variant + "] " + (h.consistent ? "consistent" : std::to_string(h.unexplained)) + "; ";
    }
    return false;
}

// The map the renderer's camera draws (the ray route stands in for the renderer), judged under
// the declared camera: rejected as it stands, and named.
void requireNamed(const MapVerifier& verifier, const CameraSpec& renderer, const CameraSpec& declared, ExportQuantity quantity,
                  const Named& wanted)
{
    const Checker& checker = verifier.checker();
    const Camera rendering(renderer), judging(declared);
    const DepthMap map = mapOf(checker.scene(), rendering, checker.renderRay(rendering), quantity);
    INFO(wanted.mistake << " [" << wanted.variant << "], " << declared.convention.name << ", " << toString(quantity));
    REQUIRE(testing::anyHit(checker.renderRay(rendering)));
    REQUIRE_FALSE(verifier.verify(judging, map).comparison.report.consistent());
    std::string seen;
    const bool named = names(verifier, judging, map, wanted, seen);
    INFO("diagnosis: " << seen);
    CHECK(named);
}

}  // namespace

TEST_CASE("a principal point off along one axis, by any amount, is found and measured", "[diagnose][vision]")
{
    // Blender's shift_y with the wrong sign: 38 px at 320×240, found by the sample-offset fit
    // starting from the whole-image shift; and other amounts, axes, scenes and conventions.
    struct Case {
        const Scene* scene;
        std::string convention;
        int width, height;
        glm::dvec2 shift;  // image pixels the principal point moved (x right, y down)
        ExportQuantity quantity;
    };
    const Scene defaultScene = builtinScene("builtin:default");
    for (const Case& c : {Case{&defaultScene, "opengl", 320, 240, {0, 38}, ExportQuantity::EyeZ},
                          Case{&defaultScene, "opencv", 320, 240, {0, -38}, ExportQuantity::Distance},
                          Case{&bunny(), "vulkan", 240, 180, {17.25, 0}, ExportQuantity::Window},
                          Case{&bunny(), "opengl", 240, 180, {-6.5, 0}, ExportQuantity::EyeZ}}) {
        const Checker checker(*c.scene);
        const MapVerifier verifier(checker);
        const CameraSpec declared = smallSpec(checker.scene(), c.convention, c.width, c.height);
        Departure moved;
        moved.principalShift = c.shift;
        const CameraSpec renderer = departedCameraSpec(Camera(declared), moved);
        const Camera rendering(renderer), judging(declared);
        const DepthMap map = mapOf(checker.scene(), rendering, checker.renderRay(rendering), c.quantity);
        INFO(c.convention << " shift (" << c.shift.x << ", " << c.shift.y << ")");
        REQUIRE_FALSE(verifier.verify(judging, map).comparison.report.consistent());
        bool found = false;
        for (const Hypothesis& h : verifier.diagnose(judging, map))
            if (h.consistent && h.name == "sample-offset") {
                found = true;
                // The image moved with the principal point: sampled at minus the shift.
                CHECK(h.fitted[0].value == Approx(-c.shift.x).margin(0.02));
                CHECK(h.fitted[1].value == Approx(-c.shift.y).margin(0.02));
                CHECK(h.explanation.find("principal point off by") != std::string::npos);
            }
        CHECK(found);
    }
}

TEST_CASE("cx and cy exchanged are named", "[diagnose][vision]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    for (const char* convention : {"opencv", "opengl"}) {
        CameraSpec declared = pinholeSpec(checker.scene(), convention, 200, 150, 180, 100, 75);
        CameraSpec renderer = declared;
        renderer.projection.cx = 75, renderer.projection.cy = 100;
        requireNamed(verifier, renderer, declared, ExportQuantity::EyeZ, {"cx-cy-swapped", ""});
    }
}

TEST_CASE("a transposed rotation is named, with t kept or the eye kept", "[diagnose][vision]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    for (const char* convention : {"opencv", "opengl"}) {
        const CameraSpec base = smallSpec(checker.scene(), convention);
        // The renderer's pose: a rotation from a quaternion, aimed at the scene.
        const glm::dmat3 r = rotationOf(0.82, 0.21, -0.43, 0.31);
        const CameraSpec renderer = aimed(base, r);
        const glm::dmat4 cv = cvFromEyeAxes(renderer.convention) * renderer.view.eyeFromWorld;
        const glm::dvec3 t(cv[3]), eye = -(glm::transpose(r) * t);
        // The file's pose read with Rᵀ: t kept, or the eye kept.
        requireNamed(verifier, renderer, withPose(base, glm::transpose(r), t), ExportQuantity::EyeZ,
                     {"transposed-rotation", "translation kept"});
        requireNamed(verifier, renderer, withPose(base, glm::transpose(r), -(glm::transpose(r) * eye)), ExportQuantity::Window,
                     {"transposed-rotation", "eye kept"});
    }
}

TEST_CASE("transposes as people make them: a matrix_world's 3×3 in OpenGL axes, and a whole 4×4 read in the other layout",
          "[diagnose][vision]")
{
    const glm::dmat3 f(1, 0, 0, 0, -1, 0, 0, 0, -1);  // OpenGL camera axes from OpenCV's, and back
    {
        const Checker checker(builtinScene("builtin:default"));
        const MapVerifier verifier(checker);
        for (const char* convention : {"opengl", "opencv"}) {
            const CameraSpec base = smallSpec(checker.scene(), convention);
            const glm::dmat3 r = rotationOf(0.82, 0.21, -0.43, 0.31);
            const CameraSpec renderer = aimed(base, r);
            const glm::dmat4 cv = cvFromEyeAxes(renderer.convention) * renderer.view.eyeFromWorld;
            const glm::dvec3 t(cv[3]), eye = -(glm::transpose(r) * t);
            // The file's camera-to-world in OpenGL axes, [Rᵀ·F | eye], with its 3×3 transposed:
            // F·R, whose world-to-camera in OpenCV axes is (F·R·F)ᵀ... written from the matrices.
            const glm::dmat3 c2wGl = glm::transpose(r) * f;
            const glm::dmat3 declaredR = glm::transpose(glm::transpose(c2wGl) * f);
            requireNamed(verifier, renderer, withPose(base, declaredR, -(declaredR * eye)), ExportQuantity::EyeZ,
                         {"transposed-rotation", "OpenGL axes, eye kept"});
        }
    }
    {
        // The renderer at the world origin (the scene moved so that its camera's eye is there),
        // having read the file's 4×4 transposed; the file's own pose is elsewhere.
        Scene scene = builtinScene("builtin:default");
        const glm::vec3 eye0 = glm::vec3(scene.defaultCamera.view.eye);
        for (glm::vec3& p : scene.positions) p -= eye0;
        scene.defaultCamera.view.eye -= glm::dvec3(eye0), scene.defaultCamera.view.target -= glm::dvec3(eye0);
        const Checker checker(std::move(scene));
        const MapVerifier verifier(checker);
        for (const char* convention : {"opengl", "vulkan"}) {
            const CameraSpec base = smallSpec(checker.scene(), convention);
            const glm::dmat4 cv = cvFromEyeAxes(base.convention) * Camera(base).eyeFromWorld;
            const glm::dmat3 r(cv);  // world-to-camera at the origin, OpenCV axes
            const CameraSpec renderer = withPose(base, r, glm::dvec3(0));
            const glm::dvec3 fileEye(0.7, 1.9, 2.4);
            // Camera-to-world 4×4 in OpenCV axes as the file holds it: [Rf | fileEye], read
            // transposed: the renderer's rotation Rfᵀ, so Rf = rᵀ... its world-to-camera Rfᵀ = r.
            const glm::dmat3 fileWorldToCameraCv = glm::transpose(r);
            requireNamed(verifier, renderer, withPose(base, fileWorldToCameraCv, -(fileWorldToCameraCv * fileEye)),
                         ExportQuantity::EyeZ, {"transposed-4x4", "OpenCV axes"});
            // The same file in OpenGL axes (Blender's matrix_world): [Rgl | fileEye] read transposed.
            const glm::dmat3 fileWorldToCameraGl = f * glm::transpose(r) * f;
            requireNamed(verifier, renderer, withPose(base, fileWorldToCameraGl, -(fileWorldToCameraGl * fileEye)),
                         ExportQuantity::Distance, {"transposed-4x4", "OpenGL axes"});
        }
    }
}

TEST_CASE("an eye displaced along the viewing direction is named a pose error, on the bunny and the default scene",
          "[diagnose][vision]")
{
    for (const bool onBunny : {true, false}) {
        const Checker checker(onBunny ? Scene(bunny()) : builtinScene("builtin:default"));
        const MapVerifier verifier(checker);
        for (const char* convention : {"opencv", "opengl"})
            for (const double nearer : {0.01, -0.01}) {  // 1 % nearer the target, and 1 % farther
                const CameraSpec declared = smallSpec(checker.scene(), convention);
                CameraSpec renderer = declared;
                renderer.view.eye = declared.view.eye + nearer * (declared.view.target - declared.view.eye);
                requireNamed(verifier, renderer, declared, ExportQuantity::EyeZ, {"pose", ""});
                // ... and first: not a depth scale or a field of view, which a move along the view mimics.
                const Camera rendering(renderer);
                const DepthMap map = mapOf(checker.scene(), rendering, checker.renderRay(rendering), ExportQuantity::EyeZ);
                const std::vector<Hypothesis> hypotheses = verifier.diagnose(Camera(declared), map);
                INFO(hypotheses.front().name << ": " << hypotheses.front().explanation);
                CHECK(hypotheses.front().name == "pose");
            }
    }
}

TEST_CASE("a lens shift dropped is named as dropped, in x, in y, and in both", "[diagnose][vision]")
{
    // The file's camera has its principal point 32 px right of centre (Blender's shift_x = 0.1 at
    // 320 px), or also 20 px up; the renderer drew a centred image.
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    for (const char* convention : {"opengl", "opencv"}) {
        CameraSpec centred = pinholeSpec(checker.scene(), convention, 320, 240, 300, 159.5, 119.5);  // centred
        CameraSpec shifted = centred;
        shifted.projection.cx += 32;
        requireNamed(verifier, centred, shifted, ExportQuantity::EyeZ, {"lens-shift-dropped", "x"});
        shifted.projection.cy -= 20;
        requireNamed(verifier, centred, shifted, ExportQuantity::Window, {"lens-shift-dropped", "x and y"});
        CameraSpec onlyY = shifted;  // dropped in y only: x's shift drawn
        onlyY.projection.cy = centred.projection.cy;
        requireNamed(verifier, onlyY, shifted, ExportQuantity::EyeZ, {"lens-shift-dropped", "y only"});
        // Not "Blender's shift_x read with the wrong sign".
        const Camera rendering(centred);
        shifted.projection.cy = centred.projection.cy;
        const DepthMap map = mapOf(checker.scene(), rendering, checker.renderRay(rendering), ExportQuantity::EyeZ);
        for (const Hypothesis& h : verifier.diagnose(Camera(shifted), map)) {
            INFO(h.name << " [" << h.variant << "]");
            REQUIRE_FALSE((h.consistent && h.name == "principal-point-mirrored"));
        }
    }
}

TEST_CASE("a quaternion read in the other order is named, world-to-camera and camera-to-world", "[diagnose][vision]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    const CameraSpec base = smallSpec(checker.scene(), "opencv");
    const double w = 0.71, x = -0.18, y = 0.62, z = 0.27;
    // COLMAP-style: the world-to-camera quaternion (w, x, y, z), t kept.
    const CameraSpec renderer = aimed(base, rotationOf(w, x, y, z));
    const glm::dvec3 t(renderer.view.eyeFromWorld[3]);
    // The same four numbers taken as x y z w: w' = the stored w's place read as... the file
    // holds "w x y z" and a reader expecting "x y z w" builds (w' = z, x' = w, y' = x, z' = y).
    requireNamed(verifier, renderer, withPose(base, rotationOf(z, w, x, y), t), ExportQuantity::EyeZ,
                 {"quaternion-order", "world-to-camera, x y z w read as w x y z"});
    // The file holds "x y z w" read as "w x y z": w' = x, x' = y, y' = z, z' = w.
    requireNamed(verifier, renderer, withPose(base, rotationOf(x, y, z, w), t), ExportQuantity::Distance,
                 {"quaternion-order", "world-to-camera, w x y z read as x y z w"});
    // TUM-style: the camera-to-world quaternion of the same pose, the eye kept.
    const glm::dmat3 r = rotationOf(w, x, y, z), c2w = glm::transpose(r);
    const glm::dvec3 eye = -(c2w * t);
    const double cw = w, cx = -x, cy = -y, cz = -z;  // the conjugate: the inverse rotation
    REQUIRE(rotationOf(cw, cx, cy, cz)[0][1] == Approx(c2w[0][1]).margin(1e-12));
    const glm::dmat3 misread = glm::transpose(rotationOf(cz, cw, cx, cy));
    requireNamed(verifier, renderer, withPose(base, misread, -(misread * eye)), ExportQuantity::EyeZ,
                 {"quaternion-order", "camera-to-world, x y z w read as w x y z"});
}

TEST_CASE("a mesh turned between Y-up and Z-up, and a mesh in other units, are named", "[diagnose][vision]")
{
    for (const Scene* scene : {&bunny()}) {
        const Checker checker(*scene);
        const MapVerifier verifier(checker);
        for (const char* convention : {"opengl", "vulkan"}) {
            const CameraSpec declared = smallSpec(checker.scene(), convention);
            // The renderer's mesh turned −90° about x (Blender's OBJ import of a Y-up file): the
            // same as the view composed with the turn.
            for (const double degrees : {-90.0, 90.0}) {
                Scene turned = *scene;
                const double c = std::cos(glm::radians(degrees)), s = std::sin(glm::radians(degrees));
                for (glm::vec3& p : turned.positions) p = glm::vec3(p.x, c * p.y - s * p.z, s * p.y + c * p.z);
                const Checker renderer(std::move(turned));
                const Camera camera(declared);
                const DepthMap map = mapOf(renderer.scene(), camera, renderer.renderRay(camera), ExportQuantity::EyeZ);
                if (!testing::anyHit(renderer.renderRay(camera))) continue;  // turned out of view: no evidence
                INFO(convention << " turned " << degrees);
                std::string seen;
                const bool named = names(verifier, camera, map, {"mesh-up-axis", ""}, seen);
                INFO(seen);
                CHECK(named);
            }
        }
    }
    // The mesh in millimetres where the pose is in metres (and the reverse): the renderer drew
    // the mesh 1000× too large, or 1000× too small — from a camera that sees it.
    const Scene defaultScene = builtinScene("builtin:default");
    for (const double k : {1000.0, 0.01}) {
        Scene scaled = defaultScene;
        for (glm::vec3& p : scaled.positions) p *= float(k);
        const Checker renderer(std::move(scaled)), checker(defaultScene);
        const MapVerifier verifier(checker);
        // A camera the scaled mesh is in view of: the default one's pose with its eye scaled too,
        // declared with the eye where the file says (scaled back).
        CameraSpec seeing = smallSpec(defaultScene, "opengl");
        seeing.view.eye *= k, seeing.view.target *= k;
        seeing.projection.near *= k, seeing.projection.far *= k;
        // The mistake: the camera file is right for the scaled mesh's units, the mesh file is not.
        const Camera camera(seeing);
        const DepthMap map = mapOf(renderer.scene(), camera, renderer.renderRay(camera), ExportQuantity::Distance);
        INFO("mesh × " << k);
        std::string seen;
        const bool named = names(verifier, camera, map, {"mesh-units", ""}, seen);
        INFO(seen);
        CHECK(named);
    }
}

TEST_CASE("a pose translation in millimetres is named, for t and for the eye", "[diagnose][vision]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    const CameraSpec renderer = smallSpec(checker.scene(), "opencv");
    const Camera rendering(renderer);
    const glm::dmat3 r = glm::dmat3(rendering.eyeFromWorld);  // opencv: eye axes are OpenCV's
    const glm::dvec3 t(rendering.eyeFromWorld[3]), eye = -(glm::transpose(r) * t);
    // The camera file written in millimetres: t × 1000, or the eye × 1000.
    requireNamed(verifier, renderer, withPose(renderer, r, 1000.0 * t), ExportQuantity::EyeZ, {"pose-units", "t / 1000"});
    requireNamed(verifier, renderer, withPose(renderer, r, -(r * (1000.0 * eye))), ExportQuantity::EyeZ,
                 {"pose-units", "eye / 1000"});
    // And in centimetres read as metres by the renderer (the map's eye 100× nearer the origin).
    requireNamed(verifier, withPose(renderer, r, -(r * (0.01 * eye))), renderer, ExportQuantity::Distance,
                 {"pose-units", "eye / 100"});
}

TEST_CASE("an eye a little nearer or farther along the viewing direction is measured", "[diagnose][vision]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    for (const double fraction : {0.01, -0.03}) {
        const CameraSpec declared = smallSpec(checker.scene(), "opengl");
        CameraSpec renderer = declared;
        renderer.view.eye += fraction * (declared.view.target - declared.view.eye);
        const Camera rendering(renderer), judging(declared);
        const DepthMap map = mapOf(checker.scene(), rendering, checker.renderRay(rendering), ExportQuantity::EyeZ);
        INFO("eye moved " << fraction << " of the way to the target");
        REQUIRE_FALSE(verifier.verify(judging, map).comparison.report.consistent());
        bool found = false;
        std::string seen;
        for (const Hypothesis& h : verifier.diagnose(judging, map)) {
            seen += h.name + (h.consistent ? " consistent; " : "; ");
            if (h.consistent && h.name == "pose") {
                found = true;
                CHECK(h.explanation.find("the eye at") != std::string::npos);
            }
        }
        INFO(seen);
        CHECK(found);
    }
}

// Held out: written after the mistakes above were implemented and the cases above passed, run
// once as they stand (their first results are in the notes of the change that added them), never
// tuned for: other scenes, conventions, quantities and magnitudes.
TEST_CASE("held out: the vision mistakes on other scenes, conventions, quantities and magnitudes", "[diagnose][vision][heldout]")
{
    const Scene spot = loadScene(std::string(ZCHECK_MODELS_DIR) + "/spot.obj");
    const Scene teapot = loadScene(std::string(ZCHECK_MODELS_DIR) + "/teapot.obj");
    {  // a principal point 23.4 px off in x, Direct3D, a distance map
        const Checker checker(spot);
        const MapVerifier verifier(checker);
        const CameraSpec declared = smallSpec(spot, "direct3d", 256, 192);
        Departure moved;
        moved.principalShift = {23.4, 0};
        requireNamed(verifier, departedCameraSpec(Camera(declared), moved), declared, ExportQuantity::Distance,
                     {"sample-offset", ""});
    }
    {  // a transposed rotation, eye kept, Vulkan, on the bunny
        const Checker checker(bunny());
        const MapVerifier verifier(checker);
        const CameraSpec base = smallSpec(bunny(), "vulkan");
        const glm::dmat3 r = rotationOf(0.55, -0.32, 0.61, 0.47);
        const CameraSpec renderer = aimed(base, r);
        const glm::dmat4 cv = cvFromEyeAxes(renderer.convention) * renderer.view.eyeFromWorld;
        const glm::dvec3 eye = -(glm::transpose(r) * glm::dvec3(cv[3]));
        requireNamed(verifier, renderer, withPose(base, glm::transpose(r), -(glm::transpose(r) * eye)), ExportQuantity::Distance,
                     {"transposed-rotation", "eye kept"});
    }
    {  // a camera-to-world quaternion stored w x y z and read as x y z w, OpenGL, the teapot
        const Checker checker(teapot);
        const MapVerifier verifier(checker);
        const CameraSpec base = smallSpec(teapot, "opengl");
        const double w = 0.35, x = 0.52, y = -0.44, z = 0.64;
        const CameraSpec renderer = aimed(base, glm::transpose(rotationOf(w, x, y, z)));  // c2w = R(q)
        const glm::dmat4 cv = cvFromEyeAxes(renderer.convention) * renderer.view.eyeFromWorld;
        const glm::dvec3 eye = -(rotationOf(w, x, y, z) * glm::dvec3(cv[3]));
        const glm::dmat3 misreadC2w = rotationOf(z, w, x, y), r = glm::transpose(misreadC2w);
        requireNamed(verifier, renderer, withPose(base, r, -(r * eye)), ExportQuantity::EyeZ,
                     {"quaternion-order", "camera-to-world, x y z w read as w x y z"});
    }
    {  // the pose's t written in centimetres, Direct3D, a window map
        const Checker checker(teapot);
        const MapVerifier verifier(checker);
        const CameraSpec renderer = smallSpec(teapot, "direct3d");
        const glm::dmat4 cv = cvFromEyeAxes(renderer.convention) * Camera(renderer).eyeFromWorld;
        requireNamed(verifier, renderer, withPose(renderer, glm::dmat3(cv), 100.0 * glm::dvec3(cv[3])), ExportQuantity::Window,
                     {"pose-units", "t / 100"});
    }
    {  // the mesh turned +90° about x, OpenCV, eye-z
        const Checker checker(spot);
        const MapVerifier verifier(checker);
        const CameraSpec declared = smallSpec(spot, "opencv");
        Scene turned = spot;
        for (glm::vec3& p : turned.positions) p = glm::vec3(p.x, -p.z, p.y);
        const Checker renderer(std::move(turned));
        const Camera camera(declared);
        const DepthMap map = mapOf(renderer.scene(), camera, renderer.renderRay(camera), ExportQuantity::EyeZ);
        REQUIRE(testing::anyHit(renderer.renderRay(camera)));
        std::string seen;
        const bool named = names(verifier, camera, map, {"mesh-up-axis", ""}, seen);
        INFO(seen);
        CHECK(named);
        // ... saying what to type in Blender.
        for (const Hypothesis& h : verifier.diagnose(camera, map))
            if (h.consistent && h.name == "mesh-up-axis")
                CHECK(h.explanation.find("bpy.ops.wm.obj_export(forward_axis='Y', up_axis='Z')") != std::string::npos);
    }
    {  // cx and cy exchanged off centre, 320×240, a window map, Metal
        const Checker checker(spot);
        const MapVerifier verifier(checker);
        CameraSpec declared = smallSpec(spot, "metal", 320, 240);
        declared.projection.type = ProjectionType::Pinhole;
        declared.projection.fx = declared.projection.fy = 300;
        declared.projection.cx = 150, declared.projection.cy = 110;
        CameraSpec renderer = declared;
        std::swap(renderer.projection.cx, renderer.projection.cy);
        requireNamed(verifier, renderer, declared, ExportQuantity::Window, {"cx-cy-swapped", ""});
    }
    {  // the eye 2 % farther from the target, Metal, the bunny, distance
        const Checker checker(bunny());
        const MapVerifier verifier(checker);
        const CameraSpec declared = smallSpec(bunny(), "metal");
        CameraSpec renderer = declared;
        renderer.view.eye -= 0.02 * (declared.view.target - declared.view.eye);
        requireNamed(verifier, renderer, declared, ExportQuantity::Distance, {"pose", ""});
    }
    {  // the mesh in centimetres drawn as metres (100× too large), eye-z, the teapot
        Scene scaled = teapot;
        for (glm::vec3& p : scaled.positions) p *= 100.0f;
        const Checker renderer(std::move(scaled)), checker(teapot);
        const MapVerifier verifier(checker);
        CameraSpec seeing = smallSpec(teapot, "vulkan");
        seeing.view.eye *= 100.0, seeing.view.target *= 100.0;
        seeing.projection.near *= 100.0, seeing.projection.far *= 100.0;
        const Camera camera(seeing);
        const DepthMap map = mapOf(renderer.scene(), camera, renderer.renderRay(camera), ExportQuantity::EyeZ);
        std::string seen;
        const bool named = names(verifier, camera, map, {"mesh-units", ""}, seen);
        INFO(seen);
        CHECK(named);
    }
}
