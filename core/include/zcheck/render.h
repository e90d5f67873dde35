#pragma once
// What a route produces: window depth and the primitive seen, per pixel.
//
// Images are stored row by row, row 0 at the top of the picture, width·height entries;
// pixel (col,row) is entry row·width + col.
#include "zcheck/camera.h"
#include "zcheck/large_buffer.h"
#include "zcheck/quantity.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace zcheck {

struct RenderResult {
    // Window depth per pixel. Ray route: the exact value the forward chain gives the hit
    // point (double, not quantized). Raster route: the value the depth buffer stores
    // (quantized to the depth format). Where nothing was hit: the camera's clear value.
    DepthImage windowDepth;
    LargeVector<std::uint32_t> primitiveId;  // index into Scene::triangles, or kNoPrimitive
    LargeVector<glm::dvec3> pEye;            // ray route, when asked (EyePoints::Keep): hit point in eye
                                             // space (double); empty otherwise
    double renderMilliseconds = 0;           // wall time of render()

    bool hit(std::size_t pixel) const { return primitiveId[pixel] != kNoPrimitive; }

    // A render where nothing was hit yet: every pixel at the clear value and kNoPrimitive.
    static RenderResult cleared(int width, int height, double clearDepth)
    {
        RenderResult result = allocated(width, height);
        std::fill(result.windowDepth.value.begin(), result.windowDepth.value.end(), clearDepth);
        std::fill(result.primitiveId.begin(), result.primitiveId.end(), kNoPrimitive);
        return result;
    }
    // The buffers of a render, uninitialised, for a renderer that writes every pixel's depth
    // and primitive id (its threads then fault the pages in as they write them, once).
    static RenderResult allocated(int width, int height)
    {
        RenderResult result;
        result.windowDepth.width = width, result.windowDepth.height = height;
        result.windowDepth.quantity = DepthQuantity::Window;
        result.windowDepth.value.resize(std::size_t(width) * height);
        result.primitiveId.resize(std::size_t(width) * height);
        return result;
    }
};

}  // namespace zcheck
