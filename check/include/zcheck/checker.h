#pragma once
// Checker: one scene, both routes built once, and every question zcheck answers about it.
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
// compared while in the cache, for the same report. verify() and diagnose() judge a depth map
// rendered elsewhere against the ray route (verify.h).
//
// Thread-safety: a Checker is immutable after construction; every member function is const
// and may be called from several threads at once. Each call allocates its own results.
#include "zcheck/compare.h"
#include "zcheck/depth_map_reading.h"
#include "zcheck/quantity.h"
#include "zcheck/raster_renderer.h"
#include "zcheck/ray_renderer.h"
#include "zcheck/scene.h"

#include <memory>
#include <mutex>
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

// What was compared, how long it took, what was found (report.h prints it).
struct CheckReport {
    std::string scene;              // scene name as addressed
    std::size_t triangles = 0;      // triangles in the scene
    CameraSpec camera;              // the camera both routes used
    ToleranceModel tolerance;
    ComparisonReport comparison;
    Timings timings;
    std::vector<std::string> warnings;  // about the inputs (PolygonPlanarity::warning), in the report
    MapAccuracy declared;               // verify: what the map declared (DepthMap::accuracy); check: nothing
    std::string secondRoute = "raster"; // what the truth is compared with: "raster" (check) or "map" (verify),
                                        // as the report and its JSON keys name it
    MapErrors mapErrors;                // verify: the map's errors in its units; check: nothing compared
    std::string outOfRangeRule;         // verify: what the map's quantity holds ("window map holds values
                                        // in [0, 1], the camera's depth range"), for values out of range

    // Fills what the report says of its inputs: the scene (name, triangles, warnings), the
    // camera and the tolerance. Checker::check and verify share it.
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

// How one value of a map is judged (value units): the step it was stored or rounded with (0:
// binary32's own spacing at the value), and the accuracy its producer declares, ± (absolute +
// relative·|value|).
struct ValueAccuracy {
    double step = 0;
    double relative = 0, absolute = 0;
};

// A depth map rendered elsewhere, as read: values per pixel in one depth quantity.
struct DepthMap {
    int width = 0, height = 0;
    DepthQuantity quantity = DepthQuantity::Window;
    std::vector<double> value;   // row 0 at the top; misses and values out of range as
                                 // kindOfDepthValue (inverse_projection.h) defines them
    double valueQuantum = 0;     // the storage step of `value` (1/scale for integer files); 0: binary32
    std::vector<float> valueStep;  // each value's own step (binary16 files), overriding valueQuantum; or empty
    MapAccuracy accuracy;        // what its producer declares (depth_map_reading.h)
    double scale = 0, offset = 0;  // how stored values became `value`: stored / scale + offset (scale 0: 1)

