// zcheck.Camera's factories: from a camera file, its JSON, OpenCV's K, R, t or an engine's
// matrices, and Camera.replace. Each reads its arguments and leaves the rules to the library:
// the pose and intrinsics rule (pose.h: PinholeIntrinsics::fromK, poseFromRotationTranslation,
// viewFromPose), how matrices are written (camera.h: matrixForVectors) and the camera's own
// validation (Camera). Refusals are prefixed with the factory's name ("Camera.from_opencv: ").
#include "bindings.h"

#include <algorithm>

#include "zcheck/camera_file.h"
#include "zcheck/camera_sources.h"
#include "zcheck/pose.h"

#include <pybind11/stl.h>

#include <cmath>
#include <tuple>
#include <utility>

namespace zcheck::python {

namespace {

DepthSettings depthSettings(const std::string& format, bool reversed, const std::pair<double, double>& range,
                            const std::string& where)
{
    DepthSettings d;
    d.format = prefixedErrors(where + ": depth_format is invalid", [&] { return depthFormatFromName(format); });
    d.reversed = reversed;
    d.rangeMin = range.first;
    d.rangeMax = range.second;
    return d;
}

Convention conventionNamed(const std::string& name, const std::string& where)
{
    return prefixedErrors(where + ": convention is invalid", [&] { return Convention::preset(name); });
}

// width= and height=, both required: whole numbers of pixels (640 or 640.0).
std::pair<int, int> requireImageSize(const py::object& width, const py::object& height, const std::string& where)
{
    const std::optional<int> w = sizeArgument(width, (where + ": width").c_str());
    const std::optional<int> h = sizeArgument(height, (where + ": height").c_str());
    if (!w || !h) fail(where + ": width and height (the image size in pixels) are required");
    return {*w, *h};
}

Camera cameraFromFile(const std::string& reference, std::optional<std::string> format, const Scene* scene,
                      std::optional<double> near, std::optional<double> far, const py::object& width, const py::object& height)
{
    const ImportedCamera imported =
        importCamera(reference, format ? &cameraFormatNamed(*format) : nullptr);
    return makeCamera(completeCamera(imported, scene, {near, far, sizeArgument(width, "Camera.from_file: width"),
                                                      sizeArgument(height, "Camera.from_file: height"), std::nullopt}),
                      "Camera.from_file");
}

// K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] as zcheck's pinhole projection, by the pose rule's
// reading of intrinsics (pose.h).
Projection projectionFromK(const py::object& K, double pixelCenter, double near, double far, const std::string& where)
{
    const std::string at = where + ": ";
    const py::array k = numericArray(K, at + "K");
    if (k.ndim() != 2 || k.shape(0) != 3 || k.shape(1) != 3) fail(at + "K must be a 3x3 matrix, got shape " + shapeText(k));
    const DoubleArray kd = asDoubles(k);
    const auto kv = kd.unchecked<2>();
    double kRows[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) kRows[r][c] = kv(r, c);
    return prefixedErrors(where, [&] { return PinholeIntrinsics::fromK(kRows, pixelCenter, "K").projection(near, far, "K"); });
}

// cam_from_world = [R | t] from R (3x3) and t (3 elements), each element named when not finite.
glm::dmat4 poseFromRt(const py::object& R, const py::object& t, const std::string& at)
{
    if (R.is_none() || t.is_none()) fail(at + "R and t go together (cam_from_world = [R | t])");
    const py::array r = numericArray(R, at + "R");
    if (r.ndim() != 2 || r.shape(0) != 3 || r.shape(1) != 3) fail(at + "R must be a 3x3 matrix, got shape " + shapeText(r));
    const py::array tt = numericArray(t, at + "t");
    if (tt.size() != 3 || !(tt.ndim() == 1 || (tt.ndim() == 2 && (tt.shape(0) == 1 || tt.shape(1) == 1))))
        fail(at + "t must have 3 elements (shape (3,) or (3, 1)), got shape " + shapeText(tt));
    const DoubleArray rd = asDoubles(r), td = asDoubles(tt);
    const auto rv = rd.unchecked<2>();
    const double* tv = td.data();
    glm::dmat3 rotation;
    glm::dvec3 translation;
    for (int i = 0; i < 3; ++i) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(rv(i, c))) fail(at + "R[" + std::to_string(i) + ", " + std::to_string(c) + "] is not finite");
            rotation[c][i] = rv(i, c);
        }
        if (!std::isfinite(tv[i])) fail(at + "t[" + std::to_string(i) + "] is not finite");
        translation[i] = tv[i];
    }
    return poseFromRotationTranslation(rotation, translation);
}

