#include "zcheck/camera.h"

#include "zcheck/error.h"
#include "zcheck/pose.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

std::string toString(ProjectionType type)
{
    switch (type) {
    case ProjectionType::Perspective: return "perspective";
    case ProjectionType::Frustum: return "frustum";
    case ProjectionType::Orthographic: return "orthographic";
    case ProjectionType::Oblique: return "oblique";
    case ProjectionType::Pinhole: return "pinhole";
    case ProjectionType::Lens: return "lens";
    case ProjectionType::Matrix: return "matrix";
    case ProjectionType::NonLinear: return "lens model";
    }
    return "?";
}

bool Projection::isPerspective() const
{
    if (type == ProjectionType::Matrix)  // w depends on eye z: a centre of projection
        return clipFromEye[2][3] != 0.0 || clipFromEye[0][3] != 0.0 || clipFromEye[1][3] != 0.0;
    return type != ProjectionType::Orthographic && type != ProjectionType::Oblique;
}

std::vector<IntrinsicParameter> intrinsicParameters(const Projection& p, IntrinsicChange change,
                                                    const glm::dvec2& focalScale, const glm::dvec2& principalShift)
{
    const bool oneScale = change == IntrinsicChange::FocalScale;
    const glm::dvec2 k = oneScale ? glm::dvec2(focalScale.x) : focalScale;
    switch (p.type) {
    case ProjectionType::Perspective: {
        if (!oneScale) return {};
        const double fovyDeg = glm::degrees(2 * std::atan(std::tan(glm::radians(p.fovyDeg) / 2) / k.y));
        return {{"fovy_deg", "vertical field of view", "°", 4, p.fovyDeg, fovyDeg}};
    }
    case ProjectionType::Lens:  // the sensor's width spans the image: the focal length is x's
        if (!oneScale) return {};
        return {{"focal_mm", "focal length", " mm", 4, p.focalMm, p.focalMm * k.x}};
    case ProjectionType::Pinhole: {
        std::vector<IntrinsicParameter> out = {{"fx", "focal length", " px", 6, p.fx, p.fx * k.x},
                                               {"fy", "focal length", " px", 6, p.fy, p.fy * k.y}};
        if (!oneScale)
            out.push_back({"cx", "principal point", " px", 6, p.cx, p.cx + principalShift.x}),
                out.push_back({"cy", "principal point", " px", 6, p.cy, p.cy + principalShift.y});
        return out;
    }
    default: return {};
    }
}

View View::axonometricView(const std::string& kind, const glm::dvec3& target, double distance, double azimuthDeg,
                           double elevationDeg)
{
    if (kind != "isometric" && kind != "dimetric" && kind != "trimetric")
        throw Error("unknown axonometric view '" + kind + "' (expected isometric, dimetric or trimetric)");
    if (!std::isfinite(distance) || !(distance > 0))
        throw Error("'view.distance' must be > 0, got " + formatNumber(distance));
    if (!std::isfinite(azimuthDeg) || !std::isfinite(elevationDeg) || !(std::abs(elevationDeg) < 90))
        throw Error("'view.elevation_deg' must be in (-90, 90) and 'view.azimuth_deg' finite");
    View view;
    const double a = glm::radians(azimuthDeg), e = glm::radians(elevationDeg);
    view.eye = target + distance * glm::dvec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
    view.target = target;
    view.up = {0.0, 1.0, 0.0};
    view.axonometric = kind;
    view.distance = distance, view.azimuthDeg = azimuthDeg, view.elevationDeg = elevationDeg;
    return view;
}

namespace {
testing::MatrixHook matrixHook = nullptr;
void applyMatrixHook(const char* which, ProjectionType type, glm::dmat4& matrix)
{
    if (matrixHook) matrixHook(which, type, matrix);
}
}  // namespace

void testing::setMatrixHook(MatrixHook hook) { matrixHook = hook; }

