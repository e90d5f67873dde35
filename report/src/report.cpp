#include "zcheck/report.h"

#include "zcheck/error.h"

#include "report_json.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/detail/depth_map_json.h"
#include "zcheck/png_file.h"
#include "zcheck/report_images.h"
#include "zcheck/version.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace zcheck {

std::string reportjson::className(PixelClass c, const std::string& second)
{
    std::string name = toString(c);
    if (const std::size_t at = name.find("raster"); at != std::string::npos) name.replace(at, 6, second);
    return name;
}

namespace {

using reportjson::className;

nlohmann::json toJson(const PixelFinding& f, const std::string& second)
{
    auto depthOrNull = [](double d) { return std::isfinite(d) ? nlohmann::json(d) : nlohmann::json(nullptr); };
    return {
        {"col", f.col},
        {"row", f.row},
        {"class", className(f.pixelClass, second)},
        {"ray_window_depth", depthOrNull(f.rayWindowDepth)},
        {second + "_window_depth", depthOrNull(f.rasterWindowDepth)},
        {"error_quanta", depthOrNull(f.errorQuanta)},
        {"tolerance_quanta", depthOrNull(f.toleranceQuanta)},
        {"ray_primitive", f.rayPrimitive == kNoPrimitive ? nlohmann::json(nullptr) : nlohmann::json(f.rayPrimitive)},
        {second + "_primitive",
         f.rasterPrimitive == kNoPrimitive ? nlohmann::json(nullptr) : nlohmann::json(f.rasterPrimitive)},
    };
}

std::string percent(std::int64_t part, std::int64_t whole)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%6.2f%%", whole > 0 ? 100.0 * double(part) / double(whole) : 0.0);
    return buffer;
}

}  // namespace

