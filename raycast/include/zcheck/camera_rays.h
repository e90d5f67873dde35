#pragma once
// The ray route's camera: rays and expected depths from the camera's *definition*, not from
// the matrices the raster route draws with, so that a wrong coefficient in a matrix builder
// cannot appear in both routes and cancel out.
//
//   projection (in OpenGL's eye axes: x right, y up, looking down −z; image point (x, y) in
//   pixels from the top-left corner, W×H pixels):
//     perspective  direction ((2x/W − 1)·aspect·tan(fovy/2), (1 − 2y/H)·tan(fovy/2), −1)
//     lens         the same with tan = sensor_width / (2·focal), top = right·H/W
//     pinhole      OpenCV's u = x − ½, v = y − ½: direction ((u − cx)/fx, −(v − cy)/fy, −1)
//     frustum      the near-plane point l + (r − l)·x/W, t − (t − b)·y/H, −near, from the eye
//     orthographic the box point (l + (r − l)·x/W, t − (t − b)·y/H) on the eye plane, direction −z
//     oblique      the same box point, moved by λ·near·(cos a, sin a) on the eye plane, and
//                  direction (−λ·cos a, −λ·sin a, −1): depth d shifts a point by λ(d − near)
//   view: a look-at from eye, target and up (or the rows of a raw eyeFromWorld);
//   depth: d = eye-z of the hit (its distance along the viewing axis), and window depth from
//   the convention's mapping written as a formula, with zN, zF the NDC z of near and far
//   (swapped by reversed-Z):
//     perspective  z_ndc = (zF·f·(d − n) + zN·n·(f − d)) / (d·(f − n)),  or zF + (zN − zF)·n/d for f = ∞
//     parallel     z_ndc = zN + (zF − zN)·(d − n)/(f − n)
//     window       rangeMin + (rangeMax − rangeMin)·(z_ndc − ndcZMin)/(1 − ndcZMin)
//   (folded once per camera into window = A + B/d, or A + B·d for parallel projections)
// None of this reads Camera's matrices, nor the camera's resolved near-plane window. A
// raw-matrix projection has no other definition: its rays and depths necessarily come from
// the matrix (the inverse-projection module), as the raster route's do.
//   lens model   the lens's own inverse (lens.h): a unit direction per image point, none outside
//                the lens's field; near and far are distances along it, and the route's depth
//                is the distance (there is no window depth)
#include "zcheck/camera.h"
#include "zcheck/inverse_projection.h"

#include <cmath>
#include <cstddef>
#include <optional>

namespace zcheck {

// For every model but a raw matrix, the ray through image point p = (x, y) is affine in p:
// origin(p) = origin + x·originPerX + y·originPerY on the eye plane, and direction(p) likewise,
// scaled to gain one unit of eye-z per unit of t (so t along it *is* eye-z, and the near and
// far planes lie at t = near and t = far). World space.
struct AffineRays {
    glm::dvec3 origin, originPerX, originPerY;
    glm::dvec3 direction, directionPerX, directionPerY;

    glm::dvec3 originAt(const glm::dvec2& p) const { return origin + p.x * originPerX + p.y * originPerY; }
    glm::dvec3 directionAt(const glm::dvec2& p) const { return direction + p.x * directionPerX + p.y * directionPerY; }
};

class CameraRays {
public:
    explicit CameraRays(const Camera& camera);

    // The rays as an affine function of the image point; empty for a raw-matrix projection and
    // a lens model.
    std::optional<AffineRays> affine() const;
    // A lens model's camera (its route's depth is the distance along a unit ray).
    const LensModel* lens() const { return lens_; }
    // A lens camera's world direction through pixel (col, row)'s centre, worldRay's without its
    // call: the lens's table (LensModel::pixelDirections) turned into the world, not normalised
    // again (the turn is orthonormal to rounding: unit within a few ulp); false outside the
    // field. The pixel must lie in the image. The eye is every lens ray's origin, near and far
    // its [tNear, tFar]. (Inline: the trace calls it per lane.)
    bool lensDirectionAtPixel(int col, int row, glm::dvec3& direction) const
    {
        const glm::dvec3& d = lensTable_[std::size_t(row) * std::size_t(camera_.width()) + std::size_t(col)];
        if (std::isnan(d.x)) return false;
        direction = d.x * right_ - d.y * up_ + d.z * forward_;  // lens frame: x right, y down, z forward
        return true;
    }
    const glm::dvec3& eye() const { return eye_; }

