#pragma once
// One rule for poses and intrinsics. Every way a camera's pose or pinhole intrinsics enter
// zcheck — the camera file's raw view matrices, the importers (COLMAP, nerfstudio,
// instant-ngp, OpenCV, ROS, glTF), the Python module's Camera.from_opencv and the Camera
// constructor itself — goes through these functions, so that all of them accept, repair and
// refuse the same things with the same words.
//
// Camera axes. A stored pose maps between world and a camera frame whose axes the format
// fixes. zcheck names those axes by the convention whose eye space has them (convention.h):
//   "opencv"  x right, y down, z forward   (COLMAP, OpenCV, ROS optical frames)
//   "opengl"  x right, y up,   z backward  (nerfstudio, instant-ngp, glTF, Blender)
// so that a pose in one frame becomes the eye space of any convention by eyeFromEye().
//
// Rotations. A rotation a file stores is orthonormal only to the digits it kept: a pose
// written with 5 decimals departs from RᵀR = I by up to ~2·10⁻⁵. The rule, by the largest
// element of |RᵀR − I| (the departure):
//   ≤ kRotationExact           used as given (binary64 arithmetic keeps no better);
//   ≤ kRotationRoundingBound   re-orthonormalised — replaced by the nearest rotation (polar
//                              decomposition) — and the departure is kept, so that reports
//                              say so (View::rotationDeparture);
//   beyond                     refused: a scale or a shear is not a pose.
// The determinant must be that of the target axes: +1 where world and eye are both
// right-handed (opengl, vulkan, metal, opencv), −1 for direct3d's left-handed eye space. The
// other sign mirrors the picture: one axis flipped instead of two, refused.
//
// Intrinsics. Formats write the principal point in pixel coordinates whose top-left pixel
// has its centre at `pixelCenter`: 0 for OpenCV and ROS (a centred camera has
// cx = (width − 1)/2), 0.5 for COLMAP, nerfstudio and instant-ngp (cx = width/2). zcheck's
// pinhole projection stores OpenCV's (camera.h).
//
// Every function throws Error naming `what` (the format's own name of the value: "R",
// "images.txt line 7 qvec", "view.eye_from_world") and the rule broken.
#include "zcheck/camera.h"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace zcheck {

inline constexpr double kRotationExact = 1e-12;
inline constexpr double kRotationRoundingBound = 1e-4;

// The determinant a rotation from a right-handed world into `convention`'s eye space has:
// +1, or −1 for a left-handed eye space (direct3d).
int eyeHandedness(const Convention& convention);

// `to`'s eye space from `from`'s: a diagonal of ±1 (x is "image right" in every convention).
glm::dmat4 eyeFromEye(const Convention& to, const Convention& from);

// A rigid transform checked by the rule above: its rotation orthonormal to binary64 rounding.
struct RigidTransform {
    glm::dmat4 matrix{1.0};   // column vectors, last row 0 0 0 1
    double departure = 0;     // the departure of the rotation as given; 0 when ≤ kRotationExact
};

// `m` (column vectors) as a rigid transform whose rotation has determinant `determinant`
// (+1 or −1). Refuses a non-finite entry, a last row other than 0 0 0 1 (hasRigidLastRow), a
// departure beyond kRotationRoundingBound (scale or shear) and the wrong determinant (a
// reflection).
RigidTransform requireRigid(const glm::dmat4& m, int determinant, const std::string& what);

// The last row of `m` (column vectors) is exactly 0 0 0 1, as a rigid transform's is: the
// first rule of requireRigid after finiteness, for callers that check a pose's shape before
// the rest of the rule (Python's cam_from_world=, a 4x4 or 3x4 array).
bool hasRigidLastRow(const glm::dmat4& m);

