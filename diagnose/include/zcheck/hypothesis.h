#pragma once
// What a diagnosis says (library zcheck::diagnose): one hypothesis per mistake of the catalogue
// (mistakes.h), fitted family (fit.h) or declared reading (declared_reading.h) it tried, judged
// by a full comparison of the map as the hypothesis reads it (MapVerifier::diagnose,
// map_verifier.h), or ruled out by an estimate.
#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

// A parameter a diagnosis measured: "fovy_deg", "sample_dx_px", "near", "value_scale", ...
struct FittedValue {
    std::string name;
    double value = 0;      // fitted
    double declared = 0;   // what the camera file or the reading says
};

// One hypothesis of the diagnosis: a mistake of the catalogue (mistakes.h), perhaps one of
// several variants of it, under which the map was re-read or the truth re-rendered.
struct Hypothesis {
    std::string name;         // the mistake's name, e.g. "distance-as-eye-z", "half-pixel"
    std::string variant;      // which variant, e.g. "x and y"; empty when there is one
    std::string explanation;  // "consistent if read as ray distance instead of eye-z"
    bool consistent = false;
    std::int64_t unexplained = 0;
    bool estimated = false;   // `unexplained` estimated from a sample that already ruled the
                              // hypothesis out (src/verify_estimators.h, screenUnexplained)
    std::vector<FittedValue> fitted;  // a fitted hypothesis's values (fit.h); empty for the catalogue's
    // Of the unexplained pixels, those at edges of the truth (a 3×3 neighbourhood that is not
    // one plane), and of those the ones whose depth lies between the truth's around them.
    std::int64_t unexplainedAtEdges = 0, blendsAtEdges = 0;
    std::int64_t compared = 0;  // pixels where either side sees a surface (full comparisons only)
    // Not consistent, but only at edges: every unexplained pixel at an edge, and at most 10 % of
    // the compared ones (a silhouette-rich 200×150 view has 4 % at its edges): "consistent
    // except N edge pixels".
    bool consistentExceptEdges() const
    {
        return !consistent && !estimated && unexplained > 0 && unexplainedAtEdges == unexplained && compared > 0 &&
               unexplained <= compared / 10;
    }
    // The hypothesis explains the map: consistent, or consistent but for edge pixels. The one
    // rule the diagnosis, the reports and the datasets name a mistake by.
    bool explains() const { return consistent || consistentExceptEdges(); }
};

}  // namespace zcheck
