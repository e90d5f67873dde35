#include "zcheck/pose.h"

#include "zcheck/error.h"

#include <algorithm>
#include <cmath>

namespace zcheck {

int eyeHandedness(const Convention& convention) { return convention.eyeUpY * -convention.eyeForwardZ; }

glm::dmat4 eyeFromEye(const Convention& to, const Convention& from)
{
    glm::dmat4 m(1.0);
    m[1][1] = to.eyeUpY * from.eyeUpY;
    m[2][2] = to.eyeForwardZ * from.eyeForwardZ;
    return m;
}

namespace {

double departureOf(const glm::dmat3& rotation)
{
    const glm::dmat3 gram = glm::transpose(rotation) * rotation;
    double worst = 0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(gram[c][r] - (c == r ? 1.0 : 0.0)));
    return worst;
}

// The rotation nearest to `m` (the orthogonal factor of its polar decomposition), by Newton's
// iteration X ← (X + X⁻ᵀ)/2, which converges quadratically from a nearly orthonormal start
// and keeps the determinant's sign.
glm::dmat3 nearestRotation(glm::dmat3 m)
{
    for (int iteration = 0; iteration < 20; ++iteration) {
        const glm::dmat3 next = 0.5 * (m + glm::transpose(glm::inverse(m)));
        double change = 0;
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) change = std::max(change, std::abs(next[c][r] - m[c][r]));
        m = next;
        if (change < 1e-16) break;
    }
    return m;
}

}  // namespace

RigidTransform requireRigid(const glm::dmat4& m, int determinant, const std::string& what)
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r]))
                throw Error("'" + what + "' is not finite (element row " + std::to_string(r) + ", column " +
                            std::to_string(c) + " is " + formatNumber(m[c][r]) + ")");
    if (!hasRigidLastRow(m))
        throw Error("'" + what + "' must have the last row 0 0 0 1 (a rigid transform for column vectors)");
    const glm::dmat3 rotation(m);
    const double departure = departureOf(rotation);
    if (!(departure <= kRotationRoundingBound))
        throw Error("'" + what + "' is not a rigid transform: its 3x3 rotation part is not orthonormal (R^T R differs from "
                    "the identity by " + formatNumber(departure) + ", beyond the " + formatNumber(kRotationRoundingBound) +
                    " that rounding to a few decimals explains: scale or shear)");
    const double det = glm::determinant(rotation);
    if (det * determinant < 0)
        throw Error("the rotation of '" + what + "' has determinant " + formatNumber(std::round(det)) +
                    ": a reflection that mirrors the picture, not a camera pose (these camera axes need determinant " +
                    (determinant > 0 ? "+1" : "-1") + "; was one axis flipped instead of two?)");
    RigidTransform out;
    out.matrix = m;
    if (departure > kRotationExact) {
        const glm::dmat3 exact = nearestRotation(rotation);
        for (int c = 0; c < 3; ++c) out.matrix[c] = glm::dvec4(exact[c], 0.0);
        out.departure = departure;
    }
    return out;
}

bool hasRigidLastRow(const glm::dmat4& m) { return m[0][3] == 0 && m[1][3] == 0 && m[2][3] == 0 && m[3][3] == 1; }

glm::dmat4 poseFromRotationTranslation(const glm::dmat3& rotation, const glm::dvec3& translation)
{
    glm::dmat4 pose(rotation);
    pose[3] = glm::dvec4(translation, 1.0);
    return pose;
}

glm::dmat4 rigidInverse(const glm::dmat4& m)
{
    const glm::dmat3 rt = glm::transpose(glm::dmat3(m));
    glm::dmat4 out(rt);
    out[3] = glm::dvec4(-(rt * glm::dvec3(m[3])), 1.0);
    return out;
}

