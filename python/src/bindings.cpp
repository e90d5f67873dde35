#include "bindings.h"

namespace zcheck::python {

void fail(const std::string& message) { throw Error(message); }

ExportQuantity exportOf(DepthQuantity q)
{
    switch (q) {
    case DepthQuantity::Window: return ExportQuantity::Window;
    case DepthQuantity::Ndc: return ExportQuantity::Ndc;
    case DepthQuantity::EyeZ: return ExportQuantity::EyeZ;
    case DepthQuantity::Distance: return ExportQuantity::Distance;
    }
    return ExportQuantity::Window;
}

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

void fillVerification(PyReport& r, VerifyOutcome verified)
{
    r.verify = true;
    r.report = verified.run.report;
    r.json = std::move(verified.json);
    r.summary = std::move(verified.summary);
    if (verified.diagnosed) r.diagnosis = std::move(verified.diagnosis);
    fillComparison(r, verified.run.comparison, verified.run.truth, verified.run.map);
}

std::optional<double> numberArgument(const py::object& value, const char* name)
{
    if (value.is_none()) return std::nullopt;
    const bool number = !py::isinstance<py::bool_>(value) && !py::isinstance<py::str>(value) &&
                        (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value) ||
                         py::hasattr(value, "__float__"));
    if (number && !py::isinstance<py::array>(value)) {
        try {
            return py::float_(value).cast<double>();
        } catch (const py::error_already_set&) {
        }
    }
    fail(std::string(name) + " must be a number, got " + std::string(py::str(py::type::of(value).attr("__name__"))));
}

DepthMapReading readingOf(const ReadingArguments& a)
{
    DepthMapReading reading;
    const std::optional<double> scale = numberArgument(a.scale, "scale"), offset = numberArgument(a.offset, "offset");
    if (scale && !(std::isfinite(*scale) && *scale > 0))
        fail("scale must be a positive finite number, got " + formatNumber(*scale));
    if (offset && !std::isfinite(*offset)) fail("offset must be a finite number, got " + formatNumber(*offset));
    reading.scale = scale ? *scale : 0.0;
    reading.offset = offset ? *offset : 0.0;
    if (py::isinstance<py::str>(a.miss)) {
        reading.miss = MissRule::parse(a.miss.cast<std::string>());
    } else if (!a.miss.is_none()) {
        if (py::isinstance<py::bool_>(a.miss) || !(py::isinstance<py::float_>(a.miss) || py::isinstance<py::int_>(a.miss) ||
                                                   py::hasattr(a.miss, "__float__")))
            fail("miss must be a number or a rule such as '>=1e9', got " +
                 std::string(py::str(py::type::of(a.miss).attr("__name__"))) + " (one miss value or rule per map)");
        reading.miss = MissRule::parse(formatNumber(*numberArgument(a.miss, "miss")));
    }
    MapAccuracy& d = reading.accuracy;
    d.quantum = numberArgument(a.quantum, "quantum").value_or(0.0);
    d.relative = numberArgument(a.relTolerance, "rel_tolerance").value_or(0.0);
    d.absolute = numberArgument(a.absTolerance, "abs_tolerance").value_or(0.0);
    if (!a.allowHoles.is_none()) {
        if (!py::isinstance<py::bool_>(a.allowHoles)) fail("allow_holes must be True or False");
        d.allowHoles = a.allowHoles.cast<bool>();
    }
    try {
        d.require("the declared accuracy");
    } catch (const Error&) {
        auto bad = [](const char* name, double v) {
            fail(std::string(name) + " must be a finite number >= 0" + (std::string(name) == "rel_tolerance" ? " and below 1" : "") +
                 ", got " + formatNumber(v));
        };
        if (!(d.quantum >= 0) || !std::isfinite(d.quantum)) bad("quantum", d.quantum);
        if (!(d.absolute >= 0) || !std::isfinite(d.absolute)) bad("abs_tolerance", d.absolute);
        bad("rel_tolerance", d.relative);
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
