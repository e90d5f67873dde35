#pragma once
// The camera file (JSON):
//   { "convention": "opengl",
//     "image": {"width": 640, "height": 480},
//     "projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100},
//     "view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]},
//     "depth": {"format": "float32", "reversed": false, "range": [0, 1]} }
// Projection types: perspective (fovy_deg, optional aspect), frustum and orthographic (left,
// right, bottom, top), oblique (the orthographic box + angle_deg, foreshortening), pinhole
// (fx, fy, cx, cy), lens (focal_mm, sensor_width_mm = 36), all with near and far ("inf" for
// the perspective types); matrix (clip_from_eye: 16 numbers, layout, vectors).
// Views: eye/target/up; axonometric (isometric | dimetric | trimetric, target, distance,
// elevation_deg, azimuth_deg); or eye_from_world | world_from_eye (16 numbers, layout, vectors).
// Every key but "projection" and "view" has the default shown. Unknown keys, wrong types
// and invalid values throw Error naming the file and the key.
#include "zcheck/camera.h"

#include <string>

namespace zcheck {

// The file must be a regular file of at most 1 MiB (input_file.h). The sidecar zcheck's export
// writes beside a map is a camera file too: its "camera" object is read.
CameraSpec readCameraFile(const std::string& path);
// The same from JSON text; `source` begins every message ("camera file 'c.json'", "dict").
// A syntax error or a key repeated within one object is an Error too.
CameraSpec cameraSpecFromJsonText(const std::string& text, const std::string& source);
// The camera file's JSON for a camera (readCameraFile reads it back to the same spec).
std::string cameraJsonText(const CameraSpec& spec);
// Every transform of a camera as 4 rows of 4 numbers for column vectors (p' = M·p), plus a
// "native" block in the convention's own form (row vectors for direct3d), as JSON text.
std::string matricesJsonText(const Camera& camera);

}  // namespace zcheck
