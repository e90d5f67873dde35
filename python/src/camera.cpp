// zcheck.Camera: a validated camera (camera.h) — its matrices, rays and points (inverse
// projection, inverse_projection.h), its settings and its camera file. The factories are
// camera_factories.cpp's.
#include "bindings.h"

#include "zcheck/camera_file.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/pose.h"

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
