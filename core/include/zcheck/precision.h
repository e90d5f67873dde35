#pragma once
// Depth-buffer precision made concrete: how finely each depth layout resolves eye depth.
//
// For a camera and an eye depth d (eye-z, scene units), the resolvable step is the eye-z
// distance between the value the buffer stores for d and its neighbouring representable
// value on the far side: |z_eye(next) − z_eye(stored)|. It is +inf where d cannot be told
// from the far end (the stored value is already the last one before the clear value).
// Computed exactly from the camera's mappings through the inverse-projection module.
#include "zcheck/camera.h"

#include <string>
#include <vector>

namespace zcheck {

enum class DepthMapping {
    Standard,          // near → near end of the range
    Reversed,          // reversed-Z: near → far end
    InfiniteStandard,  // far plane at infinity (perspective only)
    InfiniteReversed,  // far plane at infinity with reversed-Z (perspective only)
};
std::string toString(DepthMapping mapping);

// The smallest resolvable eye-z step at eye-z `eyeZ` for the camera's own format and mapping.
double resolvableEyeZStep(const Camera& camera, double eyeZ);

struct PrecisionLayout {
    DepthFormat format;
    DepthMapping mapping;
};

struct PrecisionTable {
    std::vector<double> distances;            // eye-z values, ascending
    std::vector<PrecisionLayout> layouts;     // every format × every applicable mapping
    std::vector<std::vector<double>> step;    // step[layout][distance], scene units (+inf: unresolvable)
    std::size_t best = 0;                     // index of the layout with the smallest worst relative step
    double bestWorstRelativeStep = 0;         // that layout's max over distances of step / distance
};

// `distances` empty: 9 log-spaced values from near to 0.95·far (to 10^4·near with an infinite
// far plane). A raw-matrix camera can only be evaluated in its own mapping.
PrecisionTable depthPrecision(const CameraSpec& spec, std::vector<double> distances = {});

}  // namespace zcheck
