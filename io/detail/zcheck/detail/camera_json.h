#pragma once
// zcheck's internal JSON interface (library zcheck::io, target zcheck_io_detail): camera files,
// matrices and declared accuracies as nlohmann::json values, and the strict parser and the
// printer every zcheck document goes through.
//
// For zcheck's own libraries and programs that write or read JSON documents holding cameras
// (io itself, report, the command line, tests): they link `$<BUILD_INTERFACE:zcheck_io_detail>`
// PRIVATE and include "zcheck/detail/camera_json.h". It is never installed and never part of
// the exported package, so that nlohmann-json stays out of zcheck's public interface; its
// functions may change with any commit. Everyone else uses the public API, camera_file.h,
// which takes and returns text (cameraSpecFromJsonText, cameraJsonText, matricesJsonText).
//
// Refusals are zcheck::Error whose message begins with the `source` or `where` given
// ("camera file 'c.json'", "sidecar 'map.json'") and names the key.
#include "zcheck/camera.h"
#include "zcheck/depth_map_reading.h"

#include <nlohmann/json.hpp>

#include <string>

namespace zcheck {

// A camera file's document (camera_file.h: its keys and rules) as a validated camera's spec.
CameraSpec cameraSpecFromJson(const nlohmann::json& document, const std::string& source);
// A sidecar zcheck's export wrote: an object with "zcheck_version" and a "camera" object (a
// camera file's), which readCameraFile reads as the camera.
bool isExportSidecar(const nlohmann::json& document);
// JSON text parsed strictly: a syntax error or a key repeated within one object throws Error
// beginning with `source` (e.g. "camera file 'c.json'").
nlohmann::json parseJsonStrictly(const std::string& text, const std::string& source);
// A camera as the camera file's document (cameraSpecFromJson reads it back to the same spec).
nlohmann::json toJson(const CameraSpec& spec);
// Every transform of a camera as rows for column vectors, and the convention's own form
// (matricesJsonText's document, camera_file.h).
nlohmann::json matricesJson(const Camera& camera);
// JSON indented for people: arrays of numbers (matrix rows, vectors) stay on one line.
// Invalid UTF-8 in strings (file names) is replaced, never thrown over.
std::string prettyJson(const nlohmann::json& document);

// The declared accuracy an object's keys give ("quantum", "rel_tolerance", "abs_tolerance":
// finite numbers >= 0, the relative one below 1; "allow_holes": a boolean; null or absent: not
// given, 0 or false). Throws Error "<where>: \"<key>\" <rule>".
MapAccuracy accuracyFromJson(const nlohmann::json& object, const std::string& where);
// Its keys, for a report or a manifest line (every key, with its value or 0/false).
nlohmann::json toJson(const MapAccuracy& accuracy);

}  // namespace zcheck
