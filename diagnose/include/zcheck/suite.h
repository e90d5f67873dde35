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
#include "zcheck/depth_map.h"
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

// The scenes (as loadScene takes them): the built-ins, then the shared meshes of `modelsDir`
// (all of them, or the bunny alone when `quick`); and a scene's name for people.
std::vector<std::string> suiteScenes(bool quick, const std::string& modelsDir);
std::string suiteSceneLabel(const std::string& scenePath);

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

// ---- The lens part: lens cameras, the mistakes of the lens family (lens_mistakes.h) ----
//
// Configurations: each scene × lens cameras framing what the scene's own camera frames (the same
// eye, target and up; focal lengths chosen so that the object fills the view) × two magnitudes:
// opencv with 5 coefficients (k1 k2 p1 p2 k3), opencv rational (8), opencv_fisheye
// (Kannala–Brandt), double_sphere seeing past 90° in the image's corners, and equirectangular
// (part of the sphere, the whole sphere); 128×96, each with a depth quantity (eye-z or distance;
// distance where the image holds rays 90° or more off the axis).
// Per configuration:
//   clean      — Checker::check of the lens camera is consistent, and the map rendered by the ray
//                route through it (renderedMap), verified with it, is consistent; else a false positive;
//   per mistake of lensMistakes(camera, quantity), the map the mistaken renderer delivers
//   (mistakenMap) verified with the declared camera:
//     detected   — the verification is inconsistent (or refuses the map); judged without the diagnosis;
//     applicable — detected, or the mistaken map differs visibly from the clean one, judged without
//                  the checker's explanations: coverage differs, or the value by more than
//                  4 q + 2·S·m (q the binary32 step of the clean value, S = 2^-8 px, m the clean
//                  map's steepest one-sided difference along each axis, summed), at more than 0.1%
//                  of the pixels (and at least 10);
//     named      — detected, and verify --diagnose's best hypothesis (verifyMap) has the
//                  mistake's name and explains the map.
// The lens part passes when no clean configuration is a false positive and every applicable
// mistake is detected and named (a misnamed mistake sends the user after the wrong fix).
struct LensSuiteConfig {
    std::string scenePath;   // as loadScene takes it
    std::string scene;       // for people: builtin name or file name
    std::string model;       // "opencv", "opencv rational", "opencv_fisheye", "double_sphere", "equirectangular"
    std::string magnitude;   // "mild", "strong"; a panorama's "part" or "sphere"
    CameraSpec spec;
    DepthQuantity quantity = DepthQuantity::Distance;  // the clean map's
    std::string label() const;  // "builtin:default | opencv strong | distance | opencv | 128x96"
};

// Every lens camera of the lens part for `scene` at width × height, framing its own camera's view.
std::vector<LensSuiteConfig> lensCameras(const Scene& scene, const std::string& scenePath, const std::string& sceneLabel,
                                         int width, int height);
// The lens part's matrix; `quick` a representative subset for CTest (every mistake applicable).
std::vector<LensSuiteConfig> lensSuiteConfigurations(bool quick, const std::string& modelsDir);

struct LensFaultOutcome {
    std::string name, variant;   // lens_mistakes.h's
    FaultResult result = FaultResult::Meaningless;
    bool named = false;          // detected, and the diagnosis's best hypothesis is this mistake
    std::string diagnosedAs;     // the best hypothesis, "name (variant)"; "none" if none explains the map
};

struct LensConfigOutcome {
    LensSuiteConfig config;
    ComparisonReport check;      // Checker::check of the lens camera
    ComparisonReport cleanMap;   // the clean map verified with the camera
    std::vector<LensFaultOutcome> faults;  // one per lensMistakes(camera, quantity)
    double milliseconds = 0;
    bool clean() const { return check.consistent() && cleanMap.consistent(); }
};

struct LensSuiteResult {
    std::vector<LensConfigOutcome> outcomes;
    int falsePositives = 0;   // configurations whose check or clean map is inconsistent
    int missedFaults = 0;     // applicable mistakes not detected
    int misnamedFaults = 0;   // detected mistakes the diagnosis names otherwise (or not at all)
    bool passed() const { return falsePositives == 0 && missedFaults == 0 && misnamedFaults == 0; }
};

// One row of the lens mistake table: a mistake and variant, over the whole run, in the order
// first met.
struct LensFaultTally {
    std::string name, variant;
    int detected = 0, missed = 0, notApplicable = 0, named = 0;
    int configurations = 0;   // where the mistake has a meaning
};
std::vector<LensFaultTally> tallyLensFaults(const LensSuiteResult& result);

// Runs the lens part, one Checker and MapVerifier per scene; `progress(done, total, outcome)` after each.
LensSuiteResult runLensSuite(const std::vector<LensSuiteConfig>& configs,
                             const std::function<void(std::size_t, std::size_t, const LensConfigOutcome&)>& progress);

}  // namespace zcheck
