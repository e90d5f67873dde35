#pragma once
// Camera = view + projection + image size + depth settings, in one convention.
//
// Spaces (column vectors, p' = M·p; names are destFromSrc so that they cancel):
//   world  — the scene's coordinates
//   eye    — camera at the origin, axes from the convention: x right in the image,
//            y = eyeUpY · up, viewing direction = (0, 0, eyeForwardZ)
//   clip   — homogeneous, before the divide; the visible volume is
//            |x| ≤ w, |y| ≤ w, ndcZMin·w ≤ z ≤ w
//   NDC    — clip / w
//   window — x in [0, width] left to right, y in [0, height] from the convention's window
//            origin (bottom-left for opengl, top-left for the others), z = window depth in
//            [depth.rangeMin, depth.rangeMax]
//   image  — x as window x, y in [0, height] from the top edge: pixel (col,row) covers
//            [col, col+1) × [row, row+1) and its centre is (col + 0.5, row + 0.5)
//
// Units: angles in degrees at the interface, lengths in scene units, near and far are
// positive distances along the viewing direction (eye-z).
//
// A camera whose projection is a lens model (ProjectionType::NonLinear: distortion, fisheyes,
// panoramas) has no projection matrix and no depth buffer: lens() maps directions to image points
// and back, its near and far are distances along the rays, and only the eye-z and distance
// quantities exist. Its matrices are those of its linear part (the pinhole of its fx, fy, cx, cy;
// a 90° view for a panorama), kept so that a matrix is always defined, never used to project:
// whatever projects asks lens() first.
//
// Cameras are built by a validating constructor: a NaN, a degenerate view, near ≤ 0,
// far ≤ near, an empty frustum or an image outside 1…16384 pixels per side (or over 2^25
// pixels in all) throws Error naming the parameter. Nothing is silently repaired. A Camera
// is an immutable value once built: share it between threads freely.
//
//   zcheck::CameraSpec spec;                                   // opengl, 640×480, looking at the origin
//   spec.projection = zcheck::Projection::perspective(60.0, 0.1, 100.0);
//   spec.view = zcheck::View::lookAt({0, 1, 3}, {0, 0, 0}, {0, 1, 0});
//   const zcheck::Camera camera(spec);                          // camera.clipFromWorld, ...
#include "zcheck/convention.h"
#include "zcheck/lens.h"

#include <glm/glm.hpp>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

enum class ProjectionType {
    Perspective,   // gluPerspective: fovy_deg, aspect, near, far
    Frustum,       // glFrustum: left, right, bottom, top on the near plane, near, far
    Orthographic,  // glOrtho: left, right, bottom, top, near, far
    Oblique,       // the orthographic box sheared: cavalier (λ = 1), cabinet (λ = ½)
    Pinhole,       // OpenCV intrinsics fx, fy, cx, cy in pixels, near, far
    Lens,          // physical lens: focal_mm on a sensor sensor_width_mm wide (horizontal fit)
    Matrix,        // a raw clipFromEye matrix
    NonLinear,     // a lens model (lens.h): distortion, fisheye, panorama; Projection::lens holds it
};

std::string toString(ProjectionType type);

