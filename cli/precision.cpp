// zcheck precision: how finely each depth layout resolves eye depth for a camera.
#include "common.h"

#include "zcheck/precision.h"
#include "zcheck/report.h"

#include <cstdio>
#include <iostream>

namespace zcheck::cli {

namespace {

int runPrecisionCommand(const CameraOptions& cameraOptions, const std::string& at, bool json)
{
    const CameraSpec spec = cameraSpecFrom(cameraOptions);
    const PrecisionTable table = depthPrecision(spec, parseNumberList(at, "--at"));
    if (json) {
        std::cout << precisionJson(spec, table) << "\n";
        return kExitConsistent;
    }
    const Camera camera(spec);
    std::printf("depth precision: %s camera, near %g, far %g, %s convention\n", toString(spec.projection.type).c_str(),
                camera.nearDistance(), camera.farDistance(), spec.convention.name.c_str());
    std::printf("smallest resolvable eye-z step at eye-z d (scene units; '-' = cannot be told from the far end)\n");
    for (DepthFormat format : {DepthFormat::Unorm16, DepthFormat::Unorm24, DepthFormat::Float32}) {
        std::printf("\n%-8s %12s", toString(format).c_str(), "eye-z d");
        for (const auto& layout : table.layouts)
            if (layout.format == format) std::printf(" %24s", toString(layout.mapping).c_str());
        std::printf("\n");
        for (std::size_t i = 0; i < table.distances.size(); ++i) {
            std::printf("%-8s %12.6g", "", table.distances[i]);
            for (std::size_t k = 0; k < table.layouts.size(); ++k)
                if (table.layouts[k].format == format) {
                    const double step = table.step[k][i];
                    if (std::isfinite(step))
                        std::printf(" %13.3g (%8.2g%%)", step, 100 * step / table.distances[i]);
                    else
                        std::printf(" %24s", "-");
                }
            std::printf("\n");
        }
    }
    const PrecisionLayout& best = table.layouts[table.best];
    std::printf("\nbest for this camera: %s, %s (worst relative step %.3g over these distances)\n",
                toString(best.format).c_str(), toString(best.mapping).c_str(), table.bestWorstRelativeStep);
    return kExitConsistent;
}

}  // namespace

Command addPrecisionCommand(CLI::App& app)
{
    struct Options {
        CameraOptions camera;
        std::string at;
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "precision", "How finely each depth layout (unorm16, unorm24, float32 x standard, reversed, infinite far)\n"
                     "resolves eye depth for a camera's near/far: the eye-z step between neighbouring stored\n"
                     "values at each distance, and which layout is best.");
    addCameraOptions(command, o->camera, cameraFileHelp());
    command->get_option("--camera")->required();
    command->add_option("--at", o->at, "eye-z distances, comma-separated (default: 9 log-spaced from near to 0.95 far;\n"
                                    "an infinite far: to 10^4 near)")
        ->check(kNonEmptyList);
    command->add_flag("--json", o->json, "print JSON instead of tables");
    return {command, [o] { return runPrecisionCommand(o->camera, o->at, o->json); }};
}

}  // namespace zcheck::cli
