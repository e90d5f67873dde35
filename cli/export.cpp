// zcheck export: one route's render as a depth or geometry file with a JSON sidecar.
#include "common.h"
#include "image_plugin.h"

#include "zcheck/atomic_file.h"
#include "zcheck/departure.h"
#include "zcheck/detail/json.h"
#include "zcheck/error.h"
#include "zcheck/export.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/png_file.h"

#include <cmath>
#include <filesystem>
#include <iostream>

namespace zcheck::cli {

namespace {

struct ExportOptions {
    SceneAndCamera input;
    std::string backend = "ray", quantities = "eye-z", output, preview;
    double scale = 0;
    std::vector<double> sampleOffset;  // image pixels (x right, y down) from the pixel centre
    int threads = 0;
};

int runExportCommand(const ExportOptions& o)
{
    if (o.backend != "ray" && o.backend != "raster") throw Error("--backend must be ray or raster, got '" + o.backend + "'");
    if (o.output.empty()) throw Error("export needs -o FILE (.exr, .pfm, .tif or .png)");
    const std::vector<ExportQuantity> quantities = exportQuantitiesFromList(o.quantities);
    const auto threadLimit = limitThreads(o.threads);
    OutputFiles outputs;
    outputs.addInput(o.input.scene);
    outputs.addInput(cameraInputPath(o.input.camera));
    outputs.add(o.output, "-o");
    outputs.add(o.output + ".json", "the sidecar of -o");
    if (!o.preview.empty()) outputs.add(o.preview, "--preview");
    Scene loaded = loadScene(o.input.scene);
    const CameraSpec spec = cameraSpecFor(loaded, o.input);
    const Camera camera(spec);
    // One frame's rays (none from the raster): the BVH built for them (ray_renderer.h).
    const double rays = o.backend == "ray" ? double(camera.width()) * camera.height() : 0.0;
    const BvhBuild build = bvhBuildFor(rays, loaded.triangleCount());
    const Checker checker(std::move(loaded), build);
    const Scene& scene = checker.scene();
    Departure sampling;
    if (!o.sampleOffset.empty()) {
        if (o.backend != "ray") throw Error("--sample-offset needs --backend ray (the rasterizer samples pixel centres)");
        for (double v : o.sampleOffset)
            if (!(std::abs(v) <= 16)) throw Error("--sample-offset " + std::to_string(v) + " must lie within ±16 pixels");
        sampling.sampleOffset = {o.sampleOffset[0], o.sampleOffset[1]};
    }
    // The ray route keeps its hits' eye points: eye-z and distance are then exact (Checker::render).
    const RenderResult route = o.backend == "ray"
                                   ? checker.renderRay(camera, departedSampling(camera, sampling), EyePoints::Keep)
                                   : checker.renderRaster(camera);
    std::vector<QuantityImage> images;
    for (ExportQuantity q : quantities) images.push_back(quantityImage(scene, camera, route, q));
    std::string format;
    outputs.write(o.output, [&](const std::string& temporary) { format = writeDepthMapFile(temporary, images, o.scale); });

    nlohmann::json sidecar = depthFileSidecar(o.output, format, camera, images, o.scale, sampling.sampleOffset);
    sidecar["backend"] = o.backend;
    sidecar["scene"] = scene.name;
    sidecar["depth"] = {{"format", toString(spec.depth.format)}, {"reversed", spec.depth.reversed},
                        {"range", {spec.depth.rangeMin, spec.depth.rangeMax}}, {"clear_value", camera.clearDepth()}};
    outputs.writeText(o.output + ".json", prettyJson(sidecar) + "\n");
    if (!o.preview.empty())
        outputs.write(o.preview, [&](const std::string& temporary) {
            writePng8(temporary, camera.width(), camera.height(), previewRgb(images.front()));
        });
    outputs.commit();
    std::size_t hits = 0;
    for (std::size_t i = 0; i < route.primitiveId.size(); ++i) hits += route.hit(i) ? 1 : 0;
    std::cout << prettyJson({{"output", o.output}, {"sidecar", o.output + ".json"}, {"format", format},
                             {"quantities", o.quantities}, {"backend", o.backend}, {"covered_pixels", hits},
                             {"pixels", route.primitiveId.size()}})
              << "\n";
    return kExitConsistent;
}

}  // namespace

Command addExportCommand(CLI::App& app)
{
    auto o = std::make_shared<ExportOptions>();
    CLI::App* command = app.add_subcommand(
        "export", "Render depth with one route and write it as EXR, PFM, TIFF or 16-bit PNG, with a JSON sidecar\n"
                  "(FILE.json) that says everything needed to read it: quantity, unit, miss value, orientation,\n"
                  "camera and matrices.");
    command->add_option("--backend", o->backend, "ray | raster")->capture_default_str();
    command->add_option("--quantity", o->quantities,
                              "comma-separated: window, ndc, eye-z, distance, position-eye, position-world, normal, "
                              "primitive-id (several only into .exr or .h5)")
        ->capture_default_str();
    addSceneAndCameraOptions(command, o->input);
    command->add_option("-o,--output", o->output, "the depth file, in its extension's format (`zcheck formats` lists them: .exr, .npy, .png, ...;\nwritten atomically)")
        ->type_name("FILE")
        ->check(kNonEmptyPath);
    command->add_option("--scale", o->scale, "16-bit PNG: stored = value x scale (e.g. 1000 = millimetres)")
        ->check(kPositiveFinite);
    command->add_option("--preview", o->preview, "also write an 8-bit colour-mapped PNG of the first quantity")
        ->check(kNonEmptyPath);
    command->add_option("--sample-offset", o->sampleOffset,
                        "DX,DY: take each pixel's depth at this offset from its centre, in pixels, x right, y down "
                        "(ray backend): a renderer that keeps one sample of MSAA, e.g. -0.125,0.375 (4x, sample 0, in an OpenGL "
                        "camera; -0.125,-0.375 in a Direct3D or Vulkan one)")
        ->delimiter(',')
        ->expected(2);
    addThreadsOption(command, o->threads);

    return {command, [o] { return runExportCommand(*o); }};
}

}  // namespace zcheck::cli