struct Projection {
    ProjectionType type = ProjectionType::Perspective;
    double fovyDeg = 60.0;  // perspective: full vertical field of view, degrees, in (0, 180)
    double aspect = 0.0;    // perspective: width / height of the view; 0 = the image's
    // frustum: extents of the near-plane window; orthographic and oblique: the view box.
    // As seen in the image (right = image right, top = image top), in eye units.
    double left = 0.0, right = 0.0, bottom = 0.0, top = 0.0;
    // oblique: a point at depth d behind the near plane moves by λ·d·(cos a, sin a) in the
    // image plane (x right, y up) before the orthographic mapping; the near plane stays put.
    double angleDeg = 45.0;       // a
    double foreshortening = 0.5;  // λ ≥ 0: 1 cavalier, ½ cabinet, 0 orthographic
    // pinhole: focal lengths and principal point in pixels; cx, cy in OpenCV pixel
    // coordinates, where the centre of the top-left pixel is (0, 0) and y grows downwards,
    // so a centred camera has cx = (width − 1)/2, cy = (height − 1)/2.
    double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
    // lens: focal length and sensor width in millimetres; the sensor width spans the image
    // width (horizontal fit): horizontal fov = 2·atan(sensor / (2·focal)).
    double focalMm = 50.0, sensorWidthMm = 36.0;
    // matrix: the convention's clip space from the convention's eye space, p' = M·p.
    glm::dmat4 clipFromEye{1.0};
    // non-linear: the lens model and its parameters (lens.h), fx, fy, cx, cy among them where
    // the model has them.
    LensSpec lens;
    double near = 0.1;      // > 0 (not used by matrix: derived from it)
    double far = 100.0;     // > near, or +inf for the perspective types (infinite far plane)
    // A non-linear camera has no near or far plane: near and far bound the distance along each
    // ray (the `distance` quantity), a sphere around the centre of projection.

    // Rays meet at a centre of projection (perspective, frustum, pinhole, lens; a matrix
    // whose w depends on z) rather than running parallel.
    bool isPerspective() const;

    static Projection perspective(double fovyDeg, double near, double far)
    {
        Projection p;
        p.type = ProjectionType::Perspective;
        p.fovyDeg = fovyDeg, p.near = near, p.far = far;
        return p;
    }
};

// The view: a look-at, or a raw eyeFromWorld matrix. Axonometric views are a look-at
// whose eye is placed by angles (kept for printing).
struct View {
    glm::dvec3 eye{0.0, 1.0, 3.0};
    glm::dvec3 target{0.0, 0.0, 0.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    // Axonometric: "isometric", "dimetric", "trimetric" or empty. The eye stands at
    // target + distance·(cos e·sin a, sin e, cos e·cos a) for azimuth a (about world +y,
    // from +z towards +x) and elevation e (above the horizontal plane).
    std::string axonometric;
    double distance = 0.0, azimuthDeg = 0.0, elevationDeg = 0.0;
    // A raw view matrix: the convention's eye space from world, p' = M·p; rigid, its rotation
    // with the convention's handedness (pose.h: the rule, and how far from orthonormal a
    // rotation may be and still be re-orthonormalised).
    bool hasMatrix = false;
    glm::dmat4 eyeFromWorld{1.0};
    // How far the rotation as given departed from orthonormal (pose.h) when it was
    // re-orthonormalised — by the Camera constructor or an importer — 0 when it was not.
    // Reports say so.
    double rotationDeparture = 0;

    static View lookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up)
    {
        View view;
        view.eye = eye, view.target = target, view.up = up;
        return view;
    }
    // Places the eye of an axonometric view; throws Error for an unknown kind.
    static View axonometricView(const std::string& kind, const glm::dvec3& target, double distance,
                                double azimuthDeg, double elevationDeg);
};
using LookAt = View;

struct CameraSpec {
    Convention convention = Convention::preset("opengl");
    int width = 640;   // pixels, 1…16384
    int height = 480;  // pixels, 1…16384
    Projection projection;
    View view;
    DepthSettings depth;
    // What was assumed when this camera was made from a file that did not say (near and far
    // taken from the scene, an image size from the depth map, ...), one sentence each; reports
    // print them beside the pose rule's note (poseNotes). Not part of the camera's geometry.
    std::vector<std::string> notes;
};

class Camera {
public:
    explicit Camera(const CameraSpec& spec);  // validates; throws Error naming the parameter

    const CameraSpec& spec() const { return spec_; }
    // The lens model of a non-linear camera; nullptr for every linear projection.
    const LensModel* lens() const { return lens_.get(); }
    // The camera frame of lens.h (x right, y down, z forward) from the convention's eye space.
    glm::dvec3 lensFrameFromEye(const glm::dvec3& vEye) const
    {
        return {vEye.x, -spec_.convention.eyeUpY * vEye.y, spec_.convention.eyeForwardZ * vEye.z};
    }
    glm::dvec3 eyeFromLensFrame(const glm::dvec3& vLens) const { return lensFrameFromEye(vLens); }  // an involution
    const Convention& convention() const { return spec_.convention; }
    const DepthSettings& depth() const { return spec_.depth; }
    int width() const { return spec_.width; }
    int height() const { return spec_.height; }
    double aspect() const;  // the aspect the projection uses (resolved default)

