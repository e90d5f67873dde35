#include "zcheck/dataset.h"

#include "verify_estimators.h"
#include "zcheck/camera_sources.h"
#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/mesh_loader.h"

#include <tbb/parallel_for_each.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <charconv>
#include <exception>

namespace zcheck {

void DatasetRunOptions::parseShard(const std::string& text)
{
    const std::size_t slash = text.find('/');
    std::size_t i = 0, n = 0;
    bool ok = slash != std::string::npos;
    if (ok) {
        const auto [endI, errorI] = std::from_chars(text.data(), text.data() + slash, i);
        const auto [endN, errorN] = std::from_chars(text.data() + slash + 1, text.data() + text.size(), n);
        ok = errorI == std::errc() && endI == text.data() + slash && errorN == std::errc() &&
             endN == text.data() + text.size() && slash > 0 && n >= 1 && n <= 100000 && i < n;
    }
    if (!ok) throw Error("--shard '" + text + "' must be I/N with 0 <= I < N <= 100000 (frames I, I+N, I+2N, ...)");
    shard = i, shards = n;
}

struct SceneVerifiers::Built {
    explicit Built(Scene scene) : checker(std::move(scene)), verifier(checker) {}
    const Checker checker;
    const MapVerifier verifier;
};

const MapVerifier& SceneVerifiers::operator()(const std::string& scene)
{
    const std::lock_guard<std::mutex> lock(mutex_);
    auto& built = built_[scene];
    if (!built) built = std::make_shared<const Built>(loadScene(scene));
    return built->verifier;
}

DatasetRunner::DatasetRunner(Dataset dataset, DatasetRunOptions options, DepthMapReader readDepthMap,
                             std::shared_ptr<SceneVerifiers> verifiers)
    : dataset_(std::move(dataset)), options_(std::move(options)), readDepthMap_(std::move(readDepthMap)),
      verifiers_(verifiers ? std::move(verifiers) : std::make_shared<SceneVerifiers>())
{
    if (options_.shards < 1 || options_.shard >= options_.shards) throw Error("the shard must be I/N with 0 <= I < N");
    if (!options_.quantity.empty()) depthQuantityFromName(options_.quantity);  // a bad --quantity is the run's error
    if (!options_.miss.empty()) MissRule::parse(options_.miss);
    options_.accuracy.require("the run's options");
    if (!options_.convention.empty()) Convention::preset(options_.convention);
    (*verifiers_)(options_.scene);
}

DatasetRunner::~DatasetRunner() = default;

std::vector<std::size_t> DatasetRunner::shardFrames() const
{
    std::vector<std::size_t> out;
    for (std::size_t i = options_.shard; i < dataset_.frames.size(); i += options_.shards) out.push_back(i);
    return out;
}

FramePlan planFrame(const DatasetFrame& frame, const DatasetRunOptions& options)
{
    if (!frame.error.empty()) throw Error(frame.error);
    FramePlan plan;
    plan.quantityName = frame.quantity.value_or(options.quantity);
    if (plan.quantityName.empty())
        throw Error("frame '" + frame.name + "' has no quantity: give --quantity (or \"quantity\" in the manifest)");
    plan.quantity = depthQuantityFromName(plan.quantityName);
    DepthMapReading& reading = plan.reading;
    reading.channel = frame.channel.value_or(options.channel);
    reading.quantityChannel = channelNameOf(exportQuantityOf(plan.quantity));
    reading.scale = frame.scale ? *frame.scale : options.scale ? *options.scale : frame.impliedScale.value_or(0.0);
    reading.offset = frame.offset.value_or(options.offset.value_or(0.0));
    const std::string miss = frame.miss.value_or(options.miss);
    if (!miss.empty()) reading.miss = MissRule::parse(miss);
    reading.accuracy = frame.accuracy.over(options.accuracy);
    plan.given.near = frame.near ? frame.near : options.near;
    plan.given.far = frame.far ? frame.far : options.far;
    plan.scene = frame.scene.value_or(options.scene);
    if (!frame.scale && !options.scale && frame.impliedScale) plan.notes.push_back(frame.impliedScaleNote);
    return plan;
}

CameraForMap frameCameraAndMap(const DatasetFrame& frame, const FramePlan& plan, const Scene& scene,
                               const DatasetRunOptions& options, const DepthMapReader& readDepthMap)
{
    // The map read at the camera's size (or the camera taking the map's), near and far covering it.
    CameraForMap made = completeCameraForMap(*frame.camera, &scene, plan.given, plan.quantity, [&](int width, int height) {
        return readDepthMap(frame.depth, plan.reading, width, height);
    });
    if (!options.convention.empty()) made.spec.convention = Convention::preset(options.convention);
    made.spec.notes.insert(made.spec.notes.end(), plan.notes.begin(), plan.notes.end());
    return made;
}

FrameResult DatasetRunner::verify(std::size_t index, VerifiedMap* keep) const
{
    const auto start = Clock::now();
    const DatasetFrame& frame = dataset_.frames.at(index);
    FrameResult result;
    result.index = index, result.of = dataset_.frames.size();
    result.frame = frame.name, result.source = dataset_.source;
    result.scene = frame.scene.value_or(options_.scene);
    result.map.file = frame.depth;
    try {
        const FramePlan plan = planFrame(frame, options_);
        result.map.quantity = plan.quantityName;
        result.map.reading = plan.reading;
        const MapVerifier& verifier = (*verifiers_)(plan.scene);
        CameraForMap made = frameCameraAndMap(frame, plan, verifier.checker().scene(), options_, readDepthMap_);
        const Camera camera(made.spec);
        result.map.channel = made.map.channel;
        const DepthMapFile file = made.map;  // for the other frames' cameras, if the map needs them
        const DepthMap map = DepthMap::of(std::move(made.map), plan.quantity, plan.reading);
        // A frame's own readings first (its camera file's implied scale, another frame's camera),
        // then the full diagnosis only where they explain nothing.
        const MapDiagnoser diagnoser = [&](const Camera&, const DepthMap&) -> std::vector<Hypothesis> {
            if (std::optional<Hypothesis> unscaled = impliedScaleOnFloat(frame, plan, verifier, file, camera, map))
                return {std::move(*unscaled)};
            if (std::optional<Hypothesis> other = otherFrameCamera(index, plan, verifier, file, camera, map))
                return {std::move(*other)};
            return verifier.diagnose(camera, map);
        };
        VerifiedMap verified = verifyMap(verifier, camera, map, options_.diagnose, result.map.name(), diagnoser);
        result.verified = true;
        result.report = verified.run.report;
        result.diagnosed = verified.diagnosed;
        result.diagnosis = verified.diagnosis;
        if (keep) *keep = std::move(verified);
    } catch (const Error& e) {
        result.error = e.what();
    }
    result.seconds = secondsSince(start);
    return result;
}

namespace {

struct OtherFrame {
    long offset;
    const char *name, *phrase, *whose;
};
constexpr OtherFrame kOtherFrames[] = {
    {-1, "previous-frame-camera", "consistent with the previous frame's camera", "the previous frame's"},
    {+1, "next-frame-camera", "consistent with the next frame's camera", "the next frame's"},
    {-2, "camera-2-frames-back", "consistent with the camera of two frames before", "two frames before"},
    {+2, "camera-2-frames-ahead", "consistent with the camera of two frames after", "two frames after"},
    {0, "another-frame-camera", "consistent with another frame's camera (the frames' order is not the cameras')",
     "another frame's"},
};

const OtherFrame& otherFrame(long offset)
{
    for (const OtherFrame& f : kOtherFrames)
        if (f.offset == offset) return f;
    return kOtherFrames[4];
}

}  // namespace

std::optional<std::string> datasetPhraseOf(const std::string& hypothesisName)
{
    for (const OtherFrame& f : kOtherFrames)
        if (hypothesisName == f.name) return std::string(f.phrase);
    return std::nullopt;
}

std::optional<Hypothesis> DatasetRunner::impliedScaleOnFloat(const DatasetFrame& frame, const FramePlan& plan,
                                                             const MapVerifier& verifier, const DepthMapFile& file,
                                                             const Camera& camera, const DepthMap& map) const
{
    // Only where the implied scale was used (no --scale, no manifest scale) on a float file.
    if (frame.scale || options_.scale || !frame.impliedScale || file.valueQuantum > 0 || !(plan.reading.scale > 0))
        return std::nullopt;
    DepthMap asStored = map;  // read with scale 1: the stored value plus the offset
    for (double& v : asStored.value) v = map.storedOf(v) + map.offset;
    asStored.scale = 0;
    for (float& step : asStored.valueStep) step = float(step * plan.reading.scale);
    const VerifyResult run = verifier.verify(camera, asStored);
    if (!run.comparison.report.consistent() || run.comparison.report.bothHit == 0) return std::nullopt;
    Hypothesis h;
    h.name = "implied-scale-on-float";
    h.explanation = "consistent read as stored: the map holds floats already in scene units, which the camera file's "
                    "implied depth scale (" + frame.impliedScaleNote + ") divided by " + formatNumber(plan.reading.scale) +
                    ": pass --scale 1 (nerfstudio applies depth_unit_scale_factor to .npy and float files too, so write "
                    "\"depth_unit_scale_factor\": 1 into the file for nerfstudio as well)";
    h.consistent = true;
    const ComparisonReport& r = run.comparison.report;
    h.compared = r.bothHit + r.rayOnly + r.rasterOnly;
    h.fitted.push_back({"value_scale", 1.0, plan.reading.scale});
    return h;
}

std::optional<Hypothesis> DatasetRunner::otherFrameCamera(std::size_t index, const FramePlan& plan,
                                                          const MapVerifier& verifier, const DepthMapFile& file,
                                                          const Camera& camera, const DepthMap& map) const
{
    const Scene& scene = verifier.checker().scene();
    // Frame j's camera for this map (its size, near and far from this scene and map); none where
    // frame j cannot give one or it images the world as this frame's own does.
    auto cameraOf = [&](std::size_t j) -> std::optional<Camera> {
        const DatasetFrame& other = dataset_.frames[j];
        if (j == index || !other.camera || !other.error.empty() || other.scene.value_or(options_.scene) != plan.scene)
            return std::nullopt;
        try {
            CameraForMap made = completeCameraForMap(*other.camera, &scene, plan.given, plan.quantity,
                                                     [&](int, int) { return file; });
            if (!options_.convention.empty()) made.spec.convention = Convention::preset(options_.convention);
            Camera c(made.spec);
            if (c.worldFromClip == camera.worldFromClip) return std::nullopt;
            return c;
        } catch (const Error&) {
            return std::nullopt;
        }
    };
    auto hypothesisFor = [&](std::size_t j, const VerifyResult& run) {
        const long offset = long(j) - long(index);
        const OtherFrame& f = otherFrame(offset);
        Hypothesis h;
        h.name = f.name;
        h.explanation = std::string(f.phrase) + ": frame '" + dataset_.frames[index].name + "''s map matches frame '" +
                        dataset_.frames[j].name + "''s camera (" + f.whose + ", " + (offset > 0 ? "+" : "") +
                        std::to_string(offset) + "): the cameras and the maps are paired wrongly (a frame number "
                        "off by one, Blender's frame_current against the frame rendered, a list shifted or shuffled)";
        h.consistent = true;
        const ComparisonReport& r = run.comparison.report;
        h.compared = r.bothHit + r.rayOnly + r.rasterOnly;
        h.fitted.push_back({"camera_frame_offset", double(offset), 0});
        return h;
    };
    const RayRenderer& rays = verifier.checker().rayRenderer();
    auto judge = [&](std::size_t j, const Camera& c) -> std::optional<Hypothesis> {
        if (probeAgreement(scene, rays, c, map).rulesOut()) return std::nullopt;
        const VerifyResult run = verifier.verify(c, map);
        if (!run.comparison.report.consistent() || run.comparison.report.bothHit == 0) return std::nullopt;
        return hypothesisFor(j, run);
    };
    const long n = long(dataset_.frames.size());
    for (const long offset : {-1L, +1L, -2L, +2L}) {
        const long j = long(index) + offset;
        if (j < 0 || j >= n) continue;
        if (const std::optional<Camera> c = cameraOf(std::size_t(j)))
            if (std::optional<Hypothesis> h = judge(std::size_t(j), *c)) return h;
    }
    // Shuffled: every other frame probed, the three closest judged in full.
    std::vector<std::pair<double, std::size_t>> probed;
    for (long j = 0; j < n; ++j) {
        if (std::labs(j - long(index)) <= 2) continue;
        if (const std::optional<Camera> c = cameraOf(std::size_t(j))) {
            const Probe probe = probeAgreement(scene, rays, *c, map);
            if (!probe.rulesOut()) probed.emplace_back(probe.agreeing, std::size_t(j));
        }
    }
    std::sort(probed.begin(), probed.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t k = 0; k < probed.size() && k < 3; ++k)
        if (const std::optional<Camera> c = cameraOf(probed[k].second))
            if (std::optional<Hypothesis> h = judge(probed[k].second, *c)) return h;
    return std::nullopt;
}

void DatasetRunner::run(const std::vector<std::size_t>& frames, const std::function<void(FrameResult&&)>& done) const
{
    std::mutex doneMutex;
    std::atomic<bool> stop{false};
    std::exception_ptr failure;
    // Each frame is itself parallel inside (the trace, the raster, the comparison); running
    // frames side by side too keeps the threads busy while one frame reads its file.
    tbb::parallel_for_each(frames.begin(), frames.end(), [&](std::size_t index) {
        if (stop) return;
        FrameResult result = verify(index);
        const std::lock_guard<std::mutex> lock(doneMutex);
        if (stop) return;
        try {
            done(std::move(result));
        } catch (...) {
            failure = std::current_exception();
            stop = true;
        }
    });
    if (failure) std::rethrow_exception(failure);
}

}  // namespace zcheck
