#include "zcheck/dataset.h"

#include "zcheck/camera_sources.h"
#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/mesh_loader.h"

#include <tbb/parallel_for_each.h>

#include <atomic>
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
        const DepthMap map = DepthMap::of(std::move(made.map), plan.quantity, plan.reading);
        VerifiedMap verified = verifyMap(verifier, camera, map, options_.diagnose, result.map.name());
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
