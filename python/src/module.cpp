// zcheck._zcheck — the Python binding (pybind11 + numpy) of zcheck's libraries.
//
// Everything here is a thin adapter: arrays in and out, names for enums, and the same
// zcheck::Error messages the command line prints (without its "zcheck: error: " prefix).
// Arrays are row-major numpy arrays; images have row 0 at the top; matrices are written as on
// paper for column vectors (M[r, c], p' = M·p), while GLM stores m[c][r].
// The GIL is released around every render, check, verify, diagnosis, scene load and BVH build.
#include "bindings.h"

#include "zcheck/camera.h"
#include "zcheck/camera_file.h"
#include "zcheck/camera_sources.h"
#include "zcheck/checker.h"
#include "zcheck/compare.h"
#include "zcheck/convention.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/mistakes.h"
#include "zcheck/pose.h"
#include "zcheck/quantity.h"
#include "zcheck/report.h"
#include "zcheck/scene.h"
#include "zcheck/version.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace py = pybind11;
using namespace zcheck;
using namespace zcheck::python;

namespace {

// A Report's per-pixel array; refused for a check made with keep_pixels=False.
template <class Values>
const Values& pixelsOf(const PyReport& r, const Values& values)
{
    if (!r.pixelsKept)
        fail("this report keeps no per-pixel arrays: it was made with keep_pixels=False "
             "(check again with keep_pixels=True for pixel_classes, error_over_tolerance and the depths)");
    return values;
}


// ---------------------------------------------------------------------------------------------
// numpy helpers

std::string shapeText(const py::array& a)
{
    std::string text = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) text += (i ? ", " : "") + std::to_string(a.shape(i));
    return text + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtypeText(const py::array& a) { return py::str(py::handle(a.dtype())).cast<std::string>(); }

// Any array-like of numbers (float, signed or unsigned integer); `what` names the argument.
py::array numericArray(py::handle object, const std::string& what)
{
    if (object.is_none()) fail(what + " is missing");
    py::array a = py::array::ensure(object);
    if (!a) fail(what + " must be an array of numbers");
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
        fail(what + " must be an array of numbers (float or integer), got dtype " + dtypeText(a));
    return a;
}

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

DoubleArray asDoubles(const py::array& a) { return DoubleArray::ensure(a); }

// A 4×4 (or, with `allow3x4`, 3×4 [R|t]) matrix written for column vectors, M[r, c].
glm::dmat4 matrixFromArray(py::handle object, const std::string& what, bool allow3x4)
{
    const py::array a = numericArray(object, what);
    const bool ok = a.ndim() == 2 && a.shape(1) == 4 && (a.shape(0) == 4 || (allow3x4 && a.shape(0) == 3));
    if (!ok)
        fail(what + " must be a " + std::string(allow3x4 ? "4x4 or 3x4" : "4x4") + " matrix, got shape " + shapeText(a));
    const DoubleArray d = asDoubles(a);
    const auto v = d.unchecked<2>();
    glm::dmat4 m(1.0);
    for (py::ssize_t r = 0; r < d.shape(0); ++r)
        for (int c = 0; c < 4; ++c) {
            if (!std::isfinite(v(r, c)))
                fail(what + "[" + std::to_string(r) + ", " + std::to_string(c) + "] is not finite (" +
                     formatNumber(v(r, c)) + ")");
            m[c][int(r)] = v(r, c);
        }
    if (d.shape(0) == 4 && allow3x4 && !hasRigidLastRow(m))
        fail(what + " must have the last row 0 0 0 1 (a rigid transform for column vectors)");
    return m;
}

py::array_t<double> arrayFromMatrix(const glm::dmat4& m)
{
    py::array_t<double> out({py::ssize_t(4), py::ssize_t(4)});
    auto v = out.mutable_unchecked<2>();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) v(r, c) = m[c][r];
    return out;
}

py::array_t<double> arrayFromVec3(const glm::dvec3& p)
{
    py::array_t<double> out(py::ssize_t(3));
    auto v = out.mutable_unchecked<1>();
    for (int i = 0; i < 3; ++i) v(i) = p[i];
    return out;
}

// Runs `make` and prefixes a refusal with `where` ("Camera.from_opencv"): the rules are the
// library's (pose.h, camera.h), the names of the arguments the caller's.
template <class Make>
auto prefixedErrors(const std::string& where, Make&& make)
{
    try {
        return make();
    } catch (const Error& e) {
        throw Error(where + ": " + e.what());
    }
}

// ---------------------------------------------------------------------------------------------
// names

constexpr int kPixelClassCount = int(PixelClass::Hole) + 1;  // the last class (compare.h)

// ---------------------------------------------------------------------------------------------
// threads: at most N worker threads for one call (TBB's limit is process-wide while it lives)

// ---------------------------------------------------------------------------------------------
// scenes

Scene sceneFromArrays(py::object vertices, py::object triangles, const std::string& name)
{
    const std::string where = "Scene.from_arrays: ";
    const py::array v = numericArray(vertices, where + "vertices");
    if (v.ndim() != 2 || v.shape(1) != 3 || v.shape(0) < 1)
        fail(where + "vertices must have shape (N, 3) with N >= 1, got " + shapeText(v));
    const py::array t = numericArray(triangles, where + "triangles");
    if (t.dtype().kind() == 'f')
        fail(where + "triangles must be an integer array of vertex indices, got dtype " + dtypeText(t));
    if (t.ndim() != 2 || t.shape(1) != 3 || t.shape(0) < 1)
        fail(where + "triangles must have shape (M, 3) with M >= 1, got " + shapeText(t));
    if (name.empty()) fail(where + "name is empty");

    Scene scene;
    scene.name = name;
    const DoubleArray vd = asDoubles(v);
    const auto pv = vd.unchecked<2>();
    scene.positions.resize(std::size_t(vd.shape(0)));
    for (py::ssize_t i = 0; i < vd.shape(0); ++i) {
        for (int k = 0; k < 3; ++k) {
            const double x = pv(i, k);
            const float f = float(x);
            if (!std::isfinite(x) || !std::isfinite(f))
                fail(where + "vertices[" + std::to_string(i) + ", " + std::to_string(k) + "] = " + formatNumber(x) +
                     (std::isfinite(x) ? " does not fit in binary32" : " is not finite"));
            scene.positions[std::size_t(i)][k] = f;
        }
    }
    const std::size_t n = scene.positions.size();
    const bool isSigned = t.dtype().kind() == 'i';
    // Unsigned indices are read as uint64, signed as int64: no value changes on the way.
    scene.triangles.resize(std::size_t(t.shape(0)));
    auto setIndex = [&](py::ssize_t j, int k, long double index) {
        if (index < 0 || index >= static_cast<long double>(n))
            fail(where + "triangles[" + std::to_string(j) + ", " + std::to_string(k) + "] = " +
                 std::to_string(static_cast<long long>(index)) + " is not a vertex index (0.." + std::to_string(n - 1) +
                 " for " + std::to_string(n) + " vertices)");
        scene.triangles[std::size_t(j)][k] = std::uint32_t(index);
    };
    if (isSigned) {
        const auto ti = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(t);
        const auto pt = ti.unchecked<2>();
        for (py::ssize_t j = 0; j < ti.shape(0); ++j)
            for (int k = 0; k < 3; ++k) setIndex(j, k, static_cast<long double>(pt(j, k)));
    } else {
        const auto tu = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(t);
        const auto pt = tu.unchecked<2>();
        for (py::ssize_t j = 0; j < tu.shape(0); ++j)
            for (int k = 0; k < 3; ++k) setIndex(j, k, static_cast<long double>(pt(j, k)));
    }
    // The mesh loader's rule (scene.h): something with area to draw, and a camera framing it.
    scene = frameScene(std::move(scene), "Scene.from_arrays: the mesh");
    return scene;
}

