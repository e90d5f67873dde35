#include "zcheck/report.h"

#include "zcheck/camera_file.h"

#include <cmath>
#include <cstdio>
#include <regex>
#include <sstream>

namespace zcheck {

namespace {

nlohmann::json toJson(const PixelFinding& f)
{
    auto depthOrNull = [](double d) { return std::isfinite(d) ? nlohmann::json(d) : nlohmann::json(nullptr); };
    return {
        {"col", f.col},
        {"row", f.row},
        {"class", toString(f.pixelClass)},
        {"ray_window_depth", depthOrNull(f.rayWindowDepth)},
        {"raster_window_depth", depthOrNull(f.rasterWindowDepth)},
        {"error_quanta", depthOrNull(f.errorQuanta)},
        {"tolerance_quanta", depthOrNull(f.toleranceQuanta)},
        {"ray_primitive", f.rayPrimitive == kNoPrimitive ? nlohmann::json(nullptr) : nlohmann::json(f.rayPrimitive)},
        {"raster_primitive",
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

std::string prettyJson(const nlohmann::json& document)
{
    const std::string text = document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
    // An array whose elements are all numbers (or null) is folded onto one line.
    static const std::regex numberArray(R"(\[(\s*(-?[0-9][0-9.eE+-]*|null)\s*,)*\s*(-?[0-9][0-9.eE+-]*|null)\s*\])");
    static const std::regex space(R"(\s+)");
    std::string out;
    auto last = text.cbegin();
    for (std::sregex_iterator it(text.begin(), text.end(), numberArray), end; it != end; ++it) {
        out.append(last, text.cbegin() + it->position());
        std::string folded = std::regex_replace(it->str(), space, "");
        std::string spaced;
        for (char c : folded) spaced += c == ',' ? std::string(", ") : std::string(1, c);
        out += spaced;
        last = text.cbegin() + it->position() + it->length();
    }
    out.append(last, text.cend());
    return out;
}

nlohmann::json toJson(const CheckReport& report)
{
    const ComparisonReport& c = report.comparison;
    nlohmann::json unexplained = nlohmann::json::array();
    for (const auto& f : c.unexplainedSamples) unexplained.push_back(toJson(f));
    nlohmann::json box = nullptr;
    if (c.unexplainedMaxCol >= 0)
        box = {{"min_col", c.unexplainedMinCol},
               {"min_row", c.unexplainedMinRow},
               {"max_col", c.unexplainedMaxCol},
               {"max_row", c.unexplainedMaxRow}};
    return {
        {"zcheck_version", ZCHECK_VERSION},
        {"scene", report.scene},
        {"triangles", report.triangles},
        {"camera", toJson(report.camera)},
        {"tolerance",
         {{"subpixel_bits", report.tolerance.subpixelBits},
          {"constant_quanta", ToleranceModel::constantQuanta(report.camera.depth)},
          {"rule", "|d_raster - d_ray| <= C*q + S*m (sum over both surfaces when they differ)"}}},
        {"pixels",
         {{"total", std::int64_t(c.width) * c.height},
          {"both_hit", c.bothHit},
          {"both_miss", c.bothMiss},
          {"ray_only", c.rayOnly},
          {"raster_only", c.rasterOnly},
          {"agree", c.agree},
          {"edge_surface", c.edgeSurface},
          {"depth_errors", c.depthErrors},
          {"coverage_explained", c.coverageExplained},
          {"lost_at_clear_value", c.lostAtClearValue},
          {"at_clip_plane", c.atClipPlane},
          {"coverage_unexplained", c.coverageUnexplained}}},
        {"depth_error",
         {{"max_quanta", c.maxErrorQuanta},
          {"p99_quanta", c.p99ErrorQuanta},
          {"max_over_tolerance", c.maxErrorOverTolerance},
          {"max_relative_eye_z", c.maxRelativeEyeZError},
          {"p99_relative_eye_z", c.p99RelativeEyeZError},
          {"bias_samples", c.biasSamples},
          {"mean_signed_error_quanta", c.meanSignedErrorQuanta},
          {"depth_bias", c.depthBias},
          {"worst_pixel", toJson(c.worst)}}},
        {"unexplained", {{"count", c.unexplained()}, {"bounding_box", box}, {"samples", unexplained}}},
        {"timings_ms",
         {{"bvh_build", report.timings.bvhBuildMs},
          {"trace", report.timings.traceMs},
          {"raster", report.timings.rasterMs},
          {"compare", report.timings.compareMs}}},
        {"consistent", c.consistent()},
    };
}

std::string formatSummary(const CheckReport& report, const std::string& comparing)
{
    const ComparisonReport& c = report.comparison;
    const CameraSpec& cam = report.camera;
    const std::int64_t total = std::int64_t(c.width) * c.height;
    std::ostringstream out;
    char line[256];
    out << "zcheck " << ZCHECK_VERSION << " — " << comparing << "\n";
    out << "scene      " << report.scene << "  (" << report.triangles << " triangles)\n";
    std::snprintf(line, sizeof line, "camera     %s, %s, %dx%d, near %g, far %g\n", cam.convention.name.c_str(),
                  toString(cam.projection.type).c_str(), cam.width, cam.height, cam.projection.near,
                  cam.projection.far);
    out << line;
    std::snprintf(line, sizeof line, "depth      %s%s, range [%g, %g]; tolerance C = %g q, S = 2^-%d px\n",
                  toString(cam.depth.format).c_str(), cam.depth.reversed ? ", reversed-Z" : "", cam.depth.rangeMin,
                  cam.depth.rangeMax, ToleranceModel::constantQuanta(cam.depth), report.tolerance.subpixelBits);
    out << line << "\npixels                             count\n";
    auto row = [&](const char* label, std::int64_t n, std::int64_t of) {
        std::snprintf(line, sizeof line, "  %-28s %9lld  %s\n", label, static_cast<long long>(n), percent(n, of).c_str());
        out << line;
    };
    row("both hit", c.bothHit, total);
    row("  agree", c.agree, total);
    row("  other surface at edge", c.edgeSurface, total);
    row("  DEPTH ERROR", c.depthErrors, total);
    row("both miss", c.bothMiss, total);
    row("ray only", c.rayOnly, total);
    row("raster only", c.rasterOnly, total);
    row("  explained (at an edge)", c.coverageExplained - c.lostAtClearValue - c.atClipPlane, total);
    row("  explained (at clear value)", c.lostAtClearValue, total);
    row("  explained (on near/far)", c.atClipPlane, total);
    row("  UNEXPLAINED", c.coverageUnexplained, total);

    out << "\ndepth error over compared pixels (both hit, same surface or within tolerance)\n";
    std::snprintf(line, sizeof line, "  max %.3g q, p99 %.3g q; max / tolerance %.3g\n", c.maxErrorQuanta,
                  c.p99ErrorQuanta, c.maxErrorOverTolerance);
    out << line;
    std::snprintf(line, sizeof line, "  relative eye-z error: max %.3g, p99 %.3g\n", c.maxRelativeEyeZError,
                  c.p99RelativeEyeZError);
    out << line;
    if (c.biasSamples > 0) {
        std::snprintf(line, sizeof line, "  mean signed error %+.3f q over %lld quantization-bound pixels%s\n",
                      c.meanSignedErrorQuanta, static_cast<long long>(c.biasSamples),
                      c.depthBias ? "  <- SYSTEMATIC BIAS (rounding is not to nearest)" : "");
        out << line;
    }
    if (c.agree + c.depthErrors > 0) {
        std::snprintf(line, sizeof line, "  worst pixel (%d, %d): ray %.10g, raster %.10g, %.3g q (tolerance %.3g q)\n",
                      c.worst.col, c.worst.row, c.worst.rayWindowDepth, c.worst.rasterWindowDepth,
                      c.worst.errorQuanta, c.worst.toleranceQuanta);
        out << line;
    }
    if (c.unexplained() > 0) {
        std::snprintf(line, sizeof line, "\nunexplained pixels: %lld within cols %d..%d, rows %d..%d; first:\n",
                      static_cast<long long>(c.unexplained()), c.unexplainedMinCol, c.unexplainedMaxCol,
                      c.unexplainedMinRow, c.unexplainedMaxRow);
        out << line;
        for (std::size_t k = 0; k < c.unexplainedSamples.size() && k < 5; ++k) {
            const auto& f = c.unexplainedSamples[k];
            std::snprintf(line, sizeof line, "  (%d, %d) %-12s ray %.10g, raster %.10g\n", f.col, f.row,
                          toString(f.pixelClass).c_str(), f.rayWindowDepth, f.rasterWindowDepth);
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
    std::snprintf(line, sizeof line, "\ntimings    BVH build %.1f ms, trace %.1f ms, raster %.1f ms, compare %.1f ms\n",
                  report.timings.bvhBuildMs, report.timings.traceMs, report.timings.rasterMs,
                  report.timings.compareMs);
    out << line;
    out << "verdict    " << (c.consistent() ? "CONSISTENT" : "INCONSISTENT") << "\n";
    return out.str();
}

}  // namespace zcheck
