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

}  // namespace

std::vector<FittedValue> fittedValues(const Camera& camera, const DepthMap&, const FitResult& fit)
{
    const Departure& d = fit.departure;
    const Projection& p = camera.spec().projection;
    std::vector<FittedValue> out;
    switch (fit.family) {
    case FitFamily::SampleOffset:
        out = {{"sample_dx_px", d.sampleOffset.x, 0}, {"sample_dy_px", d.sampleOffset.y, 0}};
        break;
    case FitFamily::FieldOfView: {
        const double k = d.focalScale.x;
        out.push_back({"focal_scale", k, 1});
        if (p.type == ProjectionType::Perspective)
            out.push_back({"fovy_deg", glm::degrees(2 * std::atan(std::tan(glm::radians(p.fovyDeg) / 2) / k)), p.fovyDeg});
        if (p.type == ProjectionType::Lens) out.push_back({"focal_mm", p.focalMm * k, p.focalMm});
        if (p.type == ProjectionType::Pinhole) out.push_back({"fx", p.fx * k, p.fx}), out.push_back({"fy", p.fy * k, p.fy});
        break;
    }
    case FitFamily::Intrinsics:
        out = {{"focal_scale_x", d.focalScale.x, 1},
               {"focal_scale_y", d.focalScale.y, 1},
               {"principal_dx_px", d.principalShift.x, 0},
               {"principal_dy_px", d.principalShift.y, 0}};
        if (p.type == ProjectionType::Pinhole) {
            out.push_back({"fx", p.fx * d.focalScale.x, p.fx});
            out.push_back({"fy", p.fy * d.focalScale.y, p.fy});
            out.push_back({"cx", p.cx + d.principalShift.x, p.cx});
            out.push_back({"cy", p.cy + d.principalShift.y, p.cy});
        }
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
    const Projection& p = camera.spec().projection;
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
        const double k = d.focalScale.x;
        switch (p.type) {
        case ProjectionType::Perspective:
            return "a vertical field of view of " + number(glm::degrees(2 * std::atan(std::tan(glm::radians(p.fovyDeg) / 2) / k))) +
                   "° (the camera says " + number(p.fovyDeg) + "°)";
        case ProjectionType::Lens:
            return "a focal length of " + number(p.focalMm * k) + " mm (the camera says " + number(p.focalMm) + " mm)";
        case ProjectionType::Pinhole:
            return "focal lengths fx " + number(p.fx * k, 6) + ", fy " + number(p.fy * k, 6) + " px (the camera says " +
                   number(p.fx, 6) + ", " + number(p.fy, 6) + ")";
        default:
            return "a view " + number(1 / k) + " times as wide and high as the camera says";
        }
    }
    case FitFamily::Intrinsics: {
        std::string text = "focal lengths × (" + number(d.focalScale.x, 5) + ", " + number(d.focalScale.y, 5) +
                           ") and the principal point moved by (" + signedNumber(d.principalShift.x, 3) + ", " +
                           signedNumber(d.principalShift.y, 3) + ") px (x right, y down)";
        if (p.type == ProjectionType::Pinhole)
            text += ": fx " + number(p.fx * d.focalScale.x, 6) + ", fy " + number(p.fy * d.focalScale.y, 6) + ", cx " +
                    number(p.cx + d.principalShift.x, 6) + ", cy " + number(p.cy + d.principalShift.y, 6);
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
