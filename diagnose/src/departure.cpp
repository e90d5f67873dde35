#include "zcheck/departure.h"

#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace zcheck {

namespace {

bool isMiss(const Camera& camera, double value, DepthQuantity quantity)
{
    return kindOfDepthValue(camera, quantity, value) == DepthValueKind::Miss;
}

}  // namespace

glm::dvec2 windowFromImageOffset(const Camera& camera, const glm::dvec2& offset)
{
    // Image y grows downward; window y too where the window's origin is at the top.
    return {offset.x, (camera.windowYFromImageY(1) - camera.windowYFromImageY(0)) * offset.y};
}

CameraSpec departedCameraSpec(const Camera& declared, const Departure& d)
{
    CameraSpec spec = declared.spec();
    const bool nearFarMove = d.nearDistance > 0 || d.farDistance > 0;
    if (nearFarMove) {
        if (isRawMatrix(declared)) throw Error("a raw projection matrix has no near and far to move");
        if (d.nearDistance > 0) spec.projection.near = d.nearDistance;
        if (d.farDistance > 0) spec.projection.far = d.farDistance;
    }
    // Sampling at pixel centre + offset sees what a camera whose image moved by −offset sees at
    // the centre: eye-z, distance and window depth are the same, and the comparison then judges
    // every pixel (its depth conversion, its edges) at the point that was sampled.
    const glm::dvec2 imageShift = d.principalShift - d.sampleOffset;
    if (d.focalScale != glm::dvec2(1.0) || imageShift != glm::dvec2(0.0)) {
        // The focal lengths scale eye x and y (the principal point stays: an off-axis frustum's
        // bounds scale about the axis), and the principal point moves the image by tx·w in clip
        // space (ndcFromWindow's scale turns pixels into NDC).
        const Camera withNearFar(spec);
        glm::dmat4 m = withNearFar.clipFromEye;
        m[0] *= d.focalScale.x, m[1] *= d.focalScale.y;
        const glm::dvec2 shift = windowFromImageOffset(declared, imageShift);
        const double tx = shift.x * declared.ndcFromWindow[0][0], ty = shift.y * declared.ndcFromWindow[1][1];
        for (int c = 0; c < 4; ++c) m[c][0] += tx * m[c][3], m[c][1] += ty * m[c][3];
        spec.projection.type = ProjectionType::Matrix;
        spec.projection.clipFromEye = m;
    }
    if (d.eyeShift != glm::dvec3(0.0) || d.eyeTurn != glm::dvec3(0.0)) {
        const double angle = glm::length(d.eyeTurn);
        glm::dmat4 turn(1.0);
        if (angle > 0) turn = glm::rotate(glm::dmat4(1.0), angle, d.eyeTurn / angle);
        glm::dmat4 move(1.0);
        move[3] = glm::dvec4(d.eyeShift, 1.0);
        spec.view.hasMatrix = true;
        spec.view.eyeFromWorld = move * turn * declared.eyeFromWorld;
    }
    return spec;
}

RayFaults departedSampling(const Camera& declared, const Departure& departure)
{
    RayFaults faults;
    faults.shiftPixels = windowFromImageOffset(declared, departure.sampleOffset);
    return faults;
}

DepthMap departedReading(const Camera& declared, const DepthMap& map, const Departure& d)
{
    DepthMap out = map;
    if (d.valueScale == 1 && d.valueOffset == 0) return out;
    for (int row = 0; row < map.height; ++row)
        for (int col = 0; col < map.width; ++col) {
            // A miss as read, or once undone as binary32 stores it: a far plane's 1 scaled by
            // 1.002 and back is 1 − 2^−25, which only rounding returns to the far plane.
            double& v = out.value[std::size_t(row) * map.width + col];
            const double undone = (v - d.valueOffset) / d.valueScale;
            v = isMiss(declared, v, map.quantity) || isMiss(declared, roundedToBinary32(undone), map.quantity) ? NAN : undone;
        }
    const double scale = std::abs(d.valueScale);
    out.valueQuantum /= scale, out.accuracy.quantum /= scale, out.accuracy.absolute /= scale;
    for (float& step : out.valueStep) step = float(step / scale);
    return out;
}

}  // namespace zcheck
