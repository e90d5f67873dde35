// zcheck suite: every configuration clean and with each injectable mistake of the catalogue.
#include "common.h"

#include "zcheck/atomic_file.h"
#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/report.h"
#include "zcheck/suite.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace zcheck::cli {

namespace {

struct SuiteOptions {
    bool quick = false;
    std::string filter, outDir, modelsDir;
    bool json = false;
    int threads = 0;
};

int runSuiteCommand(const SuiteOptions& o)
{
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;  // validated now, not after a long run
    const std::filesystem::path out(o.outDir);
    if (!o.outDir.empty()) {
        outputs.addFolder(o.outDir, "--out");
        outputs.add((out / "suite.json").string(), "--out");
        outputs.add((out / "suite.html").string(), "--out");
    }
    std::vector<SuiteConfig> configs;
    std::string modelsDir = o.modelsDir;
    if (const char* fromEnvironment = std::getenv("ZCHECK_MODELS_DIR"); modelsDir.empty() && fromEnvironment)
        modelsDir = fromEnvironment;
    if (modelsDir.empty())
        std::fprintf(stderr, "zcheck suite: no --models folder (or ZCHECK_MODELS_DIR): built-in scenes only\n");
    for (auto& config : suiteConfigurations(o.quick, modelsDir))
        if (o.filter.empty() || config.label().find(o.filter) != std::string::npos) configs.push_back(config);
    if (configs.empty()) throw Error("--filter '" + o.filter + "' matches no configuration");
    const bool terminal = ::isatty(2);
    const auto start = Clock::now();
    int failuresSoFar = 0;
    const SuiteResult result = runSuite(configs, [&](std::size_t done, std::size_t total, const ConfigOutcome& outcome) {
        for (FaultResult r : outcome.faults) failuresSoFar += r == FaultResult::Missed ? 1 : 0;
        failuresSoFar += outcome.clean.consistent() ? 0 : 1;
        const double seconds = secondsSince(start);
        if (terminal || done == total || done % 25 == 0)
            std::fprintf(stderr, "%s[%zu/%zu] %.0f s, failures %d: %-70.70s%s", terminal ? "\r" : "", done, total,
                         seconds, failuresSoFar, outcome.config.label().c_str(), terminal && done < total ? "" : "\n");
    });
    const double seconds = secondsSince(start);
    const std::string json = suiteReportJson(result, o.quick, seconds);
    if (!o.outDir.empty()) {
        outputs.writeText((out / "suite.json").string(), json);
        outputs.writeText((out / "suite.html").string(), suiteReportHtml(result, seconds));
    }
    outputs.commit();
    if (o.json)
        std::cout << json << "\n";
    else
        std::cout << "zcheck suite" << (o.quick ? " --quick" : "") << ": " << configs.size() << " configurations x "
                  << injectableMistakes().size() << " faults in " << std::lround(seconds) << " s\n\n"
                  << suiteTable(result) << "\nverdict    " << (result.passed() ? "PASSED" : "FAILED") << "\n";
    return result.passed() ? kExitConsistent : kExitInconsistent;
}

}  // namespace

Command addSuiteCommand(CLI::App& app)
{
    auto o = std::make_shared<SuiteOptions>();
    CLI::App* command = app.add_subcommand(
        "suite", "Run the consistency suite: every configuration clean (no false positive allowed) and with each\n"
                 "fault of the catalogue injected into one route (each applicable fault must be detected).\n"
                 "Exit status 0 only when both hold.");
    command->add_flag("--quick", o->quick, "a representative subset (what CTest runs)");
    command->add_option("--filter", o->filter, "only configurations whose label contains TEXT");
    command->add_option("--out", o->outDir,
                        "the folder to write suite.json (every configuration and fault with its result) and suite.html (a "
                        "self-contained report with images of every failure) into, both or neither")->type_name("DIR")
        ->check(kNonEmptyPath);
    command->add_flag("--json", o->json, "print the results as JSON instead of the table");
    command->add_option("--models", o->modelsDir,
                        "folder of the shared meshes (stanford-bunny.obj, spot.obj, teapot.obj, suzanne.obj); "
                        "default: $ZCHECK_MODELS_DIR, else the built-in scenes only")
        ->check(kNonEmptyPath);
    addThreadsOption(command, o->threads);

    return {command, [o] { return runSuiteCommand(*o); }};
}

}  // namespace zcheck::cli