namespace reportjson {

nlohmann::json pixelsJson(const CheckReport& r)
{
    const ComparisonReport& c = r.comparison;
    return {{"total", std::int64_t(c.width) * c.height},
            {"both_hit", c.bothHit},
            {"both_miss", c.bothMiss},
            {"ray_only", c.rayOnly},
            {r.secondRoute + "_only", c.rasterOnly},
            {"agree", c.agree},
            {"edge_surface", c.edgeSurface},
            {"depth_errors", c.depthErrors},
            {"coverage_explained", c.coverageExplained},
            {"lost_at_clear_value", c.lostAtClearValue},
            {"at_clip_plane", c.atClipPlane},
            {"holes", c.holes},
            {"coverage_unexplained", c.coverageUnexplained},
            {"out_of_range", c.outOfRange}};
}

nlohmann::json depthErrorJson(const CheckReport& r)
{
    const ComparisonReport& c = r.comparison;
    return {{"max_quanta", c.maxErrorQuanta},
            {"p99_quanta", c.p99ErrorQuanta},
            {"max_over_tolerance", c.maxErrorOverTolerance},
            {"max_relative_eye_z", c.maxRelativeEyeZError},
            {"p99_relative_eye_z", c.p99RelativeEyeZError},
            {"bias_samples", c.biasSamples},
            {"mean_signed_error_quanta", c.meanSignedErrorQuanta},
            {"depth_bias", c.depthBias},
            {"worst_pixel", toJson(c.worst, r.secondRoute)}};
}

nlohmann::json unexplainedJson(const CheckReport& r, bool samples)
{
    const ComparisonReport& c = r.comparison;
    nlohmann::json box = nullptr;
    if (c.unexplainedMaxCol >= 0)
        box = {{"min_col", c.unexplainedMinCol},
               {"min_row", c.unexplainedMinRow},
               {"max_col", c.unexplainedMaxCol},
               {"max_row", c.unexplainedMaxRow}};
    nlohmann::json out = {{"count", c.unexplained()}, {"bounding_box", box}};
    if (samples) {
        nlohmann::json list = nlohmann::json::array();
        for (const auto& f : c.unexplainedSamples) list.push_back(toJson(f, r.secondRoute));
        out["samples"] = list;
    }
    return out;
}

nlohmann::json mapErrorsJson(const CheckReport& r)
{
    const MapErrors& e = r.mapErrors;
    if (e.compared == 0) return nullptr;
    return {{"quantity", e.quantity},
            {"eye_z_equivalent", e.eyeZEquivalent},
            {"units", e.eyeZEquivalent ? "scene units" : "the map's units (after scale and offset)"},
            {"compared", e.compared},
            {"max_abs", e.maxAbs},
            {"p99_abs", e.p99Abs},
            {"median_abs", e.medianAbs},
            {"max_rel", e.maxRel},
            {"p99_rel", e.p99Rel},
            {"median_rel", e.medianRel},
            {"worst_pixel", {{"col", e.worstCol}, {"row", e.worstRow}, {"map", e.worstMap}, {"true", e.worstTrue}}}};
}

nlohmann::json declaredRefusedJson(const CheckReport& r)
{
    const std::string& why = r.comparison.declaredAccuracyRefused;
    return why.empty() ? nlohmann::json(nullptr) : nlohmann::json(why);
}

nlohmann::json outOfRangeJson(const CheckReport& r)
{
    const ComparisonReport& c = r.comparison;
    nlohmann::json first = nullptr;
    if (c.outOfRange > 0) first = {{"col", c.outOfRangeCol}, {"row", c.outOfRangeRow}, {"stored", c.outOfRangeValue}};
    return {{"count", c.outOfRange}, {"first", first}};
}

nlohmann::json depthMapJson(const DepthMapSource& source)
{
    const DepthMapReading& r = source.reading;
    return {{"file", source.file},
            {"quantity", source.quantity},
            {"channel", source.channel},
            {"scale", r.scale > 0 ? nlohmann::json(r.scale) : nlohmann::json(nullptr)},  // null: none given
            {"offset", r.offset.value_or(0.0)},
            {"miss", r.miss.given() ? nlohmann::json(r.miss.text()) : nlohmann::json(nullptr)},
            {"declared", toJson(r.accuracy)}};
}

nlohmann::json hypothesisJson(const Hypothesis& h)
{
    nlohmann::json fitted = nlohmann::json::array();
    for (const FittedValue& v : h.fitted) fitted.push_back({{"name", v.name}, {"value", v.value}, {"declared", v.declared}});
    return {{"hypothesis", h.name}, {"variant", h.variant}, {"explanation", h.explanation},
            {"consistent", h.consistent}, {"consistent_except_edges", h.consistentExceptEdges()},
            {"unexplained", h.unexplained}, {"unexplained_estimated", h.estimated},
            {"unexplained_at_edges", h.unexplainedAtEdges}, {"fitted", fitted}};
}

}  // namespace reportjson

