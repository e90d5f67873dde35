// zcheck dataset: a whole dataset as one job — verify (sharded, resumable), report, import,
// submit (a Slurm job array: dataset_submit.cpp).
#include "common.h"
#include "dataset_options.h"
#include "image_plugin.h"

#include "zcheck/atomic_file.h"
#include "zcheck/camera_sources.h"
#include "zcheck/dataset.h"
#include "zcheck/dataset_report.h"
#include "zcheck/error.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <filesystem>
#include <fstream>
#include <thread>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <set>

extern char** environ;

namespace zcheck::cli {

// "a COLMAP model, a transforms.json": the camera formats that are dataset sources.
std::string datasetSourceHelp()
{
    std::string out;
    for (const CameraFormat* format : cameraFormats())
        if (format->datasetSource) out += (out.empty() ? "a " : ", a ") + format->title;
    return out;
}

void addDatasetVerifyOptions(CLI::App* command, DatasetVerifyOptions& o)
{
    command->add_option("source", o.source, datasetSourceHelp() + ", or a manifest (.jsonl)")
        ->required()
        ->check(kNonEmptyPath);
    command->add_option("--scene", o.scene, "the mesh every frame is checked against (a manifest line may name its own)")
        ->capture_default_str()
        ->check(kNonEmptyPath);
    command->add_option("--quantity", o.quantity, "what the maps hold: window | ndc | eye-z | distance (a manifest line may say)");
    command->add_option("--depth", o.depthPattern,
                        "COLMAP: each image's depth map, {name} the image name, {stem} without its extension\n"
                        "(dense/stereo/depth_maps/{name}.geometric.bin)");
    command->add_option("--scale", o.scale, "stored value = depth x scale (integer maps; replaces nerfstudio's 1000)")
        ->check(kPositiveFinite);
    command->add_option("--offset", o.offset, "added to every depth after --scale");
    command->add_option("--miss", o.miss, "the stored value meaning 'no surface': 0, 65535, 1e10, nan, inf, '>=1e9'")
        ->check(kMissRule);
    command->add_option("--channel", o.channel, "the channel or HDF5 dataset to read (depth, distance, Z, ...)");
    addAccuracyOptions(command, o.accuracy);
    command->add_option("--camera-format", o.cameraFormat, "the source's format when its content should not decide: " +
                                                            cameraFormatChoices(CameraFormatsWith::Dataset));
    command->add_option("--near", o.near, "near plane of every frame whose manifest line gives none, over its camera file's (default:\n"
                                        "the camera file's, else from the scene)")
        ->check(kPositiveFinite);
    command->add_option("--far", o.far, "far plane of every frame whose manifest line gives none, over its camera file's (default:\n"
                                       "the camera file's, else from the scene)")
        ->check(kPositiveFinite);
    command->add_option("--convention", o.convention, "replace every camera's convention");
    command->add_flag("--diagnose", o.diagnose, "diagnose the inconsistent frames (only they pay for it)");
    addThreadsOption(command, o.threads);
}

Dataset openSource(const DatasetVerifyOptions& o)
{
    DatasetSourceOptions options;
    options.depthPattern = o.depthPattern;
    if (!o.cameraFormat.empty()) options.cameraFormat = &cameraFormatNamed(o.cameraFormat);
    return openDataset(o.source, options);
}

DatasetRunOptions runOptions(const DatasetVerifyOptions& o)
{
    DatasetRunOptions options;
    options.scene = o.scene, options.quantity = o.quantity;
    options.scale = o.scale, options.offset = o.offset, options.miss = o.miss, options.channel = o.channel;
    options.accuracy = o.accuracy;
    options.near = o.near, options.far = o.far, options.convention = o.convention;
    options.diagnose = o.diagnose;
    if (!o.shard.empty()) options.parseShard(o.shard);
    return options;
}

// The command line of `dataset verify` that `o` stands for (without -o, --shard, --resume).
std::vector<std::string> verifyArgumentsOf(const DatasetVerifyOptions& o)
{
    std::vector<std::string> args = {o.source, "--scene", o.scene};
    auto add = [&](const char* option, const std::string& value) {
        if (!value.empty()) args.insert(args.end(), {option, value});
    };
    auto addNumber = [&](const char* option, const std::optional<double>& value) {
        char text[40];
        if (value) std::snprintf(text, sizeof text, "%.17g", *value), args.insert(args.end(), {option, text});
    };
    add("--quantity", o.quantity), add("--depth", o.depthPattern), add("--miss", o.miss), add("--channel", o.channel);
    add("--camera-format", o.cameraFormat), add("--convention", o.convention);
    addNumber("--scale", o.scale), addNumber("--offset", o.offset), addNumber("--near", o.near), addNumber("--far", o.far);
    auto addDeclared = [&](const char* option, double value) {
        if (value > 0) addNumber(option, value);
    };
    addDeclared("--quantum", o.accuracy.quantum), addDeclared("--rel-tolerance", o.accuracy.relative);
    addDeclared("--abs-tolerance", o.accuracy.absolute);
    if (o.accuracy.noise.any()) args.insert(args.end(), {"--noise-model", o.accuracy.noise.text()});
    if (o.accuracy.allowHoles) args.push_back("--allow-holes");
    if (o.diagnose) args.push_back("--diagnose");
    if (o.threads > 0) args.insert(args.end(), {"--threads", std::to_string(o.threads)});
    return args;
}

namespace {

// Appends records to a results file as frames finish: one write(2) per line, so a killed run
// leaves at most its last line torn (which --resume drops).
class ResultsSink {
public:
    explicit ResultsSink(const std::string& path) : path_(path) {}
    ~ResultsSink()
    {
        if (fd_ >= 0) ::close(fd_);
    }
    void truncateTo(std::uint64_t bytes)
    {
        if (::truncate(path_.c_str(), off_t(bytes)) != 0)
            throw Error("cannot drop the torn last line of results file '" + path_ + "': " + std::strerror(errno));
    }
    void write(const std::string& line)
    {
        if (path_ == "-") {
            std::fwrite(line.data(), 1, line.size(), stdout);
            std::fputc('\n', stdout);
            std::fflush(stdout);
            return;
        }
        if (fd_ < 0) {  // created with the first record: a run that verifies nothing writes nothing
            fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
            if (fd_ < 0) throw Error("cannot write results file '" + path_ + "': " + std::strerror(errno));
        }
        const std::string whole = line + "\n";
        std::size_t done = 0;
        while (done < whole.size()) {
            const ssize_t n = ::write(fd_, whole.data() + done, whole.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) throw Error("cannot write results file '" + path_ + "': " + std::strerror(errno));
            done += std::size_t(n);
        }
    }
    void finish()
    {
        if (fd_ >= 0 && ::fsync(fd_) != 0) throw Error("cannot write results file '" + path_ + "': " + std::strerror(errno));
    }

private:
    std::string path_;
    int fd_ = -1;
};

// Frames done / total, frames per second, ETA and failures on a terminal; nothing otherwise.
class Progress {
public:
    Progress(std::size_t total, std::size_t already) : total_(total), done_(already), start_(std::chrono::steady_clock::now())
    {
        enabled_ = ::isatty(STDERR_FILENO);
        base_ = already;
    }
    void frameDone(bool failed)
    {
        ++done_;
        failures_ += failed;
        if (!enabled_) return;
        const auto now = std::chrono::steady_clock::now();
        if (done_ < total_ && now - last_ < std::chrono::milliseconds(100)) return;
        last_ = now;
        const double seconds = std::chrono::duration<double>(now - start_).count();
        const double rate = seconds > 0 ? double(done_ - base_) / seconds : 0;
        const double eta = rate > 0 ? double(total_ - done_) / rate : 0;
        std::fprintf(stderr, "\rframes %zu/%zu  %.1f frames/s  ETA %d:%02d  failed %zu   ", done_, total_, rate, int(eta) / 60,
                     int(eta) % 60, failures_);
        if (done_ == total_) std::fputc('\n', stderr);
        std::fflush(stderr);
    }

private:
    bool enabled_ = false;
    std::size_t total_, done_, base_ = 0, failures_ = 0;
    std::chrono::steady_clock::time_point start_, last_{};
};

bool fileHasContent(const std::string& path)
{
    struct stat status {};
    return ::stat(path.c_str(), &status) == 0 && status.st_size > 0;
}

namespace fs = std::filesystem;


int runDatasetVerify(const DatasetVerifyOptions& o)
{
    const auto threadLimit = limitThreads(o.threads);
    const std::string output = o.output.empty() ? "-" : o.output;
    if (o.resume && output == "-") throw Error("--resume completes a results file: give it with -o FILE");
    if (output != "-") {
        OutputFiles check;  // the path rules (a folder, an input, a missing parent) before any work
        check.addInput(o.source);
        check.addInput(o.scene.rfind("builtin:", 0) == 0 ? "" : o.scene);
        check.add(output, "-o");
    }
    if (!o.resume && output != "-" && fileHasContent(output))
        throw Error("results file '" + output + "' exists: --resume completes it; remove it to start over");
    const DatasetRunner runner(openSource(o), runOptions(o), [](const std::string& path, const DepthMapReading& reading,
                                                               int width, int height) {
        return readDepthMapFile(path, reading, width, height);
    });
    ResultsSink sink(output);
    std::set<std::size_t> done;
    std::vector<FrameRecord> previous;
    if (o.resume && fileHasContent(output)) {
        const ResultsFile existing = readResults(output);
        for (const FrameRecord& r : existing.records) {
            if (r.source != runner.dataset().source || r.of != runner.dataset().frames.size())
                throw Error("results file '" + output + "' line " + std::to_string(r.line) + " is of dataset '" + r.source +
                            "' (" + std::to_string(r.of) + " frames), not this run's '" + runner.dataset().source + "' (" +
                            std::to_string(runner.dataset().frames.size()) + " frames)");
            if (done.insert(r.index).second) previous.push_back(r);
        }
        if (existing.torn) sink.truncateTo(existing.completeBytes);
    }
    std::vector<std::size_t> frames;
    for (std::size_t i : runner.shardFrames())
        if (!done.count(i)) frames.push_back(i);
    Progress progress(runner.shardFrames().size(), runner.shardFrames().size() - frames.size());
    bool allConsistent = true;
    for (const FrameRecord& r : previous) allConsistent = allConsistent && r.consistent;
    ResultsFile thisRun;
    thisRun.path = output;
    runner.run(frames, [&](FrameResult&& result) {
        const std::string record = frameRecordJson(result);
        sink.write(record);
        allConsistent = allConsistent && result.consistent();
        progress.frameDone(!result.consistent());
        FrameRecord r = frameRecordOf(record, "frame '" + result.frame + "'");  // as `dataset report` reads it
        r.file = output;
        thisRun.records.push_back(r);
    });
    sink.finish();
    if (output != "-" && !thisRun.records.empty()) {  // the shard's frames, as `dataset report` would say
        thisRun.records.insert(thisRun.records.end(), previous.begin(), previous.end());
        std::cout << datasetSummaryText(summarizeResults({thisRun}));
    }
    return allConsistent ? kExitConsistent : kExitInconsistent;
}

// A failing frame verified again from its record, for the HTML report's pictures.
FramePictures picturesOf(FrameRecord r, const std::shared_ptr<SceneVerifiers>& verifiers)
{
    // The record's paths as `dataset verify` was given them: from where it ran, or else from the
    // results file's folder (a report made elsewhere).
    const fs::path resultsFolder = fs::path(r.file).parent_path();
    auto resolved = [&](std::string& path) {
        if (path.empty() || path.rfind("builtin:", 0) == 0 || fs::path(path).is_absolute() || fs::exists(path)) return;
        if (const fs::path there = resultsFolder / path; !resultsFolder.empty() && fs::exists(there)) path = there.string();
    };
    resolved(r.source), resolved(r.depth), resolved(r.scene);
    try {
        DatasetVerifyOptions source;
        source.source = r.source;
        source.depthPattern = "{name}";  // a COLMAP model names no depth maps: the record's file is used
        const Dataset dataset = openSource(source);
        if (r.index >= dataset.frames.size() || dataset.frames[r.index].name != r.frame)
            return FramePictures::none("the dataset '" + r.source + "' no longer has frame '" + r.frame + "' at index " + std::to_string(r.index));
        DatasetFrame frame = dataset.frames[r.index];
        frame.index = 0;
        frame.depth = r.depth;
        frame.quantity = r.quantity;
        if (!r.channel.empty()) frame.channel = r.channel;
        if (r.scale > 0) frame.scale = r.scale;
        frame.offset = r.offset;
        if (!r.miss.empty()) frame.miss = r.miss;
        frame.accuracy = r.accuracy;
        if (r.projection != "matrix") {  // the camera as it was used: near and far as recorded
            frame.near = r.near;
            if (std::isfinite(r.far)) frame.far = r.far;
        }
        DatasetRunOptions options;
        options.scene = r.scene, options.convention = r.convention;
        const DatasetRunner runner(Dataset{dataset.source, dataset.kind, {frame}}, options,
                                   [](const std::string& path, const DepthMapReading& reading, int width, int height) {
                                       return readDepthMapFile(path, reading, width, height);
                                   },
                                   verifiers);
        VerifiedMap kept;
        const FrameResult again = runner.verify(0, &kept);
        if (!again.error.empty()) return FramePictures::none(again.error);
        return framePictures(kept);
    } catch (const Error& e) {
        return FramePictures::none(e.what());
    }
}

int runDatasetReport(const std::vector<std::string>& files, const std::string& outDir, bool json)
{
    OutputFiles outputs;
    for (const std::string& f : files) outputs.addInput(f);
    const std::string summaryFile = (fs::path(outDir) / "summary.json").string(), htmlFile = (fs::path(outDir) / "report.html").string();
    if (!outDir.empty()) {
        outputs.addFolder(outDir, "--out");
        outputs.add(summaryFile, "--out");
        outputs.add(htmlFile, "--out");
    }
    std::vector<ResultsFile> results;
    for (const std::string& f : files) results.push_back(readResults(f));
    const DatasetSummary summary = summarizeResults(results);
    const std::string summaryJson = datasetSummaryJson(summary) + "\n";
    if (!outDir.empty()) {
        outputs.writeText(summaryFile, summaryJson);
        const auto verifiers = std::make_shared<SceneVerifiers>();
        std::vector<std::string> missing;  // said on the terminal too, not only in the page
        outputs.writeText(htmlFile, datasetReportHtml(summary, [&](const FrameRecord& r) {
                              FramePictures p = picturesOf(r, verifiers);
                              if (!p.unavailable.empty()) missing.push_back("frame '" + r.frame + "': " + p.unavailable);
                              return p;
                          }));
        for (const std::string& m : missing) std::cerr << "zcheck: note: no pictures of " << m << "\n";
    }
    outputs.commit();
    std::cout << (json ? summaryJson : datasetSummaryText(summary));
    const bool all = summary.missing.empty() && summary.consistent == summary.frames;
    return all ? kExitConsistent : kExitInconsistent;
}

int runDatasetImport(const DatasetVerifyOptions& o, const std::string& manifest)
{
    OutputFiles outputs;
    outputs.addInput(o.source);
    outputs.add(manifest, "-o");
    const Dataset dataset = openSource(o);
    if (dataset.kind == "manifest") throw Error("'" + o.source + "' is a manifest already");
    std::string text;
    std::size_t skipped = 0;
    for (const DatasetFrame& frame : dataset.frames) {
        if (!frame.camera) {
            ++skipped;
            continue;
        }
        text += manifestLine(frame, o.source + "#" + frame.name, manifest) + "\n";
    }
    outputs.writeText(manifest, text);
    outputs.commit();
    std::cout << "wrote " << dataset.frames.size() - skipped << " frames of " << dataset.kind << " '" << o.source << "' to "
              << manifest << "\n";
    return kExitConsistent;
}

}  // namespace

Command addDatasetCommand(CLI::App& app)
{
    CLI::App* dataset = app.add_subcommand(
        "dataset", "A dataset of depth maps as one job: verify every frame of " + datasetSourceHelp() + " or a\n"
                   "manifest (sharded, resumable), report on results, import a source as a manifest, or submit\n"
                   "the job to a Slurm cluster.");
    dataset->require_subcommand(1);

    auto verify = std::make_shared<DatasetVerifyOptions>();
    CLI::App* verifyCommand = dataset->add_subcommand(
        "verify", "Verify every frame (of a shard) against its scene; one JSON line per frame, appended as it finishes.\n"
                  "Exit 0 when every frame is consistent, 1 when any is not (or could not be read), 2 for a bad\n"
                  "source or option. Example:\n"
                  "  zcheck dataset verify transforms.json --scene mesh.ply --quantity eye-z -o results.jsonl");
    addDatasetVerifyOptions(verifyCommand, *verify);
    verifyCommand->add_option("--shard", verify->shard, "I/N: frames I, I+N, I+2N, ... (N tasks cover the dataset once)");
    verifyCommand->add_option("-o,--output", verify->output, "the results file (JSON Lines); '-' or none: standard output")
        ->type_name("FILE");
    verifyCommand->add_flag("--resume", verify->resume,
                            "complete the -o file: frames already in it are skipped, a torn last line is dropped");

    struct ReportOptions {
        std::vector<std::string> files;
        std::string outDir;
        bool json = false;
    };
    auto report = std::make_shared<ReportOptions>();
    CLI::App* reportCommand = dataset->add_subcommand(
        "report", "Merge result files (of shards, resumed runs) and say what they hold: frames consistent,\n"
                  "inconsistent, in error, missing or recorded twice, the mistakes found, the worst frames.");
    reportCommand->add_option("results", report->files, "results files (JSON Lines)")->required()->check(kNonEmptyPath);
    reportCommand->add_option("--out", report->outDir,
                              "the folder to write summary.json (the summary as JSON) and report.html (a self-contained "
                              "page with the worst frames' pictures) into, both or neither")->type_name("DIR")
        ->check(kNonEmptyPath);
    reportCommand->add_flag("--json", report->json, "print the summary as JSON instead of text");

    auto import = std::make_shared<DatasetVerifyOptions>();
    auto manifest = std::make_shared<std::string>();
    CLI::App* importCommand = dataset->add_subcommand(
        "import", "Write the manifest (JSON Lines, one frame a line) a dataset source implies.");
    importCommand->add_option("source", import->source, datasetSourceHelp())->required()->check(kNonEmptyPath);
    importCommand->add_option("--depth", import->depthPattern, "COLMAP: the depth map pattern ({name}, {stem})");
    importCommand->add_option("--camera-format", import->cameraFormat, "the source's format when its content should not decide: " +
                                                                       cameraFormatChoices(CameraFormatsWith::Dataset));
    importCommand->add_option("-o,--output", *manifest, "the manifest to write")
        ->type_name("FILE")->required()->check(kNonEmptyPath);


    const std::function<int()> runSubmit = addDatasetSubmitCommand(dataset);

    return {dataset, [=] {
                if (verifyCommand->parsed()) return runDatasetVerify(*verify);
                if (reportCommand->parsed()) return runDatasetReport(report->files, report->outDir, report->json);
                if (importCommand->parsed()) return runDatasetImport(*import, *manifest);
                return runSubmit();
            }};
}

}  // namespace zcheck::cli
