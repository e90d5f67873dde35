#pragma once
// What a route produces, and the interface both routes implement.
//
// Images are stored row by row, row 0 at the top of the picture, width·height entries;
// pixel (col,row) is entry row·width + col.
#include "zcheck/camera.h"
#include "zcheck/scene.h"

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

struct DepthImage {
    int width = 0;
    int height = 0;
    DepthQuantity quantity = DepthQuantity::Window;
    std::vector<double> value;  // width·height, row 0 at the top

    double at(int col, int row) const { return value[std::size_t(row) * width + col]; }
};

struct RenderResult {
    // Window depth per pixel. Ray route: the exact value the forward chain gives the hit
    // point (double, not quantized). Raster route: the value the depth buffer stores
    // (quantized to the depth format). Where nothing was hit: the camera's clear value.
    DepthImage windowDepth;
    std::vector<std::uint32_t> primitiveId;  // index into Scene::triangles, or kNoPrimitive
    std::vector<glm::dvec3> pEye;            // ray route only: hit point in eye space (double)
    double renderMilliseconds = 0;           // wall time of render()

    bool hit(std::size_t pixel) const { return primitiveId[pixel] != kNoPrimitive; }
};

// A route draws the scene it was built with through any camera. Building may be costly
// (a BVH); rendering is repeatable and thread-safe with respect to other renders.
class Renderer {
public:
    virtual ~Renderer() = default;
    virtual std::string name() const = 0;
    virtual RenderResult render(const Camera& camera) const = 0;
};

}  // namespace zcheck