namespace {

using namespace reportjson;

nlohmann::json toJson(const CheckReport& report)
{
    const ComparisonReport& c = report.comparison;
    nlohmann::json document = {
        {"zcheck_version", kVersion},
        {"scene", report.scene},
        {"triangles", report.triangles},
        {"warnings", report.warnings},
        {"camera", toJson(report.camera)},
        {"tolerance",
         {{"subpixel_bits", report.tolerance.subpixelBits},
          {"constant_quanta", report.tolerance.constantFor(report.camera.depth)},
          {"slope_credit", report.tolerance.slopeCredit == SlopeCredit::SampleOffset ? "sample-offset" : "vertex-snapping"},
          {"declared", toJson(report.declared)},
          {"rule", report.tolerance.slopeCredit == SlopeCredit::SampleOffset
                       ? "|d_map - d_ray| <= C*q + S*m, m = |dd/dx| + |dd/dy| (sum over both surfaces when they differ)"
                       : "|d_raster - d_ray| <= C*q + S*m, m = max(|dd/dx|, |dd/dy|) (sum over both surfaces when they differ)"}}},
        {"pixels", pixelsJson(report)},
        {"depth_error", depthErrorJson(report)},
        {"unexplained", unexplainedJson(report, true)},
        {"timings_ms",
         {{"bvh_build", report.timings.bvhBuildMs},
          {"trace", report.timings.traceMs},
          {"raster", report.timings.rasterMs},
          {"compare", report.timings.compareMs},
          {"tile_by_tile", report.timings.tileByTile}}},
        {"consistent", c.consistent()},
    };
    if (report.lens) {  // a lens model's check: no raster; its two directions
        const LensCheck& lens = *report.lens;
        document["timings_ms"].erase("raster");
        document["timings_ms"].erase("tile_by_tile");
        document["lens"] = {
            {"model", lens.model},
            {"field_angle_deg", lens.fieldAngleDeg},
            {"in_field", lens.inField},
            {"outside_field", lens.outsideField},
            {"hits", lens.hits},
            {"round_trip", {{"max_px", lens.roundTripMaxPx}, {"bound_px", LensCheck::kRoundTripBoundPx},
                            {"col", lens.roundTripCol}, {"row", lens.roundTripRow}, {"beyond", lens.roundTripFailures}}},
            {"forward", {{"max_px", lens.forwardMaxPx}, {"bound_px", LensCheck::kForwardBoundPx},
                         {"widest_bound_px", lens.forwardWidestBoundPx}, {"col", lens.forwardCol},
                         {"row", lens.forwardRow}, {"beyond", lens.forwardFailures}}},
            {"raster", "does not apply: a lens model has no projection matrix to rasterize through"},
        };
    }
    if (report.secondRoute == "map") {  // verify: no raster was drawn; the map's errors in its units
        document["timings_ms"].erase("raster");
        document["timings_ms"].erase("tile_by_tile");
        document["map_errors"] = mapErrorsJson(report);
        document["out_of_range"] = outOfRangeJson(report);
        document["declared_accuracy_refused"] = declaredRefusedJson(report);
    }
    return document;
}

}  // namespace

std::string checkReportJson(const CheckReport& report) { return prettyJson(toJson(report)); }

namespace {

// A lens model's check (checker.h, LensCheck): its own table in place of the routes' classes.
std::string formatLensCheck(const CheckReport& report)
{
    const LensCheck& lens = *report.lens;
    const ComparisonReport& c = report.comparison;
    const CameraSpec& cam = report.camera;
    const std::int64_t total = std::int64_t(c.width) * c.height;
    std::ostringstream out;
    char line[320];
    out << "zcheck " << kVersion << " — lens model: its two directions and the ray route (Embree)\n";
    out << "scene      " << report.scene << "  (" << report.triangles << " triangles)\n";
    for (const std::string& warning : report.warnings) out << "warning    " << warning << "\n";
    std::snprintf(line, sizeof line, "camera     %s, lens model %s, %dx%d, near %g, far %g (distances along the rays)\n",
                  cam.convention.name.c_str(), lens.model.c_str(), cam.width, cam.height, cam.projection.near,
                  cam.projection.far);
    out << line;
    std::snprintf(line, sizeof line, "field      up to %.4g° from the axis\n", lens.fieldAngleDeg);
    out << line;
    out << "\npixels                             count\n";
    auto row = [&](const char* label, std::int64_t n) {
        std::snprintf(line, sizeof line, "  %-28s %9lld  %s\n", label, static_cast<long long>(n), percent(n, total).c_str());
        out << line;
    };
    row("in the lens's field", lens.inField);
    row("  ray hits the scene", lens.hits);
    row("  ray misses", lens.inField - lens.hits);
    row("outside the lens's field", lens.outsideField);
    out << "\n";
    std::snprintf(line, sizeof line, "round trip  pixel -> ray -> pixel over the field: max %.3g px (bound %g px)", lens.roundTripMaxPx,
                  LensCheck::kRoundTripBoundPx);
    out << line;
    if (lens.roundTripRow >= 0) out << " at (" << lens.roundTripCol << ", " << lens.roundTripRow << ")";
    out << "; " << lens.roundTripFailures << " beyond\n";
    std::snprintf(line, sizeof line, "forward     traced hit -> pixel: max %.3g px (bound %g px", lens.forwardMaxPx,
                  LensCheck::kForwardBoundPx);
    out << line;
    if (lens.forwardWidestBoundPx > LensCheck::kForwardBoundPx) {
        std::snprintf(line, sizeof line, ", up to %.3g px where the hit's rounding, as the lens magnifies it, allows",
                      lens.forwardWidestBoundPx);
        out << line;
    }
    out << ")";
    if (lens.forwardRow >= 0) out << " at (" << lens.forwardCol << ", " << lens.forwardRow << ")";
    out << "; " << lens.forwardFailures << " beyond\n";
    out << "raster     does not apply: a lens model has no projection matrix to rasterize through\n";
    std::snprintf(line, sizeof line, "\ntimings    BVH build %.1f ms, trace %.1f ms, compare %.1f ms\n", report.timings.bvhBuildMs,
                  report.timings.traceMs, report.timings.compareMs);
    out << line;
    out << "verdict    " << (c.consistent() ? "CONSISTENT" : "INCONSISTENT") << "\n";
    return out.str();
}

}  // namespace

