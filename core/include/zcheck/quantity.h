#pragma once
// What a pixel can hold: the four depth quantities, and the per-pixel quantities a route
// exports, as data (names, channels, units, miss values). No I/O.
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
// eye plane along the ray). Images are stored row by row, row 0 at the top of the picture;
// pixel (col,row) is entry row·width + col.
#include "zcheck/large_buffer.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

constexpr std::uint32_t kNoPrimitive = 0xFFFFFFFFu;  // primitive id of a pixel where nothing was hit

enum class DepthQuantity {
    Window,    // depth-buffer value, in [depth.rangeMin, depth.rangeMax]
    Ndc,       // z_ndc
    EyeZ,      // planar depth: distance along the viewing axis, positive, scene units
    Distance,  // Euclidean range from the centre of projection, scene units
};
std::string toString(DepthQuantity quantity);
DepthQuantity depthQuantityFromName(const std::string& name);  // throws Error naming the value
const std::vector<std::string>& depthQuantityNames();           // window, ndc, eye-z, distance

struct DepthImage {
    int width = 0;
    int height = 0;
    DepthQuantity quantity = DepthQuantity::Window;
    LargeVector<double> value;  // width·height, row 0 at the top

    double at(int col, int row) const { return value[std::size_t(row) * width + col]; }
};

enum class ExportQuantity { Window, Ndc, EyeZ, Distance, PositionEye, PositionWorld, Normal, PrimitiveId };

std::string toString(ExportQuantity quantity);
// "eye-z,normal" → {EyeZ, Normal}; throws Error naming an unknown or repeated name.
std::vector<ExportQuantity> exportQuantitiesFromList(const std::string& commaSeparated);
// One name; throws Error naming it and listing the names.
ExportQuantity exportQuantityFromName(const std::string& name);
const std::vector<std::string>& exportQuantityNames();
// The export quantity that stores a depth quantity (the same name: window, ndc, eye-z, distance).
ExportQuantity exportQuantityOf(DepthQuantity quantity);
// The channel name a single-channel quantity is stored under (window, ndc, Z, distance).
std::string channelNameOf(ExportQuantity quantity);

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

}  // namespace zcheck
