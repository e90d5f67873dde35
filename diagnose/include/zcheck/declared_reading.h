#pragma once
// What a rejected map's values say its reading should have declared — the options of `verify`
// that would have accepted it (a miss value, a rounding grid, holes, a stated accuracy) —
// measured against the ground truth, so that a correct map read without them is named as such
// instead of being blamed on a convention (library zcheck::diagnose). MapVerifier::diagnose
// judges each finding (and all of them together) with a full comparison, like every
// hypothesis: nothing here accepts a map by itself.
//
//   miss value  one finite value holds ≥ 90 % of the pixels where the truth sees nothing, at
//               least 16 of them, and at most 1 % of its pixels are where the truth hits: the
//               renderer's "no surface" (Cycles' 1e10, Eevee's 65504, a PNG's 65535, 0, the far
//               plane). Suggested as a rule on stored values: ">=1e9" from 1e9 up, else the value.
//   grid        ≥ 99 % of the values where the truth hits lie within 1/1000 of a step (or four
//               binary32 spacings) of a multiple of Q, for the largest Q of 1, 2 or 5 × 10^k
//               (k = −6..0) or 2^−k (k = 1..24) at least 16 binary32 spacings of the largest
//               value: values rounded to a grid coarser than their storage.
//   holes       pixels without a value where the truth hits that the comparison leaves
//               unexplained once the miss value above is read as one (MapVerifier::diagnose
//               counts them).
//   noise       only where no convention explains the map (MapVerifier::diagnose asks last): an
//               eye-z or distance map whose errors (map − truth, 256 pixels or more) are noise —
//               unbiased (|median| ≤ 0.1 of their robust spread, 1.4826·MAD), uncorrelated from
//               each pixel to its right-hand neighbour (correlation under 0.3) and, within 1.5 ×,
//               bounded by 6 σ(z) of a model σ(z) = a + b·z² (z the map's value) fitted to the
//               spread of eight depth bins; the model is scaled up until it bounds every pixel
//               and suggested as --noise-model, two significant digits rounded up.
//   tolerance   where the errors are not noise, likewise: an
//               eye-z or distance map whose values where both see a surface lie within a small
//               relative (≤ 1 %) or absolute error of the truth; the more uniform of the two
//               (largest over median) is suggested, rounded up to one significant digit.
#include "zcheck/checker.h"
#include "zcheck/depth_map.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

struct ReadingFindings {
    // The miss value as the map holds it (value units) and as a rule on stored values, and
    // on how many pixels where nothing is hit.
    std::optional<double> missValue;
    std::string missRule;
    std::int64_t missPixels = 0;
    double grid = 0;               // the rounding grid (value units); 0: none
    std::int64_t holes = 0;        // unexplained holes (above); findReading leaves it 0
};

// Which findings a reading declares.
struct Declared {
    bool missValue = false, grid = false, holes = false;
    bool any() const { return missValue || grid || holes; }
    // "miss-value", "quantum", "holes", joined by " + " ("" for none): the hypothesis's name.
    std::string name() const;
    // The readings a diagnosis tries for these findings: each alone, then (if more than one) all.
    std::vector<Declared> readingsToTry() const;
};

// The findings of a map against the declared camera's ground truth (already rendered).
ReadingFindings findReading(const Camera& camera, const DepthMap& map, const RenderResult& truth);

// The map as it reads with the findings `use` declares: the miss value read as "no surface",
// the grid as its quantum, holes allowed.
DepthMap declaredReading(const DepthMap& map, const ReadingFindings& findings, const Declared& use);

// A stated accuracy that would accept `map` (relative or absolute, the other 0), or nothing:
// see above. `truth` is the declared camera's.
std::optional<MapAccuracy> toleranceFinding(const Camera& camera, const DepthMap& map, const RenderResult& truth);

// A sensor's noise in the map's errors, as above, or nothing.
struct NoiseFinding {
    NoiseModel model;
    double zNear = 0, zFar = 0;      // the 5th and 95th percentiles of the map's values compared
    double correlation = 0;          // of neighbouring pixels' errors
};
std::optional<NoiseFinding> noiseFinding(const Camera& camera, const DepthMap& map, const RenderResult& truth);

// "the map holds 1e10 at all 54,155 pixels where nothing is hit: its miss value (pass --miss '>=1e9')",
// and likewise for the grid and holes: one clause per finding `use` names.
std::string describeFindings(const ReadingFindings& findings, const Declared& use);

}  // namespace zcheck