std::string formatSummary(const CheckReport& report, const std::string& comparing)
{
    if (report.lens) return formatLensCheck(report);
    const ComparisonReport& c = report.comparison;
    const CameraSpec& cam = report.camera;
    const std::int64_t total = std::int64_t(c.width) * c.height;
    std::ostringstream out;
    char line[256];
    out << "zcheck " << kVersion << " — " << comparing << "\n";
    out << "scene      " << report.scene << "  (" << report.triangles << " triangles)\n";
    for (const std::string& warning : report.warnings) out << "warning    " << warning << "\n";
    std::snprintf(line, sizeof line, "camera     %s, %s, %dx%d, near %g, far %g\n", cam.convention.name.c_str(),
                  toString(cam.projection.type).c_str(), cam.width, cam.height, cam.projection.near,
                  cam.projection.far);
    out << line;
    if (report.tolerance.storageConstant > 0)  // an eye-z or distance map: its own storage, not the camera's buffer
        std::snprintf(line, sizeof line,
                      "depth      the map's own storage (and a linearized binary32 buffer's step); tolerance C = %g q, "
                      "S = 2^-%d px\n",
                      report.tolerance.storageConstant, report.tolerance.subpixelBits);
    else
        std::snprintf(line, sizeof line, "depth      %s%s, range [%g, %g]; tolerance C = %g q, S = 2^-%d px\n",
                      toString(cam.depth.format).c_str(), cam.depth.reversed ? ", reversed-Z" : "", cam.depth.rangeMin,
                      cam.depth.rangeMax, report.tolerance.constantFor(cam.depth), report.tolerance.subpixelBits);
    out << line;
    if (const MapAccuracy& d = report.declared; d.any()) {
        std::string declared;
        auto add = [&](const std::string& part) { declared += (declared.empty() ? "" : "; ") + part; };
        if (d.quantum > 0) add("values rounded to " + formatNumber(d.quantum));
        if (d.relative > 0 || d.absolute > 0)
            add("good to ±(" + formatNumber(d.absolute) + " + " + formatNumber(d.relative) + "·|value|), added to each tolerance");
        if (d.noise.any()) add("noise σ(z) = " + d.noise.text() + ", 6σ added to each tolerance");
        if (d.allowHoles) add("holes allowed");
        out << "declared   " << declared << " (" << d.options() << ")\n";
    }
    out << "\npixels                             count\n";
    auto row = [&](const char* label, std::int64_t n, std::int64_t of) {
        std::snprintf(line, sizeof line, "  %-28s %9lld  %s\n", label, static_cast<long long>(n), percent(n, of).c_str());
        out << line;
    };
    row("both hit", c.bothHit, total);
    row("  agree", c.agree, total);
    row("  other surface at edge", c.edgeSurface, total);
    row("  DEPTH ERROR", c.depthErrors, total);
    row("both miss", c.bothMiss, total);
    const std::string second = report.secondRoute;
    row("ray only", c.rayOnly, total);
    row((second + " only").c_str(), c.rasterOnly, total);
    row("  explained (at an edge)", c.coverageExplained - c.lostAtClearValue - c.atClipPlane - c.holes, total);
    row("  explained (at clear value)", c.lostAtClearValue, total);
    row("  explained (on near/far)", c.atClipPlane, total);
    if (report.declared.allowHoles) row("  holes (allowed)", c.holes, total);
    row("  UNEXPLAINED", c.coverageUnexplained, total);
    if (c.outOfRange > 0) {
        row("OUT OF RANGE (errors)", c.outOfRange, total);
        out << "  values the map's quantity cannot hold (a " << report.outOfRangeRule << "), e.g. "
            << formatNumber(c.outOfRangeValue) << " stored at (" << c.outOfRangeCol << ", " << c.outOfRangeRow
            << "); counted above by what the comparison made of them\n";
    }

    out << "\ndepth error over compared pixels (both hit, same surface or within tolerance)\n";
    std::snprintf(line, sizeof line, "  max %.3g q, p99 %.3g q; max / tolerance %.3g\n", c.maxErrorQuanta,
                  c.p99ErrorQuanta, c.maxErrorOverTolerance);
    out << line;
    std::snprintf(line, sizeof line, "  relative %s error: max %.3g, p99 %.3g\n",
                  cam.projection.type == ProjectionType::NonLinear ? "distance" : "eye-z", c.maxRelativeEyeZError,
                  c.p99RelativeEyeZError);
    out << line;
    if (c.biasSamples > 0) {
        std::snprintf(line, sizeof line, "  mean signed error %+.3f q over %lld quantization-bound pixels%s\n",
                      c.meanSignedErrorQuanta, static_cast<long long>(c.biasSamples),
                      c.depthBias ? "  <- SYSTEMATIC BIAS (rounding is not to nearest)" : "");
        out << line;
    }
    if (c.agree + c.depthErrors > 0) {
        std::snprintf(line, sizeof line, "  worst pixel (%d, %d): ray %.10g, %s %.10g, %.3g q (tolerance %.3g q)\n",
                      c.worst.col, c.worst.row, c.worst.rayWindowDepth, second.c_str(), c.worst.rasterWindowDepth,
                      c.worst.errorQuanta, c.worst.toleranceQuanta);
        out << line;
    }
    if (const MapErrors& e = report.mapErrors; e.compared > 0) {
        out << "\nmap - truth " << (e.eyeZEquivalent ? "as eye-z, in scene units" : "(" + e.quantity + "), in the map's units")
            << ", over the " << e.compared << " pixels compared on depth\n";
        std::snprintf(line, sizeof line, "  |error|   max %.4g, p99 %.4g, median %.4g\n", e.maxAbs, e.p99Abs, e.medianAbs);
        out << line;
        std::snprintf(line, sizeof line, "  relative  max %.3g, p99 %.3g, median %.3g\n", e.maxRel, e.p99Rel, e.medianRel);
        out << line;
        std::snprintf(line, sizeof line, "  worst pixel (%d, %d): map %.10g, true %.10g\n", e.worstCol, e.worstRow,
                      e.worstMap, e.worstTrue);
        out << line;
    }
    if (!c.declaredAccuracyRefused.empty())
        out << "\ndeclared accuracy REFUSED: " << c.declaredAccuracyRefused << "\n";
    if (c.unexplained() > 0) {
        std::snprintf(line, sizeof line, "\nunexplained pixels: %lld within cols %d..%d, rows %d..%d; first:\n",
                      static_cast<long long>(c.unexplained()), c.unexplainedMinCol, c.unexplainedMaxCol,
                      c.unexplainedMinRow, c.unexplainedMaxRow);
        out << line;
        for (std::size_t k = 0; k < c.unexplainedSamples.size() && k < 5; ++k) {
            const auto& f = c.unexplainedSamples[k];
            std::snprintf(line, sizeof line, "  (%d, %d) %-12s ray %.10g, %s %.10g\n", f.col, f.row,
                          className(f.pixelClass, second).c_str(), f.rayWindowDepth, second.c_str(), f.rasterWindowDepth);
            out << line;
        }
    }
    if (c.lostAtClearValue > 0) {
        std::snprintf(line, sizeof line,
                      "\nnote: %lld pixels see surfaces whose depth rounds to the clear value in %s, so no depth test\n"
                      "      can pass there: raise near or use a finer depth format to see them in a real depth buffer\n",
                      static_cast<long long>(c.lostAtClearValue), toString(cam.depth.format).c_str());
        out << line;
    }
    if (second == "raster")
        std::snprintf(line, sizeof line, "\ntimings    BVH build %.1f ms, trace %.1f ms, raster %.1f ms, compare %.1f ms%s\n",
                      report.timings.bvhBuildMs, report.timings.traceMs, report.timings.rasterMs,
                      report.timings.compareMs, report.timings.tileByTile ? " (tile by tile, interleaved)" : "");
    else
        std::snprintf(line, sizeof line, "\ntimings    BVH build %.1f ms, trace %.1f ms, compare %.1f ms\n",
                      report.timings.bvhBuildMs, report.timings.traceMs, report.timings.compareMs);
    out << line;
    out << "verdict    " << (c.consistent() ? "CONSISTENT" : "INCONSISTENT") << "\n";
    return out.str();
}