    // The near-plane window as seen in the image, after resolving fovy/aspect.
    double left() const { return left_; }
    double right() const { return right_; }
    double bottom() const { return bottom_; }
    double top() const { return top_; }
    // Near and far distances along the viewing direction (eye-z), derived from the matrix
    // for a raw matrix; far is +inf for an infinite far plane.
    double nearDistance() const { return near_; }
    double farDistance() const { return far_; }
    bool farIsInfinite() const { return std::isinf(far_); }

    glm::dmat4 eyeFromWorld, worldFromEye;
    glm::dmat4 clipFromEye, eyeFromClip;
    glm::dmat4 clipFromWorld, worldFromClip;
    glm::dmat4 windowFromNdc, ndcFromWindow;  // affine; z is the depth-range mapping

    // NDC z of the near and far planes (swapped by reversed-Z).
    double ndcZNear() const;
    double ndcZFar() const;
    double windowDepthFromNdcZ(double zNdc) const;
    double ndcZFromWindowDepth(double windowDepth) const;
    double windowDepthNear() const { return windowDepthFromNdcZ(ndcZNear()); }
    double windowDepthFar() const { return windowDepthFromNdcZ(ndcZFar()); }
    // The value a cleared depth buffer holds: the far end of the range (rangeMin when reversed).
    // A lens camera's ray route holds distances, and a miss is +inf.
    double clearDepth() const { return lens_ ? INFINITY : quantizeDepth(spec_.depth.format, windowDepthFar()); }
    // The depth test: LESS, or GREATER with reversed-Z.
    bool passesDepthTest(double candidate, double stored) const
    {
        return spec_.depth.reversed ? candidate > stored : candidate < stored;
    }

    // Planar depth (eye-z) of an eye-space point: its distance along the viewing direction.
    double eyeZOf(const glm::dvec3& pEye) const { return spec_.convention.eyeForwardZ * pEye.z; }

    // Window y ↔ image y (image y grows downward from the top edge).
    double imageYFromWindowY(double yWindow) const
    {
        return spec_.convention.windowOriginTop ? yWindow : spec_.height - yWindow;
    }
    double windowYFromImageY(double yImage) const { return imageYFromWindowY(yImage); }  // an involution

    // The largest world coordinate of the eye and of the near-plane window's corners (rays
    // are traced in binary32); the constructor refuses cameras beyond it.
    static constexpr double kMaxWorldCoordinate = 1e15;
    // The largest image side in pixels (the smallest is 1), and the most pixels in all; the
    // constructor refuses larger images. About 85 bytes per pixel go to both routes, the
    // comparison and --out: 2^25 pixels (8192×4096) stay within ~3 GiB; more would risk the
    // machine's memory instead of failing cleanly.
    static constexpr int kMaxImageSide = 16384;
    static constexpr long long kMaxImagePixels = 1LL << 25;
    // Whether a side as a file states it is one an image may have: a whole number in 1…kMaxImageSide.
    static bool isImageSide(double pixels) { return pixels == std::floor(pixels) && pixels >= 1 && pixels <= kMaxImageSide; }
    // Whether both sides are image sides and their product is at most kMaxImagePixels.
    static bool isImageSize(long long width, long long height)
    {
        return width >= 1 && height >= 1 && width <= kMaxImageSide && height <= kMaxImageSide && width * height <= kMaxImagePixels;
    }

private:
    void requireRepresentable() const;

    CameraSpec spec_;
    std::shared_ptr<const LensModel> lens_;
    double left_ = 0, right_ = 0, bottom_ = 0, top_ = 0;
    double near_ = 0, far_ = 0;
};

