// What both extension modules use: errors, arguments, thread limits, and filling a Report.
#include "bindings.h"

#include <cmath>

namespace zcheck::python {

void fail(const std::string& message) { throw Error(message); }

py::object jsonLoads(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

std::unique_ptr<tbb::global_control> threadLimit(std::optional<int> threads)
{
    if (!threads) return nullptr;
    if (*threads < 1 || *threads > 1024) fail("threads must be in 1..1024, got " + std::to_string(*threads));
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(*threads));
}

void fillComparison(PyReport& r, const Comparison& c, const RenderResult& ray, const RenderResult& compared)
{
    r.pixelClass.resize(c.pixelClass.size());
    for (std::size_t i = 0; i < c.pixelClass.size(); ++i) r.pixelClass[i] = std::uint8_t(c.pixelClass[i]);
    r.errorOverTolerance = c.errorOverTolerance;
    r.rayWindowDepth = ray.windowDepth.value;
    r.comparedWindowDepth = compared.windowDepth.value;
}

void fillVerification(PyReport& r, VerifiedMap verified, const DepthMapSource& source)
{
    VerificationReport formatted = formatVerification(verified, source);
    r.verify = true;
    r.report = verified.run.report;
    r.json = std::move(formatted.json);
    r.summary = std::move(formatted.summary);
    if (verified.diagnosed) r.diagnosis = std::move(verified.diagnosis);
    fillComparison(r, verified.run.comparison, verified.run.truth, verified.run.map);
}

namespace {

// A Python int or float or a NumPy scalar, not a bool, a string or an array.
bool isRealNumber(const py::object& value)
{
    return !py::isinstance<py::bool_>(value) && !py::isinstance<py::str>(value) && !py::isinstance<py::array>(value) &&
           (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value) || py::hasattr(value, "__float__"));
}

std::string typeName(const py::object& value) { return py::str(py::type::of(value).attr("__name__")); }

}  // namespace

std::optional<double> numberArgument(const py::object& value, const char* name)
{
    if (value.is_none()) return std::nullopt;
    if (isRealNumber(value)) {
        try {
            return py::float_(value).cast<double>();
        } catch (const py::error_already_set&) {
        }
    }
    fail(std::string(name) + " must be a number, got " + typeName(value));
}

std::optional<int> sizeArgument(const py::object& value, const char* name)
{
    const std::optional<double> v = numberArgument(value, name);
    if (!v) return std::nullopt;
    if (!(*v == std::floor(*v)) || !(std::abs(*v) <= 1e9))
        fail(std::string(name) + " must be a whole number of pixels, got " + formatNumber(*v));
    return int(*v);
}

DepthMapReading readingOf(const ReadingArguments& a)
{
    DepthMapReading reading;
    const std::optional<double> scale = numberArgument(a.scale, "scale"), offset = numberArgument(a.offset, "offset");
    if (scale) DepthMapReading::requireScale(*scale, "scale");
    if (offset) DepthMapReading::requireOffset(*offset, "offset");
    reading.scale = scale ? *scale : 0.0;
    reading.offset = offset;
    if (py::isinstance<py::str>(a.miss)) {
        reading.miss = MissRule::parse(a.miss.cast<std::string>());
    } else if (!a.miss.is_none()) {
        if (!isRealNumber(a.miss))
            fail("miss must be a number or a rule such as '>=1e9', got " + typeName(a.miss) +
                 " (one miss value or rule per map)");
        reading.miss = MissRule::parse(formatNumber(*numberArgument(a.miss, "miss")));
    }
    // What the map declares, by the library's rule (MapAccuracy::requireDeclared), named as its argument.
    auto declared = [](const py::object& value, const char* name, bool relative) {
        return MapAccuracy::requireDeclared(numberArgument(value, name).value_or(0.0), name, relative);
    };
    MapAccuracy& d = reading.accuracy;
    d.quantum = declared(a.quantum, "quantum", false);
    d.relative = declared(a.relTolerance, "rel_tolerance", true);
    d.absolute = declared(a.absTolerance, "abs_tolerance", false);
    if (!a.noiseModel.is_none()) {
        if (!py::isinstance<py::str>(a.noiseModel))
            fail("noise_model must be a string: \"kinect\", \"A+B*z^2\" or \"A+B*(z-C)^2\"");
        d.noise = NoiseModel::parse(a.noiseModel.cast<std::string>(), "noise_model");
    }
    if (!a.allowHoles.is_none()) {
        if (!py::isinstance<py::bool_>(a.allowHoles)) fail("allow_holes must be True or False");
        d.allowHoles = a.allowHoles.cast<bool>();
    }
    return reading;
}

DepthQuantity quantityArgument(const py::object& quantity, std::string& name)
{
    if (quantity.is_none())
        fail("quantity is required: what the map holds, \"window\", \"ndc\", \"eye-z\" or \"distance\" (mixing them up is "
             "a mistake zcheck exists to catch)");
    if (!py::isinstance<py::str>(quantity))
        fail("quantity must be a string (\"window\", \"ndc\", \"eye-z\" or \"distance\"), got " +
             std::string(py::str(py::type::of(quantity).attr("__name__"))));
    name = quantity.cast<std::string>();
    return depthQuantityFromName(name);
}

}  // namespace zcheck::python
