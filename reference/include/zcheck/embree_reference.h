#pragma once
// A yardstick, not part of the check: Embree's own best primary-ray throughput on a scene and
// camera, for `zcheck bench --reference` to set zcheck's ray route against.
//
// What it does is what an Embree user would write for speed, and nothing zcheck needs:
//   - its own BVH with the ray route's settings (robust, medium quality), timed;
//   - one ray per pixel centre, generated in binary32 as an affine function of the pixel
//     (the ray route's AffineRays, camera_rays.h, or for a raw matrix the affine rays through
//     three pixels' rays; unnormalised, t ∈ [0, ∞)); for a lens model, no such function
//     exists: every pixel's world direction is computed before the clock starts (the ray
//     route's, CameraRays::worldRay, in binary32) and read from that table, a pixel outside
//     the lens's field an invalid lane;
//   - 8×8 tiles in parallel with TBB, each traced as four 4×4 packets with rtcIntersect16 and a
//     coherent context; the primitive id stored per pixel into a buffer allocated beforehand.
// Not done: no clip planes, no double-precision hit, no depth.
#include "zcheck/camera.h"
#include "zcheck/scene.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace zcheck::reference {

class EmbreeReference {
public:
    // Builds the BVH; throws Error. `scene` must outlive it (its index buffer is shared).
    explicit EmbreeReference(const Scene& scene);
    ~EmbreeReference();
    EmbreeReference(const EmbreeReference&) = delete;
    EmbreeReference& operator=(const EmbreeReference&) = delete;

    double buildMilliseconds() const { return buildMilliseconds_; }
    // Traces one frame; returns its wall time in milliseconds. primitiveId: width·height
    // entries (resized once), the hit primitive or 0xFFFFFFFF, rows top-down.
    double trace(const Camera& camera, std::vector<std::uint32_t>& primitiveId) const;
    // The same into width·height entries at `primitiveId` that the caller allocated: memory
    // never touched before makes a cold frame's trace (the time then includes its page faults).
    double trace(const Camera& camera, std::uint32_t* primitiveId) const;

private:
    struct Embree;
    std::unique_ptr<Embree> embree_;
    double buildMilliseconds_ = 0;
};

}  // namespace zcheck::reference
