#pragma once
// Remapping a depth map between two cameras that share a centre of projection — fisheye to
// pinhole, distorted to undistorted, pinhole to equirectangular, one view turned — exactly:
// each target pixel's ray (the target camera's own inverse, lens.h or its matrices) is taken into
// the source camera's eye space and projected into the source image by the source camera's
// closed form (imageFromEye), so nothing is approximated but the sampling, and the quantity is
// converted per ray (a distance stays a distance; an eye-z becomes distance·cos θ of the target's
// ray, or a window depth through the target's depth mapping).
//
// Sampling never interpolates across a depth edge:
//   nearest  the source pixel the point falls in; its sample's distance from the centre (which the
//            cameras share) is the target ray's distance.
//   plane    the 2×2 source samples around the point, unprojected, when they lie on one plane
//            (the fourth within 10⁻⁴ of its distance of the plane of the other three): the target
//            ray meets that plane — exact for a planar surface, what a renderer's facet holds; where
//            they do not (an edge, a miss, the image's border), nearest.
// A target pixel the source does not see (outside its image or its lens's field, or a miss
// there) is a miss: +inf for eye-z and distance, the clear value for window depth.
//
// Pure functions of the cameras and values; throws Error for cameras whose centres differ
// (more than 10⁻⁹ of their distance from the origin, or 10⁻⁹), maps of the wrong size, or a
// quantity a camera cannot hold (window or ndc of a lens model, inverse_projection.h).
#include "zcheck/camera.h"
#include "zcheck/quantity.h"

#include <cstddef>
#include <string>
#include <vector>

namespace zcheck {

enum class RemapSampling { Nearest, Plane };
// "nearest" or "plane"; throws Error naming `what`.
RemapSampling remapSamplingFromName(const std::string& name, const std::string& what);

struct RemappedMap {
    std::vector<double> values;        // to.width() × to.height(), row 0 at the top, of the target quantity
    std::size_t unseen = 0;            // target rays outside the source's image or field
    std::size_t misses = 0;            // target rays whose source sample is a miss (or holds no eye-z there)
    std::size_t nearestAtEdges = 0;    // plane sampling: samples not on one plane, taken nearest
};

// The pinhole a lens camera's image is undistorted to, at the same size and pose, its K chosen as
// OpenCV's getOptimalNewCameraMatrix chooses it (calib3d, centerPrincipalPoint false): the rays of
// a 9×9 grid of points (OpenCV's (i·W/8, j·H/8), i, j = 0…8) on the plane z = 1; alpha 0 keeps
// only what every edge sees (the largest rectangle inside the undistorted border), 1 every source
// pixel (the rectangle around them all), between them linearly. Throws Error for a camera without
// a lens, and for a lens whose grid holds a pixel with no ray or a ray 90° or more off the axis
// (no pinhole image holds it: a fisheye past 180°, a panorama).
CameraSpec undistortedCameraSpec(const Camera& lensCamera, double alpha);

RemappedMap remapDepthMap(const Camera& from, const std::vector<double>& values, DepthQuantity fromQuantity,
                          const Camera& to, DepthQuantity toQuantity, RemapSampling sampling);

}  // namespace zcheck