std::string verifyReportJson(const CheckReport& report, const DepthMapSource& source,
                             const std::vector<Hypothesis>* diagnosis)
{
    nlohmann::json document = toJson(report);
    document["depth_map"] = depthMapJson(source);
    if (diagnosis) {
        nlohmann::json list = nlohmann::json::array();
        for (const auto& h : *diagnosis) list.push_back(hypothesisJson(h));
        document["diagnosis"] = list;
    }
    return prettyJson(document);
}

VerificationReport formatVerification(const VerifiedMap& verified, const DepthMapSource& source)
{
    VerificationReport out;
    const CheckReport& report = verified.run.report;
    out.json = verifyReportJson(report, source, verified.diagnosed ? &verified.diagnosis : nullptr);
    out.summary = formatSummary(report, "ground truth (Embree) vs depth map '" + source.file + "' channel '" +
                                            source.channel + "' (" + source.quantity + ")");
    if (verified.diagnosed) {
        const ComparisonReport& c = verified.run.comparison.report;
        out.summary += "\n" + formatDiagnosis(verified.diagnosis, c.bothHit + c.rayOnly + c.rasterOnly);
    }
    return out;
}

std::string formatDiagnosis(const std::vector<Hypothesis>& hypotheses, std::int64_t compared)
{
    // Ranked (MapVerifier::diagnose): the consistent ones first, then those failing only at edges.
    if (hypotheses.empty()) return "diagnosis  no hypothesis applies to this camera and map\n";
    auto named = [](const Hypothesis& h) {
        std::string text = h.explanation;
        if (h.consistentExceptEdges())
            text += " (consistent except " + std::to_string(h.unexplained) + " edge pixel" + (h.unexplained == 1 ? "" : "s") + ")";
        return text;
    };
    const Hypothesis& best = hypotheses.front();
    if (best.name == "empty-map") return "diagnosis  " + best.explanation + "\n";
    if (best.explains()) {
        std::string out = "diagnosis  " + named(best) + "\n";
        for (std::size_t k = 1; k < hypotheses.size() && k < 4; ++k)
            if (hypotheses[k].explains())
                out += "  also     " + hypotheses[k].name + ": " + named(hypotheses[k]) + "\n";
        return out;
    }
    const std::string none = "diagnosis  none of the " + std::to_string(hypotheses.size()) + " hypotheses makes the map consistent";
    if (compared < kFewestToDiagnose)
        return none + ": only " + std::to_string(compared) + " pixel" + (compared == 1 ? "" : "s") +
               " were compared (the map or the truth sees almost nothing), too few to tell them apart\n";
    // A best that still leaves most compared pixels unexplained explains nothing: naming it would
    // point the user at a mistake the map does not show.
    if (!comesClose(best, compared))
        return none + ", and none comes close: the best (" + best.name + (best.variant.empty() ? "" : " " + best.variant) +
               ") still leaves " + (best.estimated ? "about " : "") + std::to_string(best.unexplained) + " of the " +
               std::to_string(compared) + " compared pixels unexplained\n";
    if (best.unexplained == 0)
        return none + " (closest: " + best.name + (best.variant.empty() ? "" : " " + best.variant) +
               ", which explains every pixel but leaves a systematic bias or values out of range)\n";
    return none + " (closest: " + best.name + (best.variant.empty() ? "" : " " + best.variant) + ", " +
           (best.estimated ? "about " : "") + std::to_string(best.unexplained) + " of the " + std::to_string(compared) +
           " compared pixels unexplained)\n";
}

