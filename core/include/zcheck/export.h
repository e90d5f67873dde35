#pragma once
// Per-pixel quantities a route can export, with their units and miss values.
//
//   quantity        channels          unit                      miss value
//   window          window            depth-buffer value        the clear value (far end; rangeMin with reversed-Z)
//   ndc             ndc               z_ndc                     NDC z of the far plane
//   eye-z           Z                 scene units (planar)      +inf (0 in 16-bit PNG)
//   distance        distance          scene units (range)       +inf (0 in 16-bit PNG)
//   position-eye    P.X P.Y P.Z       scene units, eye space    NaN
//   position-world  Pw.X Pw.Y Pw.Z    scene units, world space  NaN
//   normal          N.X N.Y N.Z       unit, world space         NaN
//   primitive-id    id (uint32)       triangle index            0xFFFFFFFF
//
// eye-z is planar depth: the distance from the eye plane along the viewing axis. distance
// is the Euclidean range from the centre of projection (for parallel projections, from the
// eye plane along the ray). The normal is the triangle's geometric normal, turned to face
// the camera. Ray route: values from the exact hit (double). Raster route: positions are
// unprojected from the stored window depth, so they carry the depth format's quantization.
#include "zcheck/camera.h"
#include "zcheck/render.h"
#include "zcheck/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

enum class ExportQuantity { Window, Ndc, EyeZ, Distance, PositionEye, PositionWorld, Normal, PrimitiveId };

std::string toString(ExportQuantity quantity);
std::vector<ExportQuantity> exportQuantitiesFromList(const std::string& commaSeparated);  // throws Error
const std::vector<std::string>& exportQuantityNames();

struct QuantityImage {
    ExportQuantity quantity = ExportQuantity::Window;
    int width = 0, height = 0;
    std::vector<std::string> channels;  // channel names, see the table above
    std::string unit;
    std::vector<double> value;          // width·height·channels, interleaved; row 0 at the top
    std::vector<std::uint32_t> id;      // primitive-id only: width·height
    double missValue = 0;               // per channel (NaN, +inf, clear value, 0xFFFFFFFF)
    bool isMiss(std::size_t pixel) const;
};

// The channel name a single-channel quantity is stored under (window, ndc, Z, distance).
std::string channelNameOf(ExportQuantity quantity);

QuantityImage quantityImage(const Scene& scene, const Camera& camera, const RenderResult& route, ExportQuantity quantity);

}  // namespace zcheck