glm::dmat4 matrixFromRows(const double rows[4][4])
{
    glm::dmat4 m(0.0);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[c][r] = rows[r][c];  // GLM indexes [column][row]
    return m;
}

std::optional<MatrixVectors> matrixVectorsFromName(const std::string& name)
{
    if (name == "column") return MatrixVectors::Column;
    if (name == "row") return MatrixVectors::Row;
    return std::nullopt;
}

glm::dmat4 matrixForVectors(const glm::dmat4& m, MatrixVectors vectors)
{
    return vectors == MatrixVectors::Row ? glm::transpose(m) : m;
}

namespace {

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

void validateNearFar(const Projection& p)
{
    requireFinite(p.near, "projection.near");
    if (!(p.near > 0)) throw Error("'projection.near' must be > 0, got " + formatNumber(p.near));
    if (std::isnan(p.far)) throw Error("'projection.far' must be a number, got nan");
    if (std::isinf(p.far) && !(p.far > 0 && p.isPerspective()))
        throw Error("'projection.far' must be finite for a parallel projection");
    if (!(p.far > p.near))
        throw Error("'projection.far' must be > projection.near (" + formatNumber(p.near) + "), got " +
                    formatNumber(p.far));
    if (!std::isinf(p.far) && !(p.far / p.near <= 1e12))
        throw Error("'projection.far' / 'projection.near' = " + formatNumber(p.far / p.near) +
                    " exceeds 1e12: depth cannot be resolved");
}

void requirePositive(double value, const std::string& name)
{
    requireFinite(value, name);
    if (!(value > 0)) throw Error("'" + name + "' must be > 0, got " + formatNumber(value));
}

void validateProjection(const CameraSpec& spec)
{
    const Projection& p = spec.projection;
    switch (p.type) {
    case ProjectionType::Matrix: requireMatrixFinite(p.clipFromEye, "projection.clip_from_eye"); return;
    case ProjectionType::Perspective:
        requireFinite(p.fovyDeg, "projection.fovy_deg");
        if (!(p.fovyDeg > 0 && p.fovyDeg < 180))
            throw Error("'projection.fovy_deg' must be in (0, 180) degrees, got " + formatNumber(p.fovyDeg));
        requireFinite(p.aspect, "projection.aspect");
        if (p.aspect < 0) throw Error("'projection.aspect' must be > 0, got " + formatNumber(p.aspect));
        break;
    case ProjectionType::Pinhole:
        requirePositive(p.fx, "projection.fx");
        requirePositive(p.fy, "projection.fy");
        requireFinite(p.cx, "projection.cx");
        requireFinite(p.cy, "projection.cy");
        break;
    case ProjectionType::Lens:
        requirePositive(p.focalMm, "projection.focal_mm");
        requirePositive(p.sensorWidthMm, "projection.sensor_width_mm");
        break;
    case ProjectionType::NonLinear: break;  // the LensModel's constructor validates the lens
    case ProjectionType::Oblique:
        requireFinite(p.angleDeg, "projection.angle_deg");
        requireFinite(p.foreshortening, "projection.foreshortening");
        if (p.foreshortening < 0)
            throw Error("'projection.foreshortening' must be >= 0, got " + formatNumber(p.foreshortening));
        [[fallthrough]];
    case ProjectionType::Frustum:
    case ProjectionType::Orthographic:
        for (auto [value, name] : {std::pair{p.left, "left"}, {p.right, "right"}, {p.bottom, "bottom"}, {p.top, "top"}})
            requireFinite(value, std::string("projection.") + name);
        if (!(p.right > p.left))
            throw Error("'projection.right' must be > projection.left (" + formatNumber(p.left) + "), got " +
                        formatNumber(p.right));
        if (!(p.top > p.bottom))
            throw Error("'projection.top' must be > projection.bottom (" + formatNumber(p.bottom) + "), got " +
                        formatNumber(p.top));
        break;
    }
    validateNearFar(p);
}

void validateLookAt(const CameraSpec& spec);

// Validates `spec`, re-orthonormalising a raw view's rotation within the pose rule (pose.h).
void validate(CameraSpec& spec)
{
    for (auto [value, name] : {std::pair{spec.width, "image.width"}, {spec.height, "image.height"}})
        if (!Camera::isImageSide(value))
            throw Error(std::string("'") + name + "' must be in 1.." + std::to_string(Camera::kMaxImageSide) +
                        " pixels, got " + std::to_string(value));
    if (!Camera::isImageSize(spec.width, spec.height))  // both sides are within bounds: their product is not
        throw Error("image " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " has more than " +
                    std::to_string(Camera::kMaxImagePixels) + " pixels (8192x4096)");
    validateProjection(spec);
    if (spec.view.hasMatrix) {
        // A view is a rigid motion with the convention's handedness (pose.h): eye-z must be a
        // world distance, and a reflection would mirror the picture.
        const RigidTransform rigid = requireRigid(spec.view.eyeFromWorld, eyeHandedness(spec.convention), "view.eye_from_world");
        spec.view.eyeFromWorld = rigid.matrix;
        spec.view.rotationDeparture = std::max(spec.view.rotationDeparture, rigid.departure);
    } else {
        validateLookAt(spec);
    }
    const DepthSettings& d = spec.depth;
    requireFinite(d.rangeMin, "depth.range[0]");
    requireFinite(d.rangeMax, "depth.range[1]");
    if (!(d.rangeMin >= 0 && d.rangeMax <= 1 && d.rangeMin < d.rangeMax))
        throw Error("'depth.range' must satisfy 0 <= min < max <= 1, got [" + formatNumber(d.rangeMin) + ", " +
                    formatNumber(d.rangeMax) + "] (reversed-Z is 'depth.reversed', not a reversed range)");
}

void validateLookAt(const CameraSpec& spec)
{
    requireFinite(spec.view.eye, "view.eye");
    requireFinite(spec.view.target, "view.target");
    requireFinite(spec.view.up, "view.up");
    const glm::dvec3 forward = spec.view.target - spec.view.eye;
    const double forwardLength = glm::length(forward);
    if (!(forwardLength > 0)) throw Error("'view.target' must differ from 'view.eye'");
    if (!(glm::length(spec.view.up) > 0)) throw Error("'view.up' must not be the zero vector");
    const double sine = glm::length(glm::cross(forward / forwardLength, glm::normalize(spec.view.up)));
    if (!(sine > 1e-9)) throw Error("'view.up' must not be parallel to the viewing direction (view.target - view.eye)");
}

}  // namespace

