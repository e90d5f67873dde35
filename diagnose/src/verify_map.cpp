#include "zcheck/verify_map.h"

#include "zcheck/verify.h"

namespace zcheck {

VerifiedMap verifyMap(const Checker& checker, const Camera& camera, const DepthMap& map, bool diagnose,
                      const std::string& name)
{
    requireDepthsInRange(camera, map, name);
    VerifiedMap out;
    out.run = checker.verify(camera, map);
    requireSomethingCompared(out.run.comparison.report, checker.scene().name);
    out.diagnosed = diagnose && !out.run.comparison.report.consistent();
    if (out.diagnosed) out.diagnosis = checker.diagnose(camera, map);
    return out;
}

}  // namespace zcheck
