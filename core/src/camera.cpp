#include "zcheck/camera.h"

#include "zcheck/error.h"

#include <cmath>

namespace zcheck {

std::string toString(ProjectionType type)
{
    switch (type) {
    case ProjectionType::Perspective: return "perspective";
    case ProjectionType::Frustum: return "frustum";
    case ProjectionType::Orthographic: return "orthographic";
    }
    return "?";
}

glm::dmat4 matrixFromRows(const double rows[4][4])
{
    glm::dmat4 m(0.0);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[c][r] = rows[r][c];  // GLM indexes [column][row]
    return m;
}

namespace {

constexpr int kMaxImageSide = 16384;
// About 85 bytes per pixel across both routes, the comparison and --out: 2^25 pixels
// (8192×4096) stay within ~3 GiB; more would risk the machine's memory instead of failing
// cleanly.
constexpr long long kMaxImagePixels = 1LL << 25;

void requireFinite(double value, const std::string& name)
{
    if (!std::isfinite(value)) throw Error("'" + name + "' must be a finite number, got " + formatNumber(value));
}

void requireFinite(const glm::dvec3& v, const std::string& name)
{
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(v[i]))
            throw Error("'" + name + "' must hold finite numbers, got " + formatNumber(v[i]) + " at index " +
                        std::to_string(i));
}

void requireMatrixFinite(const glm::dmat4& m, const std::string& name)
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) throw Error("camera matrix '" + name + "' is not finite (degenerate camera)");
}

// OpenGL's eye space (x right, y up, looking down −Z) from the convention's eye space.
glm::dmat4 eyeGlFromEye(const Convention& convention)
{
    glm::dmat4 m(1.0);
    m[1][1] = convention.eyeUpY;
    m[2][2] = -convention.eyeForwardZ;
    return m;
}

// The canonical projection in OpenGL's eye space: x, y as glFrustum / glOrtho, and the
// depth d = −z_gl mapped to NDC z so that d = near ↦ zNear and d = far ↦ zFar (far may be
// +inf for perspective). Perspective: z_ndc = −P + Q/d; orthographic: affine in d.
glm::dmat4 clipGlFromEyeGl(const Projection& projection, double l, double r, double b, double t, double zNear,
                           double zFar)
{
    const double n = projection.near, f = projection.far;
    if (projection.isPerspective()) {
        const bool infinite = std::isinf(f);
        const double P = infinite ? -zFar : (zNear - zFar) * n / (f - n) - zFar;
        const double Q = infinite ? (zNear - zFar) * n : (zNear - zFar) * n * f / (f - n);
        const double rows[4][4] = {
            {2 * n / (r - l), 0, (r + l) / (r - l), 0},
            {0, 2 * n / (t - b), (t + b) / (t - b), 0},
            {0, 0, P, Q},
            {0, 0, -1, 0},
        };
        return matrixFromRows(rows);
    }
    const double P = -(zFar - zNear) / (f - n);
    const double Q = zNear - (zFar - zNear) * n / (f - n);
    const double rows[4][4] = {
        {2 / (r - l), 0, 0, -(r + l) / (r - l)},
        {0, 2 / (t - b), 0, -(t + b) / (t - b)},
        {0, 0, P, Q},
        {0, 0, 0, 1},
    };
    return matrixFromRows(rows);
}

