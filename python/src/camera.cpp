// zcheck.Camera: a validated camera (camera.h) — its matrices, rays and points (inverse
// projection, inverse_projection.h), its settings and its camera file. The factories are
// camera_factories.cpp's.
#include "bindings.h"

#include "zcheck/camera_file.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/pose.h"
#include "zcheck/remap.h"

#include <pybind11/stl.h>

#include <sstream>

namespace zcheck::python {

namespace {

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

// (N, 3) from a (3,) or (N, 3) array of finite or NaN numbers; `what` names it in messages.
DoubleArray rowsOf(const py::object& object, int columns, const std::string& what)
{
    DoubleArray a = asDoubles(numericArray(object, what));
    if (a.ndim() == 1 && a.shape(0) == columns) a = a.reshape({py::ssize_t(1), py::ssize_t(columns)});
    if (a.ndim() != 2 || a.shape(1) != columns)
        fail(what + " must have shape (N, " + std::to_string(columns) + "), got " + shapeText(a));
    return a;
}

// Camera.project: world (or eye) points to pixel coordinates, OpenCV's (the centre of pixel (c, r) at (c, r)).
py::array_t<double> project(const Camera& camera, const py::object& points, const std::string& space)
{
    const PointSpace from = pointSpaceFromName(space, "space");
    const DoubleArray p = rowsOf(points, 3, "Camera.project: points");
    const py::ssize_t n = p.shape(0);
    py::array_t<double> out({n, py::ssize_t(2)});
    auto o = out.mutable_unchecked<2>();
    const auto in = p.unchecked<2>();
    for (py::ssize_t i = 0; i < n; ++i) {
        glm::dvec3 q(in(i, 0), in(i, 1), in(i, 2));
        if (from == PointSpace::World) q = glm::dvec3(camera.eyeFromWorld * glm::dvec4(q, 1.0));
        const std::optional<glm::dvec2> pImage = imageFromEye(camera, q);
        o(i, 0) = pImage ? pImage->x - 0.5 : NAN;
        o(i, 1) = pImage ? pImage->y - 0.5 : NAN;
    }
    return out;
}

// Camera.unproject: pixel coordinates (OpenCV's) and depths of one quantity to points.
py::array_t<double> unproject(const Camera& camera, const py::object& pixels, const py::object& depth,
                              const std::string& quantityName, const std::string& space)
{
    const DepthQuantity quantity = depthQuantityFromName(quantityName);
    const PointSpace to = pointSpaceFromName(space, "space");
    const DoubleArray p = rowsOf(pixels, 2, "Camera.unproject: pixels");
    const DoubleArray d = asDoubles(numericArray(depth, "Camera.unproject: depth"));
    const py::ssize_t n = p.shape(0);
    if (d.size() != n) fail("Camera.unproject: depth holds " + std::to_string(d.size()) + " values for " + std::to_string(n) + " pixels");
    requireQuantityOf(camera, quantity, "Camera.unproject: quantity " + quantityName);
    py::array_t<double> out({n, py::ssize_t(3)});
    auto o = out.mutable_unchecked<2>();
    const auto in = p.unchecked<2>();
    const double* values = d.data();
    for (py::ssize_t i = 0; i < n; ++i) {
        const glm::dvec2 pImage(in(i, 0) + 0.5, in(i, 1) + 0.5);
        const std::optional<glm::dvec3> pEye =
            eyePointFromDepth(camera, {pImage.x, camera.windowYFromImageY(pImage.y)}, values[i], quantity);
        glm::dvec3 q = pEye ? *pEye : glm::dvec3(NAN);
        if (pEye && to == PointSpace::World) q = glm::dvec3(camera.worldFromEye * glm::dvec4(q, 1.0));
        o(i, 0) = q.x, o(i, 1) = q.y, o(i, 2) = q.z;
    }
    return out;
}

py::object lensDict(const Camera& camera)
{
    const LensModel* lens = camera.lens();
    if (!lens) return py::none();
    py::dict out;
    out["model"] = lens->spec().model;
    for (std::size_t i = 0; i < lens->info().params.size(); ++i) out[lens->info().params[i]] = lens->spec().params[i];
    return std::move(out);
}

std::string cameraRepr(const Camera& c)
{
    std::ostringstream out;
    out << "<zcheck.Camera " << c.convention().name << " " << toString(c.spec().projection.type) << " " << c.width()
        << "x" << c.height() << ", near " << formatNumber(c.nearDistance()) << ", far " << formatNumber(c.farDistance())
        << ", " << toString(c.depth().format) << (c.depth().reversed ? " reversed-Z" : "") << ">";
    return out.str();
}

}  // namespace

void bindCamera(py::module_& m)
{
    py::class_<Camera> camera(m, "Camera", R"doc(A validated camera: view + projection + image size + depth settings, in one convention.

Build one with Camera.from_file, Camera.from_dict (the camera file's keys), Camera.from_json,
Camera.from_opencv (K, R, t) or Camera.from_matrices (clip_from_eye, eye_from_world). Cameras are
immutable; Camera.replace returns a changed copy. Every factory refuses NaNs, degenerate views,
near <= 0, far <= near and images outside 1..16384 pixels per side with a zcheck.Error naming the
parameter.)doc");
    bindCameraFactories(camera);
    camera
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
        .def("project", &project, py::arg("points"), py::kw_only(), py::arg("space") = "world",
             R"doc(Where points are seen: an (N, 2) float64 array of pixel coordinates as OpenCV counts them
(the centre of pixel (col, row) is (col, row); x right, y down) for an (N, 3) array of points in
`space` ("world" or "eye"), through the lens model where the camera has one (the closed form:
what cv2.projectPoints computes). NaN where a point is not seen: at or behind a perspective
camera's eye plane, outside a lens's field. Points beyond the image's edges keep their coordinates.)doc")
        .def("unproject", &unproject, py::arg("pixels"), py::arg("depth"), py::arg("quantity"), py::kw_only(),
             py::arg("space") = "world",
             R"doc(The points seen at pixels at depths: an (N, 3) float64 array in `space` ("world" or "eye") for an
(N, 2) array of pixel coordinates as Camera.project gives them and N depth values of `quantity`
("eye-z", "distance"; "window", "ndc" for cameras with a depth buffer, not lens models). NaN
where a value is a miss (0, inf, NaN, the clear value) or out of range, where a pixel has no
ray (outside a lens's field) and where eye-z is not defined (a lens's ray 90° or more off the axis).)doc")
        .def(
            "undistorted", [](const Camera& c, double alpha) { return Camera(undistortedCameraSpec(c, alpha)); },
            py::arg("alpha") = 0.0,
            R"doc(The pinhole this lens camera's image undistorts to, at the same size and pose, its K chosen as
cv2.getOptimalNewCameraMatrix(K, D, size, alpha) chooses it (0: only pixels every image edge sees;
1: every source pixel). zcheck.Error for a camera without a lens, or one whose image holds a ray
90° or more off the axis. `zcheck remap --undistort ALPHA` moves a depth map onto it.)doc")
        .def_property_readonly("lens", &lensDict,
                               "The lens model as a dict (\"model\" and each parameter by name), or None for a linear "
                               "projection.")
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
}

}  // namespace zcheck::python