namespace {

std::string htmlEscape(const std::string& text)
{
    std::string out;
    for (char c : text) out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
    return out;
}

}  // namespace

std::string suiteTable(const SuiteResult& result)
{
    std::ostringstream out;
    const auto tally = tallyFaults(result);
    const std::vector<const Mistake*> mistakes = injectableMistakes();
    const int clean = int(result.outcomes.size());
    char line[256];
    std::snprintf(line, sizeof line, "clean configurations: %d consistent of %d (false positives: %d)\n\n",
                  clean - result.falsePositives, clean, result.falsePositives);
    out << line;
    std::snprintf(line, sizeof line, "%-24s %-7s %10s %14s %9s  %s\n", "fault", "route", "detected", "not applicable",
                  "n/a", "");
    out << line;
    for (std::size_t k = 0; k < tally.size(); ++k) {
        const int applicable = tally[k].detected + tally[k].missed;
        std::snprintf(line, sizeof line, "%-24s %-7s %4d / %-4d %14d %9d  %s\n", mistakes[k]->name.c_str(),
                      toString(mistakes[k]->route).c_str(), tally[k].detected, applicable, tally[k].notApplicable,
                      tally[k].meaningless, tally[k].missed ? "<- MISSED" : "");
        out << line;
    }
    out << "\n(detected / applicable. Not applicable: the fault leaves that picture visibly unchanged - the same\n"
           " coverage, depth within twice the snapping noise - e.g. no near clipping where nothing crosses the near\n"
           " plane. n/a: the mistake has no meaning there, e.g. a field-of-view mistake on an orthographic camera.)\n";
    return out.str();
}

