// zcheck suite: every configuration clean and with each injectable mistake of the catalogue.
#include "common.h"

#include "zcheck/atomic_file.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/detail/clock.h"
#include "zcheck/detail/json.h"
#include "zcheck/error.h"
#include "zcheck/report.h"
#include "zcheck/suite.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace zcheck::cli {

namespace {

struct SuiteOptions {
    bool quick = false;
    std::string filter, outDir, modelsDir;
    bool json = false;
    int threads = 0;
};

// The lens part's table (suite.h): its clean configurations, then one row per mistake and variant.
std::string lensSuiteTable(const LensSuiteResult& result)
{
    std::ostringstream out;
    const int configurations = int(result.outcomes.size());
    char line[320];
    std::snprintf(line, sizeof line,
                  "lens configurations: %d consistent of %d (lens check and clean map; false positives: %d)\n\n",
                  configurations - result.falsePositives, configurations, result.falsePositives);
    out << line;
    std::snprintf(line, sizeof line, "%-24s %-40s %10s %14s %11s\n", "lens mistake", "variant", "detected",
                  "not applicable", "named");
    out << line;
    for (const LensFaultTally& row : tallyLensFaults(result)) {
        const int applicable = row.detected + row.missed;
        std::snprintf(line, sizeof line, "%-24s %-40s %4d / %-4d %14d %4d / %-4d %s\n", row.name.c_str(), row.variant.c_str(),
                      row.detected, applicable, row.notApplicable, row.named, row.detected,
                      row.missed ? "<- MISSED" : row.named < row.detected ? "<- MISNAMED" : "");
        out << line;
    }
    out << "\n(detected / applicable; named / detected: verify --diagnose's best hypothesis is the mistake.\n"
           " Not applicable: the mistaken map does not differ visibly from the clean one - the same coverage,\n"
           " values within twice the sampling noise - e.g. a mirror image of a symmetric picture.)\n";
    int shown = 0;
    for (const LensConfigOutcome& outcome : result.outcomes) {
        if (!outcome.clean() && shown++ < 20)
            out << "FALSE POSITIVE  " << outcome.config.label() << ": lens check " << (outcome.check.consistent() ? "consistent" : "INCONSISTENT")
                << ", clean map " << (outcome.cleanMap.consistent() ? "consistent" : "INCONSISTENT") << " ("
                << outcome.cleanMap.unexplained() << " unexplained)\n";
        for (const LensFaultOutcome& f : outcome.faults) {
            const bool missed = f.result == FaultResult::Missed, misnamed = f.result == FaultResult::Detected && !f.named;
            if ((missed || misnamed) && shown++ < 20)
                out << (missed ? "MISSED          " : "MISNAMED        ") << outcome.config.label() << ": " << f.name
                    << (f.variant.empty() ? "" : " (" + f.variant + ")")
                    << (misnamed ? ", diagnosed as " + f.diagnosedAs : std::string()) << "\n";
        }
    }
    if (shown > 20) out << "... and " << shown - 20 << " more (suite.json lists every one)\n";
    return out.str();
}

std::string lensKey(const std::string& name, const std::string& variant)
{
    return variant.empty() ? name : name + " (" + variant + ")";
}

nlohmann::json lensSuiteJson(const LensSuiteResult& result)
{
    nlohmann::json configurations = nlohmann::json::array();
    for (const LensConfigOutcome& outcome : result.outcomes) {
        nlohmann::json mistakes = nlohmann::json::object();
        for (const LensFaultOutcome& f : outcome.faults)
            mistakes[lensKey(f.name, f.variant)] = {{"result", toString(f.result)}, {"named", f.named},
                                                    {"diagnosed_as", f.diagnosedAs}};
        configurations.push_back({{"label", outcome.config.label()},
                                  {"scene", outcome.config.scene},
                                  {"model", outcome.config.model},
                                  {"magnitude", outcome.config.magnitude},
                                  {"quantity", toString(outcome.config.quantity)},
                                  {"camera", toJson(outcome.config.spec)},
                                  {"clean", {{"consistent", outcome.clean()},
                                             {"check_consistent", outcome.check.consistent()},
                                             {"map_consistent", outcome.cleanMap.consistent()},
                                             {"map_unexplained", outcome.cleanMap.unexplained()}}},
                                  {"mistakes", mistakes},
                                  {"milliseconds", outcome.milliseconds}});
    }
    nlohmann::json detection = nlohmann::json::object();
    for (const LensFaultTally& row : tallyLensFaults(result))
        detection[lensKey(row.name, row.variant)] = {{"name", row.name},
                                                     {"variant", row.variant},
                                                     {"detected", row.detected},
                                                     {"applicable", row.detected + row.missed},
                                                     {"not_applicable", row.notApplicable},
                                                     {"named", row.named},
                                                     {"configurations", row.configurations}};
    return {{"configurations", configurations},
            {"detection", detection},
            {"false_positives", result.falsePositives},
            {"missed_faults", result.missedFaults},
            {"misnamed_faults", result.misnamedFaults},
            {"passed", result.passed()}};
}

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
    std::vector<LensSuiteConfig> lensConfigs;
    for (auto& config : lensSuiteConfigurations(o.quick, modelsDir))
        if (o.filter.empty() || config.label().find(o.filter) != std::string::npos) lensConfigs.push_back(config);
    if (configs.empty() && lensConfigs.empty()) throw Error("--filter '" + o.filter + "' matches no configuration");
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
    const LensSuiteResult lens = runLensSuite(lensConfigs, [&](std::size_t done, std::size_t total, const LensConfigOutcome& outcome) {
        for (const LensFaultOutcome& f : outcome.faults)
            failuresSoFar += f.result == FaultResult::Missed || (f.result == FaultResult::Detected && !f.named) ? 1 : 0;
        failuresSoFar += outcome.clean() ? 0 : 1;
        const double seconds = secondsSince(start);
        if (terminal || done == total || done % 25 == 0)
            std::fprintf(stderr, "%s[lens %zu/%zu] %.0f s, failures %d: %-65.65s%s", terminal ? "\r" : "", done, total,
                         seconds, failuresSoFar, outcome.config.label().c_str(), terminal && done < total ? "" : "\n");
    });
    const bool passed = result.passed() && lens.passed();
    const double seconds = secondsSince(start);
    nlohmann::json document = nlohmann::json::parse(suiteReportJson(result, o.quick, seconds));
    document["lens"] = lensSuiteJson(lens);
    document["passed"] = passed;
    const std::string json = prettyJson(document) + "\n";
    const std::string lensTable = lensSuiteTable(lens);
    if (!o.outDir.empty()) {
        outputs.writeText((out / "suite.json").string(), json);
        std::string html = suiteReportHtml(result, seconds);
        const std::size_t end = html.rfind("</body>");
        std::string lensHtml = "<h2>Lens cameras</h2><pre>";
        for (char c : lensTable) lensHtml += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
        lensHtml += "</pre>";
        html.insert(end == std::string::npos ? html.size() : end, lensHtml);
        if (!lens.passed())  // the heading is the whole suite's verdict
            if (const std::size_t at = html.find("<h1>zcheck suite: PASSED</h1>"); at != std::string::npos)
                html.replace(at, 29, "<h1>zcheck suite: FAILED</h1>");
        outputs.writeText((out / "suite.html").string(), html);
    }
    outputs.commit();
    if (o.json)
        std::cout << json << "\n";
    else
        std::cout << "zcheck suite" << (o.quick ? " --quick" : "") << ": " << configs.size() << " configurations x "
                  << injectableMistakes().size() << " faults in " << std::lround(seconds) << " s\n\n"
                  << suiteTable(result) << "\n" << lensTable << "\nverdict    " << (passed ? "PASSED" : "FAILED") << "\n";
    return passed ? kExitConsistent : kExitInconsistent;
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