// [R | t] with the last row 0 0 0 1, column vectors: x' = R·x + t. It is how OpenCV's R and t
// (or rvec and tvec), COLMAP's qvec and tvec and Camera.from_opencv's R, t store a
// world-to-camera pose. Not checked: viewFromPose (or requireRigid) checks it.
glm::dmat4 poseFromRotationTranslation(const glm::dmat3& rotation, const glm::dvec3& translation);

// [Rᵀ | −Rᵀt]: the inverse of a rigid transform, by transposition (no general inverse).
glm::dmat4 rigidInverse(const glm::dmat4& m);

// The rotation of a Hamilton quaternion w + xi + yj + zk (COLMAP's qvec = qw qx qy qz, glTF's
// rotation = x y z w), column vectors. A quaternion whose norm departs from 1 by at most
// kRotationRoundingBound is normalised (the departure returned through `departure`); beyond,
// or a zero or non-finite one, is refused.
glm::dmat3 rotationFromQuaternion(double w, double x, double y, double z, const std::string& what,
                                  double* departure = nullptr);
// The unit quaternion (w, x, y, z) of a rotation, w ≥ 0 (for writers: COLMAP's qvec).
glm::dvec4 quaternionFromRotation(const glm::dmat3& rotation);

// How a format stores a pose.
enum class PoseDirection {
    CameraFromWorld,  // world-to-camera: COLMAP's (qvec, tvec), OpenCV's [R | t], rvec/tvec
    WorldFromCamera,  // camera-to-world: nerfstudio's transform_matrix, glTF nodes, Blender's matrix_world
};

// A stored pose as the view of a camera in `target`'s eye space: checked (requireRigid, with
// the determinant of `poseAxes`), inverted rigidly when stored camera-to-world, and turned from
// `poseAxes` into `target`'s eye axes. The view keeps the departure (View::rotationDeparture).
View viewFromPose(const glm::dmat4& pose, PoseDirection direction, const Convention& poseAxes, const Convention& target,
                  const std::string& what);

// What a report says of a camera: its notes (CameraSpec::notes) and, when the pose rule
// re-orthonormalised its rotation, one sentence saying by how much.
std::vector<std::string> cameraNotes(const CameraSpec& spec);

// Pinhole intrinsics as formats write them (units: pixels).
struct PinholeIntrinsics {
    double fx = 0, fy = 0;   // focal lengths
    double cx = 0, cy = 0;   // the principal point, in the format's pixel coordinates
    double pixelCenter = 0;  // the centre of the top-left pixel in those coordinates: 0 or 0.5

    // zcheck's pinhole projection (cx, cy moved to OpenCV's coordinates), with near and far.
    // Refuses a pixelCenter other than 0 or 0.5 and focal lengths or a principal point that are
    // not finite (or focal lengths ≤ 0), naming `what`.
    Projection projection(double near, double far, const std::string& what) const;
    // zcheck's lens-model projection (camera.h, ProjectionType::NonLinear; lens.h): `model` with
    // these fx, fy, cx, cy (moved to OpenCV's coordinates) and then `coefficients` in the model's
    // order (its parameters after cy). Refuses as projection() does; the lens itself is validated
    // when a Camera is built from it.
    Projection lensProjection(const std::string& model, const std::vector<double>& coefficients, double near,
                              double far, const std::string& what) const;

    // From K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (k[row][col]); refuses skew and any other
    // form, naming `what` ("K", "camera_matrix") and the element.
    static PinholeIntrinsics fromK(const double (&k)[3][3], double pixelCenter, const std::string& what);
};

// The pinhole intrinsics of a camera whose rays meet at a point and whose image plane is
// perpendicular to the viewing axis (perspective, frustum, pinhole, lens; the fx, fy, cx, cy of a
// lens model that has them — its distortion is not in them), with the principal
// point in coordinates whose top-left pixel centre is `pixelCenter`. Throws Error naming the
// projection type for any other (orthographic, oblique, a raw matrix).
PinholeIntrinsics pinholeIntrinsicsOf(const Camera& camera, double pixelCenter);

}  // namespace zcheck
