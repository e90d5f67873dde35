#pragma once
// JSON values of camera files and matrices (nlohmann, private to zcheck_io and zcheck_report:
// never installed). The public API (camera_file.h) takes and returns text.
#include "zcheck/camera.h"

#include <nlohmann/json.hpp>

#include <string>

namespace zcheck {

CameraSpec cameraSpecFromJson(const nlohmann::json& document, const std::string& source);
// JSON text parsed strictly: a syntax error or a key repeated within one object throws Error
// beginning with `source` (e.g. "camera file 'c.json'").
nlohmann::json parseJsonStrictly(const std::string& text, const std::string& source);
nlohmann::json toJson(const CameraSpec& spec);
nlohmann::json matricesJson(const Camera& camera);
// JSON indented for people: arrays of numbers (matrix rows, vectors) stay on one line.
// Invalid UTF-8 in strings (file names) is replaced, never thrown over.
std::string prettyJson(const nlohmann::json& document);

}  // namespace zcheck
