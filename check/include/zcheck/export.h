#pragma once
// A route's render as one of the exported quantities (table in quantity.h).
//
// The normal is the triangle's geometric normal, turned to face the camera. Ray route:
// values from the exact hit (double) where the render kept its eye points (EyePoints::Keep),
// else from its depth. Raster route: positions are unprojected from the stored window depth, so
// they carry the depth format's quantization. A lens camera's route holds the distance along each
// pixel's ray (it has no depth buffer), and its points are unprojected from that.
#include "zcheck/camera.h"
#include "zcheck/quantity.h"
#include "zcheck/render.h"
#include "zcheck/scene.h"

namespace zcheck {

QuantityImage quantityImage(const Scene& scene, const Camera& camera, const RenderResult& route, ExportQuantity quantity);

// The image of `quantity` for `camera` without its values: size, channel names, unit and the
// value a miss holds (quantityImage's; a depth file's sidecar describes it). Refuses window and
// NDC depth for a lens camera, which has no depth buffer.
QuantityImage quantityImageShape(const Camera& camera, ExportQuantity quantity);

}  // namespace zcheck