namespace {

// The near-plane window (perspective types) or view box (parallel types) as seen in the image.
struct Window {
    double left, right, bottom, top;
};

Window imageWindow(const CameraSpec& spec, double aspect, const LensModel* lens)
{
    const Projection& p = spec.projection;
    const double n = p.near;
    switch (p.type) {
    case ProjectionType::Perspective: {
        const double top = n * std::tan(glm::radians(p.fovyDeg) / 2);
        return {-top * aspect, top * aspect, -top, top};
    }
    case ProjectionType::Pinhole: {
        // OpenCV: u = fx·X/Z + cx with u = 0 at the centre of the leftmost pixel, so the
        // image's left edge is u = −½ and its right edge u = width − ½ (likewise v, downwards).
        const double W = spec.width, H = spec.height;
        return {n * (-0.5 - p.cx) / p.fx, n * (W - 0.5 - p.cx) / p.fx, -n * (H - 0.5 - p.cy) / p.fy,
                n * (p.cy + 0.5) / p.fy};
    }
    case ProjectionType::Lens: {
        const double right = n * p.sensorWidthMm / (2 * p.focalMm);
        const double top = right * spec.height / spec.width;
        return {-right, right, -top, top};
    }
    case ProjectionType::NonLinear: {
        // The linear part (camera.h): the pinhole of the model's fx, fy, cx, cy; for a panorama (and
        // Blender's panoramic cameras, which have no focal length) a 90° view.
        const LensModel::Terms& t = lens->terms();
        if (lens->isPanorama() || !lens->info().hasFocal) return {-n, n, -n * spec.height / spec.width, n * spec.height / spec.width};
        const double W = spec.width, H = spec.height;
        return {n * (-0.5 - t.cx) / t.fx, n * (W - 0.5 - t.cx) / t.fx, -n * (H - 0.5 - t.cy) / t.fy, n * (t.cy + 0.5) / t.fy};
    }
    default: return {p.left, p.right, p.bottom, p.top};
    }
}

// Oblique shear in OpenGL's eye space: depth d = −z_gl behind the near plane moves a point by
// λ·(d − near)·(cos a, sin a), so x' = x − λ·cos a·(z_gl + near), likewise y.
glm::dmat4 obliqueShear(const Projection& p)
{
    glm::dmat4 shear(1.0);
    if (p.type != ProjectionType::Oblique) return shear;
    const double sx = p.foreshortening * std::cos(glm::radians(p.angleDeg));
    const double sy = p.foreshortening * std::sin(glm::radians(p.angleDeg));
    shear[2][0] = -sx, shear[3][0] = -sx * p.near;
    shear[2][1] = -sy, shear[3][1] = -sy * p.near;
    return shear;
}

}  // namespace

