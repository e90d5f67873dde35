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

}  // namespace

Convention Convention::preset(const std::string& name)
{
    for (const auto& convention : presets())
        if (convention.name == name) return convention;
    throw Error("unknown convention '" + name + "' (expected one of " + joinedNames(presetNames()) + ")");
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
    throw Error("unknown depth format '" + name + "' (expected one of " + joinedNames(depthFormatNames()) + ")");
}

}  // namespace zcheck
