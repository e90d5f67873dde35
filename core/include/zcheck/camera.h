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
// Cameras are built by a validating constructor: a NaN, a degenerate view, near ≤ 0,
// far ≤ near, an empty frustum or an image outside 1…16384 pixels per side (or over 2^25
// pixels in all) throws Error
// naming the parameter. Nothing is silently repaired.
#include "zcheck/convention.h"

#include <glm/glm.hpp>

#include <string>

namespace zcheck {

enum class ProjectionType {
    Perspective,   // gluPerspective: fovy_deg, aspect, near, far
    Frustum,       // glFrustum: left, right, bottom, top on the near plane, near, far
    Orthographic,  // glOrtho: left, right, bottom, top, near, far
};

std::string toString(ProjectionType type);

struct Projection {
    ProjectionType type = ProjectionType::Perspective;
    double fovyDeg = 60.0;  // perspective: full vertical field of view, degrees, in (0, 180)
    double aspect = 0.0;    // perspective: width / height of the view; 0 = the image's
    // frustum: extents of the near-plane window; orthographic: extents of the view box.
    // As seen in the image (right = image right, top = image top), in eye units.
    double left = 0.0, right = 0.0, bottom = 0.0, top = 0.0;
    double near = 0.1;      // > 0
    double far = 100.0;     // > near

    bool isPerspective() const { return type != ProjectionType::Orthographic; }
};

struct LookAt {
    glm::dvec3 eye{0.0, 1.0, 3.0};
    glm::dvec3 target{0.0, 0.0, 0.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
};

struct CameraSpec {
    Convention convention = Convention::preset("opengl");
    int width = 640;   // pixels, 1…16384
    int height = 480;  // pixels, 1…16384
    Projection projection;
    LookAt view;
    DepthSettings depth;
};

class Camera {
public:
    explicit Camera(const CameraSpec& spec);  // validates; throws Error naming the parameter

    const CameraSpec& spec() const { return spec_; }
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
    double clearDepth() const { return quantizeDepth(spec_.depth.format, windowDepthFar()); }
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

private:
    CameraSpec spec_;
    double left_ = 0, right_ = 0, bottom_ = 0, top_ = 0;
};

// A camera that sees a bounding sphere (centre, radius) whole, looking at it from the front
// right and above, 640×480, near/far hugging the sphere. Used for meshes without a camera.
CameraSpec framingCameraSpec(const glm::dvec3& centre, double radius);

// Row-major construction for readable matrix literals: rows[r][c] is row r, column c.
glm::dmat4 matrixFromRows(const double rows[4][4]);

}  // namespace zcheck
