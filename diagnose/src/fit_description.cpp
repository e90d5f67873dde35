// What a fit found, in words for people and as named values for --json (fit.h's describeFit and
// fittedValues): the fits' prose, kept apart from their model (fit.cpp) and numerics (numerics.h).
#include "zcheck/fit.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace zcheck {

namespace {

std::string signedNumber(double v, int digits = 4)
{
    char text[32];
    std::snprintf(text, sizeof text, "%+.*g", digits, std::abs(v) < 5e-13 ? 0.0 : v);
    return text;
}

std::string number(double v, int digits = 4)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    return text;
}

// The standard sample positions of 4× and 8× multisampling (in 1/16 pixel, x right and y away
// from the framebuffer's first row: down in Direct3D, Vulkan and Metal, up in OpenGL, where
// GL_SAMPLE_POSITION reports the same numbers from the lower-left corner — Mesa's llvmpipe does)
// the offset in the image matches within 1/64 px, as "sample k of N× MSAA".
std::string msaaSampleOf(const Camera& camera, const glm::dvec2& imageOffset)
{
    const glm::dvec2 offset = windowFromImageOffset(camera, imageOffset);
    static const int four[4][2] = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
    static const int eight[8][2] = {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
    auto near = [&](const int p[2]) { return std::abs(offset.x - p[0] / 16.0) < 1.0 / 64 && std::abs(offset.y - p[1] / 16.0) < 1.0 / 64; };
    if (std::abs(offset.x) < 1.0 / 64 && std::abs(offset.y) < 1.0 / 64) return "";
    for (int k = 0; k < 4; ++k)
        if (near(four[k])) return "sample " + std::to_string(k) + " of 4× MSAA's standard pattern";
    for (int k = 0; k < 8; ++k)
        if (near(eight[k])) return "sample " + std::to_string(k) + " of 8× MSAA's standard pattern";
    return "";
}

glm::dvec3 eyePositionOf(const glm::dmat4& eyeFromWorld) { return glm::dvec3(glm::inverse(eyeFromWorld)[3]); }

// The camera's own parameters that state the fit's focal scales and principal point (camera.h),
// empty where its model cannot: the field-of-view fit changes one focal scale, the intrinsics fit
// both and the principal point.
std::vector<IntrinsicParameter> statedIntrinsics(const Camera& camera, const FitResult& fit)
{
    const IntrinsicChange change =
        fit.family == FitFamily::FieldOfView ? IntrinsicChange::FocalScale : IntrinsicChange::FocalScalesAndPrincipalPoint;
    return intrinsicParameters(camera.spec().projection, change, fit.departure.focalScale, fit.departure.principalShift);
}

void appendStated(std::vector<FittedValue>& out, const std::vector<IntrinsicParameter>& stated)
{
    for (const IntrinsicParameter& parameter : stated) out.push_back({parameter.key, parameter.changed, parameter.declared});
}

// "fx 512.3, fy 510" (the changed values)
std::string changedValues(const std::vector<IntrinsicParameter>& stated)
{
    std::string text;
    for (const IntrinsicParameter& parameter : stated)
        text += (text.empty() ? "" : ", ") + std::string(parameter.key) + " " + number(parameter.changed, parameter.digits);
    return text;
}

// "a vertical field of view of 56.5° (the camera says 55°)"; parameters of one kind together:
// "focal lengths fx 512.3, fy 510 px (the camera says 500, 500)".
std::string changedAgainstDeclared(const std::vector<IntrinsicParameter>& stated)
{
    const IntrinsicParameter& first = stated.front();
    if (stated.size() == 1)
        return std::string("a ") + first.words + " of " + number(first.changed, first.digits) + first.unit +
               " (the camera says " + number(first.declared, first.digits) + first.unit + ")";
    std::string declared;
    for (const IntrinsicParameter& parameter : stated)
        declared += (declared.empty() ? "" : ", ") + number(parameter.declared, parameter.digits);
    return std::string(first.words) + "s " + changedValues(stated) + first.unit + " (the camera says " + declared + ")";
}

}  // namespace