    // The viewing ray through image point pImage (pixels; x right, y down from the top-left
    // corner), in world space: origin on the eye plane, unit direction, [tNear, tFar]
    // between the near and far planes; t is the `distance` quantity. Empty only for a lens
    // model's point outside its field.
    std::optional<EyePlaneRay> worldRay(const glm::dvec2& pImage) const;
    // Eye-space point (the convention's eye axes) of a world point.
    glm::dvec3 eyeFromWorld(const glm::dvec3& pWorld) const
    {
        const glm::dvec3 v = pWorld - eye_;
        return {glm::dot(v, right_), eyeUpY_ * glm::dot(v, up_), eyeForwardZ_ * glm::dot(v, forward_)};
    }
    // Eye-z (along the viewing axis) of a world point.
    double eyeZ(const glm::dvec3& pWorld) const { return glm::dot(pWorld - eye_, forward_); }
    // The window depth of the point at eye-z `eyeZ` on the ray through image point pImage, in
    // closed form (exact, not quantized); a raw-matrix camera's through its matrix.
    // (Inline: the trace and the comparison call these per pixel.)
    double windowDepth(const glm::dvec2& pImage, double eyeZ) const
    {
        if (fromMatrix_) return matrixWindowDepth(pImage, eyeZ);
        return parallel_ ? parallelWindowDepth(depthA_, depthB_, eyeZ) : perspectiveWindowDepth(depthA_, depthB_, eyeZ);
    }
    // windowDepth of n eye-z values into out[j], several per instruction (the same operations);
    // false (nothing written) for a raw-matrix camera, whose pixels differ.
    bool windowDepths(const double* eyeZ, std::size_t n, double* out) const
    {
        if (fromMatrix_) return false;
        const double A = depthA_, B = depthB_;
        if (parallel_) {
            for (std::size_t j = 0; j < n; ++j) out[j] = parallelWindowDepth(A, B, eyeZ[j]);
        } else {
            for (std::size_t j = 0; j < n; ++j) out[j] = perspectiveWindowDepth(A, B, eyeZ[j]);
        }
        return true;
    }
    // Its inverse: the eye-z at which the ray through pImage has window depth `windowDepth`.
    double eyeZFromWindowDepth(const glm::dvec2& pImage, double windowDepth) const
    {
        if (fromMatrix_) return matrixEyeZFromWindowDepth(pImage, windowDepth);
        return parallel_ ? (windowDepth - depthA_) / depthB_ : depthB_ / (windowDepth - depthA_);
    }
    // |z(other) − z(reference)| / |z(reference)| for two window depths on the ray through
    // pImage, z being eye-z: with z = B/(w − A) that is |(w_ref − w_other)/(w_other − A)|, one
    // division where the two conversions take three.
    double relativeEyeZDifference(const glm::dvec2& pImage, double reference, double other) const
    {
        if (fromMatrix_) {
            const double zReference = eyeZFromWindowDepth(pImage, reference);
            return std::abs(eyeZFromWindowDepth(pImage, other) - zReference) / std::abs(zReference);
        }
        return parallel_ ? parallelRelative(depthA_, reference, other) : perspectiveRelative(depthA_, reference, other);
    }

    // relativeEyeZDifference of n pairs (reference[j], other[j]) into out[j], several per
    // instruction; false (nothing written) for a raw-matrix camera, whose pixels differ.
    bool relativeEyeZDifferences(const double* reference, const double* other, std::size_t n, double* out) const
    {
        if (fromMatrix_) return false;
        const double A = depthA_;
        if (parallel_) {
            for (std::size_t j = 0; j < n; ++j) out[j] = parallelRelative(A, reference[j], other[j]);
        } else {
            for (std::size_t j = 0; j < n; ++j) out[j] = perspectiveRelative(A, reference[j], other[j]);
        }
        return true;
    }

    // The closed form relativeEyeZDifferences computes, for a kernel that computes it itself
    // (the same operations): window depth = A + B/z (perspective) or A + B·z (parallel).
    // None for a raw-matrix camera.
    struct RelativeForm {
        double A;
        bool parallel;
    };
    std::optional<RelativeForm> relativeForm() const
    {
        if (fromMatrix_) return std::nullopt;
        return RelativeForm{depthA_, parallel_};
    }

private:
    // The closed forms of windowDepth: window = A + B/z (perspective) or A + B·z (parallel).
    static double perspectiveWindowDepth(double A, double B, double eyeZ) { return A + B / eyeZ; }
    static double parallelWindowDepth(double A, double B, double eyeZ) { return A + B * eyeZ; }
    // The closed forms of relativeEyeZDifference. Perspective: z = B/(w − A), so
    // (z_o − z_r)/z_r = (w_r − w_o)/(w_o − A); parallel: z = (w − A)/B, so (w_o − w_r)/(w_r − A).
    static double perspectiveRelative(double A, double reference, double other)
    {
        return std::abs((reference - other) / (other - A));
    }
    static double parallelRelative(double A, double reference, double other)
    {
        return std::abs((other - reference) / (reference - A));
    }

    // A raw-matrix camera's depth mapping, through the inverse-projection module.
    double matrixWindowDepth(const glm::dvec2& pImage, double eyeZ) const;
    double matrixEyeZFromWindowDepth(const glm::dvec2& pImage, double windowDepth) const;
    // The ray through pImage in OpenGL's eye axes: eye-plane origin and direction (z = −1).
    void eyeRay(const glm::dvec2& pImage, glm::dvec3& origin, glm::dvec3& direction) const;
    glm::dvec3 worldFromEyeVector(const glm::dvec3& v) const { return v.x * right_ + v.y * up_ - v.z * forward_; }

    const Camera& camera_;
    const LensModel* lens_;                // a lens model's camera: its own rays
    const glm::dvec3* lensTable_ = nullptr;  // and its table of pixel directions
    bool fromMatrix_;                     // raw-matrix projection: the inverse-projection module
    bool parallel_ = false;               // orthographic or oblique: window depth affine in eye-z
    double depthA_ = 0, depthB_ = 0;      // window depth = A + B/eyeZ, or A + B·eyeZ when parallel
    glm::dvec3 eye_, right_, up_, forward_;  // the view as world-space axes
    double eyeUpY_ = 1, eyeForwardZ_ = -1;   // the convention's eye axes along up and forward
};

}  // namespace zcheck
