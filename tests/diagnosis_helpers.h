#pragma once
// For the tests of the diagnosis: a map as a renderer that made a mistake would deliver it,
// and whether the diagnosis names that mistake.
#include "zcheck/checker.h"
#include "zcheck/export.h"
#include "zcheck/map_verifier.h"
#include "zcheck/mistakes.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace zcheck::testing {

inline const Mistake& mistakeNamed(const std::string& name)
{
    const auto& all = mistakeCatalogue();
    const auto found = std::find_if(all.begin(), all.end(), [&](const Mistake& m) { return m.name == name; });
    if (found == all.end()) throw std::logic_error("no mistake named " + name);
    return *found;
}

// One quantity of a render as a float32 file stores it.
inline DepthMap mapOf(const Scene& scene, const Camera& camera, const RenderResult& route, ExportQuantity quantity)
{
    const QuantityImage image = quantityImage(scene, camera, route, quantity);
    DepthMap map;
    map.width = image.width, map.height = image.height;
    map.quantity = quantity == ExportQuantity::Window ? DepthQuantity::Window
                   : quantity == ExportQuantity::Ndc  ? DepthQuantity::Ndc
                   : quantity == ExportQuantity::EyeZ ? DepthQuantity::EyeZ
                                                       : DepthQuantity::Distance;
    map.value = image.value;
    for (double& v : map.value) v = double(float(v));
    return map;
}

// The window depth of `render`, stored as a float32 file stores it.
inline DepthMap windowMapOf(const Camera& camera, const RenderResult& render)
{
    DepthMap map = DepthMap::exact(camera.width(), camera.height(), DepthQuantity::Window,
                                   {render.windowDepth.value.begin(), render.windowDepth.value.end()});
    for (double& v : map.value) v = double(float(v));
    return map;
}

inline bool anyHit(const RenderResult& render)
{
    return std::any_of(render.primitiveId.begin(), render.primitiveId.end(), [](std::uint32_t id) { return id != kNoPrimitive; });
}

// Whether one of the diagnosis's consistent hypotheses is `name`.
inline bool diagnosedAs(const MapVerifier& verifier, const Camera& camera, const DepthMap& map, const std::string& name)
{
    for (const Hypothesis& h : verifier.diagnose(camera, map))
        if (h.consistent && h.name == name) return true;
    return false;
}

}  // namespace zcheck::testing
