#pragma once
// Verifying a map and diagnosing it: the one entry point the command line, Python and datasets
// call (library zcheck::diagnose). Reports format what it returns (report.h's
// formatVerification); they run nothing.
//
//   const zcheck::MapVerifier verifier(checker);   // one per Checker, for many maps (map_verifier.h)
//   const zcheck::VerifiedMap verified = zcheck::verifyMap(verifier, camera, map, /*diagnose=*/true);
//   if (!verified.run.comparison.report.consistent())
//       for (const zcheck::Hypothesis& h : verified.diagnosis) ...   // ranked, consistent ones first
//
// Thread-safe as MapVerifier is: call it for many maps at once.
#include "zcheck/depth_map.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/hypothesis.h"
#include "zcheck/map_verifier.h"
#include "zcheck/verify.h"

#include <functional>
#include <string>
#include <vector>

namespace zcheck {

// Where a verified map came from, for its report.
struct DepthMapSource {
    std::string file, quantity, channel;  // channel: the one read
    DepthMapReading reading;              // as asked (scale 0: not given)

    // "depth map 'FILE'": how verifyMap's refusals name it.
    std::string name() const { return "depth map '" + file + "'"; }
};

struct VerifiedMap {
    VerifyResult run;
    bool diagnosed = false;             // the map was inconsistent and a diagnosis was asked for
    std::vector<Hypothesis> diagnosis;  // MapVerifier::diagnose's ranking
};

// A map holding no value of its quantity, only misses and values it cannot hold, is refused
// (Error beginning with `name`, requireDepthsInRange); then MapVerifier::verify; then a
// comparison with nothing in it is refused (Error "nothing to compare",
// requireSomethingCompared); then, when `diagnose` and the map is inconsistent,
// MapVerifier::diagnose. With `diagnose`, the refusal of a map holding nothing of its quantity
// says which other quantity reads its values consistently ("…; --diagnose: its values are
// consistent read as eye-z (pass --quantity eye-z)"), or that none does.
// `diagnoser`, when given, replaces MapVerifier::diagnose for an inconsistent map (datasets try
// their own readings first: another frame's camera).
using MapDiagnoser = std::function<std::vector<Hypothesis>(const Camera&, const DepthMap&)>;
VerifiedMap verifyMap(const MapVerifier& verifier, const Camera& camera, const DepthMap& map, bool diagnose,
                      const std::string& name = "the depth map", const MapDiagnoser& diagnoser = {});

}  // namespace zcheck
