#include "zcheck/verify_map.h"

#include "verify_estimators.h"
#include "zcheck/error.h"

#include <string>

namespace zcheck {

VerifiedMap verifyMap(const MapVerifier& verifier, const Camera& camera, const DepthMap& map, bool diagnose,
                      const std::string& name, const MapDiagnoser& diagnoser)
{
    try {
        requireDepthsInRange(camera, map, name);
    } catch (const Error& refused) {
        if (!diagnose) throw;
        // Still refused (the map holds nothing of its quantity), but said what it holds.
        auto readsConsistentlyAs = [&](DepthQuantity other) {
            DepthMap reread = map;
            reread.quantity = other;
            try {
                requireDepthsInRange(camera, reread, name);
            } catch (const Error&) {
                return false;
            }
            const ComparisonReport r = verifier.verify(camera, reread).comparison.report;
            return r.consistent() && r.bothHit > 0;
        };
        for (const DepthQuantity other : {DepthQuantity::EyeZ, DepthQuantity::Distance, DepthQuantity::Window, DepthQuantity::Ndc})
            if (other != map.quantity && readsConsistentlyAs(other))
                throw Error(std::string(refused.what()) + "; --diagnose: its values are consistent read as " + toString(other) +
                            " (pass --quantity " + toString(other) + ")");
        throw Error(std::string(refused.what()) + "; --diagnose: no other quantity reads it consistently either");
    }
    VerifiedMap out;
    out.run = verifier.verify(camera, map);
    requireSomethingCompared(out.run.comparison.report, verifier.checker().scene().name);
    out.diagnosed = diagnose && !out.run.comparison.report.consistent();
    if (out.diagnosed) out.diagnosis = diagnoser ? diagnoser(camera, map) : verifier.diagnose(camera, map);
    return out;
}

}  // namespace zcheck