// ---------------------------------------------------------------------------------------------
// cameras

// Builds and validates; a validation message is prefixed with the factory's name.
Camera makeCamera(const CameraSpec& spec, const std::string& where)
{
    try {
        return Camera(spec);
    } catch (const Error& e) {
        throw Error(where + ": " + e.what());
    }
}

DepthSettings depthSettings(const std::string& format, bool reversed, const std::pair<double, double>& range,
                            const std::string& where)
{
    DepthSettings d;
    try {
        d.format = depthFormatFromName(format);
    } catch (const Error& e) {
        throw Error(where + ": depth_format is invalid: " + e.what());
    }
    d.reversed = reversed;
    d.rangeMin = range.first;
    d.rangeMax = range.second;
    return d;
}

Convention conventionNamed(const std::string& name, const std::string& where)
{
    try {
        return Convention::preset(name);
    } catch (const Error& e) {
        throw Error(where + ": convention is invalid: " + e.what());
    }
}

// width= and height=, both required: whole numbers of pixels (640 or 640.0).
std::pair<int, int> requireImageSize(const py::object& width, const py::object& height, const std::string& where)
{
    const std::optional<int> w = sizeArgument(width, (where + ": width").c_str());
    const std::optional<int> h = sizeArgument(height, (where + ": height").c_str());
    if (!w || !h) fail(where + ": width and height (the image size in pixels) are required");
    return {*w, *h};
}

Camera cameraFromOpencv(py::object K, py::object R, py::object t, py::object width, py::object height,
                        py::object camFromWorld, py::object worldFromCam, double near, double far, double pixelCenter,
                        const std::string& convention, const std::string& depthFormat, bool reversed,
                        std::pair<double, double> depthRange)
{
    const std::string where = "Camera.from_opencv";
    const std::string at = where + ": ";
    CameraSpec spec;
    std::tie(spec.width, spec.height) = requireImageSize(width, height, where);
    spec.convention = conventionNamed(convention, where);
    spec.depth = depthSettings(depthFormat, reversed, depthRange, where);

    // Intrinsics: [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], by the pose rule's reading (pose.h).
    const py::array k = numericArray(K, at + "K");
    if (k.ndim() != 2 || k.shape(0) != 3 || k.shape(1) != 3) fail(at + "K must be a 3x3 matrix, got shape " + shapeText(k));
    const DoubleArray kd = asDoubles(k);
    const auto kv = kd.unchecked<2>();
    double kRows[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) kRows[r][c] = kv(r, c);
    spec.projection = prefixedErrors(where, [&] {
        return PinholeIntrinsics::fromK(kRows, pixelCenter, "K").projection(near, far, "K");
    });

    // Extrinsics: exactly one of (R, t), cam_from_world, world_from_cam.
    const int given = int(!R.is_none() || !t.is_none()) + int(!camFromWorld.is_none()) + int(!worldFromCam.is_none());
    if (given != 1)
        fail(at + "give the view as exactly one of R and t, cam_from_world= or world_from_cam= (got " +
             std::to_string(given) + ")");
    glm::dmat4 eyeFromWorld(1.0);
    std::string named;
    if (!R.is_none() || !t.is_none()) {
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
                if (!std::isfinite(rv(i, c)))
                    fail(at + "R[" + std::to_string(i) + ", " + std::to_string(c) + "] is not finite");
                rotation[c][i] = rv(i, c);
            }
            if (!std::isfinite(tv[i])) fail(at + "t[" + std::to_string(i) + "] is not finite");
            translation[i] = tv[i];
        }
        eyeFromWorld = poseFromRotationTranslation(rotation, translation);
        named = "R";
    } else if (!camFromWorld.is_none()) {
        eyeFromWorld = matrixFromArray(camFromWorld, at + "cam_from_world", true);
        named = "cam_from_world";
    } else {
        eyeFromWorld = matrixFromArray(worldFromCam, at + "world_from_cam", true);
        named = "world_from_cam";
    }
    // The pose rule (pose.h): rigid, with the convention's handedness, re-orthonormalised
    // within the rounding bound, inverted by transposition when given camera-to-world.
    const PoseDirection direction = named == "world_from_cam" ? PoseDirection::WorldFromCamera : PoseDirection::CameraFromWorld;
    spec.view = prefixedErrors(where, [&] { return viewFromPose(eyeFromWorld, direction, spec.convention, spec.convention, named); });
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