void validateProjection(const CameraSpec& spec)
{
    const Projection& p = spec.projection;
    requireFinite(p.near, "projection.near");
    if (!(p.near > 0)) throw Error("'projection.near' must be > 0, got " + formatNumber(p.near));
    if (std::isnan(p.far)) throw Error("'projection.far' must be a number, got nan");
    if (std::isinf(p.far) && !(p.far > 0 && p.isPerspective()))
        throw Error("'projection.far' must be finite for an orthographic projection");
    if (!(p.far > p.near))
        throw Error("'projection.far' must be > projection.near (" + formatNumber(p.near) + "), got " +
                    formatNumber(p.far));
    if (!std::isinf(p.far) && !(p.far / p.near < 1e12))
        throw Error("'projection.far' / 'projection.near' = " + formatNumber(p.far / p.near) +
                    " exceeds 1e12: depth cannot be resolved");
    if (p.type == ProjectionType::Perspective) {
        requireFinite(p.fovyDeg, "projection.fovy_deg");
        if (!(p.fovyDeg > 0 && p.fovyDeg < 180))
            throw Error("'projection.fovy_deg' must be in (0, 180) degrees, got " + formatNumber(p.fovyDeg));
        requireFinite(p.aspect, "projection.aspect");
        if (p.aspect < 0) throw Error("'projection.aspect' must be > 0, got " + formatNumber(p.aspect));
    } else {
        for (auto [value, name] : {std::pair{p.left, "left"}, {p.right, "right"}, {p.bottom, "bottom"}, {p.top, "top"}})
            requireFinite(value, std::string("projection.") + name);
        if (!(p.right > p.left))
            throw Error("'projection.right' must be > projection.left (" + formatNumber(p.left) + "), got " +
                        formatNumber(p.right));
        if (!(p.top > p.bottom))
            throw Error("'projection.top' must be > projection.bottom (" + formatNumber(p.bottom) + "), got " +
                        formatNumber(p.top));
    }
}

void validate(const CameraSpec& spec)
{
    for (auto [value, name] : {std::pair{spec.width, "image.width"}, {spec.height, "image.height"}})
        if (value < 1 || value > kMaxImageSide)
            throw Error(std::string("'") + name + "' must be in 1.." + std::to_string(kMaxImageSide) + " pixels, got " +
                        std::to_string(value));
    if (static_cast<long long>(spec.width) * spec.height > kMaxImagePixels)
        throw Error("image " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " has more than " +
                    std::to_string(kMaxImagePixels) + " pixels (8192x4096)");
    validateProjection(spec);
    requireFinite(spec.view.eye, "view.eye");
    requireFinite(spec.view.target, "view.target");
    requireFinite(spec.view.up, "view.up");
    const glm::dvec3 forward = spec.view.target - spec.view.eye;
    const double forwardLength = glm::length(forward);
    if (!(forwardLength > 0)) throw Error("'view.target' must differ from 'view.eye'");
    if (!(glm::length(spec.view.up) > 0)) throw Error("'view.up' must not be the zero vector");
    const double sine = glm::length(glm::cross(forward / forwardLength, glm::normalize(spec.view.up)));
    if (!(sine > 1e-9)) throw Error("'view.up' must not be parallel to the viewing direction (view.target - view.eye)");
    const DepthSettings& d = spec.depth;
    requireFinite(d.rangeMin, "depth.range[0]");
    requireFinite(d.rangeMax, "depth.range[1]");
    if (!(d.rangeMin >= 0 && d.rangeMax <= 1 && d.rangeMin < d.rangeMax))
        throw Error("'depth.range' must satisfy 0 <= min < max <= 1, got [" + formatNumber(d.rangeMin) + ", " +
                    formatNumber(d.rangeMax) + "] (reversed-Z is 'depth.reversed', not a reversed range)");
}

}  // namespace

