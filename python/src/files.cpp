// zcheck._zcheck_files: depth-map files (OpenImageIO). zcheck/__init__.py imports it on first
// use of read_depth_map or Checker.verify_file, so that `import zcheck` stays fast.
#include "bindings.h"

#include "zcheck/image_io.h"
#include "zcheck/report.h"

#include <pybind11/stl.h>

#include <cmath>

namespace py = pybind11;
using namespace zcheck;
using namespace zcheck::python;

PYBIND11_MODULE(_zcheck_files, m)
{
    m.doc() = "Depth-map files for zcheck (OpenImageIO); use zcheck.read_depth_map and Checker.verify_file.";
    py::module_::import("zcheck._zcheck");  // Checker, Camera and Report are registered there
    m.def(
        "verify_file",
        [](const Checker& checker, const Camera& camera, const std::string& path, const std::string& quantityName,
           std::optional<double> scale, bool diagnose, std::optional<int> threads) {
            // Exactly `zcheck verify --depth-map PATH --quantity Q [--scale S] [--diagnose]`
            // (cli/verify.cpp): the quantity's channel, the file's own storage quantum.
            const DepthQuantity quantity = depthQuantityFromName(quantityName);
            if (scale && !(std::isfinite(*scale) && *scale > 0))
                fail("scale must be a positive finite number, got " + formatNumber(*scale));
            const double s = scale ? *scale : 0.0;
            auto r = std::make_unique<PyReport>();
            r->verify = true;
            {
                py::gil_scoped_release release;
                const auto limit = threadLimit(threads);
                const DepthMapFile file =
                    readDepthMap(path, channelNameOf(exportOf(quantity)), s, camera.width(), camera.height());
                const DepthMap map{file.width, file.height, quantity, file.value, file.valueQuantum};
                VerifyOutcome verified =
                    verifyAndReport(checker, camera, map, {path, quantityName, file.channel, s}, diagnose);
                const VerifyResult& run = verified.run;
                r->report = run.report;
                r->json = std::move(verified.json);
                r->summary = std::move(verified.summary);
                if (verified.diagnosed) r->diagnosis = std::move(verified.diagnosis);
                fillComparison(*r, run.comparison, run.truth, run.map);
            }
            return r;
        },
        py::arg("checker"), py::arg("camera"), py::arg("path"), py::arg("quantity"), py::kw_only(), py::arg("scale") = py::none(),
        py::arg("diagnose") = false, py::arg("threads") = py::none(),
        R"doc(A depth map file against the ground truth, exactly as `zcheck verify --depth-map PATH --quantity Q
[--scale S] [--diagnose]` does it: EXR, PFM, TIFF or 16-bit PNG (scale required: value = stored /
scale, 0 = miss), the quantity's channel (window, ndc, Z, distance) or else the first, and the
file's storage quantum (1/scale for integer files, binary32's own step for float files). to_dict() equals `zcheck verify --json`'s
document but for timings.)doc");

    m.def(
        "read_depth_map",
        [](const std::string& path, const Camera& camera, std::optional<std::string> quantity,
           std::optional<std::string> channel, std::optional<double> scale) {
            if (quantity && channel) fail("read_depth_map: give quantity or channel, not both");
            const std::string preferred =
                channel ? *channel : quantity ? channelNameOf(exportOf(depthQuantityFromName(*quantity))) : std::string();
            if (scale && !(std::isfinite(*scale) && *scale > 0))
                fail("scale must be a positive finite number, got " + formatNumber(*scale));
            DepthMapFile file;
            {
                py::gil_scoped_release release;
                file = readDepthMap(path, preferred, scale ? *scale : 0.0, camera.width(), camera.height());
            }
            if (channel && file.channel != *channel)
                fail("depth map '" + path + "' has no channel '" + *channel + "' (the first channel is '" + file.channel +
                     "')");
            return image(file.value, file.width, file.height);
        },
        py::arg("path"), py::arg("camera"), py::kw_only(), py::arg("quantity") = py::none(),
        py::arg("channel") = py::none(), py::arg("scale") = py::none(),
        R"doc(Read a depth map file as `zcheck verify` and `zcheck unproject` do: EXR, PFM, TIFF, or a 16-bit
PNG with scale (value = stored / scale, 0 = miss -> NaN), told apart by their first bytes. Returns
an (H, W) float64 array, row 0 at the top (PFM's bottom-to-top rows are flipped).

camera:   the map must have the camera's size.
quantity: read that quantity's channel if the file has it (window, ndc, Z for eye-z, distance),
          else the first channel, as the command line does; or
channel:  read exactly this channel (an error if the file has none of that name).
scale:    stored value = depth x scale; float files are divided by it.)doc");
}