glm::dmat3 rotationFromQuaternion(double w, double x, double y, double z, const std::string& what, double* departure)
{
    for (double v : {w, x, y, z})
        if (!std::isfinite(v)) throw Error("'" + what + "' is not finite (" + formatNumber(v) + ")");
    const double norm = std::sqrt(w * w + x * x + y * y + z * z);
    if (!(std::abs(norm - 1) <= kRotationRoundingBound))
        throw Error("'" + what + "' is not a unit quaternion: its norm is " + formatNumber(norm) +
                    " (accepted within " + formatNumber(kRotationRoundingBound) + " of 1, as rounding explains)");
    if (departure) *departure = std::abs(norm - 1) > kRotationExact ? std::abs(norm - 1) : 0.0;
    w /= norm, x /= norm, y /= norm, z /= norm;
    // Hamilton's convention, R·v = q v q*: the textbook matrix, written column by column.
    return glm::dmat3(1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),   // column 0
                      2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),   // column 1
                      2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y));  // column 2
}

glm::dvec4 quaternionFromRotation(const glm::dmat3& m)
{
    // Shepperd's method: divide by the largest of the four candidates, never a small one.
    // m[c][r] is row r, column c.
    const double trace = m[0][0] + m[1][1] + m[2][2];
    glm::dvec4 q;  // (w, x, y, z)
    if (trace >= m[0][0] && trace >= m[1][1] && trace >= m[2][2]) {
        const double s = 2 * std::sqrt(1 + trace);
        q = {s / 4, (m[1][2] - m[2][1]) / s, (m[2][0] - m[0][2]) / s, (m[0][1] - m[1][0]) / s};
    } else if (m[0][0] >= m[1][1] && m[0][0] >= m[2][2]) {
        const double s = 2 * std::sqrt(1 + m[0][0] - m[1][1] - m[2][2]);
        q = {(m[1][2] - m[2][1]) / s, s / 4, (m[1][0] + m[0][1]) / s, (m[2][0] + m[0][2]) / s};
    } else if (m[1][1] >= m[2][2]) {
        const double s = 2 * std::sqrt(1 + m[1][1] - m[0][0] - m[2][2]);
        q = {(m[2][0] - m[0][2]) / s, (m[1][0] + m[0][1]) / s, s / 4, (m[2][1] + m[1][2]) / s};
    } else {
        const double s = 2 * std::sqrt(1 + m[2][2] - m[0][0] - m[1][1]);
        q = {(m[0][1] - m[1][0]) / s, (m[2][0] + m[0][2]) / s, (m[2][1] + m[1][2]) / s, s / 4};
    }
    q /= glm::length(q);
    return q.x < 0 ? -q : q;
}

View viewFromPose(const glm::dmat4& pose, PoseDirection direction, const Convention& poseAxes, const Convention& target,
                  const std::string& what)
{
    const RigidTransform checked = requireRigid(pose, eyeHandedness(poseAxes), what);
    const glm::dmat4 camFromWorld =
        direction == PoseDirection::CameraFromWorld ? checked.matrix : rigidInverse(checked.matrix);
    View view;
    view.hasMatrix = true;
    view.eyeFromWorld = eyeFromEye(target, poseAxes) * camFromWorld;
    view.rotationDeparture = checked.departure;
    return view;
}

std::vector<std::string> cameraNotes(const CameraSpec& spec)
{
    std::vector<std::string> notes = spec.notes;
    if (spec.view.rotationDeparture > 0)
        notes.push_back("the camera's rotation was orthonormal only to " + formatNumber(spec.view.rotationDeparture) +
                        " (R^T R - I), as a pose rounded to a few decimals is; it was re-orthonormalised to the nearest "
                        "rotation");
    return notes;
}

