#pragma once
// What `zcheck dataset verify` and `zcheck dataset submit` (dataset_submit.cpp, which hands the
// same options to every Slurm task) share: the options, how they are read and written back.
#include "common.h"

#include "zcheck/dataset.h"
#include "zcheck/dataset_source.h"

#include <optional>
#include <string>
#include <vector>

namespace zcheck::cli {

// The options `dataset verify` takes, and `dataset submit` passes on to it.
struct DatasetVerifyOptions {
    std::string source, scene = "builtin:default", quantity, depthPattern, miss, channel, cameraFormat, convention, shard;
    std::optional<double> scale, offset, near, far;
    MapAccuracy accuracy;
    std::string output;
    bool resume = false, diagnose = false;
    int threads = 0;
};

// "a COLMAP model, a transforms.json": the camera formats that are dataset sources.
std::string datasetSourceHelp();
void addDatasetVerifyOptions(CLI::App* command, DatasetVerifyOptions& o);
// The dataset `o.source` names, read with its options.
Dataset openSource(const DatasetVerifyOptions& o);
// The run's options (a shard, the readings, the declared accuracy) as the runner takes them.
DatasetRunOptions runOptions(const DatasetVerifyOptions& o);
// The command line of `dataset verify` that `o` stands for (without -o, --shard, --resume).
std::vector<std::string> verifyArgumentsOf(const DatasetVerifyOptions& o);

// Adds `dataset submit` to `dataset`; returns what runs it once parsed (dataset_submit.cpp).
std::function<int()> addDatasetSubmitCommand(CLI::App* dataset);

}  // namespace zcheck::cli