Camera::Camera(const CameraSpec& spec) : spec_(spec)
{
    validate(spec_);
    const Projection& p = spec_.projection;
    if (p.type == ProjectionType::NonLinear) {
        lens_ = LensModel::shared(p.lens, spec_.width, spec_.height);
        spec_.projection.lens = lens_->spec();  // every parameter, the defaults written out
    }
    const Convention& c = spec_.convention;

    // View: a raw matrix, or a look-at with the eye axes the convention asks for.
    if (spec_.view.hasMatrix) {
        eyeFromWorld = spec_.view.eyeFromWorld;
    } else {
        const glm::dvec3 forward = glm::normalize(spec_.view.target - spec_.view.eye);
        const glm::dvec3 rightAxis = glm::normalize(glm::cross(forward, spec_.view.up));
        const glm::dvec3 upAxis = glm::cross(rightAxis, forward);
        const glm::dvec3 axes[3] = {rightAxis, double(c.eyeUpY) * upAxis, double(c.eyeForwardZ) * forward};
        eyeFromWorld = glm::dmat4(1.0);
        for (int row = 0; row < 3; ++row) {
            for (int col = 0; col < 3; ++col) eyeFromWorld[col][row] = axes[row][col];
            eyeFromWorld[3][row] = -glm::dot(axes[row], spec_.view.eye);
        }
        applyMatrixHook("eye_from_world", p.type, eyeFromWorld);
    }
    worldFromEye = glm::inverse(eyeFromWorld);

    // Projection: a raw matrix, or the canonical (OpenGL eye) matrix between the
    // convention's axis changes.
    if (p.type == ProjectionType::Matrix) {
        clipFromEye = p.clipFromEye;
    } else {
        const Window w = imageWindow(spec_, aspect(), lens_.get());
        left_ = w.left, right_ = w.right, bottom_ = w.bottom, top_ = w.top;
        glm::dmat4 clipFromClipGl(1.0);
        clipFromClipGl[1][1] = c.ndcUpY;
        clipFromEye = clipFromClipGl * clipGlFromEyeGl(p, left_, right_, bottom_, top_, ndcZNear(), ndcZFar()) *
                      obliqueShear(p) * eyeGlFromEye(c);
        applyMatrixHook("clip_from_eye", p.type, clipFromEye);
    }
    if (std::abs(glm::determinant(clipFromEye)) < 1e-300 || !std::isfinite(glm::determinant(clipFromEye)))
        throw Error("camera matrix 'clip_from_eye' is singular");
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
    applyMatrixHook("window_from_ndc", p.type, windowFromNdc);
    ndcFromWindow = glm::inverse(windowFromNdc);

    for (auto [m, name] : {std::pair{&eyeFromWorld, "eye_from_world"}, {&worldFromEye, "world_from_eye"},
                           {&clipFromEye, "clip_from_eye"}, {&eyeFromClip, "eye_from_clip"}})
        requireMatrixFinite(*m, name);

    requireRepresentable();

    // Near and far as eye-z distances: given, or read off a raw matrix by unprojecting the
    // ends of the NDC depth range on the viewing axis.
    if (p.type != ProjectionType::Matrix) {
        near_ = p.near, far_ = p.far;
        return;
    }
    auto eyePointAt = [&](double zNdc) { return eyeFromClip * glm::dvec4(0.0, 0.0, zNdc, 1.0); };
    const glm::dvec4 nearPoint = eyePointAt(ndcZNear()), farPoint = eyePointAt(ndcZFar());
    near_ = eyeZOf(glm::dvec3(nearPoint) / nearPoint.w);
    // w ≈ 0: the far end of the depth range is at infinity (an infinite far plane).
    far_ = std::abs(farPoint.w) <= 1e-9 * glm::length(glm::dvec3(farPoint)) ? INFINITY
                                                                              : eyeZOf(glm::dvec3(farPoint) / farPoint.w);
    const std::string hint = " (is 'convention' or 'depth.reversed' right for this matrix?)";
    if (!(near_ > 0))
        throw Error("camera matrix 'projection.clip_from_eye' puts the near plane at eye-z " + formatNumber(near_) +
                    ", not in front of the eye" + hint);
    if (!(far_ > near_))
        throw Error("camera matrix 'projection.clip_from_eye' puts the far plane (eye-z " + formatNumber(far_) +
                    ") before the near plane (eye-z " + formatNumber(near_) + ")" + hint);
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

Camera cameraAboutOrigin(const Camera& camera, const glm::dvec3& origin)
{
    if (origin == glm::dvec3(0.0)) return camera;
    CameraSpec spec = camera.spec();
    View& view = spec.view;
    view.eye -= origin, view.target -= origin;  // an axonometric view's eye follows its target
    // eye ← world ← frame: the rotation's columns as they were, the translation R·origin + t.
    if (view.hasMatrix) view.eyeFromWorld[3] = view.eyeFromWorld * glm::dvec4(origin, 1.0);
    return Camera(spec);
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

// Rays start at the eye (perspective) or on the eye plane inside the view box (parallel
// projections); the ray tracer holds them in binary32 and fails beyond ~1e19. The eye and
// the corners of the near-plane window, in world space, must lie within ±kMaxWorldCoordinate.
void Camera::requireRepresentable() const
{
    auto check = [](const glm::dvec3& pWorld, const char* what) {
        for (int axis = 0; axis < 3; ++axis)
            if (!(std::abs(pWorld[axis]) <= kMaxWorldCoordinate))
                throw Error(std::string(what) + " lies at world coordinate " + formatNumber(pWorld[axis]) +
                            ", beyond the ±1e15 that the ray tracer can represent (move the scene and camera "
                            "nearer the origin)");
    };
    check(glm::dvec3(worldFromEye[3]), "the camera's eye ('view.eye' or the view translation)");
    for (double x : {-1.0, 1.0})
        for (double y : {-1.0, 1.0}) {
            const glm::dvec4 pWorld = worldFromClip * glm::dvec4(x, y, ndcZNear(), 1.0);
            check(glm::dvec3(pWorld) / pWorld.w, "a corner of the near-plane window (the projection's box or frustum)");
        }
}

}  // namespace zcheck
