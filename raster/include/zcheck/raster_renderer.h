#pragma once
// The raster route: a software rasterizer that draws the scene forward into a z-buffer.
//
// Pipeline, one function per stage:
//   world → clip (clipFromWorld, double)
//   → homogeneous clipping against near and far always, and against a guard band of
//     |x|,|y| ≤ g·w that keeps window coordinates inside ±2^20 pixels (so 16.8 fixed point
//     and 64-bit edge functions cannot overflow, whatever the input)
//   → perspective divide → viewport (the camera's windowFromNdc, image rows top-down)
//   → snapping to 16.8 fixed point (round to nearest)
//   → scan conversion with integer edge functions and the top-left fill rule, sampled at
//     pixel centres (a shared edge covers each pixel exactly once)
//   → window depth interpolated linearly in window space (plane through the snapped
//     vertices), clamped to the depth range and quantized to the depth format on write
//   → depth test LESS, or GREATER with reversed-Z; no culling; primitive id per pixel.
//
// Parallel and deterministic: triangles are set up in fixed chunks of kChunkTriangles
// (independent of the thread count) and binned per chunk into 64×64 tiles in submission
// order; tiles are then drawn in parallel, each walking the chunks in order. The result is
// bit-identical for any number of threads.
//
// In the AVX2 and AVX-512 forms (zcheck/kernel_form.h), the vertex stage, the set-up and the
// clean chain's pixels run eight at a time, with the same integer and double operations in the
// same order as the scalar loops (no FMA contraction), so the result is bit-identical to
// theirs; the baseline form runs the scalar loops. ZCHECK_KERNELS chooses the form, read by
// render() and prepare(), which throw Error for a value it refuses.
//
//   const zcheck::RasterRenderer raster(scene);
//   const zcheck::RenderResult drawn = raster.render(camera);   // drawn.windowDepth: stored values
#include "zcheck/render.h"
#include "zcheck/scene.h"
#include "zcheck/tile_grid.h"

#include <memory>

namespace zcheck {

// Classic mistakes injected into the raster route (the mistake catalogue passes them to
// render(); the defaults are the correct chain).
struct RasterFaults {
    bool overrideClipFromWorld = false;  // draw with `clipFromWorld` instead of the camera's
    glm::dmat4 clipFromWorld{1.0};       // (a wrong projection or view matrix; the world's, as cameras are)
    bool noNearClip = false;             // clip against the far plane and guard band only
    bool screenLinearEyeZ = false;       // interpolate eye-z linearly in screen space, then map it to depth
    bool viewportMinusOne = false;       // viewport scaled by (width − 1, height − 1)
    bool truncateUnorm = false;          // unorm-N stores floor(d·(2^N − 1)) instead of rounding
    bool storeLinearEyeZ = false;        // store (eye-z − near)/(far − near) as the window depth
    bool otherDepthMapping = false;      // draw with the other depth mapping: reversed-Z's projection,
                                         // depth test and clear value where standard was declared, or
                                         // the reverse (not for raw-matrix cameras: ignored there)
};

// One camera's frame made ready to draw (RasterRenderer::prepare): vertices snapped, triangles
// set up and binned. Its tiles (kTileSize squares numbered row by row) can then be drawn in
// any order, from several threads at once: a check that compares tile by tile draws a tile
// into a buffer of its own. Holds copies of the camera (a world camera, moved into the frame of
// a scene held about a local origin: CameraInSceneFrame) and faults; the scene must outlive it.
class RasterFrame {
public:
    RasterFrame(const Scene& scene, const Camera& camera, const RasterFaults& faults);
    ~RasterFrame();
    RasterFrame(RasterFrame&&) noexcept = default;

    const TileGrid& tiles() const;  // kTileSize squares over the camera's image
    // How drawTile writes: for a reader soon after (Cached: a tile compared as it is drawn), or
    // into a whole image read much later (Streaming: streaming stores, which do not first read in the lines they overwrite).
    enum class Stores { Cached, Streaming };
    // The tile's stored depth values and primitive ids (kNoPrimitive where nothing was drawn)
    // into windowDepth/primitive, which point at the tile's first pixel: pixel (col, row) of
    // the tile goes to entry (row − row0)·stride + (col − col0). Thread-safe (const).
    void drawTile(int tile, double* windowDepth, std::uint32_t* primitive, std::size_t stride,
                  Stores stores = Stores::Cached) const;

private:
    friend struct RasterFrameTesting;  // white-box tests (raster/src/raster_testing.h)
    struct Impl;
    explicit RasterFrame(std::unique_ptr<Impl> impl);  // prepares it
    std::unique_ptr<Impl> impl_;
};

class RasterRenderer {
public:
    static constexpr int kSubpixelBits = 8;          // 16.8 fixed point
    static constexpr int kTileSize = 64;             // pixels per tile side
    static constexpr int kChunkTriangles = 16384;    // triangles per set-up chunk

    explicit RasterRenderer(const Scene& scene);     // the scene must outlive the renderer
    // Thread-safety: const, and may run from several threads at once.
    RenderResult render(const Camera& camera, const RasterFaults& faults = {}) const;
    // The frame render() draws, made ready for drawing tile by tile.
    RasterFrame prepare(const Camera& camera, const RasterFaults& faults = {}) const;

private:
    const Scene& scene_;
};

}  // namespace zcheck
