#include "zcheck/dataset_source.h"

#include "formats.h"
#include "zcheck/camera_file.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/detail/depth_map_json.h"
#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/inverse_projection.h"

#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace zcheck {

namespace {

namespace fs = std::filesystem;

// "{name}" and "{stem}" in a pattern, replaced.
std::string expandPattern(const std::string& pattern, const std::string& name)
{
    const std::size_t slash = name.find_last_of('/');
    const std::string file = slash == std::string::npos ? name : name.substr(slash + 1);
    const std::size_t dot = name.find_last_of('.');
    const std::string stem = dot == std::string::npos || (slash != std::string::npos && dot < slash) ? name : name.substr(0, dot);
    std::string out;
    for (std::size_t i = 0; i < pattern.size();) {
        if (pattern.compare(i, 6, "{name}") == 0) {
            out += name, i += 6;
        } else if (pattern.compare(i, 6, "{stem}") == 0) {
            out += stem, i += 6;
        } else if (pattern.compare(i, 6, "{file}") == 0) {
            out += file, i += 6;
        } else {
            out += pattern[i++];
        }
    }
    return out;
}

Dataset fromCameraSet(const CameraFormat& format, const CameraSet& set, const std::string& source,
                      const DatasetSourceOptions& options)
{
    Dataset dataset{source, set.format, {}};
    if (!format.namesDepthMaps && options.depthPattern.empty())
        throw Error(format.title + " '" + source +
                    "' names no depth maps: give --depth PATTERN ({name}: the image name, {stem}: without its extension; "
                    "e.g. dense/stereo/depth_maps/{name}.geometric.bin)");
    std::set<std::string> names;
    for (std::size_t i = 0; i < set.cameras.size(); ++i) {
        const ImportedCamera& camera = set.cameras[i];
        DatasetFrame frame;
        frame.index = i;
        frame.name = camera.name;
        if (!names.insert(frame.name).second) frame.name += "#" + std::to_string(i);  // names must be unique
        frame.camera = camera;
        frame.error = camera.refusal;
        if (!options.depthPattern.empty()) {
            frame.depth = expandPattern(options.depthPattern, camera.name);
        } else if (!camera.depthPath.empty()) {
            frame.depth = camera.depthPath;
        } else if (frame.error.empty()) {
            frame.error = source + ": frame '" + camera.name + "' names no depth map (depth_file_path); give --depth PATTERN";
        }
        frame.impliedScale = set.depthScale;
        frame.impliedScaleNote = set.depthScaleNote;
        dataset.frames.push_back(std::move(frame));
    }
    if (dataset.frames.empty()) throw Error("'" + source + "' holds no frames");
    return dataset;
}

class ManifestReader {
public:
    explicit ManifestReader(const std::string& path) : path_(path) {}