std::string suiteReportJson(const SuiteResult& result, bool quick, double seconds)
{
    const std::vector<const Mistake*> mistakes = injectableMistakes();
    nlohmann::json configsJson = nlohmann::json::array();
    for (const auto& outcome : result.outcomes) {
        nlohmann::json faults;
        for (std::size_t k = 0; k < outcome.faults.size(); ++k) faults[mistakes[k]->name] = toString(outcome.faults[k]);
        configsJson.push_back({{"label", outcome.config.label()},
                               {"scene", outcome.config.scene},
                               {"model", outcome.config.model},
                               {"camera", toJson(outcome.config.spec)},
                               {"clean", {{"consistent", outcome.clean.consistent()},
                                          {"unexplained", outcome.clean.unexplained()},
                                          {"max_over_tolerance", outcome.clean.maxErrorOverTolerance},
                                          {"mean_signed_error_quanta", outcome.clean.meanSignedErrorQuanta}}},
                               {"faults", faults},
                               {"milliseconds", outcome.milliseconds}});
    }
    nlohmann::json table = nlohmann::json::object();
    const auto tally = tallyFaults(result);
    for (std::size_t k = 0; k < tally.size(); ++k)
        table[mistakes[k]->name] = {{"description", mistakes[k]->description},
                                    {"route", toString(mistakes[k]->route)},
                                    {"detected", tally[k].detected},
                                    {"applicable", tally[k].detected + tally[k].missed},
                                    {"not_applicable", tally[k].notApplicable},
                                    {"meaningless", tally[k].meaningless}};
    return prettyJson({{"zcheck_version", kVersion},
                       {"quick", quick},
                       {"configurations", configsJson},
                       {"detection", table},
                       {"false_positives", result.falsePositives},
                       {"missed_faults", result.missedFaults},
                       {"passed", result.passed()},
                       {"seconds", seconds}}) +
           "\n";
}

