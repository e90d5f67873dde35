// A camera written in another format: the inverse of the importers (camera_import.h), so that
// a camera read from one format and written in another reads back as the same camera.
#include "zcheck/camera_export.h"

#include "zcheck/camera_file.h"
#include "zcheck/detail/camera_json.h"
#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <cstdio>

namespace zcheck {

namespace {

// Every digit a double needs to read back as itself.
std::string exact(double value)
{
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", value == 0.0 ? 0.0 : value);
    return text;
}

// The camera's pose in `axes`' eye space, world-to-camera, checked.
glm::dmat4 camFromWorldIn(const Camera& camera, const Convention& axes)
{
    return eyeFromEye(axes, camera.convention()) * camera.eyeFromWorld;
}

std::string colmapCameras(const PinholeIntrinsics& k, const Camera& camera)
{
    return "# Camera list with one line of data per camera:\n"
           "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
           "# Number of cameras: 1\n"
           "1 PINHOLE " + std::to_string(camera.width()) + " " + std::to_string(camera.height()) + " " + exact(k.fx) + " " +
           exact(k.fy) + " " + exact(k.cx) + " " + exact(k.cy) + "\n";
}

std::string colmapImages(const Camera& camera, const std::string& name)
{
    const glm::dmat4 m = camFromWorldIn(camera, Convention::preset("opencv"));
    const glm::dvec4 q = quaternionFromRotation(glm::dmat3(m));  // (w, x, y, z)
    return "# Image list with two lines of data per image:\n"
           "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
           "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
           "# Number of images: 1, mean observations per image: 0\n"
           "1 " + exact(q.x) + " " + exact(q.y) + " " + exact(q.z) + " " + exact(q.w) + " " + exact(m[3][0]) + " " +
           exact(m[3][1]) + " " + exact(m[3][2]) + " 1 " + name + "\n\n";
}

std::string transformsJson(const PinholeIntrinsics& k, const Camera& camera, const std::string& name)
{
    const glm::dmat4 worldFromCam = rigidInverse(camFromWorldIn(camera, Convention::preset("opengl")));
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 4; ++r)
        rows.push_back(nlohmann::json::array({worldFromCam[0][r], worldFromCam[1][r], worldFromCam[2][r], worldFromCam[3][r]}));
    const nlohmann::json document = {
        {"camera_model", "PINHOLE"},
        {"fl_x", k.fx}, {"fl_y", k.fy}, {"cx", k.cx}, {"cy", k.cy},
        {"w", camera.width()}, {"h", camera.height()},
        {"frames", nlohmann::json::array({{{"file_path", name}, {"transform_matrix", rows}}})},
    };
    return prettyJson(document) + "\n";
}

std::string opencvMatrix(const char* key, int rows, int cols, const std::vector<double>& values)
{
    std::string data;
    for (double v : values) data += (data.empty() ? "" : ", ") + exact(v);
    return std::string(key) + ": !!opencv-matrix\n   rows: " + std::to_string(rows) + "\n   cols: " + std::to_string(cols) +
           "\n   dt: d\n   data: [ " + data + " ]\n";
}

std::string opencvYaml(const PinholeIntrinsics& k, const Camera& camera)
{
    const glm::dmat4 m = camFromWorldIn(camera, Convention::preset("opencv"));
    std::vector<double> r;
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) r.push_back(m[col][row]);
    return "%YAML:1.0\n---\nimage_width: " + std::to_string(camera.width()) + "\nimage_height: " +
           std::to_string(camera.height()) + "\n" +
           opencvMatrix("camera_matrix", 3, 3, {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1}) +
           opencvMatrix("distortion_coefficients", 5, 1, {0, 0, 0, 0, 0}) + opencvMatrix("R", 3, 3, r) +
           opencvMatrix("T", 3, 1, {m[3][0], m[3][1], m[3][2]});
}

}  // namespace

std::vector<CameraFileText> cameraInFormat(const Camera& camera, CameraFormat format, const std::string& name)
{
    switch (format) {
    case CameraFormat::Zcheck: return {{"camera.json", cameraJsonText(camera.spec()) + "\n"}};
    case CameraFormat::Colmap: {
        const PinholeIntrinsics k = pinholeIntrinsicsOf(camera, 0.5);
        return {{"cameras.txt", colmapCameras(k, camera)}, {"images.txt", colmapImages(camera, name)}};
    }
    case CameraFormat::Nerfstudio: return {{"transforms.json", transformsJson(pinholeIntrinsicsOf(camera, 0.5), camera, name)}};
    case CameraFormat::OpenCv: return {{"camera.yml", opencvYaml(pinholeIntrinsicsOf(camera, 0.0), camera)}};
    default: break;
    }
    throw Error("cameras are written as zcheck, colmap, nerfstudio or opencv, not " + toString(format));
}

}  // namespace zcheck
