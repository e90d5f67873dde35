#pragma once
// The fault catalogue: classic transform-chain mistakes, each injected into one route of an
// otherwise correct chain. A checker is as good as the faults it catches.
#include "zcheck/raster_renderer.h"
#include "zcheck/ray_renderer.h"

#include <functional>
#include <string>
#include <vector>

namespace zcheck {

struct FaultInjection {
    RayFaults ray;
    RasterFaults raster;
};

struct Fault {
    std::string name;         // short, stable: used in tables and --filter
    std::string description;  // what the mistake is, in a user's words
    std::string route;        // "ray" or "raster": the route it is injected into
    // Fills the injection for this camera; false where the mistake has no meaning here (a
    // field-of-view mistake on an orthographic camera, truncation of a float buffer).
    std::function<bool(const Camera&, FaultInjection&)> inject;
};

const std::vector<Fault>& faultCatalogue();

}  // namespace zcheck
