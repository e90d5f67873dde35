#pragma once
// MapVerifier: depth maps rendered elsewhere judged against a Checker's ray route (library
// zcheck::diagnose) — verified with the comparison's tolerance model, and diagnosed.
//
//   const zcheck::Checker checker(zcheck::loadScene("bunny.obj"));   // both routes, once
//   const zcheck::MapVerifier verifier(checker);                     // beside it, for every map
//   const zcheck::VerifyResult run = verifier.verify(camera, map);
//   if (!run.comparison.report.consistent())
//       for (const zcheck::Hypothesis& h : verifier.diagnose(camera, map)) ...   // ranked
//
// Front ends call verifyMap (verify_map.h), which refuses what holds nothing to judge and
// diagnoses only an inconsistent map. How a map's surfaces are found and its pixels judged:
// verify.h; the hypotheses: the mistake catalogue (mistakes.h), the fitted families (fit.h),
// the readings a map should have declared (declared_reading.h).
//
// Lifetime: holds a reference to the Checker, which must outlive it. The triangles around each
// vertex (VertexNeighbours, verify's surface search) are built on the first verify or
// diagnose, once, and shared by every later call: keep one MapVerifier per Checker for many
// maps. Thread-safety: immutable once that index is built (std::call_once); every member
// function is const and may be called from several threads at once.
#include "zcheck/checker.h"
#include "zcheck/depth_map.h"
#include "zcheck/hypothesis.h"
#include "zcheck/verify.h"

#include <memory>
#include <mutex>
#include <vector>

namespace zcheck {

class MapVerifier {
public:
    explicit MapVerifier(const Checker& checker) : checker_(checker) {}
    MapVerifier(const MapVerifier&) = delete;
    MapVerifier& operator=(const MapVerifier&) = delete;

    const Checker& checker() const { return checker_; }

    // A depth map rendered elsewhere against the ray route's ground truth, with the same
    // tolerance model; `map` must be camera.width() × camera.height() (throws Error otherwise).
    VerifyResult verify(const Camera& camera, const DepthMap& map) const;
    // Every hypothesis of the mistake catalogue that has a meaning for this camera and map,
    // then every fitted family (fit.h), each confirmed by a full comparison; ranked: the
    // consistent ones first, then by unexplained pixels, ties in that order.
    std::vector<Hypothesis> diagnose(const Camera& camera, const DepthMap& map) const;

    // Triangles around each vertex position, built on first use (verify's surface search).
    const VertexNeighbours& neighbours() const;

private:
    const Checker& checker_;
    mutable std::once_flag neighboursOnce_;
    mutable std::unique_ptr<const VertexNeighbours> neighbours_;
};

}  // namespace zcheck