std::vector<FittedValue> fittedValues(const Camera& camera, const DepthMap&, const FitResult& fit)
{
    const Departure& d = fit.departure;
    std::vector<FittedValue> out;
    switch (fit.family) {
    case FitFamily::SampleOffset:
        out = {{"sample_dx_px", d.sampleOffset.x, 0}, {"sample_dy_px", d.sampleOffset.y, 0}};
        break;
    case FitFamily::FieldOfView:
        out = {{"focal_scale", d.focalScale.x, 1}};
        appendStated(out, statedIntrinsics(camera, fit));
        break;
    case FitFamily::Intrinsics:
        out = {{"focal_scale_x", d.focalScale.x, 1},
               {"focal_scale_y", d.focalScale.y, 1},
               {"principal_dx_px", d.principalShift.x, 0},
               {"principal_dy_px", d.principalShift.y, 0}};
        appendStated(out, statedIntrinsics(camera, fit));
        break;
    case FitFamily::NearFar:
        out = {{"near", d.nearDistance > 0 ? d.nearDistance : camera.nearDistance(), camera.nearDistance()},
               {"far", d.farDistance > 0 ? d.farDistance : camera.farDistance(), camera.farDistance()}};
        break;
    case FitFamily::DepthScale: out = {{"value_scale", d.valueScale, 1}, {"value_offset", d.valueOffset, 0}}; break;
    case FitFamily::Pose: {
        const glm::dvec3 eye = eyePositionOf(camera.eyeFromWorld);
        const glm::dvec3 moved = eyePositionOf(Camera(departedCameraSpec(camera, d)).eyeFromWorld);
        out = {{"eye_x", moved.x, eye.x},
               {"eye_y", moved.y, eye.y},
               {"eye_z", moved.z, eye.z},
               {"turn_deg", glm::degrees(glm::length(d.eyeTurn)), 0}};
        break;
    }
    }
    out.push_back({"residual", fit.residual, fit.initialResidual});
    return out;
}

std::string describeFit(const Camera& camera, const DepthMap& map, const FitResult& fit)
{
    const Departure& d = fit.departure;
    switch (fit.family) {
    case FitFamily::SampleOffset: {
        const glm::dvec2 whole = glm::round(d.sampleOffset);
        const glm::dvec2 within = d.sampleOffset - whole;
        std::string text = "depth sampled at (" + signedNumber(within.x, 3) + ", " + signedNumber(within.y, 3) +
                           ") px from the pixel centre (x right, y down)";
        if (const std::string msaa = msaaSampleOf(camera, within); !msaa.empty()) text += " — " + msaa;
        if (whole != glm::dvec2(0.0))
            text += (within == glm::dvec2(0.0) ? "" : ",") + std::string(" the image shifted by (") +
                    signedNumber(whole.x) + ", " + signedNumber(whole.y) + ") px";
        if (std::max(std::abs(d.sampleOffset.x), std::abs(d.sampleOffset.y)) >= 2)
            text += ": the principal point off by (" + signedNumber(-d.sampleOffset.x, 4) + ", " +
                    signedNumber(-d.sampleOffset.y, 4) + ") px (x right, y down) — cx or cy, or Blender's shift_x or "
                    "shift_y (in units of the larger sensor side) with the wrong sign";
        return text;
    }
    case FitFamily::FieldOfView: {
        const std::vector<IntrinsicParameter> stated = statedIntrinsics(camera, fit);
        if (stated.empty()) return "a view " + number(1 / d.focalScale.x) + " times as wide and high as the camera says";
        return changedAgainstDeclared(stated);
    }
    case FitFamily::Intrinsics: {
        std::string text = "focal lengths × (" + number(d.focalScale.x, 5) + ", " + number(d.focalScale.y, 5) +
                           ") and the principal point moved by (" + signedNumber(d.principalShift.x, 3) + ", " +
                           signedNumber(d.principalShift.y, 3) + ") px (x right, y down)";
        if (const std::vector<IntrinsicParameter> stated = statedIntrinsics(camera, fit); !stated.empty())
            text += ": " + changedValues(stated);
        return text;
    }
    case FitFamily::NearFar:
        return "near " + number(d.nearDistance > 0 ? d.nearDistance : camera.nearDistance(), 5) + ", far " +
               number(d.farDistance > 0 ? d.farDistance : camera.farDistance(), 5) + " (the camera says " +
               number(camera.nearDistance(), 5) + ", " + number(camera.farDistance(), 5) + ")";
    case FitFamily::DepthScale:
        return "the map's values " + number(d.valueScale, 5) + " × the " + toString(map.quantity) +
               (std::abs(d.valueOffset) > 0 ? " " + signedNumber(d.valueOffset, 5) : std::string()) +
               " (a unit or scale mistake: divide by " + number(d.valueScale, 5) + ")";
    case FitFamily::Pose: {
        const glm::dvec3 eye = eyePositionOf(camera.eyeFromWorld);
        const glm::dvec3 moved = eyePositionOf(Camera(departedCameraSpec(camera, d)).eyeFromWorld);
        std::string text = "the eye at (" + number(moved.x, 5) + ", " + number(moved.y, 5) + ", " + number(moved.z, 5) +
                           ") instead of (" + number(eye.x, 5) + ", " + number(eye.y, 5) + ", " + number(eye.z, 5) + ")";
        const View& v = camera.spec().view;
        if (!v.hasMatrix) {
            const double before = glm::length(v.target - eye), after = glm::length(v.target - moved);
            if (before > 0) text += ", " + number(100 * std::abs(after - before) / before, 3) + " % " +
                                    (after > before ? "farther from" : "nearer to") + " the target";
        }
        text += ", turned " + number(glm::degrees(glm::length(d.eyeTurn)), 3) + "°";
        return text;
    }
    }
    return "";
}

}  // namespace zcheck
