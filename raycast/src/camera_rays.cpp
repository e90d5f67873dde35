#include "zcheck/camera_rays.h"

#include <cmath>

namespace zcheck {

CameraRays::CameraRays(const Camera& camera)
    : camera_(camera), lens_(camera.lens()), fromMatrix_(camera.spec().projection.type == ProjectionType::Matrix)
{
    const CameraSpec& spec = camera.spec();
    const Convention& c = spec.convention;
    eyeUpY_ = c.eyeUpY, eyeForwardZ_ = c.eyeForwardZ;
    if (spec.view.hasMatrix) {
        // The rows of eyeFromWorld are the eye axes in world space (x right, y = eyeUpY·up,
        // z = eyeForwardZ·forward); the eye is where it maps to the origin.
        const glm::dmat4& m = spec.view.eyeFromWorld;
        const glm::dvec3 rows[3] = {{m[0][0], m[1][0], m[2][0]}, {m[0][1], m[1][1], m[2][1]}, {m[0][2], m[1][2], m[2][2]}};
        right_ = rows[0], up_ = double(c.eyeUpY) * rows[1], forward_ = double(c.eyeForwardZ) * rows[2];
        const glm::dvec3 t(m[3][0], m[3][1], m[3][2]);
        eye_ = -(t.x * rows[0] + t.y * rows[1] + t.z * rows[2]);  // rows orthonormal: R^T·(−t)
    } else {
        forward_ = glm::normalize(spec.view.target - spec.view.eye);
        right_ = glm::normalize(glm::cross(forward_, spec.view.up));
        up_ = glm::cross(right_, forward_);
        eye_ = spec.view.eye;
    }
    if (lens_) lensTable_ = lens_->pixelDirections();
    if (fromMatrix_ || lens_) return;
    // The depth mapping of the header, folded into window = A + B/d (perspective) or A + B·d
    // (parallel): z_ndc = a + b/d or a + b·d, then window = rangeMin + (z_ndc − ndcZMin)·s.
    const Projection& p = spec.projection;
    const DepthSettings& depth = spec.depth;
    const double ndcZMin = c.ndcDepth == NdcDepthRange::ZeroToOne ? 0.0 : -1.0;
    const double zN = depth.reversed ? 1.0 : ndcZMin, zF = depth.reversed ? ndcZMin : 1.0;
    const double n = p.near, f = p.far;
    parallel_ = p.type == ProjectionType::Orthographic || p.type == ProjectionType::Oblique;
    double a, b;
    if (parallel_)
        a = zN - (zF - zN) * n / (f - n), b = (zF - zN) / (f - n);
    else if (std::isinf(f))
        a = zF, b = (zN - zF) * n;
    else
        a = (zF * f - zN * n) / (f - n), b = n * f * (zN - zF) / (f - n);
    const double scale = (depth.rangeMax - depth.rangeMin) / (1.0 - ndcZMin);
    depthA_ = depth.rangeMin + (a - ndcZMin) * scale;
    depthB_ = b * scale;
}

void CameraRays::eyeRay(const glm::dvec2& pImage, glm::dvec3& origin, glm::dvec3& direction) const
{
    const Projection& p = camera_.spec().projection;
    const double W = camera_.width(), H = camera_.height(), x = pImage.x, y = pImage.y, n = p.near;
    origin = glm::dvec3(0.0), direction = {0.0, 0.0, -1.0};
    switch (p.type) {
    case ProjectionType::Perspective: {
        const double tanHalf = std::tan(glm::radians(p.fovyDeg) / 2);
        const double aspect = p.aspect > 0 ? p.aspect : W / H;
        direction = {(2 * x / W - 1) * aspect * tanHalf, (1 - 2 * y / H) * tanHalf, -1.0};
        break;
    }
    case ProjectionType::Lens: {
        const double right = p.sensorWidthMm / (2 * p.focalMm), top = right * H / W;
        direction = {(2 * x / W - 1) * right, (1 - 2 * y / H) * top, -1.0};
        break;
    }
    case ProjectionType::Pinhole:
        direction = {(x - 0.5 - p.cx) / p.fx, -(y - 0.5 - p.cy) / p.fy, -1.0};
        break;
    case ProjectionType::Frustum:
        direction = {(p.left + (p.right - p.left) * x / W) / n, (p.top - (p.top - p.bottom) * y / H) / n, -1.0};
        break;
    case ProjectionType::Orthographic:
    case ProjectionType::Oblique: {
        origin = {p.left + (p.right - p.left) * x / W, p.top - (p.top - p.bottom) * y / H, 0.0};
        if (p.type == ProjectionType::Oblique) {
            const double a = glm::radians(p.angleDeg), lambda = p.foreshortening;
            origin.x += lambda * n * std::cos(a), origin.y += lambda * n * std::sin(a);
            direction = {-lambda * std::cos(a), -lambda * std::sin(a), -1.0};
        }
        break;
    }
    case ProjectionType::Matrix:     // no definition but the matrix: see worldRay
    case ProjectionType::NonLinear:  // the lens's own: see worldRay
        break;
    }
}

std::optional<EyePlaneRay> CameraRays::worldRay(const glm::dvec2& pImage) const
{
    if (fromMatrix_) return worldEyePlaneRayThroughWindow(camera_, {pImage.x, camera_.windowYFromImageY(pImage.y)});
    if (lens_) {
        const Projection& p = camera_.spec().projection;
        const double col = pImage.x - 0.5, row = pImage.y - 0.5;
        glm::dvec3 direction;
        if (col == std::floor(col) && row == std::floor(row) && col >= 0 && row >= 0 && col < camera_.width() &&
            row < camera_.height()) {  // a pixel centre: from the table
            if (!lensDirectionAtPixel(int(col), int(row), direction)) return std::nullopt;
            return EyePlaneRay{eye_, direction, p.near, p.far};
        }
        const std::optional<glm::dvec3> dLens = lens_->directionFromImage(pImage);
        if (!dLens) return std::nullopt;
        // The lens frame is x right, y down, z forward: world = x·right − y·up + z·forward.
        return EyePlaneRay{eye_, glm::normalize(dLens->x * right_ - dLens->y * up_ + dLens->z * forward_), p.near, p.far};
    }
    glm::dvec3 origin, direction;
    eyeRay(pImage, origin, direction);
    // Into world space: eye-plane point and direction along the view's axes.
    EyePlaneRay ray;
    ray.origin = eye_ + worldFromEyeVector(origin);
    ray.direction = glm::normalize(worldFromEyeVector(direction));
    const double eyeZPerT = glm::dot(ray.direction, forward_);  // eye-z gained per unit of t
    const Projection& p = camera_.spec().projection;
    ray.tNear = p.near / eyeZPerT;
    ray.tFar = std::isinf(p.far) ? INFINITY : p.far / eyeZPerT;
    return ray;
}

std::optional<AffineRays> CameraRays::affine() const
{
    if (fromMatrix_ || lens_) return std::nullopt;
    // Each model's ray is affine in the image point: three points fix it.
    glm::dvec3 o00, d00, o10, d10, o01, d01;
    eyeRay({0.0, 0.0}, o00, d00);
    eyeRay({1.0, 0.0}, o10, d10);
    eyeRay({0.0, 1.0}, o01, d01);
    AffineRays rays;
    rays.origin = eye_ + worldFromEyeVector(o00);
    rays.originPerX = worldFromEyeVector(o10 - o00), rays.originPerY = worldFromEyeVector(o01 - o00);
    rays.direction = worldFromEyeVector(d00);  // eye-z component 1: t is eye-z
    rays.directionPerX = worldFromEyeVector(d10 - d00), rays.directionPerY = worldFromEyeVector(d01 - d00);
    return rays;
}

double CameraRays::matrixWindowDepth(const glm::dvec2& pImage, double d) const
{
    return windowDepthFromEyeZ(camera_, {pImage.x, camera_.windowYFromImageY(pImage.y)}, d);
}

double CameraRays::matrixEyeZFromWindowDepth(const glm::dvec2& pImage, double w) const
{
    return zcheck::eyeZFromWindowDepth(camera_, {pImage.x, camera_.windowYFromImageY(pImage.y)}, w);
}

}  // namespace zcheck
