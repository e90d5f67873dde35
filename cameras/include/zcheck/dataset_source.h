#pragma once
// Datasets as files (library zcheck::cameras): the frames a transforms.json, a COLMAP model or a
// zcheck manifest holds — each frame a camera, a depth map and how to read it.
//
// Sources (any camera format whose row is a dataset source, camera_formats.h; these today):
//   transforms.json  (nerfstudio, instant-ngp) each frame's camera and its depth_file_path (or
//                    depth_path); 16-bit depth in millimetres, nerfstudio's default
//                    (depth_unit_scale_factor 1e-3: scale 1000, noted), or instant-ngp's
//                    integer_depth_scale (scale 1/integer_depth_scale); --scale replaces it.
//   COLMAP model     (a folder with cameras/images .bin or .txt) each image's camera; its depth
//                    map by --depth PATTERN, where {name} is the image name and {stem} the name
//                    without its extension (dense/stereo/depth_maps/{name}.geometric.bin).
//   manifest         JSON Lines (.jsonl), one frame a line, blank lines skipped:
//                      {"frame": "f003", "camera": "sparse/0#img_003.png", "depth": "d/003.png",
//                       "quantity": "eye-z", "scale": 1000, "offset": 0, "miss": ">=1e9",
//                       "channel": "Z", "scene": "mesh.ply", "near": 0.1, "far": 50,
//                       "quantum": 0.001, "rel_tolerance": 0, "abs_tolerance": 0.005, "allow_holes": true}
//                    "camera" is a reference FILE#FRAME to any camera file (camera_import.h) or
//                    an inline zcheck camera (the camera file's JSON object); "frame" (default:
//                    the line number) and "depth" are required, the rest optional. Paths are
//                    relative to the manifest. A line that is not such an object becomes a frame
//                    whose `error` says why: the run records it and goes on.
// The index of a frame is its position in the source (file order), the unit of --shard.
#include "zcheck/camera_import.h"
#include "zcheck/depth_map_reading.h"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

struct DatasetFrame {
    std::size_t index = 0;
    std::string name;                       // unique within the dataset
    std::optional<ImportedCamera> camera;   // none only with an error
    std::string depth;                      // the depth map's path
    // How to read it, when the source says (else the run's options decide).
    std::optional<std::string> quantity, miss, channel, scene;
    std::optional<double> scale, offset;    // as a manifest line gives them: they win over the run's options
    std::optional<double> near, far;        // likewise (for cameras whose file has none)
    MapAccuracy accuracy;                   // what the line declares (depth_map_reading.h): its fields
                                            // win over the run's options
    std::optional<double> impliedScale;     // what the camera file implies (nerfstudio's millimetres): the
                                            // run's --scale wins over it
    std::string impliedScaleNote;           // the sentence a report prints when it is used
    std::string error;                      // this frame cannot be run: why (one line)
};

struct Dataset {
    std::string source;                     // the path as given
    std::string kind;                       // "nerfstudio", "colmap", "manifest"
    std::vector<DatasetFrame> frames;
};

struct DatasetSourceOptions {
    std::string depthPattern;                  // COLMAP: --depth PATTERN
    const CameraFormat* cameraFormat = nullptr;  // --camera-format, for a camera file given as the source
};

// Reads a dataset's frames. Throws Error (naming the file and the rule) when the source itself
// cannot be read: a missing or unreadable file, a COLMAP model without --depth, a malformed
// transforms.json, a manifest that is not UTF-8 text or holds no frame; a bad frame of a
// manifest is that frame's error. Camera files a manifest names are read once each.
// A source is a manifest (.jsonl, .ndjson) or a camera file whose format is a dataset source
// (camera_formats.h); camera files a manifest names are read by readCameraSet, in any format.
Dataset openDataset(const std::string& source, const DatasetSourceOptions& options);

// The manifest line of a frame (dataset import): "camera" as the reference `cameraReference`,
// paths relative to `manifestPath`'s folder where they lie below it. One line of JSON, no newline.
std::string manifestLine(const DatasetFrame& frame, const std::string& cameraReference, const std::string& manifestPath);

// `path` relative to the folder of `base` (a file) when it lies below it, else as it is.
std::string relativeTo(const std::string& path, const std::string& base);

}  // namespace zcheck
