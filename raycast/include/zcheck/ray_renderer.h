#pragma once
// The ray route: Embree traces one ray per pixel through the pixel centre.
//
// Rays come from core's inverse-projection module (double), are handed to Embree in
// binary32 from the eye plane (see EyePlaneRay) with [tNear, tFar] spanning near to far
// plane, traced as coherent 4×2 packets (rtcIntersect8), 8 packets per 8×8 tile, tiles in
// parallel with TBB. Each hit is then recomputed in double against the hit triangle's plane
// and pushed through the forward chain (clipFromWorld, divide, viewport) to the exact
// window depth the depth buffer should hold.
//
// Embree lifetimes: the device outlives the scene; geometry is committed before the scene
// is, and the scene is committed before any ray is traced. An error Embree reports through
// its callback becomes an Error.
#include "zcheck/render.h"

#include <memory>

namespace zcheck {

// Classic mistakes injected into the ray route (the fault catalogue and tests use them; the
// defaults are the correct chain).
struct RayFaults {
    glm::dvec2 shiftPixels{0.0, 0.0};  // added to the window position of the pixel centre
    bool flipRows = false;             // sample row H−1−row instead of row
    bool flipCols = false;             // sample column W−1−col instead of col
    bool distanceAsEyeZ = false;       // the hit's ray distance turned into depth as if it were eye-z
};
using RaySampling = RayFaults;

class RayRenderer final : public Renderer {
public:
    explicit RayRenderer(const Scene& scene);  // builds the BVH (timed); throws Error; `scene` must outlive it
    ~RayRenderer() override;
    RayRenderer(const RayRenderer&) = delete;
    RayRenderer& operator=(const RayRenderer&) = delete;

    std::string name() const override { return "ray"; }
    RenderResult render(const Camera& camera) const override;

    double buildMilliseconds() const { return buildMilliseconds_; }
    RayFaults sampling;  // injected faults; default: none

private:
    struct Embree;
    std::unique_ptr<Embree> embree_;
    const Scene& scene_;
    double buildMilliseconds_ = 0;
};

}  // namespace zcheck
