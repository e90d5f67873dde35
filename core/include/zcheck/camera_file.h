#pragma once
// The camera file (JSON):
//   { "convention": "opengl",
//     "image": {"width": 640, "height": 480},
//     "projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100},
//     "view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]},
//     "depth": {"format": "float32", "reversed": false, "range": [0, 1]} }
// "frustum" and "orthographic" take left, right, bottom, top, near, far instead of fovy_deg
// (perspective also takes an optional "aspect"). Every key but "projection" and "view" has
// the default shown. Unknown keys, wrong types and invalid values throw Error naming the
// file and the key.
#include "zcheck/camera.h"

#include <nlohmann/json.hpp>

#include <string>

namespace zcheck {

CameraSpec cameraSpecFromJson(const nlohmann::json& document, const std::string& source);
CameraSpec readCameraFile(const std::string& path);
nlohmann::json toJson(const CameraSpec& spec);

}  // namespace zcheck
