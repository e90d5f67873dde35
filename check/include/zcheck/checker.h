#pragma once
// Checker: one scene, both routes built once, checked through any camera (library zcheck::check).
//
//   const zcheck::Checker checker(zcheck::loadScene("bunny.obj"));   // BVH and raster set-up, once
//   const zcheck::Camera camera(zcheck::readCameraFile("camera.json"));
//   const zcheck::CheckResult result = checker.check(camera);
//   if (!result.report.comparison.consistent()) { /* result.comparison.pixelClass says where */ }
//
//   zcheck::RayFaults flipped;                      // render with a mistake (faults are arguments)
//   flipped.flipRows = true;
//   const zcheck::RenderResult wrong = checker.renderRay(camera, flipped);
//
// check() draws the scene through the camera by both routes — the ray route follows the
// camera's definition (camera_rays.h), the raster route its matrices — and compares them per
// pixel with the tolerance model (compare.h); asked to keep no per-pixel result
// (CheckOptions::keepPixels), it does so 64×64 tile by tile, each tile traced, drawn and
// compared while in the cache, for the same report. A depth map rendered elsewhere is judged
// against the ray route above this library: MapVerifier (zcheck::diagnose, map_verifier.h)
// holds a Checker and verifies and diagnoses maps through its routes (rayRenderer(),
// rasterRenderer()).
//
// Thread-safety: a Checker is immutable after construction; every member function is const
// and may be called from several threads at once. Each call allocates its own results.
#include "zcheck/compare.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"
#include "zcheck/raster_renderer.h"
#include "zcheck/ray_renderer.h"
#include "zcheck/scene.h"

#include <optional>
#include <string>
#include <vector>

namespace zcheck {

enum class Route { Ray, Raster };
std::string toString(Route route);
Route routeFromName(const std::string& name);  // "ray" | "raster"; throws Error naming the value

// Faults for either route (a render of one route reads its own part).
struct RouteFaults {
    RayFaults ray;
    RasterFaults raster;
};

struct Timings {
    double bvhBuildMs = 0;   // Embree scene build (BVH), wall time
    double traceMs = 0;      // ray generation + tracing + depth in double, wall time
    double rasterMs = 0;     // transform, clip, bin, rasterize, wall time
    double compareMs = 0;    // per-pixel comparison and classification, wall time
    // Drawn and compared tile by tile (CheckOptions::keepPixels false): the three phases ran
    // interleaved, so their wall time is the pass's shared out in proportion to the threads'
    // time in each, plus the raster's set-up and the comparison's (its slopes of all triangles)
    // before it; they still add up to the total.
    bool tileByTile = false;
};

// A verified map's errors as its user reads them, over the pixels compared on depth (both hit
// the same surface: agree + depth errors), error = map − truth. Eye-z and distance maps: in the
// map's own units (after scale and offset: metres, mostly). Window and ndc maps: their eye-z
// equivalents, in scene units (the quanta stay the comparison's measure).
struct MapErrors {
    std::string quantity;           // "eye-z" or "distance": what the values below measure
    bool eyeZEquivalent = false;    // a window or ndc map's errors, as eye-z
    std::int64_t compared = 0;      // 0: nothing compared (and everything below 0)
    double maxAbs = 0, p99Abs = 0, medianAbs = 0;  // |error|
    double maxRel = 0, p99Rel = 0, medianRel = 0;  // |error| / true value
    int worstCol = -1, worstRow = -1;              // the largest |error|: where, the map's value, the true one
    double worstMap = 0, worstTrue = 0;
};

// A lens model's check (lens.h). A lens has no projection matrix, so there is no raster route:
// its two directions are checked against each other and against the trace. Over the field, every
// pixel centre's ray projected back lands on the centre (the round trip, ≤ kRoundTripBoundPx), and
// every traced hit point projected forward by the closed form lands on its own pixel centre
// (≤ kForwardBoundPx, plus what rounding allows: forwardBoundPx). Pixels outside the field have
// no ray: counted, never traced.
struct LensCheck {
    static constexpr double kRoundTripBoundPx = 1e-9;
    static constexpr double kForwardBoundPx = 1e-6;
    // A hit's forward bound: kForwardBoundPx plus the rounding of its direction as the lens
    // magnifies it. The hit point is eye + t·d in world coordinates, so its direction from the eye
    // is rounded by up to 2^-52·(|eye|/t + 16) radians (|eye| the eye's distance from the world
    // origin, t the hit's from the eye: a camera in UTM coordinates, 5·10⁶ m out, looking at a wall
    // 0.5 m away, 2·10⁻⁹ rad); the lens turns a radian into up to `pixelsPerRadian` pixels there
    // (LensModel::pixelsPerRadian: ~f away from the edge of its field, far more where the map
    // nears a fold), taken twice, as it is estimated by differences. Far below what a wrong chain
    // moves a hit by: a ray shifted by 10⁻⁴ px fails at every pixel of such a camera (test_lens.cpp).
    static double forwardBoundPx(double eyeFromOrigin, double t, double pixelsPerRadian);
    std::string model;                 // the lens model's name
    double fieldAngleDeg = 0;          // the field's largest angle from the axis
    std::int64_t inField = 0;          // pixel centres with a ray
    std::int64_t outsideField = 0;     // pixel centres outside the lens's field: no ray
    std::int64_t hits = 0;             // of the rays, those that hit the scene
    double roundTripMaxPx = 0;         // max |image(ray(p)) − p| over the field
    int roundTripCol = -1, roundTripRow = -1;
    std::int64_t roundTripFailures = 0;  // pixels beyond kRoundTripBoundPx (or whose ray has no image)
    double forwardMaxPx = 0;           // max |image(hit) − p| over the hits
    int forwardCol = -1, forwardRow = -1;
    std::int64_t forwardFailures = 0;  // hits beyond their forward bound
    double forwardWidestBoundPx = kForwardBoundPx;  // the widest forward bound a hit was judged by
};

// What was compared, how long it took, what was found (report.h prints it).
struct CheckReport {
    std::string scene;              // scene name as addressed
    std::size_t triangles = 0;      // triangles in the scene
    CameraSpec camera;              // the camera both routes used
    ToleranceModel tolerance;
    ComparisonReport comparison;
    Timings timings;
    std::vector<std::string> warnings;  // about the inputs (PolygonPlanarity::warning), in the report
    MapAccuracy declared;               // verify: what the map's reading declared; check: nothing
    std::string secondRoute = "raster"; // what the truth is compared with: "raster" (check) or "map" (verify),
                                        // as the report and its JSON keys name it
    MapErrors mapErrors;                // verify: the map's errors in its units; check: nothing compared
    std::string outOfRangeRule;         // verify: what the map's quantity holds ("window map holds values
                                        // in [0, 1], the camera's depth range"), for values out of range
    std::optional<LensCheck> lens;      // check of a lens model's camera: what was checked instead of a raster