// The view from exactly one of (R, t), cam_from_world= and world_from_cam=, by the pose rule
// (pose.h): rigid, with the convention's handedness, re-orthonormalised within the rounding
// bound, inverted by transposition when given camera-to-world.
View viewFromExtrinsics(const py::object& R, const py::object& t, const py::object& camFromWorld,
                        const py::object& worldFromCam, const Convention& convention, const std::string& where)
{
    const std::string at = where + ": ";
    const int given = int(!R.is_none() || !t.is_none()) + int(!camFromWorld.is_none()) + int(!worldFromCam.is_none());
    if (given != 1)
        fail(at + "give the view as exactly one of R and t, cam_from_world= or world_from_cam= (got " +
             std::to_string(given) + ")");
    glm::dmat4 pose(1.0);
    std::string named;
    if (!R.is_none() || !t.is_none()) {
        pose = poseFromRt(R, t, at);
        named = "R";
    } else if (!camFromWorld.is_none()) {
        pose = matrixFromArray(camFromWorld, at + "cam_from_world", true);
        named = "cam_from_world";
    } else {
        pose = matrixFromArray(worldFromCam, at + "world_from_cam", true);
        named = "world_from_cam";
    }
    const PoseDirection direction = named == "world_from_cam" ? PoseDirection::WorldFromCamera : PoseDirection::CameraFromWorld;
    return prefixedErrors(where, [&] { return viewFromPose(pose, direction, convention, convention, named); });
}

// OpenCV's distortion coefficients as a lens (lens.h): calib3d's 4, 5, 8, 12 or 14 (k1 k2 p1 p2
// [k3 [k4 k5 k6 [s1 s2 s3 s4 [τx τy]]]]), or cv::fisheye's 4 (k1..k4) when `fisheye`. None or all
// zeros: the pinhole itself.
Projection projectionWithDistortion(Projection pinhole, py::object D, bool fisheye, const std::string& where)
{
    if (D.is_none()) {
        if (fisheye) fail(where + ": fisheye=True needs D, cv::fisheye's 4 coefficients (k1, k2, k3, k4)");
        return pinhole;
    }
    const DoubleArray d = asDoubles(numericArray(D, where + ": D"));
    std::vector<double> coefficients(d.data(), d.data() + d.size());
    const std::size_t n = coefficients.size();
    if (fisheye ? n != 4 : (n != 4 && n != 5 && n != 8 && n != 12 && n != 14))
        fail(where + ": D holds " + std::to_string(n) + " coefficients; " +
             (fisheye ? "cv::fisheye takes 4 (k1, k2, k3, k4)" : "OpenCV takes 4, 5, 8, 12 or 14"));
    if (!fisheye && std::all_of(coefficients.begin(), coefficients.end(), [](double c) { return c == 0; })) return pinhole;
    Projection p = pinhole;
    p.type = ProjectionType::NonLinear;
    p.lens.model = fisheye ? "opencv_fisheye" : "opencv";
    p.lens.params = {pinhole.fx, pinhole.fy, pinhole.cx, pinhole.cy};
    p.lens.params.insert(p.lens.params.end(), coefficients.begin(), coefficients.end());
    return p;
}

Camera cameraFromOpencv(py::object K, py::object R, py::object t, py::object width, py::object height, py::object D,
                        py::object camFromWorld, py::object worldFromCam, bool fisheye, double near, double far,
                        double pixelCenter, const std::string& convention, const std::string& depthFormat, bool reversed,
                        std::pair<double, double> depthRange)
{
    const std::string where = "Camera.from_opencv";
    CameraSpec spec;
    std::tie(spec.width, spec.height) = requireImageSize(width, height, where);
    spec.convention = conventionNamed(convention, where);
    spec.depth = depthSettings(depthFormat, reversed, depthRange, where);
    spec.projection = projectionWithDistortion(projectionFromK(K, pixelCenter, near, far, where), D, fisheye, where);
    spec.view = viewFromExtrinsics(R, t, camFromWorld, worldFromCam, spec.convention, where);
    return makeCamera(spec, where);
}

