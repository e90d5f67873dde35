#include "zcheck/dataset_report.h"

#include "zcheck/dataset.h"
#include "zcheck/inverse_projection.h"

#include "report_json.h"
#include "zcheck/detail/depth_map_json.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/png_file.h"
#include "zcheck/report.h"
#include "zcheck/report_images.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>
#include <set>
#include <sstream>

namespace zcheck {

using nlohmann::json;

std::string frameRecordJson(const FrameResult& r)
{
    json record = {{"frame", r.frame}, {"index", r.index}, {"of", r.of}, {"source", r.source}, {"scene", r.scene},
                   {"consistent", r.consistent()}, {"error", r.error.empty() ? json(nullptr) : json(r.error)},
                   {"seconds", r.seconds}, {"depth_map", reportjson::depthMapJson(r.map)}};
    if (r.verified) {
        const CameraSpec& camera = r.report.camera;
        record["camera"] = {{"convention", camera.convention.name}, {"type", toString(camera.projection.type)},
                            {"width", camera.width}, {"height", camera.height}, {"near", camera.projection.near},
                            {"far", std::isinf(camera.projection.far) ? json("inf") : json(camera.projection.far)}};
        record["pixels"] = reportjson::pixelsJson(r.report);
        record["depth_error"] = reportjson::depthErrorJson(r.report);
        record["map_errors"] = reportjson::mapErrorsJson(r.report);
        record["out_of_range"] = reportjson::outOfRangeJson(r.report);
        record["declared_accuracy_refused"] = reportjson::declaredRefusedJson(r.report);
        record["unexplained"] = reportjson::unexplainedJson(r.report, false);
        record["warnings"] = r.report.warnings;
    }
    if (r.diagnosed) {
        json list = json::array();
        for (const Hypothesis& h : r.diagnosis)
            if (h.explains()) list.push_back(reportjson::hypothesisJson(h));
        record["diagnosis"] = list;
        const ComparisonReport& c = r.report.comparison;
        if (list.empty() && !r.diagnosis.empty() && comesClose(r.diagnosis.front(), c.bothHit + c.rayOnly + c.rasterOnly)) {
            const Hypothesis& best = r.diagnosis.front();
            record["closest"] = {{"hypothesis", best.name}, {"variant", best.variant}, {"unexplained", best.unexplained}};
        }
    }
    return record.dump(-1, ' ', false, json::error_handler_t::replace);
}

namespace {

FrameRecord recordFrom(const json& j, const std::string& where)
{
    auto fail = [&](const std::string& why) -> FrameRecord { throw Error(where + ": " + why); };
    if (!j.is_object()) return fail("a result is a JSON object");
    auto string = [&](const char* key) {
        if (!j.contains(key) || !j[key].is_string()) fail(std::string("'") + key + "' must be a string");
        return j[key].get<std::string>();
    };
    auto count = [&](const char* key) {
        if (!j.contains(key) || !j[key].is_number_unsigned()) fail(std::string("'") + key + "' must be a whole number");
        return std::size_t(j[key].get<std::uint64_t>());
    };
    FrameRecord r;
    r.frame = string("frame");
    r.source = string("source");
    r.scene = string("scene");
    r.index = count("index");
    r.of = count("of");
    if (r.index >= r.of) fail("'index' " + std::to_string(r.index) + " is not below 'of' " + std::to_string(r.of));
    if (!j.contains("consistent") || !j["consistent"].is_boolean()) fail("'consistent' must be true or false");
    r.consistent = j["consistent"].get<bool>();
    if (j.contains("error") && j["error"].is_string()) r.error = j["error"].get<std::string>();
    if (j.contains("seconds") && j["seconds"].is_number()) r.seconds = j["seconds"].get<double>();
    if (j.contains("depth_map") && j["depth_map"].is_object()) {
        const json& m = j["depth_map"];
        auto text = [&](const char* key) { return m.contains(key) && m[key].is_string() ? m[key].get<std::string>() : std::string(); };
        r.depth = text("file"), r.quantity = text("quantity"), r.channel = text("channel"), r.miss = text("miss");
        if (m.contains("scale") && m["scale"].is_number()) r.scale = m["scale"].get<double>();
        if (m.contains("offset") && m["offset"].is_number()) r.offset = m["offset"].get<double>();
        if (m.contains("declared") && m["declared"].is_object()) r.accuracy = accuracyFromJson(m["declared"], where);
    }
    if (j.contains("camera") && j["camera"].is_object()) {
        const json& c = j["camera"];
        if (c.contains("convention") && c["convention"].is_string()) r.convention = c["convention"].get<std::string>();
        if (c.contains("type") && c["type"].is_string()) r.projection = c["type"].get<std::string>();
        if (c.contains("near") && c["near"].is_number()) r.near = c["near"].get<double>();
        if (c.contains("far") && c["far"].is_number()) r.far = c["far"].get<double>();
        if (c.contains("far") && c["far"] == "inf") r.far = INFINITY;
    }
    auto number = [](const json& object, const char* key) {
        return object.is_object() && object.contains(key) && object[key].is_number() ? object[key].get<double>() : 0.0;
    };
    if (j.contains("pixels")) {
        const json& p = j["pixels"];
        r.depthErrors = std::int64_t(number(p, "depth_errors"));
        // "raster_only": results written before verify called the map "map".
        r.compared = std::int64_t(number(p, "both_hit") + number(p, "ray_only") + number(p, "map_only") +
                                  number(p, "raster_only"));
    }
    if (j.contains("depth_error")) {
        const json& e = j["depth_error"];
        r.maxOverTolerance = number(e, "max_over_tolerance");
        r.maxRelativeEyeZ = number(e, "max_relative_eye_z");
        r.p99RelativeEyeZ = number(e, "p99_relative_eye_z");
    }
    if (j.contains("unexplained")) r.unexplained = std::int64_t(number(j["unexplained"], "count"));
    if (j.contains("warnings") && j["warnings"].is_array())
        for (const json& w : j["warnings"])
            if (w.is_string()) r.warnings.push_back(w.get<std::string>());
    if (j.contains("declared_accuracy_refused") && j["declared_accuracy_refused"].is_string())
        r.declaredRefused = j["declared_accuracy_refused"].get<std::string>();
    if (j.contains("diagnosis") && j["diagnosis"].is_array())
        for (const json& h : j["diagnosis"])
            if (h.is_object() && h.contains("hypothesis") && h["hypothesis"].is_string()) {
                r.explainedBy.push_back(h["hypothesis"].get<std::string>());
                r.explanations.push_back(h.contains("explanation") && h["explanation"].is_string() ? h["explanation"].get<std::string>() : "");
            }
    if (j.contains("closest") && j["closest"].is_object() && j["closest"].contains("hypothesis") &&
        j["closest"]["hypothesis"].is_string())
        r.closest = j["closest"]["hypothesis"].get<std::string>();
    return r;
}

}  // namespace

ResultsFile readResults(const std::string& path)
{
    ResultsFile out;
    out.path = path;
    const std::string text = readInputFile(path, kResultsInput);
    std::size_t start = 0, line = 0;
    while (start < text.size()) {
        const std::size_t end = text.find('\n', start);
        ++line;
        if (end == std::string::npos) {  // a last line cut off by a killed writer
            out.torn = true;
            break;
        }
        const std::string content = text.substr(start, end - start);
        if (content.find_first_not_of(" \t\r") != std::string::npos) {
            const std::string where = "results file '" + path + "' line " + std::to_string(line);
            FrameRecord record = recordFrom(parseJsonStrictly(content, where), where);
            record.file = path, record.line = line;
            out.records.push_back(std::move(record));
        }
        start = end + 1;
        out.completeBytes = start;
    }
    return out;
}

FrameRecord frameRecordOf(const std::string& recordJson, const std::string& where)
{
    return recordFrom(json::parse(recordJson), where);
}

DatasetSummary summarizeResults(const std::vector<ResultsFile>& files)
{
    DatasetSummary s;
    std::map<std::size_t, const FrameRecord*> first;
    std::map<std::size_t, std::vector<const FrameRecord*>> seen;
    for (const ResultsFile& file : files)
        for (const FrameRecord& r : file.records) {
            if (s.frames == 0) s.source = r.source, s.frames = r.of;
            if (r.of != s.frames || r.source != s.source)
                throw Error("results file '" + r.file + "' line " + std::to_string(r.line) + " is of dataset '" + r.source +
                            "' (" + std::to_string(r.of) + " frames), not '" + s.source + "' (" + std::to_string(s.frames) +
                            " frames): results of different datasets do not merge");
            seen[r.index].push_back(&r);
            first.emplace(r.index, &r);
        }
    if (first.empty()) throw Error("no results to report: the files hold no complete record");
    for (const auto& [index, records] : seen)
        if (records.size() > 1) {
            std::string where;
            for (const FrameRecord* r : records) where += (where.empty() ? "" : ", ") + r->file + " line " + std::to_string(r->line);
            s.duplicates.push_back("frame '" + records[0]->frame + "' (index " + std::to_string(index) + "): " + where);
        }
    for (std::size_t i = 0; i < s.frames; ++i)
        if (!first.count(i)) s.missing.push_back(i);
    std::map<std::string, std::size_t> explanationCount;
    std::map<std::string, std::string> explanationOf;
    for (const auto& [index, r] : first) {
        s.all.push_back(*r);
        s.seconds += r->seconds;
        if (!r->error.empty()) ++s.errors;
        else if (r->consistent) ++s.consistent;
        else ++s.inconsistent;
        if (r->error.empty() && !r->consistent && !r->explainedBy.empty()) {
            ++s.byMistake[r->explainedBy.front()];
            // A frame's own words, or what the hypothesis says of any frame (another frame's camera).
            explanationOf.emplace(r->explainedBy.front(),
                                  datasetPhraseOf(r->explainedBy.front()).value_or(r->explanations.front()));
        }
    }
    s.recorded = first.size();
    // What was assumed, once for the dataset: the same sentence for many frames (nerfstudio's
    // default millimetres) said once, with its count.
    // Sentences that differ only in their numbers (each frame's near and far) are one note, said
    // with "…" where the numbers differ.
    struct Note {
        std::string text;
        std::size_t frames = 0;
    };
    std::map<std::string, Note> byShape;
    const std::regex number(R"([-+]?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?)");
    for (const FrameRecord& r : s.all)
        for (const std::string& w : r.warnings) {
            Note& note = byShape[std::regex_replace(w, number, "…")];
            if (note.frames++ == 0) note.text = w;
            else if (note.text != w) note.text = std::regex_replace(w, number, "…");
        }
    for (const auto& [shape, note] : byShape) s.notes.emplace_back(note.text, note.frames);
    std::stable_sort(s.notes.begin(), s.notes.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    // The dataset's verdict, once, when most frames fail the same way.
    for (const auto& [name, count] : s.byMistake)
        if (2 * count > s.recorded) {
            s.diagnosis = std::to_string(count) + " of " + std::to_string(s.recorded) + " frames " +
                        (explanationOf[name].empty() ? "are explained by " + name : explanationOf[name]) + " (" + name + ")";
        }
    std::vector<FrameRecord> failing;
    for (const FrameRecord& r : s.all)
        if (!r.consistent) failing.push_back(r);
    std::stable_sort(failing.begin(), failing.end(), [](const FrameRecord& a, const FrameRecord& b) {
        if (a.error.empty() != b.error.empty()) return b.error.empty();  // errors first: they were not even verified
        if (a.unexplained + a.depthErrors != b.unexplained + b.depthErrors)
            return a.unexplained + a.depthErrors > b.unexplained + b.depthErrors;
        return a.maxOverTolerance > b.maxOverTolerance;
    });
    if (failing.size() > 12) failing.resize(12);
    s.worst = failing;
    return s;
}

std::string datasetSummaryText(const DatasetSummary& s)
{
    std::ostringstream out;
    char line[512];
    out << "dataset    " << s.source << "  (" << s.frames << " frames)\n";
    std::snprintf(line, sizeof line, "frames     %zu recorded: %zu consistent, %zu inconsistent, %zu errors; %zu missing\n",
                  s.recorded, s.consistent, s.inconsistent, s.errors, s.missing.size());
    out << line;
    if (!s.missing.empty()) {
        out << "missing    indices";
        for (std::size_t k = 0; k < s.missing.size() && k < 20; ++k) out << " " << s.missing[k];
        out << (s.missing.size() > 20 ? " ..." : "") << "\n";
    }
    for (std::size_t k = 0; k < s.duplicates.size() && k < 10; ++k) out << "duplicate  " << s.duplicates[k] << "\n";
    if (s.duplicates.size() > 10) out << "duplicate  ... (" << s.duplicates.size() << " in all)\n";
    for (std::size_t k = 0; k < s.notes.size() && k < 3; ++k)
        out << "note       " << s.notes[k].first << " (" << s.notes[k].second << " of " << s.recorded << " frames)\n";
    if (s.notes.size() > 3) out << "note       ... (" << s.notes.size() - 3 << " more in the records' warnings)\n";
    for (const auto& [name, count] : s.byMistake) {
        std::snprintf(line, sizeof line, "mistake    %-28s %zu frames\n", name.c_str(), count);
        out << line;
    }
    for (const FrameRecord& r : s.worst) {
        if (!r.error.empty()) {
            out << "error      " << r.frame << ": " << r.error << "\n";
        } else {
            std::snprintf(line, sizeof line, "failed     %s: %lld unexplained, %lld depth errors%s%s\n", r.frame.c_str(),
                          static_cast<long long>(r.unexplained), static_cast<long long>(r.depthErrors),
                          r.explainedBy.empty() ? "" : "; consistent if ",
                          r.explainedBy.empty() ? "" : r.explainedBy.front().c_str());
            out << line;
            if (!r.declaredRefused.empty()) out << "           declared accuracy refused: " << r.declaredRefused << "\n";
        }
    }
    if (!s.diagnosis.empty()) out << "diagnosis  " << s.diagnosis << "\n";
    out << "verdict    " << datasetVerdict(s) << (datasetVerdict(s) == "CONSISTENT" ? " (every frame)" : "") << "\n";
    return out.str();
}

std::string datasetVerdict(const DatasetSummary& s)
{
    if (!s.missing.empty()) return "INCOMPLETE";
    return s.frames > 0 && s.consistent == s.frames ? "CONSISTENT" : "INCONSISTENT";
}

std::string datasetSummaryJson(const DatasetSummary& s)
{
    json worst = json::array();
    for (const FrameRecord& r : s.worst)
        worst.push_back({{"frame", r.frame}, {"index", r.index}, {"error", r.error.empty() ? json(nullptr) : json(r.error)},
                         {"unexplained", r.unexplained}, {"depth_errors", r.depthErrors},
                         {"consistent_if", r.explainedBy.empty() ? json(nullptr) : json(r.explainedBy.front())}});
    json notes = json::array();
    for (const auto& [text, count] : s.notes) notes.push_back({{"note", text}, {"frames", count}});
    json byMistake = json::object();
    for (const auto& [name, count] : s.byMistake) byMistake[name] = count;
    return prettyJson({{"source", s.source},
                       {"frames", s.frames},
                       {"recorded", s.recorded},
                       {"consistent", s.consistent},
                       {"inconsistent", s.inconsistent},
                       {"errors", s.errors},
                       {"missing", s.missing},
                       {"duplicates", s.duplicates},
                       {"by_mistake", byMistake},
                       {"verdict", datasetVerdict(s)},
                       {"diagnosis", s.diagnosis.empty() ? json(nullptr) : json(s.diagnosis)},
                       {"notes", notes},
                       {"worst", worst}});
}

FramePictures framePictures(const VerifiedMap& verified)
{
    FramePictures out;
    const Comparison& c = verified.run.comparison;
    const int W = c.report.width, H = c.report.height;
    const Camera camera(verified.run.report.camera);
    // The truth's and the map's eye-z, misses as misses (not the clear value, which would read as
    // far), on the truth's range: a rotated mesh or a wrong camera shows as a different picture.
    auto eyeZOf = [&](const RenderResult& render) {
        QuantityImage image;
        image.quantity = ExportQuantity::EyeZ, image.width = W, image.height = H, image.channels = {"Z"};
        image.missValue = NAN;
        image.value.assign(std::size_t(W) * H, NAN);
        for (int row = 0; row < H; ++row)
            for (int col = 0; col < W; ++col) {
                const std::size_t i = std::size_t(row) * W + col;
                if (render.hit(i))
                    image.value[i] = eyeZFromWindowDepth(camera, windowFromPixelCentre(camera, col, row),
                                                         render.windowDepth.value[i]);
            }
        return image;
    };
    const QuantityImage truth = eyeZOf(verified.run.truth), map = eyeZOf(verified.run.map);
    double lo = INFINITY, hi = -INFINITY;
    for (double z : truth.value)
        if (std::isfinite(z)) lo = std::min(lo, z), hi = std::max(hi, z);
    if (!(hi >= lo))
        for (double z : map.value)
            if (std::isfinite(z)) lo = std::min(lo, z), hi = std::max(hi, z);
    out.truth = pngDataUri(W, H, previewRgb(truth, lo, hi));
    out.depth = pngDataUri(W, H, previewRgb(map, lo, hi));
    out.heatmap = pngDataUri(W, H, errorHeatmapRgb(c));
    out.classes = pngDataUri(W, H, pixelClassRgb(c));
    return out;
}

namespace {

constexpr const char* kConsistentColour = "#1e8449";
constexpr const char* kInconsistentColour = "#c0392b";

std::string escaped(const std::string& text)
{
    std::string out;
    for (char c : text) out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : c == '"' ? "&quot;" : std::string(1, c);
    return out;
}

// Frames by their p99 relative eye-z error, in decades from 1e-9 to 1 (and beyond), as SVG bars
// stacked by verdict: consistent frames green below, inconsistent ones red above (an inconsistent
// frame with nothing compared sits in the first bin, red). A legend says which is which.
std::string histogramSvg(const std::vector<FrameRecord>& records)
{
    constexpr int kBins = 11;  // ≤1e-9, (1e-9, 1e-8], ..., (0.1, 1], >1
    int good[kBins] = {}, bad[kBins] = {};
    int unverified = 0;
    for (const FrameRecord& r : records) {
        if (!r.error.empty()) {
            ++unverified;
            continue;
        }
        const double e = r.p99RelativeEyeZ;
        const int bin = e <= 1e-9 ? 0 : e > 1 ? kBins - 1 : std::min(kBins - 2, int(std::ceil(std::log10(e))) + 9);
        ++(r.consistent ? good : bad)[bin];
    }
    int most = 1;
    for (int b = 0; b < kBins; ++b) most = std::max(most, good[b] + bad[b]);
    std::ostringstream svg;
    const int barWidth = 56, height = 160;
    svg << "<svg xmlns='http://www.w3.org/2000/svg' id='histogram' width='" << kBins * barWidth + 20 << "' height='" << height + 70
        << "'>";
    for (int b = 0; b < kBins; ++b) {
        const int hGood = good[b] * height / most, hBad = bad[b] * height / most;
        const int x = 10 + b * barWidth;
        svg << "<rect class='consistent' x='" << x << "' y='" << 10 + height - hGood << "' width='" << barWidth - 6
            << "' height='" << hGood << "' fill='" << kConsistentColour << "'><title>" << good[b]
            << " consistent frames</title></rect>";
        svg << "<rect class='inconsistent' x='" << x << "' y='" << 10 + height - hGood - hBad << "' width='" << barWidth - 6
            << "' height='" << hBad << "' fill='" << kInconsistentColour << "'><title>" << bad[b]
            << " inconsistent frames</title></rect>";
        if (good[b] + bad[b] > 0)
            svg << "<text x='" << x + (barWidth - 6) / 2 << "' y='" << 8 + height - hGood - hBad
                << "' font-size='11' text-anchor='middle'>" << good[b] + bad[b] << "</text>";
        const std::string label = b == 0 ? "≤1e-9" : b == kBins - 1 ? ">1" : "1e" + std::to_string(b - 9);
        svg << "<text x='" << x + (barWidth - 6) / 2 << "' y='" << height + 26 << "' font-size='11' text-anchor='middle'>"
            << label << "</text>";
    }
    svg << "<text x='10' y='" << height + 45 << "' font-size='11'>p99 relative eye-z error per frame (decades)"
        << (unverified ? "; " + std::to_string(unverified) + " frames not verified" : std::string()) << "</text>";
    svg << "<rect x='10' y='" << height + 54 << "' width='12' height='12' fill='" << kConsistentColour
        << "'/><text x='26' y='" << height + 64 << "' font-size='11'>consistent</text><rect x='110' y='" << height + 54
        << "' width='12' height='12' fill='" << kInconsistentColour << "'/><text x='126' y='" << height + 64
        << "' font-size='11'>inconsistent</text></svg>";
    return svg.str();
}

// The coverage classes' colours (report_images.h), as a legend beside the picture.
std::string classLegend()
{
    std::ostringstream html;
    html << "<div class='legend'>";
    for (const auto& [pixelClass, rgb] : pixelClassLegend())
        html << "<span><i style='background:rgb(" << int(rgb[0]) << "," << int(rgb[1]) << "," << int(rgb[2]) << ")'></i>"
             << escaped(reportjson::className(pixelClass, "map")) << "</span>";
    html << "</div>";
    return html.str();
}

// A hypothesis's explanation after "consistent if", without saying it twice.
std::string consistentIf(const std::string& explanation)
{
    return explanation.rfind("consistent", 0) == 0 ? explanation : "consistent if " + explanation;
}

}  // namespace

std::string datasetReportHtml(const DatasetSummary& s, const FramePictureMaker& pictures)
{
    std::ostringstream html;
    html << "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>zcheck dataset report: " << escaped(s.source)
         << "</title><style>body{font-family:sans-serif;margin:2em;max-width:1200px}table{border-collapse:collapse}"
            "td,th{padding:3px 10px;border-bottom:1px solid #ddd;text-align:left}.bad{color:#c0392b}.good{color:#1e8449}"
            "img{image-rendering:pixelated;max-width:360px;margin-right:8px;border:1px solid #ccc}"
            "figure{display:inline-block;margin:0 8px 8px 0;vertical-align:top}figcaption{font-size:12px;color:#555;max-width:360px}"
            ".legend{font-size:11px;max-width:360px}.legend span{display:inline-block;margin:2px 8px 2px 0}"
            ".legend i{display:inline-block;width:10px;height:10px;margin-right:3px;border:1px solid #999}</style></head><body>\n";
    const bool all = s.missing.empty() && s.consistent == s.frames;
    html << "<h1>zcheck dataset report</h1>\n<p>" << escaped(s.source) << ": " << s.frames << " frames</p>\n";
    html << "<h2 class='" << (all ? "good'>CONSISTENT: every frame" : s.missing.empty() ? "bad'>INCONSISTENT" : "bad'>INCOMPLETE")
         << "</h2>\n";
    if (!s.diagnosis.empty()) html << "<p><b>" << escaped(s.diagnosis) << "</b></p>\n";
    html << "<table><tr><th>frames recorded</th><td>" << s.recorded << "</td></tr><tr><th>consistent</th><td>" << s.consistent
         << "</td></tr><tr><th>inconsistent</th><td>" << s.inconsistent << "</td></tr><tr><th>not verified (errors)</th><td>"
         << s.errors << "</td></tr><tr><th>missing</th><td>" << s.missing.size() << "</td></tr><tr><th>recorded twice</th><td>"
         << s.duplicates.size() << "</td></tr></table>\n";
    if (!s.byMistake.empty()) {
        html << "<h3>Mistakes found</h3><table><tr><th>consistent if</th><th>frames</th></tr>";
        for (const auto& [name, count] : s.byMistake) html << "<tr><td>" << escaped(name) << "</td><td>" << count << "</td></tr>";
        html << "</table>\n";
    }
    html << "<h3>Error per frame</h3>\n" << histogramSvg(s.all) << "\n";
    if (!s.missing.empty()) {
        html << "<h3>Missing frames (indices)</h3><p>";
        for (std::size_t i : s.missing) html << i << " ";
        html << "</p>\n";
    }
    if (!s.duplicates.empty()) {
        html << "<h3>Recorded twice</h3><ul>";
        for (const std::string& d : s.duplicates) html << "<li>" << escaped(d) << "</li>";
        html << "</ul>\n";
    }
    if (!s.worst.empty()) html << "<h3>The worst frames</h3>\n";
    for (const FrameRecord& r : s.worst) {
        html << "<h4>" << escaped(r.frame) << " <small>(index " << r.index << ")</small></h4>\n";
        if (!r.error.empty()) {
            html << "<p class='bad'>not verified: " << escaped(r.error) << "</p>\n";
            continue;
        }
        html << "<p>" << r.unexplained << " unexplained pixels, " << r.depthErrors << " depth errors; p99 relative eye-z error "
             << r.p99RelativeEyeZ;
        if (!r.explainedBy.empty()) html << "; <b class='named'>" << escaped(consistentIf(r.explanations.front())) << "</b>";
        else if (!r.closest.empty()) html << "; no hypothesis explains it (closest: " << escaped(r.closest) << ")";
        html << "</p>\n";
        const FramePictures p = pictures ? pictures(r) : FramePictures::none("no pictures asked for");
        if (!p.unavailable.empty()) {
            html << "<p><i>pictures unavailable: " << escaped(p.unavailable) << "</i></p>\n";
            continue;
        }
        html << "<figure class='truth'><img src='" << p.truth << "'><figcaption>the truth: eye-z through the camera (near dark, "
             << "far yellow; black: nothing hit)</figcaption></figure>"
             << "<figure class='map'><img src='" << p.depth << "'><figcaption>the map: eye-z as read, on the truth's colours"
             << "</figcaption></figure>"
             << "<figure class='heatmap'><img src='" << p.heatmap << "'><figcaption>error / tolerance (yellow = tolerance, red "
             << "beyond, magenta unexplained coverage)</figcaption></figure><figure class='classes'><img src='" << p.classes
             << "'><figcaption>coverage classes</figcaption>" << classLegend() << "</figure>\n";
    }
    html << "</body></html>\n";
    return html.str();
}

}  // namespace zcheck
