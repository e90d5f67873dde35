#include "run_folder.h"

#include "image_plugin.h"

#include "zcheck/png_file.h"
#include "zcheck/report_images.h"

#include <filesystem>

namespace zcheck::cli {

namespace {
std::vector<float> asFloats(const DepthImage& image) { return std::vector<float>(image.value.begin(), image.value.end()); }
}  // namespace

std::string RunFolder::path(const std::string& name) const { return (std::filesystem::path(dir) / name).string(); }

void RunFolder::plan(OutputFiles& outputs) const
{
    outputs.addFolder(dir, "--out");
    for (const std::string& name : {std::string("ray_depth.exr"), secondName, std::string("error_heatmap.png"),
                                     std::string("coverage_classes.png"), std::string("report.json")})
        outputs.add(path(name), "--out");
    if (mapError) outputs.add(path("map_error.exr"), "--out");
}

void RunFolder::write(OutputFiles& outputs, const RenderResult& ray, const RenderResult& second,
                      const Comparison& comparison, const std::string& reportJson, const std::vector<float>& error) const
{
    const int W = comparison.report.width, H = comparison.report.height;
    outputs.write(path("ray_depth.exr"), [&](const std::string& t) { images().writeExr(t, W, H, {"window"}, asFloats(ray.windowDepth)); });
    outputs.write(path(secondName), [&](const std::string& t) { images().writeExr(t, W, H, {"window"}, asFloats(second.windowDepth)); });
    outputs.write(path("error_heatmap.png"), [&](const std::string& t) { writePng8(t, W, H, errorHeatmapRgb(comparison)); });
    outputs.write(path("coverage_classes.png"), [&](const std::string& t) { writePng8(t, W, H, pixelClassRgb(comparison)); });
    if (mapError) outputs.write(path("map_error.exr"), [&](const std::string& t) { images().writeExr(t, W, H, {"error"}, error); });
    outputs.writeText(path("report.json"), reportJson + "\n");
}

}  // namespace zcheck::cli
