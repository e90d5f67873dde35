#pragma once
// A camera written in another format (library zcheck::io): what `zcheck camera --to` prints.
// Each is the importer's inverse (camera_import.h), numbers with 17 significant digits, so
// that reading the text back gives the same camera up to the rounding of a quaternion (COLMAP)
// or of the pose's inverse (nerfstudio): a few units in the last place.
//   zcheck      camera.json, the camera file
//   colmap      cameras.txt (one PINHOLE camera, cx = W/2 centred) and images.txt (world-to-
//               camera qvec and tvec in OpenCV axes, the image named `name`)
//   nerfstudio  transforms.json: fl_x, fl_y, cx, cy, w, h and one frame whose
//               transform_matrix is camera-to-world in OpenGL axes
//   opencv      camera.yml, FileStorage YAML: camera_matrix (cx = (W−1)/2 centred), zero
//               distortion, image_width, image_height, R and T world-to-camera
// The three other formats hold pinhole cameras only: perspective, frustum, pinhole and lens
// cameras are written as pinholes; the others are refused (Error naming the projection).
#include "zcheck/camera.h"
#include "zcheck/camera_import.h"

#include <string>
#include <vector>

namespace zcheck {

struct CameraFileText {
    std::string fileName;  // the name the format gives the file ("cameras.txt")
    std::string text;
};

std::vector<CameraFileText> cameraInFormat(const Camera& camera, CameraFormat format, const std::string& name);

}  // namespace zcheck
