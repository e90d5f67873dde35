#include "zcheck/precision.h"

#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

std::string toString(DepthMapping mapping)
{
    switch (mapping) {
    case DepthMapping::Standard: return "standard";
    case DepthMapping::Reversed: return "reversed";
    case DepthMapping::InfiniteStandard: return "infinite far";
    case DepthMapping::InfiniteReversed: return "infinite far, reversed";
    }
    return "?";
}

namespace {

// The representable stored value next to `stored`, one step in direction `sign`.
double neighbour(DepthFormat format, double stored, double sign)
{
    if (format == DepthFormat::Float32)
        return double(std::nextafter(float(stored), sign > 0 ? INFINITY : -INFINITY));
    return stored + sign * storageQuantum(format, stored);
}

}  // namespace

double resolvableEyeZStep(const Camera& camera, double eyeZ)
{
    const glm::dvec2 centre(camera.width() / 2.0, camera.height() / 2.0);
    const DepthSettings& depth = camera.depth();
    const double stored = quantizeDepth(depth.format, windowDepthFromEyeZ(camera, centre, eyeZ));
    const double next = neighbour(depth.format, stored, depth.reversed ? -1.0 : 1.0);
    if (next < depth.rangeMin || next > depth.rangeMax) return INFINITY;
    const double z0 = eyeZFromWindowDepth(camera, centre, stored);
    const double z1 = eyeZFromWindowDepth(camera, centre, next);
    if (!std::isfinite(z1) || !(z1 > 0)) return INFINITY;
    if (z1 != z0) return std::abs(z1 - z0);
    // The step is below double resolution of eye-z (float32 next to 0): scale the slope
    // dz/dw instead, measured over a window-depth interval double can resolve.
    const double h = std::ldexp(1.0, -30) * (depth.rangeMax - depth.rangeMin);
    const double slope = std::abs(eyeZFromWindowDepth(camera, centre, stored + (depth.reversed ? -h : h)) - z0) / h;
    return slope * std::abs(next - stored);
}

PrecisionTable depthPrecision(const CameraSpec& spec, std::vector<double> distances)
{
    const Camera camera(spec);
    PrecisionTable table;
    if (distances.empty()) {
        const double n = camera.nearDistance();
        // Up to 0.95·far: at far itself every finite mapping is, trivially, unresolvable.
        const double f = camera.farIsInfinite() ? n * 1e4 : 0.95 * camera.farDistance();
        for (int k = 0; k < 9; ++k) distances.push_back(n * std::pow(f / n, k / 8.0));
    }
    for (double d : distances)
        if (!std::isfinite(d) || !(d >= camera.nearDistance()) || !(d <= camera.farDistance()))
            throw Error("distance " + formatNumber(d) + " is outside the camera's depth range [" +
                        formatNumber(camera.nearDistance()) + ", " + formatNumber(camera.farDistance()) + "]");
    std::sort(distances.begin(), distances.end());
    table.distances = distances;

    std::vector<DepthMapping> mappings;
    if (spec.projection.type == ProjectionType::Matrix) {
        mappings = {spec.depth.reversed ? DepthMapping::Reversed : DepthMapping::Standard};
    } else {
        mappings = {DepthMapping::Standard, DepthMapping::Reversed};
        if (spec.projection.isPerspective())
            mappings.insert(mappings.end(), {DepthMapping::InfiniteStandard, DepthMapping::InfiniteReversed});
    }
    double bestWorst = INFINITY;
    for (DepthFormat format : {DepthFormat::Unorm16, DepthFormat::Unorm24, DepthFormat::Float32})
        for (DepthMapping mapping : mappings) {
            CameraSpec layout = spec;
            layout.depth.format = format;
            layout.depth.reversed = mapping == DepthMapping::Reversed || mapping == DepthMapping::InfiniteReversed;
            if (mapping == DepthMapping::InfiniteStandard || mapping == DepthMapping::InfiniteReversed)
                layout.projection.far = INFINITY;
            else if (spec.projection.type != ProjectionType::Matrix && std::isinf(spec.projection.far))
                continue;  // a finite mapping needs a finite far plane
            const Camera variant(layout);
            std::vector<double> steps;
            double worst = 0;
            for (double d : distances) {
                steps.push_back(resolvableEyeZStep(variant, d));
                worst = std::max(worst, steps.back() / d);
            }
            if (worst < bestWorst) bestWorst = worst, table.best = table.layouts.size();
            table.layouts.push_back({format, mapping});
            table.step.push_back(steps);
        }
    table.bestWorstRelativeStep = bestWorst;
    return table;
}

}  // namespace zcheck
