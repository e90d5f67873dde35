#pragma once
// The mistakes of the lens family (lens.h), each defined once as what the renderer really did:
// the camera it rendered through, the quantity it wrote, the image order it stored. The
// diagnosis (diagnose_lens.cpp) hypothesises each by re-reading a map that way; the suite
// (suite.h, the lens part) injects each by rendering the map that way. Library zcheck::diagnose.
//
//   distortion-ignored        the map made through the lens's K alone (a pinhole), declared with the lens
//   undistorted-new-k         the map undistorted to getOptimalNewCameraMatrix's K (alpha 0 or 1),
//                             declared with the lens (remap.h, undistortedCameraSpec)
//   coefficient-order         OpenCV's k1 k2 p1 p2 k3 read where k1 k2 k3 p1 p2 was meant, or the
//                             reverse; nerfstudio's k1 k2 k3 k4 p1 p2 against OpenCV's order
//   tangential-swapped        p1 and p2 exchanged (Metashape's P1 is OpenCV's p2)
//   distortion-signs-flipped  every distortion coefficient negated (undistortion's for distortion's)
//   fisheye-model             a fisheye rendered as another: equidistant, equisolid, stereographic (same K)
//   y-flip, x-flip            the image stored bottom to top, or mirrored left to right
//   half-pixel                the principal point half a pixel off (pixel centres counted from 0.5 or from 0)
//   cx-cy-swapped             cx and cy exchanged
//   distance-as-eye-z, eye-z-as-distance   the map's values of the other quantity
// A mistake that would leave the camera unchanged (p1 == p2, every coefficient 0, a model read as
// itself) is not listed for that camera.
#include "zcheck/camera.h"
#include "zcheck/checker.h"
#include "zcheck/depth_map.h"

#include <optional>
#include <string>
#include <vector>

namespace zcheck {

struct LensMistake {
    std::string name, variant;  // as the diagnosis names it: "undistorted-new-k", "alpha 0"
    std::string explanation;    // "consistent if ..." — the diagnosis's words
    std::optional<CameraSpec> camera;       // the camera the renderer used; none: the declared one
    std::optional<DepthQuantity> quantity;  // the quantity it wrote; none: the declared one
    int flip = 0;                           // the image stored with rows (1) or columns (2) reversed
};

// The lens family's mistakes that have a meaning for a map of `declaredQuantity` declared with
// `declared` (a camera with a lens model).
std::vector<LensMistake> lensMistakes(const Camera& declared, DepthQuantity declaredQuantity);

// The index of the lens model's parameter `name` ("k1", "p2"), or std::string::npos.
std::size_t lensParamIndex(const LensSpec& lens, const char* name);

// The map with its rows (flip 1) or columns (flip 2) in the other order; flip 0: the map.
DepthMap flippedMap(const DepthMap& map, int flip);

// A map of `quantity` rendered by the ray route through `camera` (EyePoints::Keep, export's
// quantityImage) as a binary32 file stores it and verify reads it: each value rounded to
// binary32, a pixel without a surface 0 (a miss).
DepthMap renderedMap(const Checker& checker, const Camera& camera, DepthQuantity quantity);

// The map a renderer making `mistake` delivers for a camera declared as `declared` with
// `declaredQuantity`: rendered through mistake.camera (else `declared`) as mistake.quantity
// (else the declared one), stored flipped as mistake.flip says, and labelled `declaredQuantity`.
// Throws Error when the mistaken camera is no valid camera.
DepthMap mistakenMap(const Checker& checker, const Camera& declared, DepthQuantity declaredQuantity,
                     const LensMistake& mistake);

}  // namespace zcheck
