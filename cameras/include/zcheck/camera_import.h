#pragma once
// Cameras in the formats people have (library zcheck::cameras): every camera of a file, read as
// the format's authors define it, through the one rule for poses and intrinsics (pose.h).
//
// What each format stores (the rows of camera_formats.h read them):
//
// | format       | pose stored                     | camera axes              | top-left pixel centre | units          |
// |--------------|---------------------------------|--------------------------|-----------------------|----------------|
// | zcheck       | look-at or a raw view           | the file's convention    | 0.5 (0 for pinhole cx)| scene units    |
// | colmap       | world-to-camera: qvec, tvec     | OpenCV: x right, y down, | 0.5 (cx = W/2 centred)| model units    |
// |              | (Hamilton, qw qx qy qz)         | z forward                |                       |                |
// | nerfstudio   | camera-to-world transform_matrix| OpenGL: x right, y up,   | 0.5                   | scene units    |
// | (instant-ngp)|                                 | z back                   |                       |                |
// | opencv       | world-to-camera R|T, rvec|tvec  | OpenCV                   | 0 (cx = (W−1)/2)      | as calibrated  |
// |              | (none: the camera's own frame)  |                          |                       |                |
// | ros          | none: the optical frame is world| OpenCV (REP 103/104)     | 0                     | metres         |
// | metashape    | camera-to-chunk, then the chunk | OpenCV                   | 0.5 (cx = W/2 + cx)   | the chunk's    |
// |              | (or component) transform        |                          |                       | world          |
// | gltf         | the node's world transform      | −Z forward, +Y up        | NDC: none             | metres         |
//
// glTF cameras are read by the scene library with the rest of the glTF (camera_sources.h),
// which registers that format. Each camera keeps its format's axes as its
// convention ("opencv" or "opengl"): the picture is the same in every convention, and
// --convention may change it.
//
// What a file does not say is not invented: near and far (no format but zcheck's and glTF's
// has them) are left for the user or the scene to give (hasClipPlanes), an image size some
// instant-ngp files omit is taken from the depth map (hasImageSize), and a camera the reader
// cannot use (a lens no lens model holds, one that folds inside its image) is kept with the
// reason (refusal), so that a dataset's other frames still run. Lens distortion, fisheyes and
// panoramas are lens models (lens.h): ProjectionType::NonLinear. Bad input throws Error naming the file, the line or key
// and the rule.
#include "zcheck/camera.h"
#include "zcheck/camera_formats.h"

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace zcheck {

// One camera of a file.
struct ImportedCamera {
    std::string name;                  // the frame's name: an image name, a file path, or its index
    std::vector<std::string> aliases;  // other names FILE#FRAME may use: a path's file name and stem
    CameraSpec spec;                   // near, far and the size are placeholders where the file is silent
    bool hasClipPlanes = false;        // the file gives near and far
    bool hasImageSize = true;          // the file gives width and height
    std::string depthPath;             // the depth map the file names for this frame, as a path ("" none)
    std::string refusal;               // why the camera cannot be used (lens distortion, fisheye); "" usable
    // Without an image size: the projection for a given size (the field of view, focal lengths
    // and principal point the file gives, resolved over it). Empty when the file gives the size.
    std::function<Projection(int width, int height)> projectionForSize;
};

struct CameraSet {
    std::string path;  // as given
    std::string format;  // the name of its format (camera_formats.h)
    std::vector<ImportedCamera> cameras;
    // The camera a reference without #FRAME means when the file holds several (a ROS
    // CameraInfo's raw camera beside its rectified one); none: the reference must name one.
    std::optional<std::size_t> defaultCamera;
    // How the file's depth maps store depth, when it says: stored value = depth × depthScale
    // (nerfstudio: 1000, millimetres by default; instant-ngp: 1 / integer_depth_scale), and
    // the sentence a report prints about it.
    std::optional<double> depthScale;
    std::string depthScaleNote;

    // The camera `frame` names: "" for a file's only camera (or its default camera); else its index (digits), its name,
    // or an alias (a leading "./" ignored). Throws Error naming the file and the frame (listing a
    // few of the file's frames) when nothing or several cameras match, and the camera's refusal
    // when it cannot be used.
    std::size_t find(const std::string& frame) const;
};

// "FILE#FRAME" → {FILE, FRAME}; {reference, ""} without a '#'. A reference that names an
// existing file or folder as a whole is a FILE even if it holds a '#'.
std::pair<std::string, std::string> splitCameraReference(const std::string& reference);

// Every camera of `path` in `format` (nullptr: told by content, detectCameraFormat). A COLMAP
// model is named by its folder (or any of its files); text and binary are both read, binary
// preferred when a folder holds both, as COLMAP does. Throws Error naming the file and the rule.
CameraSet readCameraSet(const std::string& path, const CameraFormat* format = nullptr);

// The placeholders a camera without clip planes or image size carries until they are known.
inline constexpr double kPlaceholderNear = 0.1, kPlaceholderFar = 100.0;
inline constexpr int kPlaceholderWidth = 640, kPlaceholderHeight = 480;

}  // namespace zcheck
