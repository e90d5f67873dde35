// zcheck suite: every configuration clean and with each injectable mistake of the catalogue.
#include "common.h"

#include "zcheck/atomic_file.h"
#include "zcheck/error.h"
#include "zcheck/report.h"
#include "zcheck/suite.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace zcheck::cli {

namespace {

struct SuiteOptions {
    bool quick = false;
    std::string filter, jsonFile, htmlFile, modelsDir;
    int threads = 0;
};

int runSuiteCommand(const SuiteOptions& o)
{
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;  // validated now, not after a long run
    if (!o.jsonFile.empty()) outputs.add(o.jsonFile, "--json");
    if (!o.htmlFile.empty()) outputs.add(o.htmlFile, "--html");
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
    const auto start = std::chrono::steady_clock::now();
    int failuresSoFar = 0;
    const SuiteResult result = runSuite(configs, [&](std::size_t done, std::size_t total, const ConfigOutcome& outcome) {
        for (FaultResult r : outcome.faults) failuresSoFar += r == FaultResult::Missed ? 1 : 0;
        failuresSoFar += outcome.clean.consistent() ? 0 : 1;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (terminal || done == total || done % 25 == 0)
            std::fprintf(stderr, "%s[%zu/%zu] %.0f s, failures %d: %-70.70s%s", terminal ? "\r" : "", done, total,
                         seconds, failuresSoFar, outcome.config.label().c_str(), terminal && done < total ? "" : "\n");
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "zcheck suite" << (o.quick ? " --quick" : "") << ": " << configs.size() << " configurations x "
              << injectableMistakes().size() << " faults in " << std::lround(seconds) << " s\n\n"
              << suiteTable(result) << "\nverdict    " << (result.passed() ? "PASSED" : "FAILED") << "\n";

    if (!o.jsonFile.empty()) outputs.writeText(o.jsonFile, suiteReportJson(result, o.quick, seconds));
    if (!o.htmlFile.empty()) outputs.writeText(o.htmlFile, suiteReportHtml(result, seconds));
    outputs.commit();
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
    command->add_option("--json", o->jsonFile, "write the results as JSON")->check(kNonEmptyPath);
    command->add_option("--html", o->htmlFile, "write a self-contained HTML report with images of every failure")
        ->check(kNonEmptyPath);
    command->add_option("--models", o->modelsDir,
                        "folder of the shared meshes (stanford-bunny.obj, spot.obj, teapot.obj, suzanne.obj); "
                        "default: $ZCHECK_MODELS_DIR, else the built-in scenes only")
        ->check(kNonEmptyPath);
    addThreadsOption(command, o->threads);

    return {command, [o] { return runSuiteCommand(*o); }};
}

}  // namespace zcheck::cli