py::object jsonLoads(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

py::dict matricesDict(const Camera& camera)
{
    py::dict out;
    out["eye_from_world"] = arrayFromMatrix(camera.eyeFromWorld);
    out["world_from_eye"] = arrayFromMatrix(camera.worldFromEye);
    out["clip_from_eye"] = arrayFromMatrix(camera.clipFromEye);
    out["eye_from_clip"] = arrayFromMatrix(camera.eyeFromClip);
    out["clip_from_world"] = arrayFromMatrix(camera.clipFromWorld);
    out["world_from_clip"] = arrayFromMatrix(camera.worldFromClip);
    out["window_from_ndc"] = arrayFromMatrix(camera.windowFromNdc);
    out["ndc_from_window"] = arrayFromMatrix(camera.ndcFromWindow);
    out["near"] = camera.nearDistance();
    out["far"] = camera.farDistance();
    return out;
}

glm::ivec2 requirePixel(const Camera& camera, int col, int row)
{
    return pixelInImage(camera, col, row, "pixel (" + std::to_string(col) + ", " + std::to_string(row) + ")");
}

py::dict rayDict(const EyePlaneRay& r)
{
    py::dict d;
    d["origin"] = arrayFromVec3(r.origin);
    d["direction"] = arrayFromVec3(r.direction);
    d["t_near"] = r.tNear;
    d["t_far"] = r.tFar;
    return d;
}

py::dict pixelRay(const Camera& camera, int col, int row)
{
    const glm::ivec2 pixel = requirePixel(camera, col, row);
    const glm::dvec2 pWindow = windowFromPixelCentre(camera, pixel.x, pixel.y);
    py::dict out;
    out["pixel"] = py::make_tuple(pixel.x, pixel.y);
    out["window"] = py::make_tuple(pWindow.x, pWindow.y);
    out["eye"] = rayDict(eyePlaneRayFrom(eyeRayThroughWindow(camera, pWindow)));
    out["world"] = rayDict(worldEyePlaneRayThroughWindow(camera, pWindow));
    return out;
}

// As `zcheck unproject --pixel --depth` (cli/unproject.cpp), with "depth" for "--depth".
py::dict pointAt(const Camera& camera, int col, int row, double value, const std::string& quantityName)
{
    const DepthQuantity quantity = depthQuantityFromName(quantityName);
    const glm::ivec2 pixel = requirePixel(camera, col, row);
    const PointAtDepth point = pointAtDepth(camera, windowFromPixelCentre(camera, pixel.x, pixel.y), value, quantity, "depth");
    py::dict out;
    out["eye"] = arrayFromVec3(point.pEye);
    out["world"] = arrayFromVec3(point.pWorld);
    out["eye_z"] = point.eyeZ;
    out["distance"] = point.distance;
    return out;
}

std::string cameraRepr(const Camera& c)
{
    std::ostringstream out;
    out << "<zcheck.Camera " << c.convention().name << " " << toString(c.spec().projection.type) << " " << c.width()
        << "x" << c.height() << ", near " << formatNumber(c.nearDistance()) << ", far " << formatNumber(c.farDistance())
        << ", " << toString(c.depth().format) << (c.depth().reversed ? " reversed-Z" : "") << ">";
    return out.str();
}

// ---------------------------------------------------------------------------------------------
// depth maps given as arrays

// `depth` (height × width, any float or integer dtype) → the map verify and unproject take,
// its values converted as a file's are (DepthMapReading::depthOf): integer maps need a scale,
// and step 1/scale; float16 maps carry each value's own step (binary16Step), as a file's do.
DepthMap mapFromArray(py::handle depth, const Camera& camera, const DepthMapReading& reading, DepthQuantity quantity)
{
    const py::array a = numericArray(depth, "depth");
    if (a.ndim() != 2 || a.shape(0) != camera.height() || a.shape(1) != camera.width())
        fail("depth must have shape (" + std::to_string(camera.height()) + ", " + std::to_string(camera.width()) +
             ") = (camera.height, camera.width), got " + shapeText(a));
    const bool integer = a.dtype().kind() != 'f';
    if (integer && !(reading.scale > 0))
        fail("depth is an integer array (" + dtypeText(a) +
             "): give scale= (stored value = depth × scale, e.g. 1000 for millimetres; 0 = miss)");
    const DoubleArray d = asDoubles(a);
    DepthMapFile stored;
    stored.width = camera.width(), stored.height = camera.height();
    stored.value.assign(d.data(), d.data() + d.size());
    depthsFromStored(stored,
                     integer ? StoredValues::Integer : (a.dtype().itemsize() == 2 ? StoredValues::Half : StoredValues::Float),
                     reading);
    return DepthMap::of(std::move(stored), quantity, reading);
}

// ---------------------------------------------------------------------------------------------
// reports

py::list diagnosisList(const std::vector<Hypothesis>& hypotheses)
{
    py::list out;
    for (const auto& h : hypotheses) {
        py::dict d;
        d["hypothesis"] = h.name;
        d["variant"] = h.variant;
        d["explanation"] = h.explanation;
        d["consistent"] = h.consistent;
        d["unexplained"] = h.unexplained;
        d["unexplained_estimated"] = h.estimated;
        d["consistent_except_edges"] = h.consistentExceptEdges();
        d["unexplained_at_edges"] = h.unexplainedAtEdges;
        py::list fitted;
        for (const FittedValue& v : h.fitted) {
            py::dict f;
            f["name"] = v.name, f["value"] = v.value, f["declared"] = v.declared;
            fitted.append(f);
        }
        d["fitted"] = fitted;
        out.append(d);
    }
    return out;
}

// ---------------------------------------------------------------------------------------------
// docstrings

constexpr const char* kModuleDoc = R"doc(zcheck — check a graphics transform chain by computing every pixel's depth twice.

The ray route (Embree) follows the camera's definition; the raster route (a software z-buffer)
follows its matrices. If view, projection, depth mapping, viewport orientation and pixel-centre
convention agree, both depths agree within a stated tolerance at every pixel.

    import zcheck, numpy as np
    scene = zcheck.Scene.from_file("builtin:default")           # or Scene.from_arrays(V, F)
    camera = zcheck.Camera.from_dict({...camera file keys...})  # or from_file / from_opencv / from_matrices
    checker = zcheck.Checker(scene)                             # BVH and rasterizer, once
    report = checker.check(camera)                              # report.consistent, report.to_dict()
    z = checker.render(camera, "eye-z")                         # H x W float32, row 0 at the top
    checker.verify(camera, my_depth, "eye-z").consistent        # a depth map from your renderer

Conventions every function follows:
  * images are numpy arrays of shape (height, width[, channels]); row 0 is the TOP row;
    pixel (col, row) is array[row, col]; its centre is image point (col + 0.5, row + 0.5);
  * matrices are numpy 4x4 arrays written for column vectors, M[r, c] with p' = M @ p, and named
    dest_from_src (eye_from_world maps world points into eye space);
  * depth quantities: "window" (the depth-buffer value), "ndc" (z_ndc), "eye-z" (planar depth
    along the viewing axis, positive) and "distance" (Euclidean range from the centre of
    projection);
  * bad input raises zcheck.Error (a ValueError) with the command line's one-line message.)doc";

}  // namespace

