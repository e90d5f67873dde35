#pragma once
// Reports, for people and for programs: every document zcheck prints or writes, as text
// (library zcheck::report). They format results already computed — a check, a verification
// and its diagnosis (verifyMap, verify_map.h), the suite — and run nothing themselves.
// JSON documents are indented for people, with arrays of numbers (matrix rows, vectors) on
// one line; invalid UTF-8 in strings (file names) is replaced, never thrown over. The keys
// are those docs/ documents for `--json` (docs/tolerance.md, verify.md, diagnosis.md, datasets.md).
#include "zcheck/checker.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/precision.h"
#include "zcheck/suite.h"
#include "zcheck/verify_map.h"

#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

// `zcheck check --json`: the report of one check.
std::string checkReportJson(const CheckReport& report);
// The human-readable summary `zcheck check` prints; `comparing` names the two sides.
std::string formatSummary(const CheckReport& report,
                          const std::string& comparing = "ray route (Embree) vs raster route (z-buffer)");

// `zcheck verify --json`: the check report plus the map's source and, when given, the diagnosis.
std::string verifyReportJson(const CheckReport& report, const DepthMapSource& source,
                             const std::vector<Hypothesis>* diagnosis = nullptr);
// One verification (verifyMap's result, verify_map.h) as `zcheck verify` reports it: the JSON
// document, with the diagnosis when it was diagnosed, and the summary, the diagnosis lines
// included. The command line and the Python module both format it here.
struct VerificationReport {
    std::string json;      // `zcheck verify --json`
    std::string summary;   // `zcheck verify`
};
VerificationReport formatVerification(const VerifiedMap& verified, const DepthMapSource& source);

// The diagnosis lines for people: the best hypothesis (and up to three more that also explain
// the map, or all of it but a handful of edge pixels), or the closest one — unless it leaves at
// least half of the `compared` pixels (where either side sees a surface, as the map was read)
// unexplained ("none comes close"), or fewer than kFewestToDiagnose pixels were compared.
inline constexpr std::int64_t kFewestToDiagnose = 100;
// Whether an inconsistent best hypothesis may be offered as the closest: enough compared pixels,
// and it leaves fewer than half of them unexplained.
inline bool comesClose(const Hypothesis& best, std::int64_t compared)
{
    return compared >= kFewestToDiagnose && 2 * best.unexplained < compared;
}
std::string formatDiagnosis(const std::vector<Hypothesis>& hypotheses, std::int64_t compared);

// The suite: the detection table, and the whole run as JSON and as self-contained HTML (with
// images of every kept failure).
std::string suiteTable(const SuiteResult& result);
std::string suiteReportJson(const SuiteResult& result, bool quick, double seconds);
std::string suiteReportHtml(const SuiteResult& result, double seconds);

// `zcheck precision --json`.
std::string precisionJson(const CameraSpec& spec, const PrecisionTable& table);

}  // namespace zcheck
