#pragma once
// The importers behind camera_import.h, one file each, and what they share. Private to
// zcheck::io.
#include "zcheck/camera_import.h"

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace zcheck::importers {

CameraSet readColmapModel(const std::string& path);             // import_colmap.cpp
CameraSet readTransformsJson(const std::string& path);          // import_transforms.cpp
CameraSet readCalibration(const std::string& path, CameraFormat format);  // import_calibration.cpp: opencv, ros

// The folder of a COLMAP model named by the folder or one of its files; "" if `path` is neither.
std::string colmapModelFolder(const std::string& path);

// A number as text is written: decimal or exponent form, optional sign, "1." allowed; no
// hex, no inf or nan, nothing after it. False when `text` is not such a number.
bool parseFiniteNumber(std::string_view text, double& value);

// `relative` resolved against the folder of `file` (an absolute `relative` is kept).
std::string pathBeside(const std::string& file, const std::string& relative);

// The names FILE#FRAME may use for a frame named by a path: the path without a leading "./",
// its file name, and that name's stem.
std::vector<std::string> pathAliases(const std::string& path);

// Why a camera with nonzero distortion coefficients cannot be used, naming the model and every
// coefficient: "<where>: camera model OPENCV has lens distortion (k1 = 0.1, ...): zcheck checks
// linear projections; undistort the depth map and give its pinhole camera". "" when all are 0.
std::string distortionRefusal(const std::string& where, const std::string& model,
                              const std::vector<std::pair<std::string, double>>& coefficients);

}  // namespace zcheck::importers