PYBIND11_MODULE(_zcheck, m)
{
    m.doc() = kModuleDoc;
    // Classes and signatures say zcheck.Camera, not zcheck._zcheck.Camera (the name is restored at the end).
    m.attr("__name__") = "zcheck";
    py::register_exception<Error>(m, "Error", PyExc_ValueError);
    m.attr("Error").attr("__doc__") =
        "Bad input (a file, key, value, array shape or option): the message is the one line the zcheck command "
        "prints after 'zcheck: error: '. A subclass of ValueError.";

    m.attr("__version__") = std::string(kVersion);
    m.attr("conventions") = Convention::presetNames();
    m.attr("depth_quantities") = depthQuantityNames();
    m.attr("quantities") = exportQuantityNames();
    m.attr("depth_formats") = depthFormatNames();
    m.attr("routes") = std::vector<std::string>{"ray", "raster"};
    {
        std::vector<std::string> names;
        for (const auto& n : builtinSceneNames()) names.push_back("builtin:" + n);
        m.attr("builtin_scenes") = names;
        std::vector<std::string> classes;
        for (int k = 0; k < kPixelClassCount; ++k) classes.push_back(toString(PixelClass(k)));
        m.attr("pixel_classes") = classes;
        py::list mistakes;
        for (const Mistake& mistake : mistakeCatalogue()) {
            py::dict d;
            d["name"] = mistake.name;
            d["description"] = mistake.description;
            d["route"] = toString(mistake.route);
            d["injectable"] = bool(mistake.inject);
            d["diagnosable"] = bool(mistake.reread);
            mistakes.append(d);
        }
        m.attr("mistakes") = mistakes;
    }

    // ----------------------------------------------------------------------------- Scene
    py::class_<Scene>(m, "Scene", R"doc(A triangle soup in world space (binary32 positions, uint32 indices) and the
camera it is best looked at with (Scene.default_camera).

Build one with Scene.from_file(...) or Scene.from_arrays(...).)doc")
        .def_static(
            "from_file",
            [](const std::string& nameOrPath) {
                py::gil_scoped_release release;
                return loadScene(nameOrPath);
            },
            py::arg("path"),
            R"doc(Load a scene by name, exactly as `zcheck check --scene` does.

path: "builtin:default", "builtin:terrain?n=64", "builtin:near-crossing", or a mesh file (OBJ,
PLY including triangle strips, STL, glTF/glb). A mesh's default camera frames its bounding sphere.
Raises zcheck.Error naming the file or scene for anything missing, unreadable or malformed.)doc")
        .def_static("from_arrays", &sceneFromArrays, py::arg("vertices"), py::arg("triangles"),
                    py::arg("name") = "arrays",
                    R"doc(A scene from numpy arrays.

vertices:  (N, 3) numbers, world coordinates; stored as binary32 (what GPUs and Embree use), so
           each must be finite and fit in binary32 and within +-1e15.
triangles: (M, 3) integers, indices into vertices (any integer dtype); triangle k is primitive k.
name:      the scene's name in reports.
Degenerate (zero-area) triangles are kept, but at least one must have area. The default camera
frames the bounding sphere, by the same rule as a loaded mesh file.
Raises zcheck.Error naming the argument, the entry and the rule.)doc")
        .def_property_readonly("name", [](const Scene& s) { return s.name; }, "The scene's name as addressed.")
        .def_property_readonly("vertex_count", [](const Scene& s) { return s.positions.size(); })
        .def_property_readonly("triangle_count", &Scene::triangleCount)
        .def_property_readonly(
            "vertices",
            [](const Scene& s) {
                py::array_t<float> out({py::ssize_t(s.positions.size()), py::ssize_t(3)});
                auto v = out.mutable_unchecked<2>();
                for (std::size_t i = 0; i < s.positions.size(); ++i)
                    for (int k = 0; k < 3; ++k) v(py::ssize_t(i), k) = s.positions[i][k];
                return out;
            },
            "(N, 3) float32 copy of the world-space positions.")
        .def_property_readonly(
            "triangles",
            [](const Scene& s) {
                py::array_t<std::uint32_t> out({py::ssize_t(s.triangles.size()), py::ssize_t(3)});
                auto v = out.mutable_unchecked<2>();
                for (std::size_t i = 0; i < s.triangles.size(); ++i)
                    for (int k = 0; k < 3; ++k) v(py::ssize_t(i), k) = s.triangles[i][k];
                return out;
            },
            "(M, 3) uint32 copy of the vertex indices; row k is primitive id k.")
        .def_property_readonly(
            "bounds",
            [](const Scene& s) { return py::make_tuple(arrayFromVec3(s.boundsMin()), arrayFromVec3(s.boundsMax())); },
            "(min, max) corners of the axis-aligned bounding box, world coordinates.")
        .def_property_readonly(
            "default_camera", [](const Scene& s) { return makeCamera(s.defaultCamera, "Scene.default_camera"); },
            "The camera `zcheck check` uses when no camera file is given.")
        .def(py::pickle(&sceneState, &sceneFromState))
        .def("__repr__", [](const Scene& s) {
            return "<zcheck.Scene '" + s.name + "': " + std::to_string(s.positions.size()) + " vertices, " +
                   std::to_string(s.triangles.size()) + " triangles>";
        });

    // ----------------------------------------------------------------------------- Camera
    py::class_<Camera>(m, "Camera", R"doc(A validated camera: view + projection + image size + depth settings, in one convention.

Build one with Camera.from_file, Camera.from_dict (the camera file's keys), Camera.from_json,
Camera.from_opencv (K, R, t) or Camera.from_matrices (clip_from_eye, eye_from_world). Cameras are
immutable; Camera.replace returns a changed copy. Every factory refuses NaNs, degenerate views,
near <= 0, far <= near and images outside 1..16384 pixels per side with a zcheck.Error naming the
parameter.)doc")
        .def_static(
            "from_file",
            [](const std::string& reference, std::optional<std::string> format, const Scene* scene,
               std::optional<double> near, std::optional<double> far, const py::object& width, const py::object& height) {
                const ImportedCamera imported =
                    importCamera(reference, format ? std::optional<CameraFormat>(cameraFormatFromName(*format)) : std::nullopt);
                return makeCamera(completeCamera(imported, scene, {near, far, sizeArgument(width, "Camera.from_file: width"),
                                                                  sizeArgument(height, "Camera.from_file: height"), std::nullopt}),
                                  "Camera.from_file");
            },
            py::arg("path"), py::kw_only(), py::arg("format") = py::none(), py::arg("scene") = py::none(),
            py::arg("near") = py::none(), py::arg("far") = py::none(), py::arg("width") = py::none(),
            py::arg("height") = py::none(),
            R"doc(A camera from any camera file zcheck reads, as `--camera` reads it: "FILE" or "FILE#FRAME".

FILE:   a zcheck camera (JSON), a COLMAP model folder (sparse/0#img_014.png), a transforms.json
        (nerfstudio, instant-ngp: #frame_003, #images/frame_003.png or #3), an OpenCV FileStorage
        or ROS CameraInfo YAML/XML (#raw, #rectified), a glTF's camera nodes; told by content.
format: forces the format: "zcheck", "colmap", "nerfstudio", "opencv", "ros", "gltf".
scene:  a Scene whose extent as the camera sees it gives near and far when the file has none
        (else give near and far).
width, height: the image size when the file has none (instant-ngp, glTF), or to replace it.
The errors are the command line's. camera.notes says what was assumed.)doc")
        .def_static(
            "from_json",
            [](const std::string& text, const std::string& source) { return Camera(cameraSpecFromJsonText(text, source)); },
            py::arg("text"), py::arg("source") = "camera JSON",
            R"doc(A camera from the camera file's JSON text; `source` begins every error message.)doc")
        .def_static("from_opencv", &cameraFromOpencv, py::arg("K"), py::arg("R") = py::none(), py::arg("t") = py::none(),
                    py::arg("width") = py::none(), py::arg("height") = py::none(), py::kw_only(),
                    py::arg("cam_from_world") = py::none(), py::arg("world_from_cam") = py::none(),
                    py::arg("near") = 0.1, py::arg("far") = 100.0, py::arg("pixel_center") = 0.0,
                    py::arg("convention") = "opencv", py::arg("depth_format") = "float32", py::arg("reversed") = false,
                    py::arg("depth_range") = std::pair<double, double>(0.0, 1.0),
                    R"doc(A pinhole camera from OpenCV-style intrinsics and extrinsics.

K:            3x3 intrinsics [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] in pixels (no skew).
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
camera; a raw matrix is read in the new convention's spaces.)doc")
        .def(
            "to_dict", [](const Camera& c) { return jsonLoads(cameraJsonText(c.spec())); },
            "The camera file's JSON as a dict (Camera.from_dict reads it back to the same camera).")
        .def(
            "to_json", [](const Camera& c) { return cameraJsonText(c.spec()); },
            "The camera file's JSON text, as `zcheck export` writes it in its sidecar.")
        .def("matrices", &matricesDict,
             R"doc(Every transform as a numpy 4x4 float64 array for column vectors (M[r, c], p' = M @ p), the
rows `zcheck matrices` prints: eye_from_world, world_from_eye, clip_from_eye, eye_from_clip,
clip_from_world, world_from_clip, window_from_ndc, ndc_from_window; plus the resolved near and far
(far = inf for an infinite far plane).)doc")
        .def("pixel_ray", &pixelRay, py::arg("col"), py::arg("row"),
             R"doc(The viewing ray through the centre of pixel (col, row) (row 0 at the top), as
`zcheck unproject --pixel` prints it: {"pixel", "window", "eye": {origin, direction, t_near,
t_far}, "world": {...}}. origin lies on the eye plane (the centre of projection for perspective),
direction is a unit vector, and t in [t_near, t_far] spans near to far plane.)doc")
        .def("point_at", &pointAt, py::arg("col"), py::arg("row"), py::arg("depth"), py::arg("quantity"),
             R"doc(The point seen at pixel (col, row) at `depth` of `quantity` (window, ndc, eye-z, distance), as
`zcheck unproject --pixel --depth` prints it: {"eye", "world", "eye_z", "distance"}.)doc")
        .def_property_readonly("width", &Camera::width)
        .def_property_readonly("height", &Camera::height)
        .def_property_readonly(
            "convention", [](const Camera& c) { return c.convention().name; }, "The convention's name.")
        .def_property_readonly(
            "projection_type", [](const Camera& c) { return toString(c.spec().projection.type); })
        .def_property_readonly("near", &Camera::nearDistance, "Near plane distance along the viewing axis (eye-z).")
        .def_property_readonly("far", &Camera::farDistance, "Far plane distance (inf for an infinite far plane).")
        .def_property_readonly(
            "depth_format", [](const Camera& c) { return toString(c.depth().format); })
        .def_property_readonly(
            "reversed", [](const Camera& c) { return c.depth().reversed; }, "Reversed-Z.")
        .def_property_readonly(
            "depth_range", [](const Camera& c) { return py::make_tuple(c.depth().rangeMin, c.depth().rangeMax); })
        .def_property_readonly("clear_value", &Camera::clearDepth,
                               "The window depth a cleared depth buffer holds (the far end of the range).")
        .def_property_readonly(
            "notes", [](const Camera& c) { return cameraNotes(c.spec()); },
            "What was assumed or repaired when the camera was made (near and far taken from the scene, a rotation "
            "re-orthonormalised, ...), one sentence each; reports print them as warnings.")
        .def(
            "__eq__",
            [](const Camera& a, const py::object& b) -> py::object {
                if (!py::isinstance<Camera>(b)) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
                return py::bool_(cameraJsonText(a.spec()) == cameraJsonText(b.cast<const Camera&>().spec()));
            },
            py::is_operator(), "Cameras are equal when their camera files are: the same geometry and settings.")
        .def("__hash__", [](const Camera& c) { return py::hash(py::str(cameraJsonText(c.spec()))); })
        .def(py::pickle(&cameraState, &cameraFromState))
        .def("__repr__", &cameraRepr);

    // ----------------------------------------------------------------------------- Report
    py::class_<PyReport>(m, "Report", R"doc(The result of Checker.check or Checker.verify: pixel counts, depth errors, the
verdict, and per-pixel images. to_dict() is the document `zcheck check --json` (or `zcheck verify
--json`) prints for the same inputs.)doc")
        .def_property_readonly(
            "consistent", [](const PyReport& r) { return r.report.comparison.consistent(); },
            "The verdict: no unexplained coverage mismatch, no depth error, no systematic bias.")
        .def_property_readonly("width", [](const PyReport& r) { return r.report.comparison.width; })
        .def_property_readonly("height", [](const PyReport& r) { return r.report.comparison.height; })
        .def_property_readonly("scene", [](const PyReport& r) { return r.report.scene; })
        .def_property_readonly("triangles", [](const PyReport& r) { return r.report.triangles; })
        .def_property_readonly(
            "camera", [](const PyReport& r) { return Camera(r.report.camera); }, "The camera both sides used.")
        .def_property_readonly("both_hit", [](const PyReport& r) { return r.report.comparison.bothHit; })
        .def_property_readonly("both_miss", [](const PyReport& r) { return r.report.comparison.bothMiss; })
        .def_property_readonly("ray_only", [](const PyReport& r) { return r.report.comparison.rayOnly; })
        .def_property_readonly("raster_only", [](const PyReport& r) { return r.report.comparison.rasterOnly; },
                               "Pixels only the raster route (or the verified map) covers.")
        .def_property_readonly("map_only", [](const PyReport& r) { return r.report.comparison.rasterOnly; },
                               "Pixels only the verified map covers (verify's name for raster_only).")
        .def_property_readonly("out_of_range", [](const PyReport& r) { return r.report.comparison.outOfRange; },
                               "Pixels of a verified map holding values its quantity cannot hold (window 2, a "
                               "negative eye-z): errors.")
        .def_property_readonly("agree", [](const PyReport& r) { return r.report.comparison.agree; })
        .def_property_readonly("edge_surface", [](const PyReport& r) { return r.report.comparison.edgeSurface; })
        .def_property_readonly("depth_errors", [](const PyReport& r) { return r.report.comparison.depthErrors; })
        .def_property_readonly("coverage_explained",
                               [](const PyReport& r) { return r.report.comparison.coverageExplained; })
        .def_property_readonly("lost_at_clear_value",
                               [](const PyReport& r) { return r.report.comparison.lostAtClearValue; })
        .def_property_readonly("at_clip_plane", [](const PyReport& r) { return r.report.comparison.atClipPlane; })
        .def_property_readonly("coverage_unexplained",
                               [](const PyReport& r) { return r.report.comparison.coverageUnexplained; })
        .def_property_readonly(
            "unexplained", [](const PyReport& r) { return r.report.comparison.unexplained(); },
            "depth_errors + coverage_unexplained.")
        .def_property_readonly("max_error_quanta", [](const PyReport& r) { return r.report.comparison.maxErrorQuanta; })
        .def_property_readonly("p99_error_quanta", [](const PyReport& r) { return r.report.comparison.p99ErrorQuanta; })
        .def_property_readonly("max_error_over_tolerance",
                               [](const PyReport& r) { return r.report.comparison.maxErrorOverTolerance; },
                               "max |d_compared - d_ray| / tolerance over compared pixels; <= 1 means within.")
        .def_property_readonly("max_relative_eye_z_error",
                               [](const PyReport& r) { return r.report.comparison.maxRelativeEyeZError; })
        .def_property_readonly("p99_relative_eye_z_error",
                               [](const PyReport& r) { return r.report.comparison.p99RelativeEyeZError; })
        .def_property_readonly("depth_bias", [](const PyReport& r) { return r.report.comparison.depthBias; })
        .def_property_readonly("mean_signed_error_quanta",
                               [](const PyReport& r) { return r.report.comparison.meanSignedErrorQuanta; })
        .def_property_readonly("bias_samples", [](const PyReport& r) { return r.report.comparison.biasSamples; })
        .def_property_readonly(
            "timings",
            [](const PyReport& r) {
                py::dict d;
                d["bvh_build"] = r.report.timings.bvhBuildMs;
                d["trace"] = r.report.timings.traceMs;
                d["raster"] = r.report.timings.rasterMs;
                d["compare"] = r.report.timings.compareMs;
                return d;
            },
            "Wall times in milliseconds: bvh_build, trace, raster, compare.")
        .def_property_readonly(
            "pixel_classes",
            [](const PyReport& r) { return image(pixelsOf(r, r.pixelClass), r.report.comparison.width, r.report.comparison.height); },
            "(H, W) uint8: each pixel's class, an index into zcheck.pixel_classes (row 0 at the top).")
        .def_property_readonly(
            "error_over_tolerance",
            [](const PyReport& r) {
                return image(pixelsOf(r, r.errorOverTolerance), r.report.comparison.width, r.report.comparison.height);
            },
            "(H, W) float32: |d_compared - d_ray| / tolerance where both hit, 0 elsewhere.")
        .def_property_readonly(
            "ray_window_depth",
            [](const PyReport& r) { return image(pixelsOf(r, r.rayWindowDepth), r.report.comparison.width, r.report.comparison.height); },
            "(H, W) float64: the ray route's exact window depth (the clear value where it misses).")
        .def_property_readonly(
            "compared_window_depth",
            [](const PyReport& r) {
                return image(pixelsOf(r, r.comparedWindowDepth), r.report.comparison.width, r.report.comparison.height);
            },
            "(H, W) float64: the other side's window depth: the raster route's stored values (check) or the "
            "verified map as window depth (verify); the clear value where it misses.")
        .def_property_readonly(
            "diagnosis",
            [](const PyReport& r) -> py::object {
                return r.diagnosis ? diagnosisList(*r.diagnosis) : py::list();
            },
            "verify(..., diagnose=True) on an inconsistent map: the hypotheses, as Checker.diagnose returns "
            "them; else an empty list (nothing was diagnosed).")
        .def(
            "to_json", [](const PyReport& r) { return r.json; },
            "The JSON text `zcheck check --json` / `zcheck verify --json` prints.")
        .def(
            "to_dict", [](const PyReport& r) { return jsonLoads(r.json); }, "to_json() parsed into a dict.")
        .def(
            "summary", [](const PyReport& r) { return r.summary; },
            "The summary `zcheck check` / `zcheck verify` prints (with the diagnosis line when diagnosed).")
        .def(py::pickle(&reportState, &reportFromState))
        .def("__repr__", [](const PyReport& r) {
            const auto& c = r.report.comparison;
            return std::string("<zcheck.Report ") + (r.verify ? "verify" : "check") + " " +
                   (c.consistent() ? "CONSISTENT" : "INCONSISTENT") + ": " + std::to_string(c.bothHit) +
                   " both hit, " + std::to_string(c.unexplained()) + " unexplained>";
        });

    // ----------------------------------------------------------------------------- Checker
    py::class_<PyChecker>(m, "Checker", R"doc(One scene with both routes built once (Embree's BVH and the rasterizer), and every
question zcheck answers about it. Immutable and thread-safe: its methods release the GIL and may be
called from several Python threads at once.)doc")
        .def(py::init([](const Scene& scene) {
                 Scene copy = scene;
                 py::gil_scoped_release release;
                 return std::make_unique<PyChecker>(std::move(copy));
             }),
             py::arg("scene"), "Validates the scene and builds both routes (the scene is copied).")
        .def_property_readonly(
            "scene", [](const PyChecker& self) -> const Scene& { return self.checker.scene(); },
            py::return_value_policy::reference_internal)
        .def(
            "check",
            [](const PyChecker& self, std::optional<Camera> camera, std::optional<int> threads, bool keepPixels) {
                auto r = std::make_unique<PyReport>();
                {
                    py::gil_scoped_release release;
                    const auto limit = threadLimit(threads);
                    const Camera cam = camera ? *camera : Camera(self.checker.scene().defaultCamera);
                    CheckOptions options;
                    options.keepPixels = keepPixels;
                    const CheckResult run = self.checker.check(cam, options);
                    requireSomethingCompared(run.report.comparison, self.checker.scene().name);
                    r->report = run.report;
                    r->json = checkReportJson(run.report);
                    r->summary = formatSummary(run.report);
                    r->pixelsKept = keepPixels;
                    if (keepPixels) fillComparison(*r, run.comparison, run.ray, run.raster);
                }
                return r;
            },
            py::arg("camera") = py::none(), py::arg("threads") = py::none(), py::arg("keep_pixels") = true,
            R"doc(Both routes through `camera` (default: the scene's own camera), compared per pixel: what
`zcheck check` does. Returns a Report. Raises zcheck.Error "nothing to compare" when neither route
sees any surface, as the command does. threads: at most this many worker threads (1..1024).
keep_pixels=False: the check is drawn, traced and compared tile by tile and keeps no per-pixel
array (the same report, faster, ~60 MB less memory at 1080p: for checking many cameras); the
Report's pixel_classes, error_over_tolerance, ray_window_depth and compared_window_depth then
raise zcheck.Error.)doc")
        .def(
            "render",
            [](const PyChecker& self, const Camera& camera, const std::string& quantityName, const std::string& routeName,
               py::object dtype, std::optional<int> threads) -> py::array {
                const ExportQuantity quantity = exportQuantityFromName(quantityName);
                const Route route = routeFromName(routeName);
                const py::dtype dt = py::dtype::from_args(dtype);
                if (dt.kind() != 'f' || (dt.itemsize() != 4 && dt.itemsize() != 8))
                    fail("dtype must be float32 or float64, got " + py::str(py::handle(dt)).cast<std::string>());
                QuantityImage img;
                {
                    py::gil_scoped_release release;
                    const auto limit = threadLimit(threads);
                    img = self.checker.render(camera, quantity, route);
                }
                const py::ssize_t H = img.height, W = img.width;
                if (quantity == ExportQuantity::PrimitiveId) return image(img.id, img.width, img.height);
                const py::ssize_t C = py::ssize_t(img.channels.size());
                std::vector<py::ssize_t> shape = {H, W};
                if (C > 1) shape.push_back(C);
                if (dt.itemsize() == 8) {
                    py::array_t<double> out(shape);
                    std::copy(img.value.begin(), img.value.end(), out.mutable_data());
                    return out;
                }
                py::array_t<float> out(shape);
                float* data = out.mutable_data();
                for (std::size_t i = 0; i < img.value.size(); ++i) data[i] = float(img.value[i]);
                return out;
            },
            py::arg("camera"), py::arg("quantity"), py::arg("route") = "ray", py::arg("dtype") = "float32",
            py::arg("threads") = py::none(),
            R"doc(One route's render as an image (row 0 at the top), what `zcheck export` writes:

quantity: "window", "ndc", "eye-z", "distance"  -> (H, W) float
          "position-eye", "position-world", "normal" -> (H, W, 3) float
          "primitive-id"                             -> (H, W) uint32 (triangle index)
route:    "ray" (exact hits, double precision) or "raster" (the z-buffer's stored values;
          positions unprojected from them).
dtype:    float32 (as files store it) or float64 (the ray route's double values unrounded).
Misses hold the quantity's miss value: the clear value (window), NDC z of the far plane (ndc),
+inf (eye-z, distance), NaN (positions, normals), 0xFFFFFFFF (primitive-id).)doc")
        .def(
            "verify",
            [](const PyChecker& self, const Camera& camera, py::object depth, const py::object& quantityArg,
               const py::object& miss, const py::object& scale, const py::object& offset, const py::object& quantum,
               const py::object& relTolerance, const py::object& absTolerance, const py::object& allowHoles, bool diagnose,
               std::optional<int> threads) {
                std::string quantityName;
                const DepthQuantity quantity = quantityArgument(quantityArg, quantityName);
                const DepthMapReading reading = readingOf({miss, scale, offset, quantum, relTolerance, absTolerance, allowHoles});
                const DepthMap map = mapFromArray(depth, camera, reading, quantity);
                auto r = std::make_unique<PyReport>();
                r->verify = true;
                {
                    py::gil_scoped_release release;
                    const auto limit = threadLimit(threads);
                    const DepthMapSource source{"<array>", quantityName, "", reading};
                    fillVerification(*r, verifyMap(self.verifier, camera, map, diagnose, source.name()), source);
                }
                return r;
            },
            py::arg("camera"), py::arg("depth"), py::arg("quantity") = py::none(), py::kw_only(), py::arg("miss") = py::none(),
            py::arg("scale") = py::none(), py::arg("offset") = py::none(), py::arg("quantum") = py::none(),
            py::arg("rel_tolerance") = py::none(), py::arg("abs_tolerance") = py::none(), py::arg("allow_holes") = py::none(),
            py::arg("diagnose") = false, py::arg("threads") = py::none(),
            R"doc(A depth map rendered elsewhere against the ray route's ground truth: what `zcheck verify` does.

depth:    (camera.height, camera.width) array, row 0 at the top, any float or integer dtype.
quantity: what it holds: "window", "ndc", "eye-z" or "distance" (required: mixing them up is the
          mistake zcheck exists to catch).
miss:     the stored value that marks "no surface" (0, 65535, 1e10, float("inf")), or a comparison
          as a string (">=1e9", "<=0"); compared with the value as stored, before scale and offset.
          Without it, 0 is a miss in integer arrays. NaN is always a miss; so are non-finite
          values, the clear value (window, ndc) and values <= 0 (eye-z, distance).
scale:    stored value = (depth - offset) x scale. Integer arrays need it (quantum 1/scale, like a
          16-bit PNG); float arrays are divided by it.
offset:   added to every depth after scale (default 0).
quantum:  the values were rounded to multiples of this (map units, after scale): 0.001 for
          millimetres held as float metres (`cv2.imread(p, -1) / 1000.0`). float16 arrays carry
          their own step without it.
rel_tolerance, abs_tolerance: the map is good only to ±(abs + rel·|value|) (map units): a
          rasterizer's reconstructed Z pass, a sensor; added to every pixel's tolerance.
allow_holes: a pixel without a value where the surface is hit is a hole, counted in
          report.to_dict()["pixels"]["holes"], not a failure.
diagnose: when inconsistent, also run diagnose() and put it in the report (`--diagnose`).
Returns a Report whose to_dict() is `zcheck verify --json`'s document (depth_map.file "<array>").)doc")
        .def(
            "diagnose",
            [](const PyChecker& self, const Camera& camera, py::object depth, const py::object& quantityArg,
               const py::object& miss, const py::object& scale, const py::object& offset, const py::object& quantum,
               const py::object& relTolerance, const py::object& absTolerance, const py::object& allowHoles,
               std::optional<int> threads) {
                std::string quantityName;
                const DepthQuantity quantity = quantityArgument(quantityArg, quantityName);
                const DepthMap map = mapFromArray(depth, camera,
                                                  readingOf({miss, scale, offset, quantum, relTolerance, absTolerance, allowHoles}),
                                                  quantity);
                std::vector<Hypothesis> hypotheses;
                {
                    py::gil_scoped_release release;
                    const auto limit = threadLimit(threads);
                    hypotheses = self.verifier.diagnose(camera, map);
                }
                return diagnosisList(hypotheses);
            },
            py::arg("camera"), py::arg("depth"), py::arg("quantity") = py::none(), py::kw_only(), py::arg("miss") = py::none(),
            py::arg("scale") = py::none(), py::arg("offset") = py::none(), py::arg("quantum") = py::none(),
            py::arg("rel_tolerance") = py::none(), py::arg("abs_tolerance") = py::none(), py::arg("allow_holes") = py::none(),
            py::arg("threads") = py::none(),
            R"doc(Every hypothesis of the mistake catalogue that applies to this camera and map, then every
fitted family (sample-offset, field-of-view, near-far, depth-scale, intrinsics, pose), ranked:
consistent ones first, then by unexplained pixels. Dicts {hypothesis, variant, explanation,
consistent, unexplained, unexplained_estimated, fitted}; `fitted` lists a fit's measured
parameters as {name, value, declared} (e.g. fovy_deg, sample_dx_px, near, value_scale) and
its median relative depth residual ("residual": fitted vs declared camera). The consistent
ones name what explains the map (e.g. "y-flip", "distance-as-eye-z", "sample-offset").
Arguments as for verify().)doc")
        .def("__repr__", [](const PyChecker& self) {
            const Scene& scene = self.checker.scene();
            return "<zcheck.Checker scene '" + scene.name + "', " + std::to_string(scene.triangleCount()) + " triangles>";
        });

    // ----------------------------------------------------------------------------- functions
    m.def(
        "unproject",
        [](const Camera& camera, py::object depth, const std::string& quantityName, const std::string& space,
           int stride, const py::object& miss, const py::object& scale, const py::object& offset) {
            const PointSpace pointSpace = pointSpaceFromName(space, "space");
            if (stride < 1 || stride > Camera::kMaxImageSide)
                fail("stride must be in 1.." + std::to_string(Camera::kMaxImageSide) + ", got " + std::to_string(stride));
            const DepthQuantity quantity = depthQuantityFromName(quantityName);
            ReadingArguments arguments;
            arguments.miss = miss, arguments.scale = scale, arguments.offset = offset;
            const DepthMap input = mapFromArray(depth, camera, readingOf(arguments), quantity);
            UnprojectedMap cloud;
            {
                py::gil_scoped_release release;
                cloud = unprojectMap(camera, input.value, quantity, pointSpace, stride);
            }
            const py::ssize_t n = py::ssize_t(cloud.points.size());
            py::array_t<double> points({n, py::ssize_t(3)});
            py::array_t<std::int64_t> pixels({n, py::ssize_t(2)});
            auto p = points.mutable_unchecked<2>();
            auto q = pixels.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < n; ++i) {
                for (int k = 0; k < 3; ++k) p(i, k) = cloud.points[std::size_t(i)][k];
                q(i, 0) = cloud.pixels[std::size_t(i)].x;
                q(i, 1) = cloud.pixels[std::size_t(i)].y;
            }
            return py::make_tuple(points, pixels);
        },
        py::arg("camera"), py::arg("depth"), py::arg("quantity"), py::kw_only(), py::arg("space") = "world",
        py::arg("stride") = 1, py::arg("miss") = py::none(), py::arg("scale") = py::none(), py::arg("offset") = py::none(),
        R"doc(A whole depth map back to 3-D points: what `zcheck unproject --depth-map` does.

depth:    (camera.height, camera.width) array, row 0 at the top (miss, scale, offset as for
          Checker.verify).
quantity: "window", "ndc", "eye-z" or "distance".
space:    "world" or "eye" (the camera's convention's eye axes).
stride:   every stride-th pixel in x and y from (0, 0).
Returns (points, pixels): points (N, 3) float64, pixels (N, 2) int64 as (col, row) with row 0 at
the top, one per non-miss pixel, in scan order.)doc");


    m.def(
        "release_cached_buffers", [] { releaseCachedLargeBuffers(); },
        R"doc(Gives back to the system the per-frame buffers zcheck keeps for the next render of the same
size (renders and comparisons of 1 MiB and more, up to 1 GiB in all; see cached_buffer_bytes),
and has the C library give back the free memory its heap holds. A loop over many cameras or
maps pays their page faults once because of them; a long-lived program that is done checking
calls this. Safe at any time: buffers in use are not touched.)doc");
    m.def("cached_buffer_bytes", [] { return cachedLargeBufferBytes(); },
          "The bytes zcheck's kept per-frame buffers hold (see release_cached_buffers).");

    m.attr("__name__") = "zcheck._zcheck";
}
