// dataset_loop — the yardstick of `zcheck dataset verify`'s speed (not a test): the same frames
// verified by a plain loop over verifyMap in one process, every map read and every camera made
// before the clock starts. What `dataset verify` adds over it — reading files, bookkeeping,
// running frames side by side — is the difference.
//
//   dataset_loop SOURCE --scene MESH --quantity Q [--depth PATTERN] [--scale S] [--threads N] [--repeat K]
// prints "loop frames N seconds S frames_per_second F" (the best of K loops).
#include "zcheck/camera_sources.h"
#include "zcheck/dataset.h"
#include "zcheck/detail/clock.h"
#include "zcheck/image_io.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/verify_map.h"

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <memory>

using namespace zcheck;

int main(int argc, char** argv)
{
    std::string source, scene = "builtin:default", quantity = "eye-z", depth;
    int threads = 0, repeat = 3;
    std::optional<double> scale;
    CLI::App app{"dataset_loop: frames verified by a plain loop, files decoded beforehand"};
    app.add_option("source", source)->required();
    app.add_option("--scene", scene);
    app.add_option("--quantity", quantity);
    app.add_option("--depth", depth);
    app.add_option("--scale", scale);
    app.add_option("--threads", threads);
    app.add_option("--repeat", repeat);
    CLI11_PARSE(app, argc, argv);
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
    try {
        DatasetSourceOptions sourceOptions;
        sourceOptions.depthPattern = depth;
        const Dataset dataset = openDataset(source, sourceOptions);
        DatasetRunOptions options;
        options.scene = scene, options.quantity = quantity, options.scale = scale;
        const Checker checker(loadScene(scene));
        const MapVerifier verifier(checker);
        struct Frame {
            CameraSpec spec;
            DepthMap map;
        };
        std::vector<Frame> frames;
        for (const DatasetFrame& frame : dataset.frames) {
            const FramePlan plan = planFrame(frame, options);
            CameraForMap made = frameCameraAndMap(frame, plan, checker.scene(), options, readDepthMap);
            frames.push_back({made.spec, DepthMap::of(std::move(made.map), plan.quantity, plan.reading)});
        }
        double best = 1e300;
        int consistent = 0;
        for (int k = 0; k < repeat; ++k) {
            consistent = 0;
            const auto start = Clock::now();
            for (const Frame& frame : frames)
                consistent += verifyMap(verifier, Camera(frame.spec), frame.map, false).run.comparison.report.consistent();
            best = std::min(best, secondsSince(start));
        }
        std::printf("loop frames %zu consistent %d seconds %.4f frames_per_second %.2f\n", frames.size(), consistent, best,
                    double(frames.size()) / best);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "dataset_loop: %s\n", e.what());
        return 2;
    }
    return 0;
}