Camera cameraFromMatrices(py::object clipFromEye, py::object eyeFromWorld, py::object width, py::object height,
                          py::object worldFromEye, const std::string& convention,
                          const std::string& vectors, const std::string& depthFormat, bool reversed,
                          std::pair<double, double> depthRange)
{
    const std::string where = "Camera.from_matrices";
    const std::string at = where + ": ";
    const auto [imageWidth, imageHeight] = requireImageSize(width, height, where);
    const std::optional<MatrixVectors> side = matrixVectorsFromName(vectors);
    if (!side) fail(at + "vectors must be " + kMatrixVectorsNames + ", got '" + vectors + "'");
    auto read = [&](py::handle object, const std::string& name) {
        return matrixForVectors(matrixFromArray(object, at + name, false), *side);
    };
    CameraSpec spec;
    spec.convention = conventionNamed(convention, where);
    spec.width = imageWidth, spec.height = imageHeight;
    spec.depth = depthSettings(depthFormat, reversed, depthRange, where);
    spec.projection.type = ProjectionType::Matrix;
    spec.projection.clipFromEye = read(clipFromEye, "clip_from_eye");
    if (eyeFromWorld.is_none() == worldFromEye.is_none())
        fail(at + "give the view as exactly one of eye_from_world and world_from_eye=");
    const std::string name = eyeFromWorld.is_none() ? "world_from_eye" : "eye_from_world";
    const glm::dmat4 view = read(eyeFromWorld.is_none() ? worldFromEye : eyeFromWorld, name);
    const PoseDirection direction = eyeFromWorld.is_none() ? PoseDirection::WorldFromCamera : PoseDirection::CameraFromWorld;
    spec.view = prefixedErrors(where, [&] { return viewFromPose(view, direction, spec.convention, spec.convention, name); });
    return makeCamera(spec, where);
}

Camera cameraReplaced(const Camera& camera, const std::optional<std::string>& convention, const py::object& width,
                      const py::object& height, const std::optional<std::string>& depthFormat,
                      std::optional<bool> reversed, std::optional<std::pair<double, double>> depthRange)
{
    const std::string where = "Camera.replace";
    CameraSpec spec = camera.spec();
    if (convention) spec.convention = conventionNamed(*convention, where);
    if (const auto w = sizeArgument(width, "Camera.replace: width")) spec.width = *w;
    if (const auto h = sizeArgument(height, "Camera.replace: height")) spec.height = *h;
    if (depthFormat) spec.depth.format = depthSettings(*depthFormat, false, {0, 1}, where).format;
    if (reversed) spec.depth.reversed = *reversed;
    if (depthRange) spec.depth.rangeMin = depthRange->first, spec.depth.rangeMax = depthRange->second;
    return makeCamera(spec, where);
}

}  // namespace

Camera makeCamera(const CameraSpec& spec, const std::string& where)
{
    return prefixedErrors(where, [&] { return Camera(spec); });
}

namespace {

// Camera.from_file's docstring, its formats from the table (camera_formats.h).
const std::string& fromFileDoc()
{
    static const std::string doc = [] {
        std::string formats;
        for (const CameraFormat* format : cameraFormats())
            formats += "\n        " + format->title + " (" + format->example + "): " + format->files;
        return "A camera from any camera file zcheck reads, as `--camera` reads it: \"FILE\" or \"FILE#FRAME\".\n\n"
               "FILE:   any camera file, its format told by content; FRAME an index, an image name, a path or its stem:" +
               formats + "\nformat: forces the format: " + cameraFormatChoices(CameraFormatsWith::Reader, ", ") +
               ".\nscene:  a Scene whose extent as the camera sees it gives near and far when the file has none\n"
               "        (else give near and far).\n"
               "width, height: the image size when the file has none (instant-ngp, glTF), or to replace it.\n"
               "The errors are the command line's. camera.notes says what was assumed.";
    }();
    return doc;
}

}  // namespace

