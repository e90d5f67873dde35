#pragma once
// What the camera formats' files share. Private to zcheck::cameras.
#include "zcheck/camera_formats.h"
#include "zcheck/camera_import.h"

#include <glm/glm.hpp>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace zcheck::formats {

// A number as text is written: decimal or exponent form, optional sign, "1." allowed; no
// hex, no inf or nan, nothing after it. False when `text` is not such a number.
bool parseFiniteNumber(std::string_view text, double& value);

// `relative` resolved against the folder of `file` (an absolute `relative` is kept).
std::string pathBeside(const std::string& file, const std::string& relative);

// The names FILE#FRAME may use for a frame named by a path: the path without a leading "./",
// its file name, and that name's stem.
std::vector<std::string> pathAliases(const std::string& path);

// For writers: every digit a double needs to read back as itself ("%.17g", −0 written as 0).
std::string exactNumber(double value);
// The camera's pose in `axes`' eye space, world-to-camera.
glm::dmat4 camFromWorldIn(const Camera& camera, const Convention& axes);

}  // namespace zcheck::formats
