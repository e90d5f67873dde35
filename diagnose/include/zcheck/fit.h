#pragma once
// The continuous half of the diagnosis: which camera and reading, departing a little from the
// declared ones, best explain a depth map — measured, not guessed from a list.
//
// A Departure (departure.h) describes a renderer's camera and reading relative to the declared
// camera: where in the pixel the depth was sampled, the projection's focal scale and principal
// point, near and far, a scale and offset on the values, and a small pose error. fitDeparture
// fits one family of these parameters (FitFamily) by robust least squares:
//
//   model     At each sample pixel the ground truth shows a surface; its plane is kept. The
//             departed camera's ray through the pixel's (offset) sample point meets that plane,
//             and the declared quantity of that point under the departed camera, scaled and
//             offset, is what the map should hold there. Exact for every pixel whose surface
//             stays the same plane; pixels near edges and occlusion changes break it, so
//   weights   are Cauchy's, 1/(1 + (r/c)²) with c = 2.4 × the residuals' robust spread (MAD),
//             refreshed every step, and only pixels whose 3×3 neighbourhood lies on one plane
//             are sampled (at most 4096, evenly spaced).
//   residual  (predicted − map) / (the value's change for a relative eye-z change of 1): a
//             relative eye depth, the same unit for every quantity.
//   solver    Levenberg–Marquardt on the weighted normal equations, forward-difference
//             Jacobian; then the truth is re-rendered through the fitted camera (new planes
//             where surfaces moved) and the fit repeated, three rounds at most. Near and far,
//             and a scale and offset, start from a global estimate: a window or NDC map's
//             values lie on a line in 1/z (z for parallel projections), a rescaled map's on a
//             line in the expected values, found by least median of squares over lines through
//             pairs of samples, which pixels clipped by another near plane cannot pull.
//   polish    A fit that explains the map is refined in the comparison's own terms where an
//             inlier (≤ 4 tolerances) is beyond 0.9 of its tolerance: each residual divided by
//             its pixel's tolerance (PixelJudge: C·q + S·m + E, so a steep surface's snapped or
//             offset samples weigh less than a face-on one's), Cauchy's fit again, then the
//             inliers' largest residual minimised (Lawson's iteration).
//
// MapVerifier::diagnose (map_verifier.h) then confirms each fitted camera with the full
// comparison. Library zcheck::diagnose.
#include "zcheck/checker.h"
#include "zcheck/departure.h"
#include "zcheck/depth_map.h"
#include "zcheck/hypothesis.h"

#include <functional>
#include <string>
#include <vector>

namespace zcheck {

enum class FitFamily {
    SampleOffset,  // (dx, dy): where in the pixel depth was sampled, whole-pixel shifts included
    FieldOfView,   // one focal scale: fovy, focal length, fx = fy, a frustum's or box's extent
    Intrinsics,    // focal scales in x and y (aspect) and the principal point
    NearFar,       // near and far (window and NDC maps, cameras with a model)
    DepthScale,    // a scale and offset on the values (units, a PNG's scale, an origin)
    Pose,          // a small error of eye position and orientation
};
std::string toString(FitFamily family);
// The families that have a meaning for this camera and map.
std::vector<FitFamily> fitFamilies(const Camera& camera, const DepthMap& map);

struct FitResult {
    FitFamily family = FitFamily::SampleOffset;
    Departure departure;
    double initialResidual = 0;  // robust RMS relative depth residual under the declared camera
    double residual = 0;         // the same after the fit
    std::size_t samples = 0;     // sample pixels in the last round; 0: too few to fit (not reported)
};

// Renders the ground truth through a camera with a sampling fault (Checker::renderRay).
using TruthRender = std::function<RenderResult(const Camera&, const RayFaults&)>;

// The median relative eye-depth residual of `map` against `truth` at the fit's sample pixels
// (FitResult::initialResidual, without fitting): how far a reading is from the truth where
// the truth is one plane; +inf where fewer than 16 pixels qualify.
double medianResidual(const Scene& scene, const Camera& camera, const DepthMap& map, const RenderResult& truth);

// The whole-pixel shift of the image along one axis alone (up to a third of the image) under
// which the map's depths best match the truth's at the pixels they move to: a principal point
// off by many pixels (Blender's shift_y with the wrong sign) shifts the whole picture, too far
// for a local fit. (0, 0) unless, of the sample pixels the declared sampling leaves unexplained,
// it explains at least half more than it breaks of the others. The sample-offset fit starts there.
glm::dvec2 wholeImageShift(const Camera& camera, const DepthMap& map, const RenderResult& truth);

// Fits one family. `truth` is the declared camera's ground truth (the first round's planes).
FitResult fitDeparture(const Scene& scene, const Camera& camera, const DepthMap& map, const RenderResult& truth,
                       FitFamily family, const TruthRender& render);

// What a fit found, in the camera's own terms, for people ("a vertical field of view of
// 61.5° instead of 60°") and as named values (FittedValue, hypothesis.h) for --json; the last
// value is the residual, fitted against declared.
std::string describeFit(const Camera& camera, const DepthMap& map, const FitResult& fit);
std::vector<FittedValue> fittedValues(const Camera& camera, const DepthMap& map, const FitResult& fit);

}  // namespace zcheck
