#pragma once
// What the two extension modules share: zcheck._zcheck (everything but image files) and
// zcheck._zcheck_files (depth-map files through OpenImageIO, imported on first use so that
// `import zcheck` does not pay OpenImageIO's start-up).
#include "zcheck/checker.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/error.h"
#include "zcheck/map_verifier.h"
#include "zcheck/quantity.h"
#include "zcheck/report.h"
#include "zcheck/verify_map.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace zcheck::python {

namespace py = pybind11;

// Raises zcheck.Error with `message`.
[[noreturn]] void fail(const std::string& message);
// At most N worker threads for one call (TBB's limit is process-wide while it lives); none: all.
std::unique_ptr<tbb::global_control> threadLimit(std::optional<int> threads);

// A keyword argument that must be None or a real number (a Python int or float, a NumPy scalar):
// anything else — a bool, a string, a list — is a zcheck.Error naming `name`.
std::optional<double> numberArgument(const py::object& value, const char* name);
// A keyword argument that must be None or a whole number of pixels: an int, or a float that is
// integral (instant-ngp writes "w": 640.0); 640.5, a bool or a string is a zcheck.Error naming `name`.
std::optional<int> sizeArgument(const py::object& value, const char* name);

// The keyword arguments a map is read with, as a reading (depth_map_reading.h), checked as the
// command line checks --miss, --scale, --offset, --quantum, --rel-tolerance, --abs-tolerance and
// --allow-holes; a wrong type or value is a zcheck.Error naming the argument. `miss` is None, a
// number, or a string ("65535", "nan", ">=1e9").
struct ReadingArguments {
    py::object miss = py::none(), scale = py::none(), offset = py::none();
    py::object quantum = py::none(), relTolerance = py::none(), absTolerance = py::none(), allowHoles = py::none();
};
DepthMapReading readingOf(const ReadingArguments& arguments);
// The quantity argument: a required depth quantity's name (a zcheck.Error when None or not one).
DepthQuantity quantityArgument(const py::object& quantity, std::string& name);

// zcheck.Checker: a Checker and, beside it, the MapVerifier that its verify, verify_file and
// diagnose share (map_verifier.h: the neighbour index is built once per Checker, not per map).
struct PyChecker {
    explicit PyChecker(Scene scene) : checker(std::move(scene)), verifier(checker) {}
    const Checker checker;
    const MapVerifier verifier;
};

// zcheck.Report: the result of Checker.check, Checker.verify or Checker.verify_file.
struct PyReport {
    CheckReport report;
    bool verify = false;
    std::string json;     // exactly what `zcheck check --json` / `zcheck verify --json` prints
    std::string summary;  // exactly what they print without --json
    bool pixelsKept = true;  // Checker.check(..., keep_pixels=False) keeps none: the arrays refuse
    std::vector<std::uint8_t> pixelClass;
    LargeVector<float> errorOverTolerance;
    LargeVector<double> rayWindowDepth, comparedWindowDepth;
    std::optional<std::vector<Hypothesis>> diagnosis;
};
void fillComparison(PyReport& r, const Comparison& c, const RenderResult& ray, const RenderResult& compared);
// A verification (verifyMap, verify_map.h) as a Report, its JSON and summary formatted as
// `zcheck verify` formats them (formatVerification, report.h): verify and verify_file share it.
void fillVerification(PyReport& r, VerifiedMap verified, const DepthMapSource& source);

// Pickling (pickling.cpp): each class's state as plain Python values, and back.
py::tuple cameraState(const Camera& camera);
Camera cameraFromState(const py::tuple& state);
py::tuple sceneState(const Scene& scene);
Scene sceneFromState(const py::tuple& state);
py::tuple reportState(const PyReport& report);
PyReport reportFromState(const py::tuple& state);

// zcheck._zcheck_files's datasets (dataset.cpp), adapted for zcheck/dataset.py.
void bindDatasets(py::module_& m);

// An (height, width) array of `values` (row 0 at the top).
template <class T, class Allocator>
py::array_t<T> image(const std::vector<T, Allocator>& values, int width, int height)
{
    py::array_t<T> out({py::ssize_t(height), py::ssize_t(width)});
    std::copy(values.begin(), values.end(), out.mutable_data());
    return out;
}

}  // namespace zcheck::python