    Dataset read()
    {
        Dataset dataset{path_, "manifest", {}};
        std::istringstream in(readInputFile(path_, kManifestInput));
        std::set<std::string> names;
        std::size_t lineNumber = 0;
        for (std::string line; std::getline(in, line);) {
            ++lineNumber;
            if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
            DatasetFrame frame;
            frame.index = dataset.frames.size();
            frame.name = "line " + std::to_string(lineNumber);
            try {
                readLine(line, lineNumber, frame);
            } catch (const Error& e) {
                frame.error = e.what();
            }
            if (!names.insert(frame.name).second) {
                frame.error = "manifest '" + path_ + "' line " + std::to_string(lineNumber) + ": frame '" + frame.name +
                              "' appears twice";
                frame.name += " (line " + std::to_string(lineNumber) + ")";
                names.insert(frame.name);
            }
            dataset.frames.push_back(std::move(frame));
        }
        if (dataset.frames.empty()) throw Error("manifest '" + path_ + "' holds no frames (one JSON object a line)");
        return dataset;
    }

private:
    void readLine(const std::string& line, std::size_t number, DatasetFrame& frame)
    {
        const std::string where = "manifest '" + path_ + "' line " + std::to_string(number);
        sidecarCamera_.reset();
        const nlohmann::json object = parseJsonStrictly(line, where);
        if (!object.is_object()) throw Error(where + ": a frame is a JSON object");
        static const std::set<std::string> known = {"frame", "camera", "depth", "quantity", "scale", "offset",
                                                    "miss", "channel", "scene", "near", "far", "quantum",
                                                    "rel_tolerance", "abs_tolerance", "noise_model", "allow_holes",
                                                    "sidecar"};
        for (const auto& item : object.items())
            if (!known.count(item.key())) throw Error(where + ": unknown key '" + printableExcerpt(item.key(), 40) + "'");
        auto text = [&](const char* key) -> std::optional<std::string> {
            if (!object.contains(key) || object[key].is_null()) return std::nullopt;
            if (!object[key].is_string() || object[key].get<std::string>().empty())
                throw Error(where + ": '" + key + "' must be a non-empty string");
            return object[key].get<std::string>();
        };
        auto number_ = [&](const char* key) -> std::optional<double> {
            if (!object.contains(key) || object[key].is_null()) return std::nullopt;
            if (!object[key].is_number() || !std::isfinite(object[key].get<double>()))
                throw Error(where + ": '" + key + "' must be a finite number");
            return object[key].get<double>();
        };
        if (const auto name = text("frame")) frame.name = *name;
        const auto depth = text("depth");
        if (!depth) throw Error(where + ": 'depth' (the depth map's path) is missing");
        frame.depth = formats::pathBeside(path_, *depth);
        frame.quantity = text("quantity");
        frame.channel = text("channel");
        if (const auto scene = text("scene")) frame.scene = scene->rfind("builtin:", 0) == 0 ? *scene : formats::pathBeside(path_, *scene);
        frame.scale = number_("scale");
        if (frame.scale && !(*frame.scale > 0)) throw Error(where + ": 'scale' must be > 0");
        frame.offset = number_("offset");
        frame.near = number_("near"), frame.far = number_("far");
        if ((frame.near && !(*frame.near > 0)) || (frame.far && !(*frame.far > 0)))
            throw Error(where + ": 'near' and 'far' must be > 0");
        frame.accuracy = accuracyFromJson(object, where);
        if (object.contains("miss") && !object["miss"].is_null()) {
            const nlohmann::json& miss = object["miss"];
            if (miss.is_number()) frame.miss = formatNumber(miss.get<double>());
            else if (miss.is_string()) frame.miss = miss.get<std::string>();
            else throw Error(where + ": 'miss' must be a number or a rule such as \">=1e9\"");
        }
        if (const auto sidecar = text("sidecar")) takeFromSidecar(formats::pathBeside(path_, *sidecar), object, where, frame);
        if (frame.camera && (!object.contains("camera") || object["camera"].is_null())) return;
        if (!object.contains("camera") || object["camera"].is_null())
            throw Error(where + ": 'camera' is missing (nor does a 'sidecar' of zcheck's export name one)");
        const nlohmann::json& camera = object["camera"];
        if (camera.is_object()) {
            ImportedCamera inline_;
            inline_.name = frame.name;
            inline_.spec = cameraSpecFromJson(camera, where + " camera");
            inline_.hasClipPlanes = true;
            frame.camera = inline_;
        } else if (camera.is_string()) {
            const auto [file, wanted] = splitCameraReference(formats::pathBeside(path_, camera.get<std::string>()));
            const CameraSet& set = cameras(file, where);
            frame.camera = set.cameras[set.find(wanted)];
            frame.impliedScale = set.depthScale;
            frame.impliedScaleNote = set.depthScaleNote;
        } else {
            throw Error(where + ": 'camera' must be a camera reference \"FILE#FRAME\" or a zcheck camera object");
        }
        if (sidecarCamera_ && frame.camera->hasImageSize) {
            const std::string difference = howCamerasDiffer(Camera(frame.camera->spec), Camera(*sidecarCamera_), false);
            if (!difference.empty())
                throw Error(where + ": its 'camera' and the camera in its 'sidecar' (the one that rendered the map) differ in " +
                            difference + ": give the map's own camera, or leave 'camera' out");
        }
    }

