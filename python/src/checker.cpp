// zcheck.Checker: one scene with both routes built once (checker.h), and every question about
// it: check, render, and a map rendered elsewhere verified and diagnosed (map_verifier.h,
// verify_map.h). Each releases the GIL while the library works.
#include "bindings.h"

#include <pybind11/stl.h>

#include <optional>
#include <string>

namespace zcheck::python {

namespace {

std::unique_ptr<PyReport> check(const PyChecker& self, std::optional<Camera> camera, std::optional<int> threads,
                                bool keepPixels)
{
    auto r = std::make_unique<PyReport>();
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
    return r;
}

py::array render(const PyChecker& self, const Camera& camera, const std::string& quantityName, const std::string& routeName,
                 py::object dtype, std::optional<int> threads)
{
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
}

// A map given as an array with its quantity and the keyword arguments it is read with.
struct MapArgument {
    std::string quantityName;
    DepthMapReading reading;
    DepthMap map;
};
MapArgument mapArgument(const Camera& camera, const py::object& depth, const py::object& quantity,
                        const ReadingArguments& arguments)
{
    MapArgument out;
    const DepthQuantity q = quantityArgument(quantity, out.quantityName);
    out.reading = readingOf(arguments);
    out.map = mapFromArray(depth, camera, out.reading, q);
    return out;
}

std::unique_ptr<PyReport> verify(const PyChecker& self, const Camera& camera, py::object depth, const py::object& quantity,
                                 const py::object& miss, const py::object& scale, const py::object& offset,
                                 const py::object& quantum, const py::object& relTolerance, const py::object& absTolerance,
                                 const py::object& allowHoles, const py::object& noiseModel, bool diagnose,
                                 std::optional<int> threads)
{
    const MapArgument given =
        mapArgument(camera, depth, quantity, {miss, scale, offset, quantum, relTolerance, absTolerance, allowHoles, noiseModel});
    auto r = std::make_unique<PyReport>();
    r->verify = true;
    py::gil_scoped_release release;
    const auto limit = threadLimit(threads);
    const DepthMapSource source{"<array>", given.quantityName, "", given.reading};
    fillVerification(*r, verifyMap(self.verifier, camera, given.map, diagnose, source.name()), source);
    return r;
}

py::list diagnose(const PyChecker& self, const Camera& camera, py::object depth, const py::object& quantity,
                  const py::object& miss, const py::object& scale, const py::object& offset, const py::object& quantum,
                  const py::object& relTolerance, const py::object& absTolerance, const py::object& allowHoles,
                  const py::object& noiseModel, std::optional<int> threads)
{
    const MapArgument given =
        mapArgument(camera, depth, quantity, {miss, scale, offset, quantum, relTolerance, absTolerance, allowHoles, noiseModel});
    std::vector<Hypothesis> hypotheses;
    {
        py::gil_scoped_release release;
        const auto limit = threadLimit(threads);
        hypotheses = self.verifier.diagnose(camera, given.map);
    }
    return diagnosisList(hypotheses);
}

// Checker.verify and Checker.diagnose: a map rendered elsewhere, given as an array.
void bindMapQuestions(py::class_<PyChecker>& checker)
{
    checker
        .def("verify", &verify, py::arg("camera"), py::arg("depth"), py::arg("quantity") = py::none(), py::kw_only(),
             py::arg("miss") = py::none(), py::arg("scale") = py::none(), py::arg("offset") = py::none(),
             py::arg("quantum") = py::none(), py::arg("rel_tolerance") = py::none(), py::arg("abs_tolerance") = py::none(),
             py::arg("allow_holes") = py::none(), py::arg("noise_model") = py::none(), py::arg("diagnose") = false,
             py::arg("threads") = py::none(),
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
          report.to_dict()["pixels"]["holes"], not a failure (at most half of the surface).
noise_model: a sensor's noise σ(z), z the map's value: "kinect", "A+B*z^2" or "A+B*(z-C)^2"
          (map units); each pixel may be off by 6σ(z).
What is declared absorbs rounding and noise, never a systematic error: the map's mean error must
stay unbiased, a quantum must be the values' grid, and the accuracy under a tenth of the depth
(docs/verify.md); a map that fails is inconsistent, to_dict()["declared_accuracy_refused"] says why.
diagnose: when inconsistent, also run diagnose() and put it in the report (`--diagnose`).
Returns a Report whose to_dict() is `zcheck verify --json`'s document (depth_map.file "<array>").)doc")
        .def("diagnose", &diagnose, py::arg("camera"), py::arg("depth"), py::arg("quantity") = py::none(), py::kw_only(),
             py::arg("miss") = py::none(), py::arg("scale") = py::none(), py::arg("offset") = py::none(),
             py::arg("quantum") = py::none(), py::arg("rel_tolerance") = py::none(), py::arg("abs_tolerance") = py::none(),
             py::arg("allow_holes") = py::none(), py::arg("noise_model") = py::none(), py::arg("threads") = py::none(),
             R"doc(Every hypothesis of the mistake catalogue that applies to this camera and map, then every
fitted family (sample-offset, field-of-view, near-far, depth-scale, intrinsics, pose), ranked:
consistent ones first, then by unexplained pixels. Dicts {hypothesis, variant, explanation,
consistent, unexplained, unexplained_estimated, fitted}; `fitted` lists a fit's measured
parameters as {name, value, declared} (e.g. fovy_deg, sample_dx_px, near, value_scale) and
its median relative depth residual ("residual": fitted vs declared camera). The consistent
ones name what explains the map (e.g. "y-flip", "distance-as-eye-z", "sample-offset").
Arguments as for verify().)doc");
}

}  // namespace

void bindChecker(py::module_& m)
{
    py::class_<PyChecker> checker(m, "Checker", R"doc(One scene with both routes built once (Embree's BVH and the rasterizer), and every
question zcheck answers about it. Immutable and thread-safe: its methods release the GIL and may be
called from several Python threads at once.)doc");
    checker
        .def(py::init([](const Scene& scene, std::optional<double> expectedRays) {
                 if (expectedRays && !(*expectedRays >= 0))
                     throw Error("expected_rays " + std::to_string(*expectedRays) + " must be a count of rays, >= 0");
                 const BvhBuild build = expectedRays ? bvhBuildFor(*expectedRays, scene.triangleCount()) : BvhBuild::Thorough;
                 Scene copy = scene;
                 py::gil_scoped_release release;
                 return std::make_unique<PyChecker>(std::move(copy), build);
             }),
             py::arg("scene"), py::kw_only(), py::arg("expected_rays") = py::none(),
             R"doc(Validates the scene and builds both routes (the scene is copied). expected_rays: how many rays
all the checks and renders of this Checker will trace together (e.g. width * height for one
frame); below 10 per triangle the BVH is built quickly (Embree's LOW quality, compact: ~4x faster
to build, ~1.3-1.5x slower to trace), else, and by default (None: many frames), thoroughly.
Results are the same either way.)doc")
        .def_property_readonly(
            "bvh_build", [](const PyChecker& self) { return std::string(nameOf(self.checker.rayRenderer().bvhBuild())); },
            "\"quick\" or \"thorough\": how the BVH was built (see expected_rays).")
        .def_property_readonly(
            "scene", [](const PyChecker& self) -> const Scene& { return self.checker.scene(); },
            py::return_value_policy::reference_internal)
        .def("check", &check, py::arg("camera") = py::none(), py::arg("threads") = py::none(),
             py::arg("keep_pixels") = true,
             R"doc(Both routes through `camera` (default: the scene's own camera), compared per pixel: what
`zcheck check` does. Returns a Report. Raises zcheck.Error "nothing to compare" when neither route
sees any surface, as the command does. threads: at most this many worker threads (1..1024).
keep_pixels=False: the check is drawn, traced and compared tile by tile and keeps no per-pixel
array (the same report, faster, ~60 MB less memory at 1080p: for checking many cameras); the
Report's pixel_classes, error_over_tolerance, ray_window_depth and compared_window_depth then
raise zcheck.Error.)doc")
        .def("render", &render, py::arg("camera"), py::arg("quantity"), py::arg("route") = "ray",
             py::arg("dtype") = "float32", py::arg("threads") = py::none(),
             R"doc(One route's render as an image (row 0 at the top), what `zcheck export` writes:

quantity: "window", "ndc", "eye-z", "distance"  -> (H, W) float
          "position-eye", "position-world", "normal" -> (H, W, 3) float
          "primitive-id"                             -> (H, W) uint32 (triangle index)
route:    "ray" (exact hits, double precision) or "raster" (the z-buffer's stored values;
          positions unprojected from them).
dtype:    float32 (as files store it) or float64 (the ray route's double values unrounded).
Misses hold the quantity's miss value: the clear value (window), NDC z of the far plane (ndc),
+inf (eye-z, distance), NaN (positions, normals), 0xFFFFFFFF (primitive-id).)doc")
        .def("__repr__", [](const PyChecker& self) {
            const Scene& scene = self.checker.scene();
            return "<zcheck.Checker scene '" + scene.name + "', " + std::to_string(scene.triangleCount()) + " triangles>";
        });
    bindMapQuestions(checker);
}

}  // namespace zcheck::python
