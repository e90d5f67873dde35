#include "zcheck/verify_map.h"

#include "zcheck/error.h"

#include <string>

namespace zcheck {

VerifiedMap verifyMap(const MapVerifier& verifier, const Camera& camera, const DepthMap& map, bool diagnose,
                      const std::string& name)
{
    try {
        requireDepthsInRange(camera, map, name);
    } catch (const Error& refused) {
        if (!diagnose) throw;
        // Still refused (the map holds nothing of its quantity), but said what it holds.
        for (const DepthQuantity other : {DepthQuantity::EyeZ, DepthQuantity::Distance, DepthQuantity::Window, DepthQuantity::Ndc}) {
            if (other == map.quantity) continue;
            DepthMap reread = map;
            reread.quantity = other;
            try {
                requireDepthsInRange(camera, reread, name);
                const VerifyResult run = verifier.verify(camera, reread);
                if (run.comparison.report.consistent() && run.comparison.report.bothHit > 0)
                    throw Error(std::string(refused.what()) + "; --diagnose: its values are consistent read as " +
                                toString(other) + " (pass --quantity " + toString(other) + ")");
            } catch (const Error& e) {
                if (std::string(e.what()).find("--diagnose: ") != std::string::npos) throw;
            }
        }
        throw Error(std::string(refused.what()) + "; --diagnose: no other quantity reads it consistently either");
    }
    VerifiedMap out;
    out.run = verifier.verify(camera, map);
    requireSomethingCompared(out.run.comparison.report, verifier.checker().scene().name);
    out.diagnosed = diagnose && !out.run.comparison.report.consistent();
    if (out.diagnosed) out.diagnosis = verifier.diagnose(camera, map);
    return out;
}

}  // namespace zcheck