Projection PinholeIntrinsics::projection(double near, double far, const std::string& what) const
{
    if (pixelCenter != 0.0 && pixelCenter != 0.5)
        throw Error(what + ": pixel_center must be 0.0 (OpenCV: the top-left pixel's centre is (0, 0)) or 0.5 (COLMAP, "
                           "nerfstudio: it is (0.5, 0.5)), got " + formatNumber(pixelCenter));
    for (auto [value, name] : {std::pair{fx, "fx"}, {fy, "fy"}}) {
        if (!std::isfinite(value) || !(value > 0))
            throw Error(what + ": the focal length " + name + " must be a positive finite number of pixels, got " +
                        formatNumber(value));
    }
    for (auto [value, name] : {std::pair{cx, "cx"}, {cy, "cy"}})
        if (!std::isfinite(value))
            throw Error(what + ": the principal point's " + name + " must be finite, got " + formatNumber(value));
    Projection p;
    p.type = ProjectionType::Pinhole;
    p.fx = fx, p.fy = fy;
    p.cx = cx - pixelCenter, p.cy = cy - pixelCenter;
    p.near = near, p.far = far;
    return p;
}

Projection PinholeIntrinsics::lensProjection(const std::string& model, const std::vector<double>& coefficients,
                                             double near, double far, const std::string& what) const
{
    const Projection pinhole = projection(near, far, what);
    Projection p = pinhole;
    p.type = ProjectionType::NonLinear;
    p.lens.model = model;
    p.lens.params = {pinhole.fx, pinhole.fy, pinhole.cx, pinhole.cy};
    p.lens.params.insert(p.lens.params.end(), coefficients.begin(), coefficients.end());
    return p;
}

PinholeIntrinsics PinholeIntrinsics::fromK(const double (&k)[3][3], double pixelCenter, const std::string& what)
{
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(k[r][c]))
                throw Error(what + "[" + std::to_string(r) + ", " + std::to_string(c) + "] is not finite (" +
                            formatNumber(k[r][c]) + ")");
    if (k[0][1] != 0)
        throw Error(what + "[0, 1] (skew) must be 0: zcheck's pinhole model has no skew, got " + formatNumber(k[0][1]));
    if (k[1][0] != 0 || k[2][0] != 0 || k[2][1] != 0 || k[2][2] != 1)
        throw Error(what + " must have the form [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (" + what + "[1, 0], " + what +
                    "[2, 0], " + what + "[2, 1] = 0, " + what + "[2, 2] = 1)");
    return {k[0][0], k[1][1], k[0][2], k[1][2], pixelCenter};
}

PinholeIntrinsics pinholeIntrinsicsOf(const Camera& camera, double pixelCenter)
{
    const ProjectionType type = camera.spec().projection.type;
    if (const LensModel* lens = camera.lens()) {  // a lens model's fx, fy, cx, cy, where it has them
        const LensModelInfo& info = lens->info();
        if (!info.startsWithK())
            throw Error("lens model " + lens->spec().model + " has no pinhole intrinsics fx, fy, cx, cy");
        const std::vector<double>& q = lens->spec().params;
        return {q[0], q[1], q[2] + pixelCenter, q[3] + pixelCenter, pixelCenter};
    }
    if (type != ProjectionType::Perspective && type != ProjectionType::Frustum && type != ProjectionType::Pinhole &&
        type != ProjectionType::Lens)
        throw Error("a " + toString(type) +
                    " projection has no pinhole intrinsics (only perspective, frustum, pinhole and lens cameras do)");
    // The near-plane window as seen in the image spans the image: x from left to right over
    // [0, W] pixel edges, y from top to bottom over [0, H].
    const double W = camera.width(), H = camera.height(), n = camera.nearDistance();
    const double l = camera.left(), r = camera.right(), b = camera.bottom(), t = camera.top();
    PinholeIntrinsics k;
    k.fx = W * n / (r - l);
    k.fy = H * n / (t - b);
    k.cx = W * -l / (r - l) - 0.5 + pixelCenter;
    k.cy = H * t / (t - b) - 0.5 + pixelCenter;
    k.pixelCenter = pixelCenter;
    if (type == ProjectionType::Pinhole) {  // exactly as given, not through the window's rounding
        const Projection& p = camera.spec().projection;
        k.fx = p.fx, k.fy = p.fy, k.cx = p.cx + pixelCenter, k.cy = p.cy + pixelCenter;
    }
    return k;
}

}  // namespace zcheck
