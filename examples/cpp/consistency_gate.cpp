// A renderer's test harness would do this: check a scene through its own camera in every
// convention, and fail the build when a convention's transform chain is inconsistent.
//   consistency_gate [MESH]      (default: zcheck's built-in scene)
#include <zcheck/checker.h>
#include <zcheck/error.h>
#include <zcheck/mesh_loader.h>
#include <zcheck/report.h>
#include <zcheck/version.h>

#include <cstdio>

int main(int argc, char** argv)
{
    try {
        const zcheck::Checker checker(zcheck::loadScene(argc > 1 ? argv[1] : "builtin:default"));
        int failures = 0;
        for (const std::string& convention : zcheck::Convention::presetNames()) {
            zcheck::CameraSpec spec = checker.scene().defaultCamera;
            spec.convention = zcheck::Convention::preset(convention);
            spec.width = 320, spec.height = 240;
            const zcheck::CheckResult result = checker.check(zcheck::Camera(spec));
            const zcheck::ComparisonReport& c = result.report.comparison;
            std::printf("zcheck %s  %-9s %s (%lld pixels compared, %lld unexplained)\n", zcheck::kVersion,
                        convention.c_str(), c.consistent() ? "CONSISTENT" : "INCONSISTENT",
                        static_cast<long long>(c.bothHit), static_cast<long long>(c.unexplained()));
            failures += c.consistent() ? 0 : 1;
        }
        return failures == 0 ? 0 : 1;
    } catch (const zcheck::Error& e) {
        std::fprintf(stderr, "consistency_gate: %s\n", e.what());
        return 2;
    }
}
