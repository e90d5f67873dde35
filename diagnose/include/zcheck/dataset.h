#pragma once
// A dataset verified as one job (library zcheck::diagnose): every frame of a transforms.json, a
// COLMAP model or a manifest (dataset_source.h) against the ground truth of its scene.
//
//   zcheck::DatasetRunOptions options;
//   options.scene = "mesh.ply", options.quantity = "eye-z";
//   const zcheck::DatasetRunner runner(zcheck::openDataset("transforms.json", {}), options, readDepthMap);
//   runner.run(runner.shardFrames(), [](zcheck::FrameResult result) { ... });   // as each frame finishes
//
// A scene is loaded and its BVH and raster set-up built once per runner (the run's scene up
// front; a scene a manifest line names, on first use); frames run in parallel on TBB's threads,
// each itself parallel inside. A frame that cannot be run — a missing or malformed depth map, a
// camera the file refused, a camera that sees nothing — becomes a result with that one-line
// error; the run goes on. Thread-safe: run() and verify() may be called from several threads.
#include "zcheck/camera_sources.h"
#include "zcheck/checker.h"
#include "zcheck/dataset_source.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/map_verifier.h"
#include "zcheck/verify_map.h"

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

// Reads a depth map (image_io.h's readDepthMap, or the command line's plugin of it).
using DepthMapReader = std::function<DepthMapFile(const std::string& path, const DepthMapReading& reading, int width,
                                                  int height)>;

struct DatasetRunOptions {
    std::string scene = "builtin:default";  // every frame's, unless its manifest line names one
    std::string quantity;                   // unless the line says; one of them is required
    // How maps are read (a manifest line's own values win; these win over what a camera file
    // implies, such as nerfstudio's millimetres).
    std::optional<double> scale, offset;
    std::string miss, channel;
    MapAccuracy accuracy;       // --quantum, --rel-tolerance, --abs-tolerance, --allow-holes (a manifest line's win)
    std::optional<double> near, far;        // the clip planes of cameras whose file has none
    std::string convention;                 // replaces every camera's convention ("" keeps it)
    bool diagnose = false;                  // diagnose the inconsistent frames
    std::size_t shard = 0, shards = 1;      // frames shard, shard + shards, ...

    // "I/N" (0 ≤ I < N ≤ 100000) into shard and shards; throws Error naming the text.
    void parseShard(const std::string& text);
};

// How one frame is read and its camera made: the frame's own values (a manifest line's) winning
// over the run's options, which win over what its camera file implies. Throws Error (the
// frame's error) for a frame the source could not make, or one without a quantity.
struct FramePlan {
    std::string quantityName;
    DepthQuantity quantity = DepthQuantity::EyeZ;
    DepthMapReading reading;
    CameraCompletion given;        // near and far
    std::string scene;
    std::vector<std::string> notes;  // what the plan assumed (a scale the camera file implies)
};
FramePlan planFrame(const DatasetFrame& frame, const DatasetRunOptions& options);

// The frame's camera (completed for `scene` and the map, the run's convention applied) and its
// map, read with `readDepthMap`. Throws Error.
CameraForMap frameCameraAndMap(const DatasetFrame& frame, const FramePlan& plan, const Scene& scene,
                               const DatasetRunOptions& options, const DepthMapReader& readDepthMap);

// A frame's map made with another frame's camera (the commonest animation bug: Blender's
// frame_current against the frame rendered, a glTF export of frame_start, a list shifted by one).
// `dataset verify --diagnose` tries, for an inconsistent frame i, the cameras of frames i−1, i+1,
// i−2 and i+2, then of every other frame of the same scene (a probe of single rays first, the
// three that come closest judged in full), and names the first that makes the map consistent;
// the full diagnosis runs only when none does. Cameras equal to the frame's own are skipped.
// The hypotheses' names by the offset j − i: "previous-frame-camera" (−1), "next-frame-camera"
// (+1), "camera-2-frames-back" (−2), "camera-2-frames-ahead" (+2), "another-frame-camera".
// What a dataset's summary says of its frames for such a hypothesis ("consistent with the
// previous frame's camera"); nullopt for any other hypothesis.
std::optional<std::string> datasetPhraseOf(const std::string& hypothesisName);

// The result of one frame.
struct FrameResult {
    std::size_t index = 0, of = 0;     // the frame's index in the dataset, and the dataset's size
    std::string frame, source, scene;  // names
    std::string error;                 // the frame was not verified: why (one line)
    DepthMapSource map;                // the depth map as read (file, quantity, channel, reading)
    bool verified = false;             // report and diagnosis hold a verification
    CheckReport report;                // the comparison, as `zcheck verify --json` reports it
    bool diagnosed = false;
    std::vector<Hypothesis> diagnosis;  // ranked (MapVerifier::diagnose)
    double seconds = 0;                // wall time of the frame: reading, verifying, diagnosing

    bool consistent() const { return verified && report.comparison.consistent(); }
};


// Scenes loaded and their map verifiers (each over its checker) built once, by name, for any
// number of runners (thread-safe), so that every frame of a scene shares one neighbour index.
class SceneVerifiers {
public:
    // The scene's verifier (its checker: MapVerifier::checker()), built on first use.
    const MapVerifier& operator()(const std::string& scene);

private:
    struct Built;  // a checker and its verifier
    std::mutex mutex_;
    std::map<std::string, std::shared_ptr<const Built>> built_;
};

class DatasetRunner {
public:
    // Loads the run's scene and builds its verifier (or finds it in `verifiers`, shared with other
    // runners): an Error here (a bad mesh, a bad option) is the run's, not a frame's.
    DatasetRunner(Dataset dataset, DatasetRunOptions options, DepthMapReader readDepthMap,
                  std::shared_ptr<SceneVerifiers> verifiers = nullptr);
    ~DatasetRunner();

    const Dataset& dataset() const { return dataset_; }
    const DatasetRunOptions& options() const { return options_; }
    // The indices of the frames of this run's shard, ascending.
    std::vector<std::size_t> shardFrames() const;

    // One frame. `keep` (optional) receives the verification's per-pixel results, for pictures.
    FrameResult verify(std::size_t index, VerifiedMap* keep = nullptr) const;
    // The frames in parallel; `done` is called once per frame as it finishes, never twice at
    // once. An exception from `done` stops the run and is rethrown.
    void run(const std::vector<std::size_t>& frames, const std::function<void(FrameResult&&)>& done) const;

private:
    // A float map read with the scale its camera file implies (nerfstudio's millimetres) that is
    // consistent read as stored: the hypothesis "implied-scale-on-float", saying what to type.
    std::optional<Hypothesis> impliedScaleOnFloat(const DatasetFrame& frame, const FramePlan& plan,
                                                  const MapVerifier& verifier, const DepthMapFile& file,
                                                  const Camera& camera, const DepthMap& map) const;
    // The other frame whose camera makes frame `index`'s map consistent (above), as a hypothesis.
    std::optional<Hypothesis> otherFrameCamera(std::size_t index, const FramePlan& plan, const MapVerifier& verifier,
                                               const DepthMapFile& file, const Camera& camera, const DepthMap& map) const;

    Dataset dataset_;
    DatasetRunOptions options_;
    DepthMapReader readDepthMap_;
    std::shared_ptr<SceneVerifiers> verifiers_;
};

}  // namespace zcheck
