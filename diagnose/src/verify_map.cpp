#include "zcheck/verify_map.h"

namespace zcheck {

VerifiedMap verifyMap(const MapVerifier& verifier, const Camera& camera, const DepthMap& map, bool diagnose,
                      const std::string& name)
{
    requireDepthsInRange(camera, map, name);
    VerifiedMap out;
    out.run = verifier.verify(camera, map);
    requireSomethingCompared(out.run.comparison.report, verifier.checker().scene().name);
    out.diagnosed = diagnose && !out.run.comparison.report.consistent();
    if (out.diagnosed) out.diagnosis = verifier.diagnose(camera, map);
    return out;
}

}  // namespace zcheck
