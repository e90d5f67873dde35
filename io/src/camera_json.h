#pragma once
// JSON values of camera files and matrices (nlohmann, private to zcheck_io and zcheck_report:
// never installed). The public API (camera_file.h) takes and returns text.
#include "zcheck/camera.h"
#include "zcheck/depth_map_reading.h"

#include <nlohmann/json.hpp>

#include <string>

namespace zcheck {

CameraSpec cameraSpecFromJson(const nlohmann::json& document, const std::string& source);
// A sidecar zcheck's export wrote: an object with "zcheck_version" and a "camera" object (a
// camera file's), which readCameraFile reads as the camera.
bool isExportSidecar(const nlohmann::json& document);
// JSON text parsed strictly: a syntax error or a key repeated within one object throws Error
// beginning with `source` (e.g. "camera file 'c.json'").
nlohmann::json parseJsonStrictly(const std::string& text, const std::string& source);
nlohmann::json toJson(const CameraSpec& spec);
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
