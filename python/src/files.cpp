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
        [](const PyChecker& self, const Camera& camera, const std::string& path, const py::object& quantityArg,
           std::optional<std::string> channel, const py::object& miss, const py::object& scale, const py::object& offset,
           std::optional<std::string> sidecar, const py::object& quantum, const py::object& relTolerance,
           const py::object& absTolerance, const py::object& allowHoles, const py::object& noiseModel, bool diagnose,
           std::optional<int> threads) {
            // Exactly `zcheck verify --depth-map PATH --quantity Q [--channel C] [--scale S]
            // [--offset O] [--miss M] [--quantum Q] [--rel-tolerance R] [--abs-tolerance A]
            // [--allow-holes] [--noise-model M] [--diagnose]` (cli/verify.cpp).
            std::string quantityName;
            const DepthQuantity quantity = quantityArgument(quantityArg, quantityName);
            DepthMapReading reading = readingOf({miss, scale, offset, quantum, relTolerance, absTolerance, allowHoles, noiseModel});
            reading.channel = channel ? *channel : "";
            reading.quantityChannel = channelNameOf(exportQuantityOf(quantity));
            if (sidecar) reading = withSidecar(reading, *sidecar);
            auto r = std::make_unique<PyReport>();
            r->verify = true;
            {
                py::gil_scoped_release release;
                const auto limit = threadLimit(threads);
                const DepthMapFile file = readDepthMap(path, reading, camera.width(), camera.height());
                const DepthMap map = DepthMap::of(file, quantity, reading);
                const DepthMapSource source{path, quantityName, file.channel, reading};
                fillVerification(*r, verifyMap(self.verifier, camera, map, diagnose, source.name()), source);
            }
            return r;
        },
        py::arg("checker"), py::arg("camera"), py::arg("path"), py::arg("quantity") = py::none(), py::kw_only(),
        py::arg("channel") = py::none(), py::arg("miss") = py::none(), py::arg("scale") = py::none(),
        py::arg("offset") = py::none(), py::arg("sidecar") = py::none(), py::arg("quantum") = py::none(),
        py::arg("rel_tolerance") = py::none(), py::arg("abs_tolerance") = py::none(), py::arg("allow_holes") = py::none(),
        py::arg("noise_model") = py::none(), py::arg("diagnose") = false,
        py::arg("threads") = py::none(), R"doc(See zcheck.Checker.verify_file.)doc");

    m.def(
        "read_depth_map",
        [](const std::string& path, const Camera& camera, std::optional<std::string> quantity,
           std::optional<std::string> channel, const py::object& miss, const py::object& scale, const py::object& offset,
           std::optional<std::string> sidecar) {
            if (quantity && channel) fail("read_depth_map: give quantity or channel, not both");
            ReadingArguments arguments;
            arguments.miss = miss, arguments.scale = scale, arguments.offset = offset;
            DepthMapReading reading = readingOf(arguments);
            reading.channel = channel ? *channel : "";
            if (quantity) reading.quantityChannel = channelNameOf(exportQuantityOf(depthQuantityFromName(*quantity)));
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
