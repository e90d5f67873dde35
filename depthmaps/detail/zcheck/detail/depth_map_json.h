#pragma once
// A depth map's declarations as JSON values (library zcheck::depthmaps, target
// zcheck_depthmaps_detail; never installed): the keys a sidecar, a manifest line and a report
// share, read and written in one place.
#include "zcheck/depth_map_reading.h"
#include "zcheck/detail/json.h"

#include <string>

namespace zcheck {

// A sidecar zcheck's export wrote: an object with "zcheck_version" and a "camera" object (a
// camera file's), which readCameraFile reads as the camera.
bool isExportSidecar(const nlohmann::json& document);
// The declared accuracy an object's keys give ("quantum", "rel_tolerance", "abs_tolerance":
// finite numbers >= 0, the relative one below 1; "allow_holes": a boolean; null or absent: not
// given, 0 or false). Throws Error "<where>: \"<key>\" <rule>".
MapAccuracy accuracyFromJson(const nlohmann::json& object, const std::string& where);
// Its keys, for a report or a manifest line (every key, with its value or 0/false).
nlohmann::json toJson(const MapAccuracy& accuracy);

}  // namespace zcheck
