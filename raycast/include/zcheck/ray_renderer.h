#pragma once
// The ray route: Embree traces one ray per pixel through the pixel centre.
//
// Rays come from the camera's definition (camera_rays.h, double), are handed to Embree in
// binary32 from the eye plane with [tNear, tFar] spanning near to far plane (for every model
// but a raw matrix the direction gains one unit of eye-z per unit of t: AffineRays), traced
// as coherent 4×4 packets (rtcIntersect16), row by row of packets over 64×64 regions, the
// regions in parallel with TBB (traceRect traces one rectangle), each into a buffer of its
// worker's own, copied into the image when the region is done. Each hit is then recomputed
// in double against the hit triangle's plane (one packet later, once the plane has been
// fetched while Embree traced), and its eye-z turned into the exact window depth the depth
// buffer should hold by the convention's depth mapping in closed form — never through the
// raster route's matrices. The planes (a corner and the normal cross(b − a, c − a) in double)
// are made once with the BVH and kept beside it: 40 bytes per triangle.
//
//   const zcheck::RayRenderer rays(scene);              // builds the BVH once
//   const zcheck::RenderResult truth = rays.render(camera);
//
// Thread-safety: render() is const and may run from several threads at once.
//
// Embree lifetimes: the device outlives the scene; geometry is committed before the scene
// is, and the scene is committed before any ray is traced. An error Embree reports through
// its callback becomes an Error.
#include "zcheck/kernel_form.h"
#include "zcheck/render.h"
#include "zcheck/scene.h"
#include "zcheck/tile_grid.h"

#include <memory>
#include <string>

namespace zcheck {

// Classic mistakes injected into the ray route (the mistake catalogue and tests pass them to
// render(); the defaults are the correct chain).
struct RayFaults {
    glm::dvec2 shiftPixels{0.0, 0.0};  // added to the window position of the pixel centre
    bool flipRows = false;             // sample row H−1−row instead of row
    bool flipCols = false;             // sample column W−1−col instead of col
    bool distanceAsEyeZ = false;       // the hit's ray distance turned into depth as if it were eye-z

    bool none() const { return shiftPixels == glm::dvec2(0.0) && !flipRows && !flipCols && !distanceAsEyeZ; }
};

// Whether a render also keeps each hit's eye-space point (exports of eye-z, distance and
// positions read it; a check does not).
enum class EyePoints { Omit, Keep };

// How Embree builds the BVH. Its build is most of a one-frame check of a large mesh (10 M
// triangles at 4K: ~3 s of ~5), its trace most of a check of many frames; the trace's results
// are the same whichever was built (the closest hit, its depth recomputed in double).
enum class BvhBuild {
    // Embree's RTC_BUILD_QUALITY_LOW for the mesh (Morton codes) with RTC_SCENE_FLAG_COMPACT:
    // built ~4× as fast in ~25 % less memory, traced ~1.3–1.5× as slowly.
    Quick,
    // RTC_BUILD_QUALITY_MEDIUM (binned SAH): the fastest trace. The default, for a dataset's
    // frames, a program's loop over cameras, or a use not known beforehand.
    Thorough,
};

// Measured on the development machine (docs/speed.md): the quick build saves ~180–230 ns a
// triangle and costs ~13–19 ns a ray, so it pays below ~12 rays per triangle. Below this many
// expected rays per triangle bvhBuildFor chooses it.
constexpr double kQuickBuildRaysPerTriangle = 10.0;

// The build that costs least in all where `expectedRays` rays (every trace this BVH will serve,
// together) meet `triangles` triangles: Quick below kQuickBuildRaysPerTriangle rays per
// triangle, else Thorough. An unknown count is infinity (Thorough).
BvhBuild bvhBuildFor(double expectedRays, std::size_t triangles);
// "quick", "thorough".
const char* nameOf(BvhBuild build);

// Embree's own kernels (its BVH build and traversal) come in instruction sets as zcheck's do,
// and Embree runs the widest the processor has. ZCHECK_EMBREE_ISA, read when a RayRenderer (or
// `zcheck bench`'s Embree yardstick) is made, forces one: unset, empty or `auto` leaves the
// choice to Embree; sse2, sse4.2, avx, avx2 or avx512 has Embree run that set's kernels, as on
// a processor with none wider. With ZCHECK_KERNELS=avx2 too, an AVX-512 machine then runs what
// an AVX2-only one runs (docs/speed.md measures it so). A value that is none of these, or a set
// the processor lacks (each set needs the ones below it, as Embree's do), is refused (Error,
// one line; Embree itself would take an unknown name for SSE2 silently). On a processor other
// than x86-64 only auto is taken. Every set finds each ray's closest hit; where two triangles
// are hit at exactly the same distance (an edge they share), which one it reports may differ
// from set to set, so zcheck's kernel forms are bit-identical to each other under one Embree
// set at a time.
//
//   setenv("ZCHECK_EMBREE_ISA", "avx2", 1);
//   zcheck::embreeIsa();           // "avx2" (throws Error for a bad value)
//   zcheck::embreeDeviceConfig();  // "isa=avx2", rtcNewDevice's configuration ("" for auto)
//   zcheck::embreeAutoIsa();       // "avx512": the set auto runs, the widest the processor has
//                                  // (Debian's Embree is built with all five; "" off x86-64)
std::string embreeIsa();
std::string embreeDeviceConfig();
std::string embreeAutoIsa();

class RayRenderer {
public:
    // Builds the BVH (as `build` says) and the triangles' planes, timed together; throws Error.
    // `scene` must outlive it: Embree reads its index buffer in place. The trace's steps around
    // Embree run in the form kernelForm() gives when this is made (zcheck/kernel_form.h:
    // ZCHECK_KERNELS, read here; a value it refuses throws Error), each form bit-identical to
    // the baseline. Embree runs the instruction set embreeIsa() gives (ZCHECK_EMBREE_ISA, read
    // here too, with the same refusals).
    explicit RayRenderer(const Scene& scene, BvhBuild build = BvhBuild::Thorough);
    ~RayRenderer();
    RayRenderer(const RayRenderer&) = delete;
    RayRenderer& operator=(const RayRenderer&) = delete;

