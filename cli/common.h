#pragma once
// What every subcommand shares: exit statuses, option validators, the scene-and-camera
// options, the thread limit, the check/verify --out folder, and a depth file's sidecar.
#include "zcheck/camera_sources.h"
#include "zcheck/checker.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace zcheck::cli {

constexpr int kExitConsistent = 0;
constexpr int kExitInconsistent = 1;
constexpr int kExitUsage = 2;     // bad input: a file, key, option or value (one line names it)
constexpr int kExitInternal = 3;  // zcheck itself failed: out of memory, a library or internal error

// A subcommand: registered on the app, run when parsed.
struct Command {
    CLI::App* app;
    std::function<int()> run;
};
Command addCheckCommand(CLI::App& app);
Command addMatricesCommand(CLI::App& app);
Command addPrecisionCommand(CLI::App& app);
Command addUnprojectCommand(CLI::App& app);
Command addRemapCommand(CLI::App& app);
Command addExportCommand(CLI::App& app);
Command addVerifyCommand(CLI::App& app);
Command addSuiteCommand(CLI::App& app);
Command addBenchCommand(CLI::App& app);
Command addCameraCommand(CLI::App& app);
Command addDatasetCommand(CLI::App& app);
Command addFormatsCommand(CLI::App& app);
Command addFormatsCommand(CLI::App& app);

// Option validators, the same in every subcommand.
extern const CLI::Validator kNonEmptyPath;
extern const CLI::Validator kNonEmptyList;
extern const CLI::Validator kMissRule;  // MissRule::parse's rule: "" and "abc" are refused with its message
extern const CLI::Validator kPositiveFinite;
extern const CLI::Range kThreadRange;
extern const CLI::Range kImageSideRange;

// At most `threads` worker threads (0: all cores) for the lifetime of the object.
std::unique_ptr<tbb::global_control> limitThreads(int threads);
void addThreadsOption(CLI::App* command, int& threads);

// --camera FILE[#FRAME], --camera-format, --near and --far: a camera from any file zcheck
// imports (camera_import.h, camera_sources.h).
struct CameraOptions {
    std::string reference;  // FILE or FILE#FRAME
    std::string format;     // "" : told by content
    std::optional<double> near, far;
    std::string convention;
};
void addCameraOptions(CLI::App* command, CameraOptions& options, const std::string& cameraHelp);

// --scene and the camera options, as check, export and verify take them.
struct SceneAndCamera {
    std::string scene = "builtin:default";
    CameraOptions camera;
};
void addSceneAndCameraOptions(CLI::App* command, SceneAndCamera& options);
// The camera a command uses: --camera completed for the scene (near and far from the file, the
// options or the scene; the image size from the file, `size` — a depth map's, --width and
// --height — or, for a file without one, a default with a note), else the scene's own camera
// (a glTF's first camera, or one framing the mesh); then --convention.
CameraSpec cameraSpecFor(const Scene& scene, const SceneAndCamera& options, std::optional<std::pair<int, int>> size = {});
// The camera of a command that judges a depth map (verify, unproject), and the map, made together
// (camera_sources.h's completeCameraForMap): a camera file without an image size takes the map's,
// and near and far cover the map's depths. `scene` nullptr: a command without a scene.
CameraForMap cameraAndMapFor(const Scene* scene, const SceneAndCamera& options, DepthQuantity quantity,
                             const std::function<DepthMapFile(int width, int height)>& read);
// The --camera help of commands without a scene.
std::string cameraFileHelp(const std::string& tail = "near and far: the file's, or --near/--far");
// The file part of --camera (an input a run must not overwrite).
std::string cameraInputPath(const CameraOptions& options);
// A camera without a scene (matrices, precision, unproject): near and far must be in the file
// or given — or, with `eyeZRange` (the eye-z an eye-z or distance value lies in, which needs no
// near and far), taken around it; then --convention.
CameraSpec cameraSpecFrom(const CameraOptions& options, std::optional<std::pair<int, int>> size = {},
                          std::optional<std::pair<double, double>> eyeZRange = {});

// --width and --height, as check and bench take them: they override the camera's image size.
struct ImageSize {
    std::optional<int> width, height;
    void apply(CameraSpec& spec) const
    {
        if (width) spec.width = *width;
        if (height) spec.height = *height;
    }
};
void addImageSizeOptions(CLI::App* command, ImageSize& size);

// --channel, --scale, --offset and --miss, as verify and unproject read a depth map.
struct DepthMapOptions {
    std::string channel, miss, sidecar;
    double scale = 0;
    std::optional<double> offset;  // none: not given
    MapAccuracy accuracy;
    // The reading for a map of quantity `quantityName`: the options, and for those not given,
    // the sidecar's keys ("channel", "miss", "scale", "offset"; others ignored); throws Error
    // naming a bad --miss or sidecar key.
    DepthMapReading reading(const std::string& quantityName) const;
};
void addDepthMapOptions(CLI::App* command, DepthMapOptions& options);
// What --sidecar says the map is where the command line is silent. zcheck's export sidecar
// names the camera that rendered the map — used when --camera is absent — and each channel's
// quantity — used when `quantity` is "" (not given); else "window". Returns the sidecar when it
// holds a camera and --camera was given too, for requireSidecarCameraAgrees; "" otherwise.
std::string takeFromSidecar(const DepthMapOptions& reading, CameraOptions& camera, std::string& quantity);
// Refuses (Error naming both) a --camera that images the world otherwise than the camera in
// `sidecar` (for window and ndc maps, maps depth otherwise too). "" : nothing to compare.
void requireSidecarCameraAgrees(const CameraSpec& used, const CameraOptions& camera, const std::string& sidecar,
                                DepthQuantity quantity);
// --quantum, --rel-tolerance, --abs-tolerance, --allow-holes (MapAccuracy), in their own help group.
void addAccuracyOptions(CLI::App* command, MapAccuracy& accuracy);

// The sidecar (FILE.json) of a depth file `output` that writeDepthMapFile wrote as `format` from
// `images` of `camera`: what a reader needs to read it back — format, size, orientation, pixel
// centres (moved by `sampleOffset`, image pixels), each channel's quantity, unit, type and miss
// value, the PNG scale, the convention, the camera and its matrices. Export and remap add their own
// keys.
nlohmann::json depthFileSidecar(const std::string& output, const std::string& format, const Camera& camera,
                                const std::vector<QuantityImage>& images, double scale, glm::dvec2 sampleOffset = {0, 0});

// "1,2.5,3" → {1, 2.5, 3}; throws Error naming `option` for anything that is not a number.
std::vector<double> parseNumberList(const std::string& text, const std::string& option);

}  // namespace zcheck::cli
