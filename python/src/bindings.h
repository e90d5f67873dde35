#pragma once
// The binding helpers the files of python/src share. Each file binds one class as an adapter
// (scene.cpp, camera.cpp with camera_factories.cpp, report.cpp, checker.cpp; dataset.cpp and
// files.cpp in zcheck._zcheck_files) and module.cpp declares zcheck._zcheck and calls them.
// The rules — what a valid pose, camera, scene or reading is — are the C++ libraries'; these
// helpers only turn Python values into theirs and back, naming the caller's arguments.
//
// Two extension modules: zcheck._zcheck (everything but image files) and zcheck._zcheck_files
// (depth-map files through OpenImageIO, imported on first use so that `import zcheck` does not
// pay OpenImageIO's start-up). bindings.cpp is compiled into both; arrays.cpp into _zcheck.
#include "zcheck/checker.h"
#include "zcheck/depth_map.h"
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

// ---- each file's binding (module.cpp calls them in this order: a class before its users)
void bindScene(py::module_& m);     // scene.cpp: zcheck.Scene
void bindCamera(py::module_& m);    // camera.cpp: zcheck.Camera
void bindCameraFactories(py::class_<Camera>& camera);  // camera_factories.cpp: its from_* and replace
void bindReport(py::module_& m);    // report.cpp: zcheck.Report
void bindChecker(py::module_& m);   // checker.cpp: zcheck.Checker
void bindDatasets(py::module_& m);  // dataset.cpp, in _zcheck_files: zcheck/dataset.py's _Dataset

// ---- errors and arguments (bindings.cpp)

// Raises zcheck.Error with `message`.
[[noreturn]] void fail(const std::string& message);
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
// At most N worker threads for one call (TBB's limit is process-wide while it lives); none: all.
std::unique_ptr<tbb::global_control> threadLimit(std::optional<int> threads);
// json.loads(text): the dict of a JSON document the library wrote as text.
py::object jsonLoads(const std::string& text);

// A keyword argument that must be None or a real number (a Python int or float, a NumPy scalar):
// anything else — a bool, a string, a list — is a zcheck.Error naming `name`.
std::optional<double> numberArgument(const py::object& value, const char* name);
// A keyword argument that must be None or a whole number of pixels: an int, or a float that is
// integral (instant-ngp writes "w": 640.0); 640.5, a bool or a string is a zcheck.Error naming `name`.
std::optional<int> sizeArgument(const py::object& value, const char* name);

// The keyword arguments a map is read with, as a reading (depth_map_reading.h), checked as the
// command line checks --miss, --scale, --offset, --quantum, --rel-tolerance, --abs-tolerance,
// --allow-holes and --noise-model; a wrong type or value is a zcheck.Error naming the argument. `miss` is None, a
// number, or a string ("65535", "nan", ">=1e9").
struct ReadingArguments {
    py::object miss = py::none(), scale = py::none(), offset = py::none();
    py::object quantum = py::none(), relTolerance = py::none(), absTolerance = py::none(), allowHoles = py::none();
    py::object noiseModel = py::none();  // a string: NoiseModel::parse's forms
};
DepthMapReading readingOf(const ReadingArguments& arguments);
// The quantity argument: a required depth quantity's name (a zcheck.Error when None or not one).
DepthQuantity quantityArgument(const py::object& quantity, std::string& name);

// ---- numpy arrays (arrays.cpp, _zcheck only)

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
std::string shapeText(const py::array& a);  // "(120, 160)", "(3,)"
std::string dtypeText(const py::array& a);  // "float64"
// Any array-like of numbers (float, signed or unsigned integer); `what` names the argument.
py::array numericArray(py::handle object, const std::string& what);
DoubleArray asDoubles(const py::array& a);
// A 4×4 (or, with `allow3x4`, 3×4 [R|t]) matrix written for column vectors, M[r, c]; a 4×4 pose
// must have the last row 0 0 0 1 (pose.h's hasRigidLastRow).
glm::dmat4 matrixFromArray(py::handle object, const std::string& what, bool allow3x4);
py::array_t<double> arrayFromMatrix(const glm::dmat4& m);  // 4×4, M[r, c]
py::array_t<double> arrayFromVec3(const glm::dvec3& p);
// `depth` (height × width, any float or integer dtype) as the map verify and unproject take,
// its values read as a file's are (depthsFromStored): integer arrays need a scale.
DepthMap mapFromArray(py::handle depth, const Camera& camera, const DepthMapReading& reading, DepthQuantity quantity);

// An (height, width) array of `values` (row 0 at the top).
template <class T, class Allocator>
py::array_t<T> image(const std::vector<T, Allocator>& values, int width, int height)
{
    py::array_t<T> out({py::ssize_t(height), py::ssize_t(width)});
    std::copy(values.begin(), values.end(), out.mutable_data());
    return out;
}

// ---- the classes' state shared between files

// zcheck.Checker: a Checker and, beside it, the MapVerifier that its verify, verify_file and
// diagnose share (map_verifier.h: the neighbour index is built once per Checker, not per map).
struct PyChecker {
    explicit PyChecker(Scene scene, BvhBuild build = BvhBuild::Thorough) : checker(std::move(scene), build), verifier(checker) {}
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
// Checker.diagnose's list of dicts, and Report.diagnosis's (report.cpp).
py::list diagnosisList(const std::vector<Hypothesis>& hypotheses);

// A camera built and validated; a refusal is prefixed with `where` (the factory's name).
Camera makeCamera(const CameraSpec& spec, const std::string& where);

// Pickling (pickling.cpp): each class's state as plain Python values, and back.
py::tuple cameraState(const Camera& camera);
Camera cameraFromState(const py::tuple& state);
py::tuple sceneState(const Scene& scene);
Scene sceneFromState(const py::tuple& state);
py::tuple reportState(const PyReport& report);
PyReport reportFromState(const py::tuple& state);

}  // namespace zcheck::python
