#pragma once
// White-box hooks into the raster route for tests (not installed): the vector kernels must
// match the scalar loops in every intermediate value, not only where a difference would
// survive quantization into the output.
#include "zcheck/raster_renderer.h"

#include <cstdint>
#include <vector>

namespace zcheck {

// One vertex after the vertex stage: its outcode (bit k: outside clip plane k) and, as the
// raster stores it, X and Y in 16.8 fixed point and window depth z; X = INT32_MIN where the
// vertex is not snapped (then Y is its outcode, or 0 where it could not be snapped).
struct RasterVertexForTesting {
    unsigned outcode;
    std::int32_t X, Y;
    double z;
};

// The vertex stage for every vertex of `scene`: with `vector`, the vector kernel of
// kernelForm() (ZCHECK_KERNELS applies) where the faults allow it, else the scalar loop.
std::vector<RasterVertexForTesting> rasterVertexStageForTesting(const Scene& scene, const Camera& camera,
                                                                const RasterFaults& faults, bool vector);

// The clean chain's render with depth keys of 2^52 steps instead of the format's: each
// pixel's clamped window depth to within 2^-52 (the stored value is key / 2^52), so that a
// last-bit difference between the kernels' depth arithmetic shows in about half the pixels
// it touches, where the format would hide it. ZCHECK_KERNELS applies.
RenderResult rasterRenderWithFineKeysForTesting(const Scene& scene, const Camera& camera);

}  // namespace zcheck
