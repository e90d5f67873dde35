// zcheck._zcheck — the Python binding (pybind11 + numpy) of zcheck's libraries.
//
// Everything here is a thin adapter: arrays in and out, names for enums, and the same
// zcheck::Error messages the command line prints (without its "zcheck: error: " prefix).
// Arrays are row-major numpy arrays; images have row 0 at the top; matrices are written as on
// paper for column vectors (M[r, c], p' = M·p), while GLM stores m[c][r].
// The GIL is released around every render, check, verify, diagnosis, scene load and BVH build.
//
// This file declares the module, its constants and its free functions; each class is bound by
// its own file (bindings.h lists them).
#include "bindings.h"

#include "zcheck/compare.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/kernel_form.h"
#include "zcheck/large_buffer.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/mistakes.h"
#include "zcheck/version.h"

#include <pybind11/stl.h>

#include <cstdint>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace zcheck;
using namespace zcheck::python;

namespace {

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

constexpr int kPixelClassCount = int(PixelClass::Hole) + 1;  // the last class (compare.h)

// The names of what the module's functions take, and the mistake catalogue.
void addConstants(py::module_& m)
{
    m.attr("__version__") = std::string(kVersion);
    m.attr("conventions") = Convention::presetNames();
    m.attr("depth_quantities") = depthQuantityNames();
    m.attr("quantities") = exportQuantityNames();
    m.attr("depth_formats") = depthFormatNames();
    m.attr("routes") = std::vector<std::string>{"ray", "raster"};
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

py::tuple unproject(const Camera& camera, py::object depth, const std::string& quantityName, const std::string& space,
                    int stride, const py::object& miss, const py::object& scale, const py::object& offset)
{
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
}

void bindFunctions(py::module_& m)
{
    m.def("unproject", &unproject, py::arg("camera"), py::arg("depth"), py::arg("quantity"), py::kw_only(),
          py::arg("space") = "world", py::arg("stride") = 1, py::arg("miss") = py::none(), py::arg("scale") = py::none(),
          py::arg("offset") = py::none(),
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
size (renders and comparisons of 1 MiB and more, up to 1 GiB in all, and a frame's scratch of
64 KiB and more, up to 64 MiB; see cached_buffer_bytes),
and has the C library give back the free memory its heap holds. A loop over many cameras or
maps pays their page faults once because of them; a long-lived program that is done checking
calls this. Safe at any time: buffers in use are not touched.)doc");
    m.def("cached_buffer_bytes", [] { return cachedLargeBufferBytes(); },
          "The bytes zcheck's kept per-frame buffers hold (see release_cached_buffers).");
    m.def(
        "kernel_form", [] { return std::string(nameOf(kernelForm())); },
        R"doc(The form zcheck's kernels (the trace, the raster, the comparison) run in: "baseline",
"avx2" or "avx512" — the widest this processor has, or the one the environment variable
ZCHECK_KERNELS names (read when a render or comparison starts; a form the processor lacks, or
any other value, raises ValueError). Every form's results are bit-identical.)doc");
    m.def(
        "kernel_forms_supported",
        [] {
            std::vector<std::string> forms;
            for (KernelForm form : {KernelForm::Baseline, KernelForm::Avx2, KernelForm::Avx512})
                if (kernelFormSupported(form)) forms.push_back(nameOf(form));
            return forms;
        },
        "The kernel forms this processor can run, narrowest first (see kernel_form).");
}

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
    addConstants(m);
    // A class before the classes whose signatures name it.
    bindScene(m);
    bindCamera(m);
    bindReport(m);
    bindChecker(m);
    bindFunctions(m);
    m.attr("__name__") = "zcheck._zcheck";
}