void bindCameraFactories(py::class_<Camera>& camera)
{
    camera
        .def_static("from_file", &cameraFromFile, py::arg("path"), py::kw_only(), py::arg("format") = py::none(),
                    py::arg("scene") = py::none(), py::arg("near") = py::none(), py::arg("far") = py::none(),
                    py::arg("width") = py::none(), py::arg("height") = py::none(),
                    fromFileDoc().c_str())
        .def_static(
            "from_json",
            [](const std::string& text, const std::string& source) { return Camera(cameraSpecFromJsonText(text, source)); },
            py::arg("text"), py::arg("source") = "camera JSON",
            R"doc(A camera from the camera file's JSON text; `source` begins every error message.)doc")
        .def_static("from_opencv", &cameraFromOpencv, py::arg("K"), py::arg("R") = py::none(), py::arg("t") = py::none(),
                    py::arg("width") = py::none(), py::arg("height") = py::none(), py::kw_only(),
                    py::arg("D") = py::none(), py::arg("cam_from_world") = py::none(),
                    py::arg("world_from_cam") = py::none(), py::arg("fisheye") = false, py::arg("near") = 0.1, py::arg("far") = 100.0, py::arg("pixel_center") = 0.0,
                    py::arg("convention") = "opencv", py::arg("depth_format") = "float32", py::arg("reversed") = false,
                    py::arg("depth_range") = std::pair<double, double>(0.0, 1.0),
                    R"doc(A camera from OpenCV-style intrinsics, distortion and extrinsics.

K:            3x3 intrinsics [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] in pixels (no skew).
D=           (keyword) distortion coefficients as OpenCV orders them: calib3d's 4, 5, 8, 12 or 14
              (k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tau_x tau_y]]]]), or with fisheye=True
              cv::fisheye's 4 (k1 k2 k3 k4, Kannala-Brandt). None or all zeros: a pinhole.
              With distortion the camera is a lens model (lens "opencv" or "opencv_fisheye"):
              near and far are then distances along the rays, and only eye-z and distance exist.
R, t:         cam_from_world = [R | t]: x_cam = R @ x_world + t (OpenCV's rvec/tvec, COLMAP's
              qvec/tvec). Or give instead, as a keyword, exactly one of
cam_from_world=  4x4 or 3x4 [R | t], the same transform, or
world_from_cam=  4x4 or 3x4, its inverse (camera-to-world, "c2w", the camera's pose).
width, height: the image size in pixels.
convention:   the camera axes those matrices use, and the convention of the camera built:
              "opencv" (x right, y down, z forward: OpenCV, COLMAP), "opengl" (x right, y up,
              z backward: OpenGL, Blender, nerfstudio's c2w), "vulkan", "metal", "direct3d".
pixel_center: where the intrinsics put the centre of the top-left pixel: 0.0 (OpenCV, whose
              pixel centres are integers) or 0.5 (COLMAP, nerfstudio). zcheck's "pinhole"
              projection uses OpenCV's, so cx, cy are stored minus pixel_center.
near, far:    the clipping distances along the viewing axis (far may be math.inf).
depth_format, reversed, depth_range: the depth buffer ("float32", "unorm24", "unorm16";
              reversed-Z; glDepthRange), as the camera file's "depth" block.
The rotation must be orthonormal with the determinant of a pose (not a reflection).)doc")
        .def_static("from_matrices", &cameraFromMatrices, py::arg("clip_from_eye"), py::arg("eye_from_world") = py::none(),
                    py::arg("width") = py::none(), py::arg("height") = py::none(), py::kw_only(),
                    py::arg("world_from_eye") = py::none(), py::arg("convention") = "opengl",
                    py::arg("vectors") = "column", py::arg("depth_format") = "float32", py::arg("reversed") = false,
                    py::arg("depth_range") = std::pair<double, double>(0.0, 1.0),
                    R"doc(A camera from a raw projection matrix and a raw view matrix, as an engine holds them.

clip_from_eye:  4x4 projection: the convention's clip space from its eye space.
eye_from_world: 4x4 rigid view matrix (the "view matrix"); or world_from_eye= (the camera's pose).
width, height:  the image size in pixels.
convention:     the API whose spaces the matrices use: "opengl" (eye looks down -Z, NDC z in
                [-1, 1]), "direct3d", "vulkan", "metal", "opencv" (see zcheck.conventions).
vectors:        "column" if the arrays are written for p' = M @ p (the usual mathematical layout;
                note GLM's m[c][r] indexing is column-major: np.array(glm_matrix).T), "row" if
                written for p' = p @ M (Direct3D / DirectXMath), i.e. transposed.
reversed:       the projection maps near to the far end of the depth range (depth test GREATER);
                near and far are read off the matrix accordingly.
depth_format, depth_range: as in the camera file's "depth" block.)doc")
        .def("replace", &cameraReplaced, py::kw_only(), py::arg("convention") = py::none(), py::arg("width") = py::none(),
             py::arg("height") = py::none(), py::arg("depth_format") = py::none(), py::arg("reversed") = py::none(),
             py::arg("depth_range") = py::none(),
             R"doc(A copy with the given settings replaced, as `zcheck check --convention/--width/--height/
--depth-format/--reversed-z` replace them. Replacing the convention keeps the picture of a look-at
camera; a raw matrix is read in the new convention's spaces.)doc");
}

}  // namespace zcheck::python
