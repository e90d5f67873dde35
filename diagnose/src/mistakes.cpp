#include "zcheck/mistakes.h"

#include "zcheck/departure.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/pose.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>
#include <initializer_list>

namespace zcheck {

namespace {

using Rereadings = std::vector<Rereading>;

// A projection matrix built wrongly: the raster route draws with it (inject), and the truth
// is rendered through a raw-matrix camera holding it (reread). `build` returns false where
// the mistake has no meaning.
Mistake wrongProjection(std::string name, std::string description, std::string explanation,
                        std::function<bool(const Camera&, glm::dmat4& clipFromEye)> build)
{
    Mistake mistake{std::move(name), std::move(description), Route::Raster, {}, {}};
    mistake.inject = [build](const Camera& camera, RouteFaults& faults) {
        glm::dmat4 clipFromEye;
        if (!build(camera, clipFromEye)) return false;
        faults.raster.overrideClipFromWorld = true;
        faults.raster.clipFromWorld = clipFromEye * camera.eyeFromWorld;
        return true;
    };
    mistake.reread = [build, explanation](const Camera& camera, const DepthMap&) {
        glm::dmat4 clipFromEye;
        if (!build(camera, clipFromEye)) return Rereadings{};
        CameraSpec spec = camera.spec();
        spec.projection.type = ProjectionType::Matrix;
        spec.projection.clipFromEye = clipFromEye;
        return Rereadings{{"", explanation, spec, {}, {}}};
    };
    return mistake;
}

// A view (extrinsic) built wrongly: the raster route draws through it (inject), and the truth
// is rendered through a camera holding it as its raw view matrix (reread). `build` returns
// false where the mistake has no meaning or changes nothing.
Mistake wrongView(std::string name, std::string description, std::string explanation,
                  std::function<bool(const Camera&, glm::dmat4& eyeFromWorld)> build)
{
    Mistake mistake{std::move(name), std::move(description), Route::Raster, {}, {}};
    mistake.inject = [build](const Camera& camera, RouteFaults& faults) {
        glm::dmat4 eyeFromWorld;
        if (!build(camera, eyeFromWorld)) return false;
        faults.raster.overrideClipFromWorld = true;
        faults.raster.clipFromWorld = camera.clipFromEye * eyeFromWorld;
        return true;
    };
    mistake.reread = [build, explanation](const Camera& camera, const DepthMap&) {
        glm::dmat4 eyeFromWorld;
        if (!build(camera, eyeFromWorld)) return Rereadings{};
        CameraSpec spec = camera.spec();
        spec.view.hasMatrix = true;
        spec.view.eyeFromWorld = eyeFromWorld;
        return Rereadings{{"", explanation, spec, {}, {}}};
    };
    return mistake;
}

// Whether two rigid transforms differ by more than rounding.
bool differ(const glm::dmat4& a, const glm::dmat4& b)
{
    double scale = 1, difference = 0;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            scale = std::max(scale, std::abs(a[c][r])), difference = std::max(difference, std::abs(a[c][r] - b[c][r]));
    return difference > 1e-9 * scale;
}

// A sampling mistake of the renderer: the ray route samples wrongly (inject), and the truth is
// rendered with the same wrong sampling (reread).
Mistake wrongSampling(std::string name, std::string description, std::string explanation, RayFaults faults)
{
    Mistake mistake{std::move(name), std::move(description), Route::Ray, {}, {}};
    mistake.inject = [faults](const Camera&, RouteFaults& injected) {
        injected.ray = faults;
        return true;
    };
    mistake.reread = [faults, explanation](const Camera&, const DepthMap&) {
        return Rereadings{{"", explanation, std::nullopt, faults, {}}};
    };
    return mistake;
}

// A sampling mistake that mirrors the image: the ray route samples mirrored (inject), and the
// map is mirrored back (reread; the comparison judges each pixel at its own position).
Mistake mirrored(std::string name, std::string description, std::string explanation, bool rows)
{
    RayFaults faults;
    (rows ? faults.flipRows : faults.flipCols) = true;
    Mistake mistake = wrongSampling(std::move(name), std::move(description), explanation, faults);
    mistake.reread = [rows, explanation](const Camera&, const DepthMap& map) {
        DepthMap back = map;
        for (int row = 0; row < map.height; ++row)
            for (int col = 0; col < map.width; ++col) {
                const std::size_t to = std::size_t(row) * map.width + col;
                const std::size_t from = rows ? std::size_t(map.height - 1 - row) * map.width + col
                                              : std::size_t(row) * map.width + (map.width - 1 - col);
                back.value[to] = map.value[from];
                if (!map.valueStep.empty()) back.valueStep[to] = map.valueStep[from];
            }
        return Rereadings{{"", explanation, std::nullopt, {}, back}};
    };
    return mistake;
}

// The map's values re-read as another quantity (or through a function of the value).
Rereading readAs(const DepthMap& map, DepthQuantity quantity, std::string explanation,
                 const std::function<double(double)>& value = {})
{
    DepthMap other = map;
    other.quantity = quantity;
    if (value)
        for (double& v : other.value) v = value(v);
    return {"", std::move(explanation), std::nullopt, {}, other};
}

// The projection's x and y rows scaled by (kx, ky): field-of-view and aspect mistakes.
glm::dmat4 scaledRows(const Camera& camera, double kx, double ky)
{
    glm::dmat4 m = camera.clipFromEye;
    for (int c = 0; c < 4; ++c) m[c][0] *= kx, m[c][1] *= ky;
    return m;
}

bool hasFovy(const Camera& camera) { return camera.spec().projection.type == ProjectionType::Perspective; }

// The z row rebuilt with near and far exchanged (the mapping's formula, see camera.cpp).
glm::dmat4 nearFarSwapped(const Camera& camera)
{
    const double a = camera.ndcZNear(), b = camera.ndcZFar();
    const double n = camera.farDistance(), f = camera.nearDistance();  // swapped
    const double towardsEye = -camera.convention().eyeForwardZ;       // z_gl = towardsEye·z_eye
    double P, Q;
    if (camera.spec().projection.isPerspective()) {
        P = (a - b) * n / (f - n) - b, Q = (a - b) * n * f / (f - n);
    } else {
        P = -(b - a) / (f - n), Q = a - (b - a) * n / (f - n);
    }
    glm::dmat4 m = camera.clipFromEye;
    m[2][2] = P * towardsEye, m[3][2] = Q;
    return m;
}

// The view in OpenCV's camera axes (x right, y down, z forward), as COLMAP, OpenCV and TUM-style
// trajectories store a pose: cvFromEye · eyeFromWorld, and back.
glm::dmat4 cvFromEye(const Camera& camera)
{
    glm::dmat4 f(1.0);
    f[1][1] = -camera.convention().eyeUpY, f[2][2] = camera.convention().eyeForwardZ;
    return f;  // its own inverse
}

// Views a renderer may have used instead of the declared one, each a variant with its
// explanation; a mistake of the diagnosis only (inject empty: the suite's catalogue of injected
// mistakes is the renderer's chain, not the files it was given). A variant equal to the declared
// view, or no valid camera, is left out.
struct ViewVariant {
    std::string variant, explanation;
    glm::dmat4 eyeFromWorld;
};
Mistake otherViews(std::string name, std::string description,
                   std::function<std::vector<ViewVariant>(const Camera&)> build)
{
    Mistake mistake{std::move(name), std::move(description), Route::Raster, {}, {}};
    mistake.alone = true;
    mistake.reread = [build](const Camera& camera, const DepthMap&) {
        Rereadings out;
        for (const ViewVariant& v : build(camera)) {
            if (!differ(v.eyeFromWorld, camera.eyeFromWorld)) continue;
            CameraSpec spec = camera.spec();
            spec.view.hasMatrix = true;
            spec.view.eyeFromWorld = v.eyeFromWorld;
            out.push_back({v.variant, v.explanation, spec, {}, {}});
        }
        return out;
    };
    return mistake;
}

// [R | t] of a rigid view, and the view made of a rotation and a translation.
glm::dmat3 rotationOf(const glm::dmat4& m) { return glm::dmat3(m); }
glm::dmat4 viewOf(const glm::dmat3& r, const glm::dvec3& t)
{
    glm::dmat4 m(r);
    m[3] = glm::dvec4(t, 1.0);
    return m;
}

std::string factorText(double k) { return k >= 1 ? "× " + formatNumber(k) : "/ " + formatNumber(1 / k); }

// A camera's pose as files store it: world-to-camera [R | t] in OpenCV axes, the eye at −Rᵀt;
// and views back in the camera's own axes from such a rotation with a translation or an eye.
struct FilePose {
    glm::dmat4 cvFromEyeAxes;
    glm::dmat3 r;
    glm::dvec3 t, eye;
    static FilePose of(const Camera& camera)
    {
        FilePose out;
        out.cvFromEyeAxes = cvFromEye(camera);
        const glm::dmat4 cv = out.cvFromEyeAxes * camera.eyeFromWorld;
        out.r = rotationOf(cv), out.t = glm::dvec3(cv[3]), out.eye = -(glm::transpose(out.r) * out.t);
        return out;
    }
    glm::dmat4 withT(const glm::dmat3& rotation, const glm::dvec3& translation) const
    {
        return cvFromEyeAxes * viewOf(rotation, translation);
    }
    glm::dmat4 withEye(const glm::dmat3& rotation, const glm::dvec3& position) const
    {
        return withT(rotation, -(rotation * position));
    }
};

// OpenCV camera axes from OpenGL's (x kept, y and z turned round), its own inverse.
const glm::dmat3 kCvFromGl(1, 0, 0, 0, -1, 0, 0, 0, -1);

// The pose as a file holds it, and its rotation transposed in OpenCV's camera axes and in
// OpenGL's (R_gl = F·R with F = diag(1, −1, −1), so R_glᵀ read back into OpenCV axes is F·Rᵀ·F).
struct TransposedPose {
    FilePose pose;
    glm::dmat3 cv, gl;
    static TransposedPose of(const Camera& camera)
    {
        const FilePose pose = FilePose::of(camera);
        const glm::dmat3 rt = glm::transpose(pose.r);
        return {pose, rt, kCvFromGl * rt * kCvFromGl};
    }
};

// The projection with the principal point's offset terms of the x and y rows in `rows` (0: x,
// 1: y) multiplied by `factor`: −1 mirrors the principal point about the image centre, 0 drops
// it (the image drawn centred). The offset lives in the z column (perspective) or the w column
// (parallel) of those rows. False where that changes nothing (a principal point at the centre).
bool principalScaled(const Camera& camera, double factor, std::initializer_list<int> rows, glm::dmat4& clipFromEye)
{
    clipFromEye = camera.clipFromEye;
    for (int c : {2, 3})
        for (int r : rows)  // a dropped offset is +0, not the −0 of −x·0 (a matrix written out shows it)
            clipFromEye[c][r] = factor == 0 ? 0.0 : factor * clipFromEye[c][r];
    return differ(clipFromEye, camera.clipFromEye);
}

// One axis of the principal point, as the explanations name it.
struct PrincipalAxis {
    int row;                               // the projection's row: 0 for x, 1 for y
    const char *axis, *c, *size, *shift;   // "x", "cx", "W" and Blender's "shift_x"
};
constexpr PrincipalAxis kPrincipalAxes[] = {{0, "x", "cx", "W", "shift_x"}, {1, "y", "cy", "H", "shift_y"}};

// The principal point's offset multiplied by `factor` (principalScaled) in one axis only, each
// through a raw-matrix camera: variants "x only" and "y only", explained by `explain`. None unless
// the offset changes something in both axes (in one only, the re-reading of both is that axis's).
Rereadings principalInOneAxis(const Camera& camera, double factor,
                              const std::function<std::string(const PrincipalAxis&)>& explain)
{
    Rereadings out;
    glm::dmat4 xOnly, yOnly;
    if (!principalScaled(camera, factor, {0}, xOnly) || !principalScaled(camera, factor, {1}, yOnly)) return out;
    for (const PrincipalAxis& a : kPrincipalAxes) {
        CameraSpec spec = camera.spec();
        spec.projection.type = ProjectionType::Matrix;
        spec.projection.clipFromEye = a.row == 0 ? xOnly : yOnly;
        out.push_back({std::string(a.axis) + " only", explain(a), spec, {}, {}});
    }
    return out;
}

// Orientation and sampling: the ray route samples the image mirrored or half a pixel off.
std::vector<Mistake> samplingMistakes()
{
    std::vector<Mistake> all;
    RayFaults halfPixel;
    halfPixel.shiftPixels = {-0.5, -0.5};
    all.push_back(mirrored("y-flip", "the window's y axis flipped (bottom-left vs top-left origin mixed up)",
                           "consistent if flipped vertically (the window's y origin is the other corner)", true));
    all.push_back(mirrored("x-flip", "the image mirrored left to right (a mirrored x axis)",
                           "consistent if flipped horizontally (a mirrored x axis)", false));
    Mistake half = wrongSampling("half-pixel", "pixel centres at integer coordinates: the +0.5 offset forgotten", "",
                                 halfPixel);
    half.reread = [](const Camera& camera, const DepthMap&) {
        Rereadings out;
        // Window offsets. The mixed ones are a principal point off by half a pixel in image
        // coordinates (y down) under a window whose y grows upward (OpenGL): cx, cy = W/2, H/2
        // where (W − 1)/2, (H − 1)/2 belong moves the image +0.5 in x and −0.5 in window y.
        for (auto [dx, dy, what] : {std::tuple{-0.5, -0.5, "x and y"}, std::tuple{-0.5, 0.0, "x"},
                                    std::tuple{0.0, -0.5, "y"}, std::tuple{0.5, 0.5, "x and y, the other way"},
                                    std::tuple{0.5, 0.0, "x, the other way"}, std::tuple{0.0, 0.5, "y, the other way"},
                                    std::tuple{0.5, -0.5, "x the other way and y"}, std::tuple{-0.5, 0.5, "x and y the other way"}}) {
            Rereading r;
            r.variant = what;
            r.explanation = std::string("consistent if rendered with pixel centres half a pixel off in ") + what +
                            " (the +0.5 pixel-centre offset missing or doubled, or a principal point off by half a "
                            "pixel: cx = W/2 where (W - 1)/2 belongs)";
            // The truth seen at the shifted points, through a camera whose image moved the other
            // way (fit.h): the map is then read, and its edges judged, where it was sampled.
            Departure shifted;
            shifted.sampleOffset = windowFromImageOffset(camera, {dx, dy});  // the variants are window offsets
            r.camera = departedCameraSpec(camera, shifted);
            out.push_back(r);
        }
        return out;
    };
    all.push_back(half);
    return all;
}

// The view built wrongly in the renderer's chain: inverted, or in the other camera axes.
std::vector<Mistake> viewMistakes()
{
    std::vector<Mistake> all;
    // The view: the camera-pose mistakes public issue trackers show most.
    all.push_back(wrongView("inverted-extrinsic",
                            "the view inverted: world-from-camera used as camera-from-world (or the reverse)",
                            "consistent if the view matrix is inverted (camera-to-world used as world-to-camera)",
                            [](const Camera& camera, glm::dmat4& m) {
                                m = camera.worldFromEye;
                                return differ(m, camera.eyeFromWorld);
                            }));
    all.push_back(wrongView("opencv-opengl-axes",
                            "an OpenCV camera pose used as an OpenGL one (or the reverse): turned 180° about its x axis",
                            "consistent if the camera is turned 180° about its x axis (OpenCV's y down, z forward "
                            "vs OpenGL's y up, z back)",
                            [](const Camera& camera, glm::dmat4& m) {
                                glm::dmat4 turn(1.0);
                                turn[1][1] = turn[2][2] = -1;
                                m = turn * camera.eyeFromWorld;
                                return true;
                            }));
    return all;
}

// Poses read wrongly from the files a renderer was given, each tried alone: the rotation
// transposed, a 4×4 in the other layout, the quaternion's order, the translation's units, and the
// mesh's up axis (a turned view too).
std::vector<Mistake> filePoseMistakes()
{
    std::vector<Mistake> all;
    // Poses as files store them (COLMAP, OpenCV, TUM-style trajectories): in OpenCV axes,
    // world-to-camera [R | t] or camera-to-world [Rᵀ | C].
    all.push_back(otherViews(
        "transposed-rotation", "the pose's rotation transposed (R used as Rᵀ: a row- vs column-major 3×3, or a "
                               "camera-to-world rotation used as world-to-camera)",
        [](const Camera& camera) {
            const auto [pose, rt, glRt] = TransposedPose::of(camera);
            return std::vector<ViewVariant>{
                {"translation kept", "consistent if the pose's rotation is transposed (R used as Rᵀ) and t kept: a "
                                     "row- vs column-major rotation", pose.withT(rt, pose.t)},
                {"eye kept", "consistent if the pose's rotation is transposed (R used as Rᵀ) with the eye where it "
                             "is: a camera-to-world rotation used as world-to-camera", pose.withEye(rt, pose.eye)},
                // The same in OpenGL camera axes (x right, y up, z back: Blender's matrix_world,
                // nerfstudio, a zcheck world_from_eye).
                {"OpenGL axes, eye kept", "consistent if the camera-to-world rotation in OpenGL axes (Blender's matrix_world, "
                                          "nerfstudio's transform_matrix, a world_from_eye) is transposed with the eye where it is",
                 pose.withEye(glRt, pose.eye)},
                {"OpenGL axes, translation kept", "consistent if the world-to-camera rotation in OpenGL axes (a view "
                                                  "matrix) is transposed and its translation kept",
                 pose.withT(glRt, pose.t)}};
        }));
    all.push_back(otherViews(
        "transposed-4x4", "a 4×4 pose matrix read in the other layout (row- vs column-major): its rotation transposed, "
                          "and its translation, now in the bottom row, lost",
        [](const Camera& camera) {
            const auto [pose, rt, glRt] = TransposedPose::of(camera);
            return std::vector<ViewVariant>{
                {"OpenCV axes", "consistent if the 4×4 pose (OpenCV axes, either direction) was read transposed: rotation "
                                "Rᵀ, the translation in the bottom row lost (the eye at the world origin)",
                 pose.withEye(rt, glm::dvec3(0))},
                {"OpenGL axes", "consistent if the 4×4 pose in OpenGL axes (Blender's matrix_world, nerfstudio's "
                                "transform_matrix, a view matrix) was read transposed: rotation transposed, the translation "
                                "in the bottom row lost (the eye at the world origin)",
                 pose.withEye(glRt, glm::dvec3(0))}};
        }));
    all.push_back(otherViews(
        "quaternion-order", "a pose's quaternion read in the other component order (x y z w as w x y z, or the reverse)",
        [](const Camera& camera) {
            const FilePose pose = FilePose::of(camera);
            std::vector<ViewVariant> out;
            for (const bool worldToCamera : {true, false})
                for (const bool xyzwAsWxyz : {true, false}) {
                    const glm::dmat3 stored = worldToCamera ? pose.r : glm::transpose(pose.r);
                    const glm::dvec4 q = quaternionFromRotation(stored);  // w x y z in q[0..3]
                    // Stored x y z w and read as w x y z (w' = x, x' = y, y' = z, z' = w), or stored
                    // w x y z and read as x y z w (w' = z, x' = w, y' = x, z' = y): each undoes the
                    // other, so a camera file misread either way is covered too.
                    const glm::dmat3 used = xyzwAsWxyz ? rotationFromQuaternion(q[1], q[2], q[3], q[0], "quaternion")
                                                       : rotationFromQuaternion(q[3], q[0], q[1], q[2], "quaternion");
                    const glm::dmat3 rUsed = worldToCamera ? used : glm::transpose(used);
                    const std::string order = xyzwAsWxyz ? "x y z w read as w x y z" : "w x y z read as x y z w";
                    const std::string stores = worldToCamera ? "world-to-camera" : "camera-to-world";
                    out.push_back({stores + ", " + order,
                                   "consistent if the " + stores + (worldToCamera ? " (COLMAP-style)" : " (TUM-style)") +
                                       " quaternion was read in the other order (" + order + ")",
                                   worldToCamera ? pose.withT(rUsed, pose.t) : pose.withEye(rUsed, pose.eye)});
                }
            return out;
        }));
    all.push_back(otherViews(
        "pose-units", "the pose's translation in other units than the scene (millimetres or centimetres for metres)",
        [](const Camera& camera) {
            const FilePose pose = FilePose::of(camera);
            std::vector<ViewVariant> out;
            for (const double k : {1000.0, 0.001, 100.0, 0.01}) {
                out.push_back({"t " + factorText(k), "consistent if the world-to-camera translation t is " + factorText(k) +
                                                         " (another unit than the scene's)", pose.withT(pose.r, k * pose.t)});
                out.push_back({"eye " + factorText(k), "consistent if the eye position (a camera-to-world translation) is " +
                                                           factorText(k) + " (another unit than the scene's)",
                               pose.withEye(pose.r, k * pose.eye)});
            }
            return out;
        }));
    all.push_back(otherViews(
        "mesh-up-axis", "the mesh turned between Y-up and Z-up (Blender's OBJ import turns it −90° about x)",
        [](const Camera& camera) {
            std::vector<ViewVariant> out;
            for (const double degrees : {-90.0, 90.0}) {
                // The renderer drew the mesh turned by T: eye = V·T·p, the truth through V·T.
                const glm::dmat4 turned = glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::dvec3(1, 0, 0));
                const std::string by = (degrees < 0 ? "−" : "+") + formatNumber(std::abs(degrees)) + "° about x";
                out.push_back({by, "consistent if the renderer's mesh was turned " + by +
                                       (degrees < 0 ? " (Y-up read as Z-up, as Blender's OBJ import does)" : " (Z-up read as Y-up)") +
                                       ": give zcheck the mesh in the renderer's world axes (from Blender: "
                                       "bpy.ops.wm.obj_export(forward_axis='Y', up_axis='Z'), every object exported, its "
                                       "transforms applied; docs/datasets.md)",
                               camera.eyeFromWorld * turned});
            }
            return out;
        }));
    return all;
}

// The other files a renderer was given, each tried alone: the mesh in other units than the pose,
// and the intrinsics' principal point with its coordinates exchanged.
std::vector<Mistake> meshUnitAndIntrinsicMistakes()
{
    std::vector<Mistake> all;
    // The mesh in other units: the renderer drew k·p through the view [R | t]. Its eye points are
    // k × those of p through [R | t/k], seen along the same rays by a perspective camera, and
    // clipped by near and far where p's are by near/k and far/k: the truth through that camera,
    // and the map's eye-z and distance / k (window depth, a function of z/near and z/far, stays).
    Mistake meshUnits{"mesh-units", "the mesh in other units than the camera (millimetres or centimetres for metres)",
                      Route::Raster, {}, {}};
    meshUnits.alone = true;
    meshUnits.reread = [](const Camera& camera, const DepthMap& map) {
        Rereadings out;
        if (!camera.spec().projection.isPerspective() || isRawMatrix(camera)) return out;
        // An eye at the world's origin sees a scaled mesh as the same picture with scaled depths:
        // the depth-scale fit's finding, which says more (any scale, and an offset).
        if (glm::length(glm::dvec3(camera.worldFromEye[3])) < 1e-3 * camera.nearDistance()) return out;
        for (const double k : {1000.0, 0.001, 100.0, 0.01}) {
            CameraSpec spec = camera.spec();
            spec.view.hasMatrix = true;
            spec.view.eyeFromWorld = camera.eyeFromWorld;
            spec.view.eyeFromWorld[3] = glm::dvec4(glm::dvec3(camera.eyeFromWorld[3]) / k, 1.0);
            Projection& p = spec.projection;
            p.near /= k, p.far /= k;  // an infinite far stays infinite
            if (p.type == ProjectionType::Frustum) p.left /= k, p.right /= k, p.bottom /= k, p.top /= k;
            DepthMap read = map;
            if (map.quantity == DepthQuantity::EyeZ || map.quantity == DepthQuantity::Distance) {
                for (double& v : read.value) v /= k;
                read.valueQuantum /= k;
                for (float& step : read.valueStep) step = float(step / k);
                read.accuracy.quantum /= k, read.accuracy.absolute /= k;  // declared in the map's units
            }
            out.push_back({factorText(k), "consistent if the renderer's mesh was " + factorText(k) +
                                              " (in other units than the camera's pose)",
                           spec, {}, read});
        }
        return out;
    };
    all.push_back(meshUnits);
    // The principal point's coordinates exchanged (cx for cy).
    Mistake swappedPrincipal{"cx-cy-swapped", "the principal point's coordinates exchanged (cx used for cy and cy for cx)",
                             Route::Raster, {}, {}};
    swappedPrincipal.alone = true;
    swappedPrincipal.reread = [](const Camera& camera, const DepthMap&) {
        Rereadings out;
        // Where the optical axis meets the image (x right, y down from the top-left corner).
        const glm::dvec3 axis = windowFromEye(camera, glm::dvec3(0, 0, camera.convention().eyeForwardZ));
        const glm::dvec2 principal{axis.x, camera.imageYFromWindowY(axis.y)};
        const glm::dvec2 swapped{principal.y, principal.x};
        if (!(glm::length(swapped - principal) > 0.25)) return out;
        Departure moved;
        moved.principalShift = swapped - principal;
        out.push_back({"", "consistent if the principal point's coordinates are exchanged: (" + formatNumber(swapped.x) +
                               ", " + formatNumber(swapped.y) + ") px instead of (" + formatNumber(principal.x) + ", " +
                               formatNumber(principal.y) + ")",
                       departedCameraSpec(camera, moved), {}, {}});
        return out;
    };
    all.push_back(swappedPrincipal);
    return all;
}

// An off-centre principal point mirrored about the image centre or dropped, in x and y or in
// one axis only (projectionMistakes' middle entries).
std::vector<Mistake> principalPointMistakes()
{
    std::vector<Mistake> all;
    Mistake mirroredPrincipal = wrongProjection(
        "principal-point-mirrored",
        "an off-centre principal point mirrored about the image centre (cx for W - 1 - cx, a frustum's left for "
        "-right), as a y-up vs y-down or sign slip does",
        "consistent if the principal point is mirrored about the image centre",
        [](const Camera& camera, glm::dmat4& m) { return principalScaled(camera, -1, {0, 1}, m); });
    // ... or in one axis only: a sign slip in cx or cy alone (Blender's shift_x or shift_y read
    // with the wrong sign), a diagnosis of its own.
    mirroredPrincipal.reread = [both = mirroredPrincipal.reread](const Camera& camera, const DepthMap& map) {
        Rereadings out = both(camera, map);
        for (Rereading& r : principalInOneAxis(camera, -1, [](const PrincipalAxis& a) {
                 return "consistent if the principal point is mirrored about the image centre in " + std::string(a.axis) +
                        " only (" + a.c + " for " + a.size + " - 1 - " + a.c + ": a sign slip in " + a.c +
                        ", or Blender's " + a.shift + " read with the wrong sign)";
             }))
            out.push_back(std::move(r));
        return out;
    };
    all.push_back(mirroredPrincipal);
    // ... or dropped: the renderer drew a centred image where the camera has an off-centre
    // principal point (Blender's lens shift, an asymmetric frustum, cx and cy ignored): the
    // offset terms of the x and y rows set to zero.
    Mistake droppedShift = wrongProjection(
        "lens-shift-dropped",
        "an off-centre principal point dropped (Blender's shift_x and shift_y, an asymmetric frustum, cx and cy "
        "ignored): the image drawn centred",
        "consistent if the principal point's offset from the image centre was dropped in x and y (a lens shift "
        "ignored: the image drawn centred)",
        [](const Camera& camera, glm::dmat4& m) { return principalScaled(camera, 0, {0, 1}, m); });
    droppedShift.reread = [both = droppedShift.reread](const Camera& camera, const DepthMap& map) {
        Rereadings out = both(camera, map);
        glm::dmat4 xOnly, yOnly;
        const bool x = principalScaled(camera, 0, {0}, xOnly), y = principalScaled(camera, 0, {1}, yOnly);
        for (auto& r : out) {
            r.variant = x && y ? "x and y" : x ? "x" : "y";
            if (!(x && y)) r.explanation = "consistent if the principal point's offset in " + r.variant + " was dropped (a lens "
                                           "shift ignored: the image drawn centred)";
        }
        for (Rereading& r : principalInOneAxis(camera, 0, [](const PrincipalAxis& a) {
                 return "consistent if the principal point's offset in " + std::string(a.axis) + " was dropped (Blender's " +
                        a.shift + " ignored: the image drawn centred in " + std::string(a.axis) + ")";
             }))
            out.push_back(std::move(r));
        return out;
    };
    all.push_back(droppedShift);
    return all;
}

// The projection matrix: its depth range, its depth mapping, its handedness, its principal point
// (principalPointMistakes), its layout, its aspect and field of view, its near and far planes.
std::vector<Mistake> projectionMistakes()
{
    std::vector<Mistake> all;
    all.push_back(wrongProjection(
        "ndc-range", "a [-1,1] depth matrix used with a [0,1] convention, or the reverse",
        "consistent if the projection maps depth to the other NDC range ([-1,1] vs [0,1]) than the viewport expects",
        [](const Camera& camera, glm::dmat4& m) {
            // The z row remapped directly, for every model (a raw matrix and the parallel ones
            // too): [0,1] → [−1,1] is z' = 2z − w, [−1,1] → [0,1] is z' = (z + w)/2.
            m = camera.clipFromEye;
            const bool zeroToOne = camera.convention().ndcDepth == NdcDepthRange::ZeroToOne;
            for (int c = 0; c < 4; ++c) m[c][2] = zeroToOne ? 2 * m[c][2] - m[c][3] : (m[c][2] + m[c][3]) / 2;
            return true;
        }));
    // A correct reversed-Z renderer where standard depth was declared (or the reverse): the
    // raster route draws with the other depth mapping whole (projection, depth test, clear
    // value), and the map is re-read with it.
    Mistake reversed{"reversed-as-standard", "a reversed-Z projection's values read as standard (or the reverse)",
                     Route::Raster, {}, {}};
    reversed.inject = [](const Camera& camera, RouteFaults& faults) {
        return !isRawMatrix(camera) && (faults.raster.otherDepthMapping = true);
    };
    reversed.reread = [](const Camera& camera, const DepthMap&) {
        if (isRawMatrix(camera)) return Rereadings{};
        CameraSpec spec = camera.spec();
        spec.depth.reversed = !spec.depth.reversed;
        return Rereadings{{"", std::string("consistent if read as ") + (camera.depth().reversed ? "standard" : "reversed-Z") + " depth",
                           spec, {}, {}}};
    };
    all.push_back(reversed);
    all.push_back(wrongProjection("handedness", "a left-handed view used in a right-handed pipeline: the eye's x axis mirrored",
                                  "consistent if the eye's x axis is mirrored (a left- vs right-handed view)",
                                  [](const Camera& camera, glm::dmat4& m) {
                                      glm::dmat4 mirror(1.0);
                                      mirror[0][0] = -1;
                                      m = camera.clipFromEye * mirror;
                                      return true;
                                  }));
    for (Mistake& m : principalPointMistakes()) all.push_back(std::move(m));
    all.push_back(wrongProjection("transposed", "the projection matrix transposed (row- vs column-major confusion)",
                                  "consistent if the projection matrix is transposed (row- vs column-major)",
                                  [](const Camera& camera, glm::dmat4& m) {
                                      m = glm::transpose(camera.clipFromEye);
                                      return true;
                                  }));
    all.push_back(wrongProjection("aspect-inverted", "height/width used where width/height belongs",
                                  "consistent if the aspect ratio is height/width instead of width/height",
                                  [](const Camera& camera, glm::dmat4& m) {
                                      const double aspect = double(camera.width()) / camera.height();
                                      m = scaledRows(camera, aspect * aspect, 1.0);
                                      return camera.width() != camera.height();
                                  }));
    all.push_back(wrongProjection("fovy-radians", "the vertical field of view in degrees passed where radians are expected",
                                  "consistent if the field of view in degrees was taken for radians",
                                  [](const Camera& camera, glm::dmat4& m) {
                                      if (!hasFovy(camera)) return false;
                                      const double fovy = camera.spec().projection.fovyDeg;
                                      const double k = std::tan(glm::radians(fovy) / 2) / std::tan(fovy / 2);
                                      m = scaledRows(camera, k, k);
                                      return true;
                                  }));
    all.push_back(wrongProjection("half-fov", "tan(fovy) used where tan(fovy/2) belongs (full vs half field of view)",
                                  "consistent if tan(fovy) was used where tan(fovy/2) belongs",
                                  [](const Camera& camera, glm::dmat4& m) {
                                      if (!hasFovy(camera)) return false;
                                      const double half = glm::radians(camera.spec().projection.fovyDeg) / 2;
                                      const double k = std::tan(half) / std::tan(2 * half);
                                      m = scaledRows(camera, k, k);
                                      return std::isfinite(k);
                                  }));
    // With near and far exchanged the depth test keeps the farthest surface, which no
    // re-reading of the ray route's nearest hits can produce: inject only.
    Mistake swapped = wrongProjection("near-far-swapped", "near and far exchanged in the projection", "",
                                      [](const Camera& camera, glm::dmat4& m) {
                                          if (camera.farIsInfinite() || isRawMatrix(camera)) return false;
                                          m = nearFarSwapped(camera);
                                          return true;
                                      });
    swapped.reread = nullptr;
    all.push_back(swapped);
    // A field of view off by a small factor is measured, not guessed: fit.h's field-of-view
    // family, in MapVerifier::diagnose.
    return all;
}

// An eye-z or distance map clipped by other planes than the camera declares: a ray tracer's,
// which clips at none or only far away (VTK's and Embree's casts, Blender's Z pass up to its clip
// end), or the renderer's own near and far. Re-read with the tightest planes around what the map
// holds: where the map and the truth differ only in surfaces beyond one plane or the other, the
// truth clipped there is the map. The planes bound eye-z, or, for a lens model, the distance
// along each ray; a frustum's extents lie on its near plane and move with it; an oblique box
// (sheared from its near plane) and a raw matrix keep their own.
Mistake clipPlanesMistake()
{
    Mistake clip{"clip-planes",
                 "the map clipped at other near and far planes than declared (a ray tracer that does not clip, or "
                 "the renderer's own planes)",
                 Route::Ray, {}, {}};
    clip.alone = true;
    clip.reread = [](const Camera& camera, const DepthMap& map) {
        if (map.quantity != DepthQuantity::EyeZ && map.quantity != DepthQuantity::Distance) return Rereadings{};
        CameraSpec spec = camera.spec();
        Projection& p = spec.projection;
        const bool alongRays = p.type == ProjectionType::NonLinear;
        if (p.type == ProjectionType::Oblique || p.type == ProjectionType::Matrix) return Rereadings{};
        double nearest = INFINITY, farthest = 0;  // in the planes' measure
        for (int row = 0; row < map.height; ++row)
            for (int col = 0; col < map.width; ++col) {
                const double v = map.value[std::size_t(row) * map.width + col];
                if (kindOfDepthValue(camera, map.quantity, v) != DepthValueKind::Depth) continue;
                const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
                double measure = v;
                if (alongRays && map.quantity == DepthQuantity::EyeZ) measure = distanceFromEyeZ(camera, pWindow, v);
                if (!alongRays && map.quantity == DepthQuantity::Distance) measure = eyeZFromDistance(camera, pWindow, v);
                if (!(measure > 0) || !std::isfinite(measure)) continue;
                nearest = std::min(nearest, measure), farthest = std::max(farthest, measure);
            }
        if (!(farthest > 0)) return Rereadings{};
        const double nearPlane = nearest * (1 - 1e-6), farPlane = farthest * (1 + 1e-6);
        if (p.type == ProjectionType::Frustum) {
            const double k = nearPlane / p.near;
            p.left *= k, p.right *= k, p.bottom *= k, p.top *= k;
        }
        const std::string declared = "near " + fourSignificantDigits(p.near) + " and far " + fourSignificantDigits(p.far);
        const std::string measure = alongRays ? " (distances along the rays)" : " (eye-z)";
        std::string beyond;  // the declared planes the map holds surfaces beyond
        if (nearest < p.near) beyond = "near ≤ " + fourSignificantDigits(nearest);
        if (farthest > p.far) beyond += (beyond.empty() ? "" : " and ") + ("far ≥ " + fourSignificantDigits(farthest));
        const std::string explanation =
            beyond.empty()
                ? "consistent if the map was clipped tighter than the declared " + declared + measure +
                      ": it holds surfaces only from " + fourSignificantDigits(nearest) + " to " + fourSignificantDigits(farthest) +
                      "; give the renderer's own planes"
                : "consistent if the renderer's planes were " + beyond + measure + " instead of the declared " +
                      declared + ": give its own, or, for a ray tracer that does not clip, planes around the scene";
        p.near = nearPlane, p.far = farPlane;
        return Rereadings{{"", explanation, spec, {}, {}}};
    };
    return clip;
}

// What the numbers are: linear depth, an offset, a coarser storage, and every swap of the four
// quantities.
std::vector<Mistake> quantityMistakes()
{
    std::vector<Mistake> all;
    Mistake linear{"linear-depth", "linear eye depth (z − n)/(f − n) stored as the window depth", Route::Raster, {}, {}};
    linear.inject = [](const Camera& camera, RouteFaults& faults) {
        return !camera.farIsInfinite() && (faults.raster.storeLinearEyeZ = true);
    };
    linear.reread = [](const Camera& camera, const DepthMap& map) {
        if (map.quantity != DepthQuantity::Window || camera.farIsInfinite()) return Rereadings{};
        const double n = camera.nearDistance(), f = camera.farDistance(), clear = camera.clearDepth();
        const double lo = camera.depth().rangeMin, span = camera.depth().rangeMax - camera.depth().rangeMin;
        return Rereadings{readAs(map, DepthQuantity::EyeZ,
                                 "consistent if read as linear depth (z − near)/(far − near) instead of window depth",
                                 [=](double v) { return std::isfinite(v) && v != clear ? n + (v - lo) / span * (f - n) : INFINITY; })};
    };
    all.push_back(linear);
    Mistake affineOffset{"affine-depth-offset",
                         "linear depth scaled by far - near without adding near: eye-z - near delivered as eye-z",
                         Route::Raster, {}, {}};
    affineOffset.reread = [](const Camera& camera, const DepthMap& map) {
        if (map.quantity != DepthQuantity::EyeZ && map.quantity != DepthQuantity::Distance) return Rereadings{};
        const double n = camera.nearDistance();
        return Rereadings{readAs(map, map.quantity,
                                 "consistent if near is added to the values (linear depth scaled by far - near without "
                                 "adding near)",
                                 [n](double v) { return std::isfinite(v) ? v + n : v; })};
    };
    all.push_back(affineOffset);
    all.push_back(clipPlanesMistake());
    // A map stored in fewer bits than declared: its values lie on an integer grid.
    // (unorm24 cannot be told apart: binary32 has no finer resolution than its grid near 1.)
    Mistake quantized{"quantized-depth", "window depth stored as unorm16 where float32 was declared", Route::Raster, {}, {}};
    quantized.reread = [](const Camera& camera, const DepthMap& map) {
        if (map.quantity != DepthQuantity::Window || camera.depth().format != DepthFormat::Float32 || map.valueQuantum > 0)
            return Rereadings{};
        Rereadings out;
        for (auto [format, bits] : {std::pair{DepthFormat::Unorm16, 16}}) {
            const double steps = std::ldexp(1.0, bits) - 1;
            std::size_t values = 0, onGrid = 0;
            for (double v : map.value)
                if (std::isfinite(v) && v > 0 && v < 1) {
                    ++values;
                    // Within a hundredth of a step (a binary32 value near 1 holds k/65535 to 0.004 steps).
                    onGrid += std::abs(v * steps - std::round(v * steps)) <= 0.01 ? 1 : 0;
                }
            if (values == 0 || onGrid < values - values / 100) continue;  // 99 % on the grid
            CameraSpec spec = camera.spec();
            spec.depth.format = format;
            out.push_back({toString(format), "consistent if read as " + toString(format) + " depth (the map's values lie on its grid of " +
                                                 std::to_string(std::int64_t(steps)) + " steps), not float32",
                           spec, {}, {}});
            break;
        }
        return out;
    };
    all.push_back(quantized);
    Mistake distanceAsEyeZ{"distance-as-eye-z", "ray distance taken as planar depth (eye-z)", Route::Ray, {}, {}};
    distanceAsEyeZ.inject = [](const Camera&, RouteFaults& faults) { return faults.ray.distanceAsEyeZ = true; };
    distanceAsEyeZ.reread = [](const Camera&, const DepthMap& map) {
        const std::string text = "consistent if read as ray distance instead of eye-z";
        if (map.quantity == DepthQuantity::EyeZ) return Rereadings{readAs(map, DepthQuantity::Distance, text)};
        if (map.quantity == DepthQuantity::Distance) return Rereadings{};
        RayFaults faults;
        faults.distanceAsEyeZ = true;
        return Rereadings{{"", "consistent if the renderer took the ray distance for eye-z", std::nullopt, faults, {}}};
    };
    all.push_back(distanceAsEyeZ);
    auto quantityMistake = [&](std::string name, std::string description, DepthQuantity declared, DepthQuantity actual,
                               std::string explanation) {
        Mistake m{std::move(name), std::move(description), Route::Raster, {}, {}};
        m.reread = [=](const Camera&, const DepthMap& map) {
            return map.quantity == declared ? Rereadings{readAs(map, actual, explanation)} : Rereadings{};
        };
        all.push_back(m);
    };
    quantityMistake("eye-z-as-distance", "planar depth (eye-z) delivered where ray distance was declared",
                    DepthQuantity::Distance, DepthQuantity::EyeZ, "consistent if read as eye-z (planar depth) instead of ray distance");
    quantityMistake("eye-z-as-window", "linear eye-z in scene units delivered where window depth was declared",
                    DepthQuantity::Window, DepthQuantity::EyeZ, "consistent if read as eye-z (linear, scene units) instead of window depth");
    quantityMistake("distance-as-window", "ray distance delivered where window depth was declared", DepthQuantity::Window,
                    DepthQuantity::Distance, "consistent if read as ray distance instead of window depth");
    // Every other swap of the four quantities, by the same rule: "<delivered>-as-<declared>".
    const std::pair<DepthQuantity, const char*> quantities[] = {{DepthQuantity::Window, "window depth"},
                                                                {DepthQuantity::Ndc, "NDC z"},
                                                                {DepthQuantity::EyeZ, "eye-z (planar depth)"},
                                                                {DepthQuantity::Distance, "ray distance"}};
    for (const auto& [declared, declaredText] : quantities)
        for (const auto& [actual, actualText] : quantities) {
            const std::string name = toString(actual) + "-as-" + toString(declared);
            const bool named = std::any_of(all.begin(), all.end(), [&](const Mistake& m) { return m.name == name; });
            if (actual == declared || named) continue;
            quantityMistake(name, std::string(actualText) + " delivered where " + declaredText + " was declared", declared,
                            actual, std::string("consistent if read as ") + actualText + " instead of " + declaredText);
        }
    return all;
}

// The rasterizer's own mistakes: nothing to re-read in a finished map (inject only).
std::vector<Mistake> rasterOnlyMistakes()
{
    std::vector<Mistake> all;
    auto rasterOnly = [&](std::string name, std::string description, std::function<bool(const Camera&, RasterFaults&)> set) {
        Mistake m{std::move(name), std::move(description), Route::Raster, {}, {}};
        m.inject = [set](const Camera& camera, RouteFaults& faults) { return set(camera, faults.raster); };
        all.push_back(m);
    };
    rasterOnly("no-near-clip", "no clipping at the near plane (geometry behind the eye wraps around)",
               [](const Camera&, RasterFaults& f) { return f.noNearClip = true; });
    rasterOnly("screen-linear-eye-z", "eye depth interpolated linearly in screen space instead of perspective-correctly",
               [](const Camera&, RasterFaults& f) { return f.screenLinearEyeZ = true; });
    rasterOnly("viewport-minus-one", "the viewport scaled by width − 1 and height − 1",
               [](const Camera&, RasterFaults& f) { return f.viewportMinusOne = true; });
    rasterOnly("unorm-truncation", "unorm depth quantized by truncation instead of rounding",
               [](const Camera& camera, RasterFaults& f) {
                   return camera.depth().format != DepthFormat::Float32 && (f.truncateUnorm = true);
               });
    return all;
}

// The catalogue: the families in their order, each in its own order.
std::vector<Mistake> buildCatalogue()
{
    std::vector<Mistake> all;
    for (std::vector<Mistake> (*family)() : {samplingMistakes, viewMistakes, filePoseMistakes,
                                             meshUnitAndIntrinsicMistakes, projectionMistakes, quantityMistakes,
                                             rasterOnlyMistakes})
        for (Mistake& mistake : family()) all.push_back(std::move(mistake));
    return all;
}

}  // namespace

const std::vector<Mistake>& mistakeCatalogue()
{
    static const std::vector<Mistake> catalogue = buildCatalogue();
    return catalogue;
}

std::vector<const Mistake*> injectableMistakes()
{
    std::vector<const Mistake*> out;
    for (const Mistake& mistake : mistakeCatalogue())
        if (mistake.inject) out.push_back(&mistake);
    return out;
}

}  // namespace zcheck