    // Fills what the report says of its inputs: the scene (name, triangles, warnings), the
    // camera and the tolerance. Checker::check and verifying a map (verify.h) share it.
    void describeInputs(const Scene& checked, const Camera& used, const ToleranceModel& model);
};

struct CheckResult {
    RenderResult ray;        // exact window depths, hit points in eye space (empty: !keepPixels)
    RenderResult raster;     // stored depth-buffer values (empty: !keepPixels)
    Comparison comparison;   // per-pixel classes (empty: !keepPixels) and the summary
    CheckReport report;
};

struct CheckOptions {
    ToleranceModel tolerance;
    RouteFaults faults;      // mistakes injected into either route (default: none)
    // Keep both routes' renders and the per-pixel classes in the CheckResult (pictures, maps,
    // Python's arrays). Without them the check draws, traces and compares tile by tile in
    // the cache and keeps only the report: the same report, ~60 MB less memory touched at
    // 1080p, faster (`zcheck check` without --out).
    bool keepPixels = true;
};

// Refuses a comparison with nothing in it (throws Error naming `scene`): a camera that sees
// no geometry proves nothing, and must not be reported CONSISTENT. check/verify front-ends
// call it on the report before they print a verdict.
void requireSomethingCompared(const ComparisonReport& report, const std::string& scene);

class Checker {
public:
    // Validates the scene (throws Error: no triangles, an index out of range) and builds both
    // routes: Embree's BVH (timed, Timings::bvhBuildMs; `build`: for a few rays per triangle, a
    // one-frame check, bvhBuildFor; the thorough default for many frames or unknown use) and
    // the rasterizer.
    explicit Checker(Scene scene, BvhBuild build = BvhBuild::Thorough);
    Checker(const Checker&) = delete;
    Checker& operator=(const Checker&) = delete;

    const Scene& scene() const { return scene_; }
    double bvhBuildMilliseconds() const { return rays_.buildMilliseconds(); }

    // Both routes through `camera`, compared; for a lens model's camera, its two directions and
    // the trace (LensCheck), reported in the same form (a hit within the bounds agrees, one beyond
    // them is a depth error, a pixel outside the field a miss).
    CheckResult check(const Camera& camera, const CheckOptions& options = {}) const;

    // One route's render: window depth and primitive per pixel (row 0 at the top).
    RenderResult renderRay(const Camera& camera, const RayFaults& faults = {}, EyePoints eyePoints = EyePoints::Omit) const;
    RenderResult renderRaster(const Camera& camera, const RasterFaults& faults = {}) const;
    RenderResult render(const Camera& camera, Route route, const RouteFaults& faults = {}) const;
    // One route's render as an exported quantity (quantity.h): depth in any of the four
    // quantities, positions, normals or primitive ids.
    QuantityImage render(const Camera& camera, ExportQuantity quantity, Route route) const;

    // The routes themselves, for those who judge maps through them (MapVerifier): the ray
    // route's single rays (RayRenderer::primitiveAt) and the rasterizer's drawing.
    const RayRenderer& rayRenderer() const { return rays_; }
    const RasterRenderer& rasterRenderer() const { return raster_; }

private:
    CheckResult checkTileByTile(const Camera& camera, const CheckOptions& options) const;
    CheckResult checkLens(const Camera& camera, const CheckOptions& options) const;

    Scene scene_;
    RayRenderer rays_;
    RasterRenderer raster_;
};

}  // namespace zcheck
