#include "zcheck/map_verifier.h"

#include "verify_estimators.h"

namespace zcheck {

const VertexNeighbours& MapVerifier::neighbours() const
{
    std::call_once(neighboursOnce_, [&] {
        neighbours_ = std::make_unique<const VertexNeighbours>(checker_.scene(), &checker_.rayRenderer(),
                                                               &checker_.rasterRenderer());
    });
    return *neighbours_;
}

VerifyResult MapVerifier::verify(const Camera& camera, const DepthMap& map) const
{
    if (camera.lens()) return verifyLensMap(checker_, camera, map);
    VerifyResult run = verifyAgainst(checker_.scene(), camera, map, checker_.renderRay(camera), neighbours());
    run.report.timings.bvhBuildMs = checker_.bvhBuildMilliseconds();
    measureMapErrors(camera, map, run);
    return run;
}

}  // namespace zcheck