std::string suiteReportHtml(const SuiteResult& result, double seconds)
{
    std::ostringstream html;
    html << "<!doctype html><html><head><meta charset=\"utf-8\"><title>zcheck suite</title><style>"
            "body{font-family:sans-serif;margin:2em}pre{background:#f4f4f4;padding:1em}"
            "img{image-rendering:pixelated;width:320px;margin-right:8px;border:1px solid #ccc}"
            ".failure{margin-bottom:2em}</style></head><body>"
         << "<h1>zcheck suite: " << (result.passed() ? "PASSED" : "FAILED") << "</h1><p>" << result.outcomes.size()
         << " configurations &times; " << injectableMistakes().size() << " faults, " << std::lround(seconds)
         << " s.</p><pre>" << htmlEscape(suiteTable(result)) << "</pre>";
    const int allFailures = result.falsePositives + result.missedFaults;
    html << "<h2>Failures" << (allFailures == 0 ? ": none" : "") << "</h2>";
    if (allFailures > int(result.failures.size()))
        html << "<p>Showing the first " << result.failures.size() << " of " << allFailures
             << " failures with images; the JSON report lists every configuration.</p>";
    for (const auto& failure : result.failures) {
        const Comparison& c = failure.run.comparison;
        QuantityImage depth;
        depth.quantity = ExportQuantity::Window, depth.width = c.report.width, depth.height = c.report.height;
        depth.channels = {"window"}, depth.value.assign(failure.run.raster.windowDepth.value.begin(), failure.run.raster.windowDepth.value.end());
        depth.missValue = failure.run.raster.windowDepth.value.empty() ? 0 : NAN;
        html << "<div class=\"failure\"><h3>" << htmlEscape(failure.label) << "</h3><p>" << htmlEscape(failure.what)
             << "</p><img title=\"raster depth\" src=\"" << pngDataUri(depth.width, depth.height, previewRgb(depth))
             << "\"><img title=\"error heatmap\" src=\"" << pngDataUri(depth.width, depth.height, errorHeatmapRgb(c))
             << "\"><img title=\"coverage classes\" src=\"" << pngDataUri(depth.width, depth.height, pixelClassRgb(c))
             << "\"><pre>" << htmlEscape(formatSummary(failure.run.report)) << "</pre></div>";
    }
    html << "</body></html>\n";
    return html.str();
}

std::string precisionJson(const CameraSpec& spec, const PrecisionTable& table)
{
    nlohmann::json layouts = nlohmann::json::array();
    for (std::size_t k = 0; k < table.layouts.size(); ++k) {
        nlohmann::json steps = nlohmann::json::array();
        for (double step : table.step[k]) steps.push_back(std::isfinite(step) ? nlohmann::json(step) : nlohmann::json(nullptr));
        layouts.push_back({{"format", toString(table.layouts[k].format)},
                           {"mapping", toString(table.layouts[k].mapping)},
                           {"eye_z_step", steps}});
    }
    const PrecisionLayout& best = table.layouts[table.best];
    return prettyJson({{"camera", toJson(spec)},
                       {"distances", table.distances},
                       {"definition", "eye_z_step: eye-z between the stored value at that distance and the next "
                                      "representable value farther away; null: unresolvable"},
                       {"layouts", layouts},
                       {"best", {{"format", toString(best.format)}, {"mapping", toString(best.mapping)},
                                 {"worst_relative_step", table.bestWorstRelativeStep}}}});
}

}  // namespace zcheck
