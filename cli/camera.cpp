// zcheck camera: one camera of any camera file, in zcheck's JSON with its matrices in every
// convention, or written in another format (camera_formats.h).
#include "common.h"

#include "zcheck/atomic_file.h"
#include "zcheck/camera_formats.h"
#include "zcheck/camera_sources.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/error.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/pose.h"

#include <iostream>

namespace zcheck::cli {

namespace {

struct CameraCommandOptions {
    CameraOptions camera;
    std::string scene, to = "zcheck", output, outDir;
    ImageSize size;
};

nlohmann::json intrinsicsJson(const Camera& camera, double pixelCenter)
{
    const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, pixelCenter);
    return {{"fx", k.fx}, {"fy", k.fy}, {"cx", k.cx}, {"cy", k.cy}};
}

// The formats written as a folder of files ("colmap").
std::string folderFormats()
{
    std::string out;
    for (const CameraFormat* format : cameraFormats())
        if (format->write && format->writesFolder) out += (out.empty() ? "" : " | ") + format->name;
    return out;
}

int runCameraCommand(const CameraCommandOptions& o)
{
    const CameraFormat& to = cameraFormatNamed(o.to);
    const auto [file, frame] = splitCameraReference(o.camera.reference);
    const CameraFormat* format = o.camera.format.empty() ? nullptr : &cameraFormatNamed(o.camera.format);
    OutputFiles outputs;
    outputs.addInput(file);
    if (!o.output.empty() && !o.outDir.empty()) throw Error("-o FILE and --out DIR are alternatives");
    if (!to.write)
        throw Error("--to takes " + cameraFormatChoices(CameraFormatsWith::Writer, ", ") + ", not " + o.to);
    if (to.writesFolder && !o.output.empty())
        throw Error("a " + to.title + " is a folder: write it with --out DIR, not -o");
    if (!to.writesFolder && !o.outDir.empty())
        throw Error("--out DIR writes a format whose files make a folder (--to " + folderFormats() + "); write a " + o.to +
                    " camera with -o FILE");
    if (!o.output.empty()) outputs.add(o.output, "-o");
    if (!o.outDir.empty()) {
        outputs.addFolder(o.outDir, "--out");
    }

    const CameraSet set = readCameraSet(file, format);
    const std::size_t index = set.find(frame);
    const ImportedCamera& imported = set.cameras[index];
    const std::optional<std::pair<int, int>> size =
        o.size.width ? std::optional<std::pair<int, int>>(std::pair{*o.size.width, o.size.height.value_or(0)}) : std::nullopt;
    if (o.size.width.has_value() != o.size.height.has_value()) throw Error("give both --width and --height, or neither");

    // Near and far: the file's, --near/--far, or the scene's; with none of them the camera is
    // shown without the matrices that depend on them.
    bool clipKnown = true;
    CameraSpec spec;
    if (!o.scene.empty()) {
        SceneAndCamera input;
        input.scene = o.scene;
        input.camera = o.camera;
        spec = cameraSpecFor(loadScene(o.scene), input, size);
    } else {
        CameraOptions options = o.camera;
        clipKnown = imported.hasClipPlanes || (options.near && options.far);
        if (!clipKnown) options.near = kPlaceholderNear, options.far = kPlaceholderFar;
        spec = cameraSpecFrom(options, size);
        if (!clipKnown)
            spec.notes.push_back("the camera file gives no near and far: clip_from_eye and the matrices after it are "
                                 "not shown (--near and --far, or --scene, give them)");
    }
    const Camera camera(spec);

    if (to.name != "zcheck" || !o.output.empty()) {
        const std::vector<CameraFileText> files = cameraInFormat(camera, to, imported.name);
        if (!o.output.empty()) outputs.writeText(o.output, files.front().text);
        if (!o.outDir.empty())
            for (const CameraFileText& f : files) {
                outputs.add(o.outDir + "/" + f.fileName, "--out");
                outputs.writeText(o.outDir + "/" + f.fileName, f.text);
            }
        outputs.commit();
        if (o.output.empty() && o.outDir.empty())
            for (const CameraFileText& f : files) std::cout << f.text;
        return kExitConsistent;
    }

    nlohmann::json out;
    out["source"] = {{"file", file}, {"format", set.format}, {"frame", imported.name}, {"index", index},
                     {"frames", set.cameras.size()}};
    out["camera"] = toJson(spec);
    if (!clipKnown) out["camera"]["projection"]["near"] = nullptr, out["camera"]["projection"]["far"] = nullptr;
    out["notes"] = cameraNotes(spec);
    const ProjectionType type = spec.projection.type;
    const bool hasK = camera.lens() ? camera.lens()->info().startsWithK()
                                    : type == ProjectionType::Perspective || type == ProjectionType::Frustum ||
                                          type == ProjectionType::Pinhole || type == ProjectionType::Lens;
    if (hasK)  // a lens model's K (its distortion is in "camera"'s "lens")
        out["intrinsics"] = {{"opencv", intrinsicsJson(camera, 0.0)}, {"colmap", intrinsicsJson(camera, 0.5)},
                             {"definition", "pixels; opencv: the top-left pixel's centre is (0, 0), colmap (and "
                                            "nerfstudio): it is (0.5, 0.5)"}};
    nlohmann::json matrices;
    // A raw projection matrix belongs to its convention alone.
    const std::vector<std::string> conventions =
        type == ProjectionType::Matrix ? std::vector<std::string>{spec.convention.name} : Convention::presetNames();
    for (const std::string& name : conventions) {
        CameraSpec in = spec;
        in.convention = Convention::preset(name);
        if (in.view.hasMatrix) in.view.eyeFromWorld = eyeFromEye(in.convention, spec.convention) * spec.view.eyeFromWorld;
        nlohmann::json m = matricesJson(Camera(in));
        if (!clipKnown)
            for (const char* key : {"clip_from_eye", "eye_from_clip", "clip_from_world", "near", "far"}) m.erase(key);
        if (!clipKnown && m.contains("native")) m["native"].erase("clip_from_eye");  // a lens model has no native block
        matrices[name] = m;
    }
    out["matrices"] = matrices;
    std::cout << prettyJson(out) << "\n";
    return kExitConsistent;
}

}  // namespace

