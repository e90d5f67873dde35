#pragma once
// What a route produces: window depth and the primitive seen, per pixel.
//
// Images are stored row by row, row 0 at the top of the picture, width·height entries;
// pixel (col,row) is entry row·width + col.
#include "zcheck/camera.h"
#include "zcheck/large_buffer.h"
#include "zcheck/quantity.h"

#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

struct RenderResult {
    // Window depth per pixel. Ray route: the exact value the forward chain gives the hit
    // point (double, not quantized). Raster route: the value the depth buffer stores
    // (quantized to the depth format). Where nothing was hit: the camera's clear value.
    DepthImage windowDepth;
    std::vector<std::uint32_t> primitiveId;  // index into Scene::triangles, or kNoPrimitive
    std::vector<glm::dvec3> pEye;            // ray route, when asked (EyePoints::Keep): hit point in eye
                                             // space (double); empty otherwise
    double renderMilliseconds = 0;           // wall time of render()

    bool hit(std::size_t pixel) const { return primitiveId[pixel] != kNoPrimitive; }

    // A render where nothing was hit yet: every pixel at the clear value and kNoPrimitive
    // (buffers on huge pages: large_buffer.h).
    static RenderResult cleared(int width, int height, double clearDepth)
    {
        RenderResult result;
        result.windowDepth.width = width, result.windowDepth.height = height;
        result.windowDepth.quantity = DepthQuantity::Window;
        assignLarge(result.windowDepth.value, std::size_t(width) * height, clearDepth);
        assignLarge(result.primitiveId, std::size_t(width) * height, kNoPrimitive);
        return result;
    }
};

}  // namespace zcheck
