#include "zcheck/quantity.h"

#include "zcheck/error.h"

#include <cmath>

namespace zcheck {

std::string toString(DepthQuantity quantity)
{
    switch (quantity) {
    case DepthQuantity::Window: return "window";
    case DepthQuantity::Ndc: return "ndc";
    case DepthQuantity::EyeZ: return "eye-z";
    case DepthQuantity::Distance: return "distance";
    }
    return "?";
}

namespace {
const DepthQuantity kDepthQuantities[] = {DepthQuantity::Window, DepthQuantity::Ndc, DepthQuantity::EyeZ,
                                          DepthQuantity::Distance};
const ExportQuantity kAll[] = {ExportQuantity::Window,      ExportQuantity::Ndc,           ExportQuantity::EyeZ,
                               ExportQuantity::Distance,    ExportQuantity::PositionEye,   ExportQuantity::PositionWorld,
                               ExportQuantity::Normal,      ExportQuantity::PrimitiveId};

template <class Quantity, std::size_t N>
std::vector<std::string> namesOf(const Quantity (&all)[N])
{
    std::vector<std::string> names;
    for (Quantity q : all) names.push_back(toString(q));
    return names;
}
}  // namespace

DepthQuantity depthQuantityFromName(const std::string& name)
{
    for (DepthQuantity q : kDepthQuantities)
        if (toString(q) == name) return q;
    throw Error("unknown depth quantity '" + name + "' (expected window, ndc, eye-z or distance)");
}

const std::vector<std::string>& depthQuantityNames()
{
    static const std::vector<std::string> names = namesOf(kDepthQuantities);
    return names;
}

std::string toString(ExportQuantity quantity)
{
    switch (quantity) {
    case ExportQuantity::Window: return "window";
    case ExportQuantity::Ndc: return "ndc";
    case ExportQuantity::EyeZ: return "eye-z";
    case ExportQuantity::Distance: return "distance";
    case ExportQuantity::PositionEye: return "position-eye";
    case ExportQuantity::PositionWorld: return "position-world";
    case ExportQuantity::Normal: return "normal";
    case ExportQuantity::PrimitiveId: return "primitive-id";
    }
    return "?";
}

const std::vector<std::string>& exportQuantityNames()
{
    static const std::vector<std::string> names = namesOf(kAll);
    return names;
}

std::vector<ExportQuantity> exportQuantitiesFromList(const std::string& text)
{
    std::vector<ExportQuantity> out;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        const std::string name = text.substr(start, end - start);
        bool found = false;
        for (ExportQuantity q : kAll)
            if (toString(q) == name) {
                for (ExportQuantity seen : out)
                    if (seen == q) throw Error("--quantity lists '" + name + "' twice");
                out.push_back(q), found = true;
            }
        if (!found)
            throw Error("unknown quantity '" + name + "' (expected one or more of " + joinedNames(exportQuantityNames()) +
                        ", comma-separated)");
        start = end + 1;
    }
    return out;
}

ExportQuantity exportQuantityFromName(const std::string& name)
{
    for (ExportQuantity q : kAll)
        if (toString(q) == name) return q;
    throw Error("unknown quantity '" + name + "' (expected one of " + joinedNames(exportQuantityNames()) + ")");
}

ExportQuantity exportQuantityOf(DepthQuantity quantity)
{
    switch (quantity) {
    case DepthQuantity::Window: return ExportQuantity::Window;
    case DepthQuantity::Ndc: return ExportQuantity::Ndc;
    case DepthQuantity::EyeZ: return ExportQuantity::EyeZ;
    case DepthQuantity::Distance: return ExportQuantity::Distance;
    }
    return ExportQuantity::Window;
}

std::string channelNameOf(ExportQuantity quantity)
{
    switch (quantity) {
    case ExportQuantity::Window: return "window";
    case ExportQuantity::Ndc: return "ndc";
    case ExportQuantity::EyeZ: return "Z";
    case ExportQuantity::Distance: return "distance";
    default: return toString(quantity);
    }
}

bool QuantityImage::isMiss(std::size_t pixel) const
{
    if (quantity == ExportQuantity::PrimitiveId) return id[pixel] == kNoPrimitive;
    const double v = value[pixel * channels.size()];
    return std::isnan(missValue) ? std::isnan(v) : v == missValue;
}

}  // namespace zcheck