    // A line's "sidecar": what zcheck's export (or another producer) wrote beside the map. Its reading
    // keys and quantity apply where the line is silent; its camera is the frame's when the line has
    // none, and is compared with the line's otherwise.
    void takeFromSidecar(const std::string& sidecar, const nlohmann::json& object, const std::string& where,
                         DatasetFrame& frame)
    {
        sidecarCamera_.reset();
        try {
            const DepthMapReading reading = withSidecar(DepthMapReading{}, sidecar);
            if (!frame.channel && !reading.channel.empty()) frame.channel = reading.channel;
            if (!frame.scale && reading.scale > 0) frame.scale = reading.scale;
            if (!frame.offset && reading.offset) frame.offset = reading.offset;
            if (!frame.miss && reading.miss.given()) frame.miss = reading.miss.text();
            frame.accuracy = frame.accuracy.over(reading.accuracy);
            const SidecarSubject subject = sidecarSubject(sidecar);
            if (!frame.quantity) frame.quantity = subject.quantityOf(sidecar, frame.channel.value_or(""));
            if (subject.hasCamera) {
                sidecarCamera_ = readCameraFile(sidecar);
                if (!object.contains("camera") || object["camera"].is_null()) {
                    ImportedCamera camera;
                    camera.name = frame.name;
                    camera.spec = *sidecarCamera_;
                    camera.hasClipPlanes = true;
                    frame.camera = camera;
                }
            }
        } catch (const Error& e) {
            throw Error(where + ": " + e.what());
        }
    }

    // Each camera file once; a file that cannot be read is every referring frame's error.
    const CameraSet& cameras(const std::string& file, const std::string& where)
    {
        auto found = sets_.find(file);
        if (found == sets_.end()) {
            Entry entry;
            try {
                entry.set = readCameraSet(file);
            } catch (const Error& e) {
                entry.error = e.what();
            }
            found = sets_.emplace(file, std::move(entry)).first;
        }
        if (!found->second.error.empty()) throw Error(where + ": " + found->second.error);
        return found->second.set;
    }

    struct Entry {
        CameraSet set;
        std::string error;
    };
    std::string path_;
    std::optional<CameraSpec> sidecarCamera_;  // the current line's sidecar's camera
    std::map<std::string, Entry> sets_;
};

}  // namespace

Dataset openDataset(const std::string& source, const DatasetSourceOptions& options)
{
    if (source.empty()) throw Error("the dataset source path is empty");
    const std::string ext = lowerExtension(source);
    if (ext == ".jsonl" || ext == ".ndjson") return ManifestReader(source).read();
    const CameraFormat& format = options.cameraFormat ? *options.cameraFormat : detectCameraFormat(source);
    if (!format.datasetSource)
        throw Error("dataset source '" + source + "' is a " + format.name + " camera file: a dataset is a " +
                    cameraFormatChoices(CameraFormatsWith::Dataset, ", ") + " source or a manifest (.jsonl)");
    return fromCameraSet(format, readCameraSet(source, &format), source, options);
}

std::string relativeTo(const std::string& path, const std::string& base)
{
    if (path.empty() || path.rfind("builtin:", 0) == 0) return path;
    const fs::path absolute = fs::absolute(path).lexically_normal();
    const fs::path folder = fs::absolute(base).lexically_normal().parent_path();
    const std::string relative = absolute.lexically_relative(folder).generic_string();
    return relative.empty() || relative.rfind("..", 0) == 0 ? absolute.generic_string() : relative;
}

std::string manifestLine(const DatasetFrame& frame, const std::string& cameraReference, const std::string& manifestPath)
{
    nlohmann::json line;
    line["frame"] = frame.name;
    line["camera"] = relativeTo(cameraReference, manifestPath);
    line["depth"] = relativeTo(frame.depth, manifestPath);
    if (frame.quantity) line["quantity"] = *frame.quantity;
    if (frame.scale || frame.impliedScale) line["scale"] = frame.scale ? *frame.scale : *frame.impliedScale;
    if (frame.offset) line["offset"] = *frame.offset;
    if (frame.miss) line["miss"] = *frame.miss;
    if (frame.channel) line["channel"] = *frame.channel;
    if (frame.scene) line["scene"] = relativeTo(*frame.scene, manifestPath);
    if (frame.near) line["near"] = *frame.near;
    if (frame.far) line["far"] = *frame.far;
    if (frame.accuracy.quantum > 0) line["quantum"] = frame.accuracy.quantum;
    if (frame.accuracy.relative > 0) line["rel_tolerance"] = frame.accuracy.relative;
    if (frame.accuracy.absolute > 0) line["abs_tolerance"] = frame.accuracy.absolute;
    if (frame.accuracy.noise.any()) line["noise_model"] = frame.accuracy.noise.text();
    if (frame.accuracy.allowHoles) line["allow_holes"] = true;
    return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace zcheck
