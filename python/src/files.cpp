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
    bindDatasets(m);
    m.def(
        "verify_file",
        [](const Checker& checker, const Camera& camera, const std::string& path, const std::string& quantityName,
           std::optional<std::string> channel, const py::object& miss, std::optional<double> scale,
           std::optional<double> offset, std::optional<std::string> sidecar, bool diagnose, std::optional<int> threads) {
            // Exactly `zcheck verify --depth-map PATH --quantity Q [--channel C] [--scale S]
            // [--offset O] [--miss M] [--diagnose]` (cli/verify.cpp).
            const DepthQuantity quantity = depthQuantityFromName(quantityName);
            DepthMapReading reading = readingOf(miss, scale, offset);
            reading.channel = channel ? *channel : "";
            reading.quantityChannel = channelNameOf(exportOf(quantity));
            if (sidecar) reading = withSidecar(reading, *sidecar);
            auto r = std::make_unique<PyReport>();
            r->verify = true;
            {
                py::gil_scoped_release release;
                const auto limit = threadLimit(threads);
                const DepthMapFile file = readDepthMap(path, reading, camera.width(), camera.height());
                const DepthMap map{file.width, file.height, quantity, file.value, file.valueQuantum};
                fillVerification(*r, verifyAndReport(checker, camera, map, {path, quantityName, file.channel, reading}, diagnose));
            }
            return r;
        },
        py::arg("checker"), py::arg("camera"), py::arg("path"), py::arg("quantity"), py::kw_only(),
        py::arg("channel") = py::none(), py::arg("miss") = py::none(), py::arg("scale") = py::none(),
        py::arg("offset") = py::none(), py::arg("sidecar") = py::none(), py::arg("diagnose") = false,
        py::arg("threads") = py::none(), R"doc(See zcheck.Checker.verify_file.)doc");

    m.def(
        "read_depth_map",
        [](const std::string& path, const Camera& camera, std::optional<std::string> quantity,
           std::optional<std::string> channel, const py::object& miss, std::optional<double> scale,
           std::optional<double> offset, std::optional<std::string> sidecar) {
            if (quantity && channel) fail("read_depth_map: give quantity or channel, not both");
            DepthMapReading reading = readingOf(miss, scale, offset);
            reading.channel = channel ? *channel : "";
            if (quantity) reading.quantityChannel = channelNameOf(exportOf(depthQuantityFromName(*quantity)));
            if (sidecar) reading = withSidecar(reading, *sidecar);
            DepthMapFile file;
            {
                py::gil_scoped_release release;
                file = readDepthMap(path, reading, camera.width(), camera.height());
            }
            return image(file.value, file.width, file.height);
        },
        py::arg("path"), py::arg("camera"), py::kw_only(), py::arg("quantity") = py::none(),
        py::arg("channel") = py::none(), py::arg("miss") = py::none(), py::arg("scale") = py::none(),
        py::arg("offset") = py::none(), py::arg("sidecar") = py::none(), R"doc(See zcheck.read_depth_map.)doc");
}
