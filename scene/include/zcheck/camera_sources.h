#pragma once
// Cameras for a scene, from any camera file (library zcheck::scene): the formats of
// camera_formats.h and glTF camera nodes (whose row this library registers: a program linking
// zcheck::scene reads glTF cameras with readCameraSet as any other format), a frame chosen by
// FILE#FRAME, and completed with what the file does not say.
//
//   const zcheck::Scene scene = zcheck::loadScene("mesh.ply");
//   const zcheck::CameraSet set = zcheck::readCameraSet("sparse/0");      // a COLMAP model
//   const zcheck::CameraSpec spec = zcheck::completeCamera(set.cameras[set.find("img_014.png")], scene, {});
//
// Near and far: only zcheck's camera files and glTF give them. An imported camera needs them
// only to clip (and to map window depth), so, unless given, they hug the scene as seen from
// the camera: near and far are the smallest and largest eye-z of the scene's triangles
// clipped to the camera's view (its four side planes and the eye plane), less and more 1 %
// (sceneNearFar). A window or NDC map depends on near and far: give the renderer's.
#include "zcheck/camera_import.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"
#include "zcheck/scene.h"

#include <functional>
#include <optional>
#include <string>

namespace zcheck {

// glTF's row of the camera formats (camera_formats.h); readCameraSet reads a file with it: the
// camera nodes of the default scene, in the order the node hierarchy is walked (depth first):
// perspective (yfov, aspectRatio or the image's, znear, zfar or an infinite far plane) and
// orthographic (xmag, ymag half extents, znear, zfar) cameras, posed by the node's world
// transform without its scale (as glTF says), looking down −Z with +Y up. glTF has no image
// size: the cameras carry hasImageSize false. Named by the node's name, else "nodes[i]"; the
// camera's own name is an alias.
const CameraFormat& gltfCameraFormat();

struct SceneNearFar {
    double near = 0, far = 0;
    std::string note;  // what was assumed, for the report ("" when the scene decided alone)
};
// Near and far hugging `scene` as `spec`'s camera sees it (the header's rule); near is held at
// far·1e-7 or more. Throws Error when the camera sees none of the scene.
SceneNearFar sceneNearFar(const Scene& scene, const CameraSpec& spec);

// What the user gives beside a camera file (--near, --far, --width, --height, a depth map's size),
// and the eye-z range a depth map holds (its eye-z values, or its distances times the cosine of
// the widest ray's angle), which near and far must also cover. (A lens model's near and far are
// distances along its rays: for its camera, mapEyeZ is the map's range of distances.)
struct CameraCompletion {
    std::optional<double> near, far;
    std::optional<int> width, height;
    std::optional<std::pair<double, double>> mapEyeZ;
};

// The camera FILE#FRAME names (splitCameraReference, readCameraSet, CameraSet::find).
ImportedCamera importCamera(const std::string& reference, const CameraFormat* format = nullptr);

// An imported camera made usable: the image size (`given`'s — a depth map's, --width and
// --height — else the file's, else a default of 640 wide, noted), near and far (`given`'s,
// else the file's, else sceneNearFar `scene` widened to the map's eye-z range; only the map's
// when the camera sees none of the scene, as a wrong pose does), each assumption added to its
// notes. Throws Error for a camera the file refused (ImportedCamera::refusal), one whose near
// and far are unknown (no scene, or one it does not see, and no map), and one that cannot be built.
CameraSpec completeCamera(const ImportedCamera& camera, const Scene* scene, const CameraCompletion& given);

// A camera and the depth map it is to judge, made together: the map is read at the camera's
// size (or, for a camera file without one, at its own, which the camera then takes), and the
// camera's near and far cover what the map holds (completeCamera). `read(width, height)` reads
// the map (0 × 0: any size).
struct CameraForMap {
    CameraSpec spec;
    DepthMapFile map;
};
CameraForMap completeCameraForMap(const ImportedCamera& camera, const Scene* scene, CameraCompletion given,
                                  DepthQuantity quantity, const std::function<DepthMapFile(int width, int height)>& read);

}  // namespace zcheck
