#include "zcheck/convention.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

namespace {

const std::vector<Convention>& presets()
{
    //                       name        fwdZ upY  ndc depth                         ndcUpY top   rowVec
    static const std::vector<Convention> all = {
        {"opengl",   -1, +1, NdcDepthRange::MinusOneToOne, +1, false, false},
        {"direct3d", +1, +1, NdcDepthRange::ZeroToOne,     +1, true,  true},
        {"vulkan",   -1, +1, NdcDepthRange::ZeroToOne,     -1, true,  false},
        {"metal",    -1, +1, NdcDepthRange::ZeroToOne,     +1, true,  false},
        {"opencv",   +1, -1, NdcDepthRange::ZeroToOne,     -1, true,  false},
    };
    return all;
}

std::string joined(const std::vector<std::string>& names)
{
    std::string text;
    for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
    return text;
}

}  // namespace

Convention Convention::preset(const std::string& name)
{
    for (const auto& convention : presets())
        if (convention.name == name) return convention;
    throw Error("unknown convention '" + name + "' (expected one of " + joined(presetNames()) + ")");
}

const std::vector<std::string>& Convention::presetNames()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> all;
        for (const auto& convention : presets()) all.push_back(convention.name);
        return all;
    }();
    return names;
}

std::string toString(DepthFormat format)
{
    switch (format) {
    case DepthFormat::Float32: return "float32";
    case DepthFormat::Unorm24: return "unorm24";
    case DepthFormat::Unorm16: return "unorm16";
    }
    return "?";
}

const std::vector<std::string>& depthFormatNames()
{
    static const std::vector<std::string> names = {"float32", "unorm24", "unorm16"};
    return names;
}

DepthFormat depthFormatFromName(const std::string& name)
{
    for (DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24, DepthFormat::Unorm16})
        if (toString(format) == name) return format;
    throw Error("unknown depth format '" + name + "' (expected one of " + joined(depthFormatNames()) + ")");
}

namespace {
double unormMax(DepthFormat format)
{
    return format == DepthFormat::Unorm24 ? 16777215.0 : 65535.0;
}
}  // namespace

double quantizeDepth(DepthFormat format, double windowDepth)
{
    if (format == DepthFormat::Float32) return static_cast<double>(static_cast<float>(windowDepth));
    const double maxCode = unormMax(format);
    const double code = std::nearbyint(std::clamp(windowDepth, 0.0, 1.0) * maxCode);
    return code / maxCode;
}

double storageQuantum(DepthFormat format, double windowDepth)
{
    if (format != DepthFormat::Float32) return 1.0 / unormMax(format);
    const float magnitude = std::fabs(static_cast<float>(windowDepth));
    return static_cast<double>(std::nextafter(magnitude, INFINITY)) - static_cast<double>(magnitude);
}

}  // namespace zcheck