// Whether a projection is a raw matrix (ProjectionType::Matrix): it has no parameters of its own
// (no field of view, near or far to change), only its matrix.
inline bool isRawMatrix(const Projection& projection) { return projection.type == ProjectionType::Matrix; }
inline bool isRawMatrix(const Camera& camera) { return isRawMatrix(camera.spec().projection); }

// A change of the focal lengths and the principal point, as a fit finds one: eye x and y scaled by
// `focalScale` before the projection (> 1 is narrower), the principal point moved by
// `principalShift` image pixels (x right, y down).
enum class IntrinsicChange {
    FocalScale,                    // one scale for x and y (focalScale.x); the principal point stays
    FocalScalesAndPrincipalPoint,  // a scale each for x and y, and the principal point moves
};
// One of the projection model's own parameters, with its value as declared and after a change.
struct IntrinsicParameter {
    const char* key;    // as the camera file names it: "fovy_deg", "focal_mm", "fx", ...
    const char* words;  // what it is: "vertical field of view", "focal length", "principal point"
    const char* unit;   // as printed after the value: "°", " mm", " px"
    int digits;         // the significant digits that show it
    double declared = 0, changed = 0;
};
// The model's parameters that state such a change in the camera's own terms, in the camera file's
// order: perspective fovy_deg and lens focal_mm state one focal scale; pinhole fx, fy state one
// scale or two, and cx, cy the moved principal point. Empty where the model cannot state the
// change: a frustum's or box's extents, a raw matrix, a field of view or a lens's focal length
// under two scales and a moved principal point.
std::vector<IntrinsicParameter> intrinsicParameters(const Projection& projection, IntrinsicChange change,
                                                    const glm::dvec2& focalScale, const glm::dvec2& principalShift);

// The same camera in a world moved by −origin: the frame a scene far from the world's origin is
// held in (Scene::origin). Eye space, projection, lens and image are the camera's own; only the
// view's place moves, in binary64 (eye and scene then meet to ~2^-53 of their distance from the
// world's origin, where binary32 positions would part by ~2^-24 of it). A zero origin gives the
// camera unchanged.
Camera cameraAboutOrigin(const Camera& camera, const glm::dvec3& origin);

// A camera that sees a bounding sphere (centre, radius) whole, looking at it from the front
// right and above, 640×480, near/far hugging the sphere. Used for meshes without a camera.
CameraSpec framingCameraSpec(const glm::dvec3& centre, double radius);

namespace testing {
// A test hook (tests/test_independence.cpp proves the two routes independent with it): when
// set, every Camera built afterwards passes each matrix it derives from the projection
// model's parameters through it before use — "eye_from_world" (look-at views),
// "clip_from_eye" (every type but a raw matrix) and "window_from_ndc" — so that a test can
// perturb one coefficient. nullptr (the default) turns it off. Not thread-safe; tests only.
using MatrixHook = void (*)(const char* which, ProjectionType type, glm::dmat4& matrix);
void setMatrixHook(MatrixHook hook);
}  // namespace testing

// Row-major construction for readable matrix literals: rows[r][c] is row r, column c.
glm::dmat4 matrixFromRows(const double rows[4][4]);

// Which side of a matrix the vectors go, as an engine writes its matrices: column vectors
// (p' = M·p: OpenGL, GLM, Vulkan, Metal, zcheck) or row vectors (p' = p·M: Direct3D,
// DirectXMath), for which the same transform is written transposed.
enum class MatrixVectors { Column, Row };
// The names the camera file's "vectors" key and Python's vectors= take.
inline constexpr const char* kMatrixVectorsNames = "\"column\" (p' = M·p) or \"row\" (p' = p·M, Direct3D style)";
// "column" or "row"; nothing for any other name (the caller says kMatrixVectorsNames).
std::optional<MatrixVectors> matrixVectorsFromName(const std::string& name);
// A matrix written for `vectors` as zcheck holds it, for column vectors, and back: the
// transpose for row vectors (an involution), `m` itself for column vectors.
glm::dmat4 matrixForVectors(const glm::dmat4& m, MatrixVectors vectors);

}  // namespace zcheck
