#pragma once
// Cameras as JSON values (library zcheck::cameras, target zcheck_cameras_detail): camera files
// and matrices as nlohmann::json values, read and printed through io's strict JSON (json.h).
//
// For zcheck's own libraries and programs that write or read JSON documents holding cameras
// (cameras itself, report, the command line, tests): they link `$<BUILD_INTERFACE:zcheck_cameras_detail>`
// PRIVATE and include "zcheck/detail/camera_json.h". It is never installed and never part of
// the exported package, so that nlohmann-json stays out of zcheck's public interface; its
// functions may change with any commit. Everyone else uses the public API, camera_file.h,
// which takes and returns text (cameraSpecFromJsonText, cameraJsonText, matricesJsonText).
//
// Refusals are zcheck::Error whose message begins with the `source` or `where` given
// ("camera file 'c.json'", "sidecar 'map.json'") and names the key.
#include "zcheck/camera.h"
#include "zcheck/detail/json.h"

#include <string>

namespace zcheck {

// A camera file's document (camera_file.h: its keys and rules) as a validated camera's spec.
CameraSpec cameraSpecFromJson(const nlohmann::json& document, const std::string& source);
// A camera as the camera file's document (cameraSpecFromJson reads it back to the same spec).
nlohmann::json toJson(const CameraSpec& spec);
// Every transform of a camera as rows for column vectors, and the convention's own form
// (matricesJsonText's document, camera_file.h).
nlohmann::json matricesJson(const Camera& camera);

}  // namespace zcheck
