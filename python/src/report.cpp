// zcheck.Report: a check's or a verification's report (checker.h, verify_map.h) with the JSON
// and summary the command prints for it, and its per-pixel images.
#include "bindings.h"

#include "zcheck/compare.h"

#include <pybind11/stl.h>

namespace zcheck::python {

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

// A Report property read from its comparison's summary (compare.h), by the field's pointer.
template <auto field>
auto fromComparison(const PyReport& r)
{
    return r.report.comparison.*field;
}

// A Report's per-pixel array (by the field's pointer) as an (H, W) image.
template <auto values>
auto pixelImage(const PyReport& r)
{
    return image(pixelsOf(r, r.*values), r.report.comparison.width, r.report.comparison.height);
}

// The per-pixel images, the diagnosis, the texts and the Python protocol.
void bindReportImagesAndTexts(py::class_<PyReport>& report)
{
    report
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
            &pixelImage<&PyReport::pixelClass>,
            "(H, W) uint8: each pixel's class, an index into zcheck.pixel_classes (row 0 at the top).")
        .def_property_readonly(
            "error_over_tolerance",
            &pixelImage<&PyReport::errorOverTolerance>,
            "(H, W) float32: |d_compared - d_ray| / tolerance where both hit, 0 elsewhere.")
        .def_property_readonly(
            "ray_window_depth",
            &pixelImage<&PyReport::rayWindowDepth>,
            "(H, W) float64: the ray route's exact window depth (the clear value where it misses).")
        .def_property_readonly(
            "compared_window_depth",
            &pixelImage<&PyReport::comparedWindowDepth>,
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
}

}  // namespace

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

void bindReport(py::module_& m)
{
    py::class_<PyReport> report(m, "Report", R"doc(The result of Checker.check or Checker.verify: pixel counts, depth errors, the
verdict, and per-pixel images. to_dict() is the document `zcheck check --json` (or `zcheck verify
--json`) prints for the same inputs.)doc");
    report
        .def_property_readonly(
            "consistent", [](const PyReport& r) { return r.report.comparison.consistent(); },
            "The verdict: no unexplained coverage mismatch, no depth error, no systematic bias.")
        .def_property_readonly("width", &fromComparison<&ComparisonReport::width>)
        .def_property_readonly("height", &fromComparison<&ComparisonReport::height>)
        .def_property_readonly("scene", [](const PyReport& r) { return r.report.scene; })
        .def_property_readonly("triangles", [](const PyReport& r) { return r.report.triangles; })
        .def_property_readonly(
            "camera", [](const PyReport& r) { return Camera(r.report.camera); }, "The camera both sides used.")
        .def_property_readonly("both_hit", &fromComparison<&ComparisonReport::bothHit>)
        .def_property_readonly("both_miss", &fromComparison<&ComparisonReport::bothMiss>)
        .def_property_readonly("ray_only", &fromComparison<&ComparisonReport::rayOnly>)
        .def_property_readonly("raster_only", &fromComparison<&ComparisonReport::rasterOnly>,
                               "Pixels only the raster route (or the verified map) covers.")
        .def_property_readonly("map_only", &fromComparison<&ComparisonReport::rasterOnly>,
                               "Pixels only the verified map covers (verify's name for raster_only).")
        .def_property_readonly("out_of_range", &fromComparison<&ComparisonReport::outOfRange>,
                               "Pixels of a verified map holding values its quantity cannot hold (window 2, a "
                               "negative eye-z): errors.")
        .def_property_readonly("agree", &fromComparison<&ComparisonReport::agree>)
        .def_property_readonly("edge_surface", &fromComparison<&ComparisonReport::edgeSurface>)
        .def_property_readonly("depth_errors", &fromComparison<&ComparisonReport::depthErrors>)
        .def_property_readonly("coverage_explained", &fromComparison<&ComparisonReport::coverageExplained>)
        .def_property_readonly("lost_at_clear_value", &fromComparison<&ComparisonReport::lostAtClearValue>)
        .def_property_readonly("at_clip_plane", &fromComparison<&ComparisonReport::atClipPlane>)
        .def_property_readonly("coverage_unexplained", &fromComparison<&ComparisonReport::coverageUnexplained>)
        .def_property_readonly(
            "unexplained", [](const PyReport& r) { return r.report.comparison.unexplained(); },
            "depth_errors + coverage_unexplained.")
        .def_property_readonly("max_error_quanta", &fromComparison<&ComparisonReport::maxErrorQuanta>)
        .def_property_readonly("p99_error_quanta", &fromComparison<&ComparisonReport::p99ErrorQuanta>)
        .def_property_readonly("max_error_over_tolerance", &fromComparison<&ComparisonReport::maxErrorOverTolerance>,
                               "max |d_compared - d_ray| / tolerance over compared pixels; <= 1 means within.")
        .def_property_readonly("max_relative_eye_z_error", &fromComparison<&ComparisonReport::maxRelativeEyeZError>)
        .def_property_readonly("p99_relative_eye_z_error", &fromComparison<&ComparisonReport::p99RelativeEyeZError>)
        .def_property_readonly("depth_bias", &fromComparison<&ComparisonReport::depthBias>)
        .def_property_readonly("mean_signed_error_quanta", &fromComparison<&ComparisonReport::meanSignedErrorQuanta>)
        .def_property_readonly("bias_samples", &fromComparison<&ComparisonReport::biasSamples>);
    bindReportImagesAndTexts(report);
}

}  // namespace zcheck::python