Camera::Camera(const CameraSpec& spec) : spec_(spec)
{
    validate(spec_);
    const Projection& p = spec_.projection;
    if (p.type == ProjectionType::Perspective) {
        top_ = p.near * std::tan(glm::radians(p.fovyDeg) / 2);
        bottom_ = -top_;
        right_ = top_ * aspect();
        left_ = -right_;
    } else {
        left_ = p.left, right_ = p.right, bottom_ = p.bottom, top_ = p.top;
    }

    // View: look-at, with the eye axes the convention asks for.
    const Convention& c = spec_.convention;
    const glm::dvec3 forward = glm::normalize(spec_.view.target - spec_.view.eye);
    const glm::dvec3 rightAxis = glm::normalize(glm::cross(forward, spec_.view.up));
    const glm::dvec3 upAxis = glm::cross(rightAxis, forward);
    const glm::dvec3 axes[3] = {rightAxis, double(c.eyeUpY) * upAxis, double(c.eyeForwardZ) * forward};
    eyeFromWorld = glm::dmat4(1.0);
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) eyeFromWorld[col][row] = axes[row][col];
        eyeFromWorld[3][row] = -glm::dot(axes[row], spec_.view.eye);
    }
    worldFromEye = glm::inverse(eyeFromWorld);

    // Projection: the canonical (OpenGL eye) matrix between the convention's axis changes.
    glm::dmat4 clipFromClipGl(1.0);
    clipFromClipGl[1][1] = c.ndcUpY;
    clipFromEye = clipFromClipGl * clipGlFromEyeGl(p, left_, right_, bottom_, top_, ndcZNear(), ndcZFar()) *
                  eyeGlFromEye(c);
    eyeFromClip = glm::inverse(clipFromEye);
    clipFromWorld = clipFromEye * eyeFromWorld;
    worldFromClip = worldFromEye * eyeFromClip;

    // Viewport: NDC x ∈ [−1,1] ↦ [0,W]; NDC y ↦ window y from the window origin; NDC z
    // range ↦ [rangeMin, rangeMax].
    const double W = spec_.width, H = spec_.height;
    const double ySign = (c.windowOriginTop ? -1.0 : 1.0) * c.ndcUpY;
    const double zScale = (spec_.depth.rangeMax - spec_.depth.rangeMin) / (1.0 - c.ndcZMin());
    const double rows[4][4] = {
        {W / 2, 0, 0, W / 2},
        {0, ySign * H / 2, 0, H / 2},
        {0, 0, zScale, spec_.depth.rangeMin - zScale * c.ndcZMin()},
        {0, 0, 0, 1},
    };
    windowFromNdc = matrixFromRows(rows);
    ndcFromWindow = glm::inverse(windowFromNdc);

    for (auto [m, name] : {std::pair{&eyeFromWorld, "eye_from_world"}, {&worldFromEye, "world_from_eye"},
                           {&clipFromEye, "clip_from_eye"}, {&eyeFromClip, "eye_from_clip"}})
        requireMatrixFinite(*m, name);
}

double Camera::aspect() const
{
    const double given = spec_.projection.aspect;
    return given > 0 ? given : double(spec_.width) / spec_.height;
}

double Camera::ndcZNear() const { return spec_.depth.reversed ? 1.0 : spec_.convention.ndcZMin(); }
double Camera::ndcZFar() const { return spec_.depth.reversed ? spec_.convention.ndcZMin() : 1.0; }

double Camera::windowDepthFromNdcZ(double zNdc) const { return windowFromNdc[2][2] * zNdc + windowFromNdc[3][2]; }
double Camera::ndcZFromWindowDepth(double windowDepth) const
{
    return (windowDepth - windowFromNdc[3][2]) / windowFromNdc[2][2];
}

CameraSpec framingCameraSpec(const glm::dvec3& centre, double radius)
{
    CameraSpec spec;
    spec.projection.type = ProjectionType::Perspective;
    spec.projection.fovyDeg = 40.0;
    // Far enough that the sphere fits the smaller (vertical) field of view with a margin.
    const double distance = radius / std::sin(glm::radians(spec.projection.fovyDeg) / 2) * 1.1;
    const glm::dvec3 direction = glm::normalize(glm::dvec3(0.45, 0.35, 1.0));  // front, right, above
    spec.view.eye = centre + distance * direction;
    spec.view.target = centre;
    spec.view.up = {0.0, 1.0, 0.0};
    spec.projection.near = (distance - radius) * 0.5;
    spec.projection.far = (distance + radius) * 1.5;
    return spec;
}

}  // namespace zcheck
