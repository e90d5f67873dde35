#pragma once
// The consistency suite: a matrix of configurations (scenes × projection models × conventions
// × depth formats × reversed-Z / infinite far × resolutions, plus extreme near/far ratios),
// each checked clean and with every injectable mistake of the catalogue (mistakes.h) injected.
//
// Per configuration and fault:
//   detected   — the check of the faulty chain is inconsistent;
//   applicable — detected, or the faulty route differs visibly from its own clean twin, judged
//                without the checker's explanations (edges, clip planes, clear value) so that
//                the suite cannot share a blind spot with them: coverage differs, or depth by
//                more than twice the snapping noise (4 q + 2·S·m), at more than 0.1% of the
//                pixels (and at least 10). A y-flip of a mirror-symmetric picture, or no near
//                clipping where nothing crosses the near plane, is not applicable, and said so.
// The suite passes when every clean configuration is consistent (no false positive) and every
// applicable fault is detected. Library zcheck::diagnose.
#include "zcheck/checker.h"
#include "zcheck/mistakes.h"

#include <functional>
#include <string>
#include <vector>

namespace zcheck {

struct NamedCamera {
    std::string name;
    CameraSpec spec;
};

// Every projection model and view, framing what the scene's own perspective camera frames:
// perspective, perspective far=inf, frustum (off-axis), pinhole, lens, orthographic, oblique
// cavalier and cabinet, axonometric isometric/dimetric/trimetric, and the perspective camera's
// matrices pasted raw. Conventions and depth settings are the base camera's.
std::vector<NamedCamera> cameraModels(const Scene& scene, int width, int height);

// `spec` in another convention and depth mapping; a raw-matrix camera gets the matrices of
// the scene's own camera in that convention and mapping (raw matrices belong to both).
CameraSpec withDepthAndConvention(CameraSpec spec, const Scene& scene, const Convention& convention, DepthSettings depth);

struct SuiteConfig {
    std::string scenePath;  // as loadScene takes it
    std::string scene;      // for people: builtin name or file name
    std::string model;
    CameraSpec spec;
    std::string label() const;  // "builtin:default | pinhole | vulkan float32 reversed | 333x257"
};

// The matrix; `quick` is a representative subset for CTest. `modelsDir` holds the shared meshes
// (stanford-bunny.obj, spot.obj, teapot.obj, suzanne.obj); empty: the built-in scenes only.
std::vector<SuiteConfig> suiteConfigurations(bool quick, const std::string& modelsDir);

enum class FaultResult { Detected, Missed, NotApplicable, Meaningless };
std::string toString(FaultResult result);

struct SuiteFailure {
    std::string label;  // configuration
    std::string what;   // "clean chain inconsistent" or "fault X not detected"
    CheckResult run;    // the run to show (images)
};

struct ConfigOutcome {
    SuiteConfig config;
    ComparisonReport clean;
    std::vector<FaultResult> faults;  // parallel to injectableMistakes()
    double milliseconds = 0;
};

struct SuiteResult {
    std::vector<ConfigOutcome> outcomes;
    std::vector<SuiteFailure> failures;   // at most a few dozen kept with their images
    int falsePositives = 0;               // clean configurations reported inconsistent
    int missedFaults = 0;                 // applicable faults not detected
    bool passed() const { return falsePositives == 0 && missedFaults == 0; }
};

// Detected / applicable per injectable mistake over the whole run.
struct FaultTally {
    int detected = 0, missed = 0, notApplicable = 0, meaningless = 0;
};
std::vector<FaultTally> tallyFaults(const SuiteResult& result);  // parallel to injectableMistakes()

// Runs the configurations, one Checker per scene; `progress(done, total, outcome)` is called after each.
SuiteResult runSuite(const std::vector<SuiteConfig>& configs,
                     const std::function<void(std::size_t, std::size_t, const ConfigOutcome&)>& progress);

}  // namespace zcheck
