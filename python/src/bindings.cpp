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

DepthMapReading readingOf(const py::object& miss, std::optional<double> scale, std::optional<double> offset)
{
    DepthMapReading reading;
    if (scale && !(std::isfinite(*scale) && *scale > 0))
        fail("scale must be a positive finite number, got " + formatNumber(*scale));
    if (offset && !std::isfinite(*offset)) fail("offset must be a finite number, got " + formatNumber(*offset));
    reading.scale = scale ? *scale : 0.0;
    reading.offset = offset ? *offset : 0.0;
    if (py::isinstance<py::str>(miss)) reading.miss = MissRule::parse(miss.cast<std::string>());
    else if (!miss.is_none()) reading.miss = MissRule::parse(formatNumber(miss.cast<double>()));
    return reading;
}

}  // namespace zcheck::python