    // A map of `quantity` as a file was read `reading`'s way, with what the reading declares.
    static DepthMap of(DepthMapFile file, DepthQuantity quantity, const DepthMapReading& reading);
    // A map of values exact to their binary32 spacing, nothing declared (tests, arrays).
    static DepthMap exact(int width, int height, DepthQuantity quantity, std::vector<double> values)
    {
        DepthMap map;
        map.width = width, map.height = height, map.quantity = quantity, map.value = std::move(values);
        return map;
    }
    // A value as the file stored it (before scale and offset).
    double storedOf(double v) const { return (v - offset) * (scale > 0 ? scale : 1.0); }
    // Value i's: its step (its own, the file's, at least the declared quantum) and the declared accuracy.
    ValueAccuracy accuracyAt(std::size_t i) const
    {
        const double own = valueStep.empty() ? valueQuantum : double(valueStep[i]);
        return {std::max(own, accuracy.quantum), accuracy.relative, accuracy.absolute};
    }
};

struct VerifyResult {
    RenderResult truth;       // the ray route
    RenderResult map;         // the map as a render result (see verify.h for the surface it saw)
    Comparison comparison;
    CheckReport report;
    std::vector<float> mapError;  // Checker::verify: per pixel map − truth in report.mapErrors' units,
                                  // NaN where not compared on depth; empty otherwise
};

// A parameter a diagnosis measured: "fovy_deg", "sample_dx_px", "near", "value_scale", ...
struct FittedValue {
    std::string name;
    double value = 0;      // fitted
    double declared = 0;   // what the camera file or the reading says
};

// One hypothesis of the diagnosis: a mistake of the catalogue (mistakes.h), perhaps one of
// several variants of it, under which the map was re-read or the truth re-rendered.
struct Hypothesis {
    std::string name;         // the mistake's name, e.g. "distance-as-eye-z", "half-pixel"
    std::string variant;      // which variant, e.g. "x and y"; empty when there is one
    std::string explanation;  // "consistent if read as ray distance instead of eye-z"
    bool consistent = false;
    std::int64_t unexplained = 0;
    bool estimated = false;   // `unexplained` estimated from a sample that already ruled the
                              // hypothesis out (verify.h, screenUnexplained)
    std::vector<FittedValue> fitted;  // a fitted hypothesis's values (fit.h); empty for the catalogue's
    // Of the unexplained pixels, those at edges of the truth (a 3×3 neighbourhood that is not
    // one plane), and of those the ones whose depth lies between the truth's around them.
    std::int64_t unexplainedAtEdges = 0, blendsAtEdges = 0;
    std::int64_t compared = 0;  // pixels where either side sees a surface (full comparisons only)
    // Not consistent, but only at edges: every unexplained pixel at an edge, and at most 10 % of
    // the compared ones (a silhouette-rich 200×150 view has 4 % at its edges): "consistent
    // except N edge pixels".
    bool consistentExceptEdges() const;
};

class VertexNeighbours;

// Refuses a comparison with nothing in it (throws Error naming `scene`): a camera that sees
// no geometry proves nothing, and must not be reported CONSISTENT. check/verify front-ends
// call it on the report before they print a verdict.
void requireSomethingCompared(const ComparisonReport& report, const std::string& scene);

class Checker {
public:
    // Validates the scene (throws Error: no triangles, an index out of range) and builds both
    // routes: Embree's BVH (timed, Timings::bvhBuildMs) and the rasterizer.
    explicit Checker(Scene scene);
    ~Checker();
    Checker(const Checker&) = delete;
    Checker& operator=(const Checker&) = delete;

    const Scene& scene() const { return scene_; }
    double bvhBuildMilliseconds() const { return rays_.buildMilliseconds(); }

    // Both routes through `camera`, compared.
    CheckResult check(const Camera& camera, const CheckOptions& options = {}) const;

    // One route's render: window depth and primitive per pixel (row 0 at the top).
    RenderResult renderRay(const Camera& camera, const RayFaults& faults = {}, EyePoints eyePoints = EyePoints::Omit) const;
    RenderResult renderRaster(const Camera& camera, const RasterFaults& faults = {}) const;
    RenderResult render(const Camera& camera, Route route, const RouteFaults& faults = {}) const;
    // One route's render as an exported quantity (quantity.h): depth in any of the four
    // quantities, positions, normals or primitive ids.
    QuantityImage render(const Camera& camera, ExportQuantity quantity, Route route) const;

    // A depth map rendered elsewhere against the ray route's ground truth, with the same
    // tolerance model; `map` must be camera.width() × camera.height() (throws Error otherwise).
    VerifyResult verify(const Camera& camera, const DepthMap& map) const;
    // Every hypothesis of the mistake catalogue that has a meaning for this camera and map,
    // then every fitted family (fit.h), each confirmed by a full comparison; ranked: the
    // consistent ones first, then by unexplained pixels, ties in that order.
    std::vector<Hypothesis> diagnose(const Camera& camera, const DepthMap& map) const;

    // Triangles around each vertex position, built on first use (verify's surface search).
    const VertexNeighbours& neighbours() const;

private:
    CheckResult checkTileByTile(const Camera& camera, const CheckOptions& options) const;

    Scene scene_;
    RayRenderer rays_;
    RasterRenderer raster_;
    mutable std::once_flag neighboursOnce_;
    mutable std::shared_ptr<const VertexNeighbours> neighbours_;  // built in zcheck::diagnose (verify.cpp)
};

}  // namespace zcheck