    // Cameras are the world's; a scene held about a local origin (Scene::origin) is traced with
    // each camera moved into its frame. EyePoints::Keep also fills RenderResult::pEye (24 bytes
    // per pixel more).
    RenderResult render(const Camera& camera, const RayFaults& faults = {}, EyePoints eyePoints = EyePoints::Omit) const;

    // The pixels `rect` of render(camera, faults), each one written (a miss: the clear value
    // and kNoPrimitive, pEye NaN): pixel (col, row) to entry (row − rect.row0)·stride +
    // (col − rect.col0) of windowDepth, primitiveId and, when given, pEye. rect.col0 and
    // rect.row0 must be multiples of 4, so that its 4×4 packets are render()'s (whose regions
    // are 64×64 tiles), and the rectangle must lie inside the image. For a check that
    // compares tile by tile.
    void traceRect(const Camera& camera, const PixelRect& rect, double* windowDepth, std::uint32_t* primitiveId,
                   std::size_t stride, const RayFaults& faults = {}, glm::dvec3* pEye = nullptr) const;

    // The triangle the viewing ray through one window point hits first (kNoPrimitive on a
    // miss), traced alone: for questions about single points, not for images.
    std::uint32_t primitiveAt(const Camera& camera, const glm::dvec2& pWindow) const;

    double buildMilliseconds() const { return buildMilliseconds_; }
    BvhBuild bvhBuild() const { return build_; }
    // The widest ray packet Embree traces natively with the instruction set it runs (above):
    // 4 (SSE), 8 (AVX, AVX2) or 16 (AVX-512).
    int embreeNativePacket() const;

private:
    // traceRect for a camera already in the scene's frame (CameraInSceneFrame).
    void traceRectInSceneFrame(const Camera& camera, const PixelRect& rect, double* windowDepth,
                               std::uint32_t* primitiveId, std::size_t stride, const RayFaults& faults,
                               glm::dvec3* pEye) const;

    struct Embree;
    std::unique_ptr<Embree> embree_;
    const Scene& scene_;
    KernelForm form_;  // the trace's form (ZCHECK_KERNELS, read when this was made)
    BvhBuild build_;
    double buildMilliseconds_ = 0;
};

}  // namespace zcheck
