#pragma once
// A departure: a renderer's camera and reading described relative to the declared camera
// (library zcheck::diagnose) — where in the pixel depth was sampled, the projection's focal
// scale and principal point, near and far, a scale and offset on the values, and a small pose
// error — and the camera, ray-route sampling and map reading it makes. The fits measure one
// (fit.h); mistakes of the catalogue are some (mistakes.h); `zcheck export --sample-offset`
// renders with one.
//
//   zcheck::Departure shifted;
//   shifted.sampleOffset = {0.5, 0.5};                          // image pixels, x right, y down
//   const zcheck::Camera renderer(zcheck::departedCameraSpec(declared, shifted));
#include "zcheck/camera.h"
#include "zcheck/depth_map.h"
#include "zcheck/ray_renderer.h"

#include <glm/glm.hpp>

namespace zcheck {

struct Departure {
    glm::dvec2 sampleOffset{0.0};      // image pixels (x right, y down) from the pixel centre to the sample
    glm::dvec2 focalScale{1.0, 1.0};   // eye x and y scaled before the projection (focal lengths): > 1 is narrower
    glm::dvec2 principalShift{0.0};    // image pixels (x right, y down) the principal point moved
    double nearDistance = 0, farDistance = 0;  // 0: as declared (only window and NDC maps see them)
    double valueScale = 1, valueOffset = 0;    // map value = valueScale · value + valueOffset
    glm::dvec3 eyeShift{0.0};          // eye-space translation composed after the view (scene units)
    glm::dvec3 eyeTurn{0.0};           // eye-space rotation vector composed after the view (radians)
};

// An offset in image pixels (x right, y down) as window pixels, and back: the same map both
// ways (only y's sign can differ).
glm::dvec2 windowFromImageOffset(const Camera& camera, const glm::dvec2& offset);

// The camera a departure describes: a raw-matrix projection when the intrinsics, the sample
// offset (as the image moved the other way: what the camera sees at its pixel centres is then
// what the declared one saw at the samples) or near and far move, a raw view when the pose
// moves, otherwise the declared spec. Throws Error where it is no valid camera.
CameraSpec departedCameraSpec(const Camera& declared, const Departure& departure);
// The sample offset alone as the ray route's fault (window coordinates): a renderer sampling
// off the pixel centres through the declared camera (zcheck export --sample-offset).
RayFaults departedSampling(const Camera& declared, const Departure& departure);
// The map as it reads once that departure's value scale and offset are undone: (v − offset) /
// scale; a miss where the declared camera reads the value or, rounded to binary32, the undone
// value as one.
DepthMap departedReading(const Camera& declared, const DepthMap& map, const Departure& departure);

}  // namespace zcheck