Command addCameraCommand(CLI::App& app)
{
    auto o = std::make_shared<CameraCommandOptions>();
    CLI::App* command = app.add_subcommand(
        "camera", "Read one camera of any camera file zcheck imports (" + cameraFormatChoices(CameraFormatsWith::Reader, ", ") +
                      ")\nand print it as zcheck's camera JSON with its intrinsics and its matrices in every convention,\n"
                      "or (--to) in another format. Examples:\n"
                  "  zcheck camera sparse/0#img_014.png\n"
                  "  zcheck camera transforms.json#frame_003 --to colmap --out model/\n"
                  "  zcheck camera calib.yml --to nerfstudio -o transforms.json");
    command->add_option("camera", o->camera.reference, "FILE or FILE#FRAME (FRAME: an index, an image name, a path or stem)")
        ->required()
        ->check(kNonEmptyPath);
    command->add_option("--camera-format", o->camera.format,
                        "the file's format when its content should not decide: " +
                            cameraFormatChoices(CameraFormatsWith::Reader));
    command->add_option("--to", o->to, "the format to write (zcheck: JSON with matrices): " +
                                           cameraFormatChoices(CameraFormatsWith::Writer))
        ->capture_default_str();
    command->add_option("--scene", o->scene, "a scene to take near and far from when the file has none");
    command->add_option("--near", o->camera.near, "near plane distance (default: the file's, else --scene's)")
        ->check(kPositiveFinite);
    command->add_option("--far", o->camera.far, "far plane distance (default: the file's, else --scene's)")
        ->check(kPositiveFinite);
    command->add_option("--convention", o->camera.convention, "show the camera in this convention");
    addImageSizeOptions(command, o->size);
    command->add_option("-o,--output", o->output, "write the camera file instead of printing (formats whose file is one file)")
        ->type_name("FILE")
        ->check(kNonEmptyPath);
    command->add_option("--out", o->outDir, "write a format whose files make a folder (a COLMAP model: cameras.txt, images.txt)")
        ->type_name("DIR")
        ->check(kNonEmptyPath);
    return {command, [o] { return runCameraCommand(*o); }};
}

}  // namespace zcheck::cli
