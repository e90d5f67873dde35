#pragma once
// The steps of verifying a map and the estimators of its diagnosis, private to zcheck::diagnose
// (verify.cpp defines them; not installed: verify.h and map_verifier.h are the public contract).
//
// Spaces and units: a pixel (col, row) is row-major, camera.width() to a row, and read at its
// centre (windowFromPixelCentre); "window depth" is z in window space (windowFromEye); a map's
// "value" is in its own quantity and units (DepthQuantity: window, NDC z, eye-z or distance in
// scene units). A `map` read by pixel fits the camera (requireMapFits, which verifyAgainst calls
// itself); a `truth` is the ray route's render through the same camera (Checker::renderRay).
//
// What is here: one pixel's value carried into window units (mapPixelDepth) and the whole map
// read as the raster side of a comparison (renderResultFromMap); the refusals of a map that
// cannot be compared (requireMapFits, requireDepthsInRange); the cheap estimates that rule a
// hypothesis out before its truth is rendered (probeAgreement) or sort its failures
// (onePlaneAround, tallyEdges); the judgement of a map's declarations as a whole
// (judgeDeclaredAccuracy); the map's errors in its own units (measureMapErrors); and the
// comparison every verification and every reading of a diagnosis runs (verifyAgainst).
// and the sampled screen that rules a hypothesis out before its full comparison
// (screenUnexplained). White-box tests include this header through their own include path.
#include "zcheck/hypothesis.h"
#include "zcheck/verify.h"

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

// The eye-z step of a standard binary32 depth buffer (near → 0, far → 1, not reversed) of the
// camera's near and far planes at `eyeZ`: the precision of an eye-z or distance map linearized
// from a renderer's depth buffer, which such a map is allowed besides its own storage step —
// the same whatever the camera's depth format, range and reversal, which no linear map depends on.
double linearizedBufferStep(const Camera& camera, double eyeZ);

// The pixel's window depth, storage step and allowance as the comparison reads them (its
// surface left kNoPrimitive); `truthDepth` is the truth's window depth there, the reference for
// a miss. The value's step and declared accuracy are carried into window units through the
// quantity's mapping at the pixel: the larger window change of value ± step, and of value ±
// ValueAccuracy::declaredAt(value). A window map's step is the camera's depth format's unless
// the file states one (then at least binary32's spacing at the window depth); an eye-z or
// distance map's is at least linearizedBufferStep.
MapPixel mapPixelDepth(const Camera& camera, const DepthMap& map, int col, int row, double truthDepth);
// The same for one value of `quantity` judged by `accuracy` (a step of 0: binary32, or for a
// window map the camera's depth format).
MapPixel mapPixelDepth(const Camera& camera, DepthQuantity quantity, double value, const ValueAccuracy& accuracy, int col,
                       int row, double truthDepth);

// The truth's value in `quantity` at pixel (col, row), where the truth hits: its window depth
// taken back to eye-z on the ray through the pixel centre (eyeZFromWindowDepth), then to
// `quantity` (depthValueFromEyeZ) — what a map of that quantity should hold there, in its units.
// `truth` is camera.width() pixels wide.
double truthValueAt(const Camera& camera, const RenderResult& truth, int col, int row, DepthQuantity quantity);

// The map as the raster side of a comparison (window depth per pixel, a hit where the value is
// not a miss, the surface chosen as verify.h states). `quantum` and `allowance` receive each pixel's
// storage step and declared accuracy in window units (allowance left empty where the map
// declares none), for the comparison's DeclaredMap. `judge` as MapReader's; the comparison of
// the result may then use it too (compareRoutes), finding the slopes it computed.
RenderResult renderResultFromMap(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                                 const VertexNeighbours& neighbours, std::vector<double>& quantum,
                                 std::vector<double>& allowance);

// A map made through a lens model (camera.lens()) against the ray route, compared as distances
// along the pixels' rays (verify_lens.cpp has the rule); MapVerifier::verify's for such cameras.
VerifyResult verifyLensMap(const Checker& checker, const Camera& camera, const DepthMap& map);

// verifyLensMap's rule on the pixels of a grid, one every `stride` columns and rows (the
// centre of each stride × stride block): how many it judged, compared (either side sees a
// surface) and found unexplained. The diagnosis rules hypotheses out on it before verifying
// the rest in full.
struct LensSample {
    std::int64_t judged = 0, compared = 0, unexplained = 0;
};
LensSample judgeLensMapOnGrid(const Checker& checker, const Camera& camera, const DepthMap& map, int stride);

// The mistakes of the lens family for a map judged through a lens camera, ranked (the consistent
// first); MapVerifier::diagnose's for such cameras (diagnose_lens.cpp lists them).
class MapVerifier;
std::vector<Hypothesis> diagnoseLensMap(const MapVerifier& verifier, const Camera& camera, const DepthMap& map);
// k1, k2 of a radial lens fitted to an eye-z or distance map — the declared lens's own, or OpenCV's
// around a pinhole's K (a lens the camera left out) — and verified in full; none when the fit
// finds nothing (or the camera is neither).
std::optional<Hypothesis> fitRadialDistortion(const MapVerifier& verifier, const Camera& camera, const DepthMap& map);

// Throws Error unless `map` is camera.width() × camera.height() with a value per pixel.
void requireMapFits(const Camera& camera, const DepthMap& map);
// The map's values its quantity cannot hold (kindOfDepthValue), counted into `report`
// (outOfRange, the first one and its stored value); verifyAgainst does it for every reading.
void countOutOfRange(const Camera& camera, const DepthMap& map, ComparisonReport& report);
// Refuses (Error beginning with `name`) a map whose values are all misses or out of range with
// at least one out of range: it holds nothing of its quantity (a wrong --quantity, mostly).
void requireDepthsInRange(const Camera& camera, const DepthMap& map, const std::string& name);

// How near a hypothesis comes, before a truth is rendered for it: at a 16×16 grid of pixel
// centres, one ray each (RayRenderer::primitiveAt), whether `map`, read through `camera`,
// agrees with the surface the ray meets by the comparison's rule (PixelJudge); where the grid
// meets a surface at fewer than 16 pixels (a small object), also at up to 256 of the pixels
// where the map holds a surface. `agreeing`: the share of the probed pixels where the map or
// the truth sees a surface at which they agree (0 where none does); `seen`: the share of the
// image they stand for. A consistent reading fails only at edges and where the map shows a
// neighbouring surface, which a coarse grid seldom meets: an `agreeing` under 3/4 rules it out.
struct Probe {
    double agreeing = 0, seen = 0;
    bool rulesOut() const { return agreeing < 0.75; }
    // The unexplained pixels of `pixels` the probe's share stands for.
    std::int64_t unexplainedOf(double pixels) const { return std::llround((1 - agreeing) * seen * pixels); }
};
Probe probeAgreement(const Scene& scene, const RayRenderer& rays, const Camera& camera, const DepthMap& map);

// Whether the truth around pixel (col, row) is one smooth surface: its 3×3 neighbourhood
// (clamped at the image's border) all hit or all miss, and, where hit, window depth nearly
// affine in x and y (a plane's is): second differences across the pixel in x, y and both
// diagonals within a tenth of the rise plus 1e-12. False at silhouettes and occlusion edges
// (there the second difference is as large as the rise) and at sharp creases; true on a
// finely tessellated curved surface, whose gentle creases bend depth far less.
bool onePlaneAround(const RenderResult& truth, int width, int height, int col, int row);
// Whether the truth hits at pixel (col, row) and all round it (its 3×3 neighbourhood, clamped
// at the image's border): inside a surface's silhouette, whatever its shape.
bool hitAllAround(const RenderResult& truth, int width, int height, int col, int row);

// Of a comparison's unexplained pixels, those at edges of the truth (a 3×3 neighbourhood that
// is not one plane, or a coverage change), and of those the ones whose map depth lies between
// the truth's depths around them (the clear value standing for a miss): a blend of the
// surfaces either side, as anti-aliased or resolved multisample depth holds.
struct EdgeTally {
    std::int64_t atEdges = 0, blends = 0;
};
EdgeTally tallyEdges(const Camera& camera, const RenderResult& truth, const RenderResult& map, const Comparison& comparison);

// A map's declarations (MapAccuracy) judged as a whole, over the pixels a
// comparison compared on depth (Agree, DepthError), in the map's own units (`mapRender`: the
// map as renderResultFromMap read it, the surface each pixel saw): what no pixel's
// tolerance can see. Sets report.declaredAccuracyRefused, which makes the map inconsistent:
//   holes   where holes are allowed, they are at most half the pixels where the truth sees a surface;
//   coarse  the declared accuracy at the median pixel is under a tenth of its depth (in eye-z):
//           a grid or tolerance as coarse as the depths accepts any map of the right order;
//   grid    a declared quantum Q is the grid the values were rounded to: ≥ 99 % of them (less
//           the offset) lie within 1/1000 of Q (or four binary32 spacings) of a multiple of Q;
//   few     32 or more pixels show the truth's own surface: fewer cannot tell noise from a scale;
//   bias    rounding and noise are unbiased: over the pixels where the map shows the truth's own
//           surface, |mean(map − truth)| — the truth rounded to the declared grid,
//           if any, so that a rounding's own error is no bias — is within the median of C·q + S·m
//           + E (the tolerance of a map declaring nothing) plus six times the mean's sampling
//           error (the spread of the means of 16 interleaved samples, over 4). A declared
//           tolerance or noise absorbs no bias: a map 4·10⁻⁴ short everywhere is a scale mistake
//           whatever --rel-tolerance says, and one a centimetre far is an offset under any grid.
// A map declaring no accuracy is left as it is: its per-pixel tolerance bounds its median.
void judgeDeclaredAccuracy(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                           const RenderResult& mapRender, const std::vector<double>& quantum, Comparison& comparison);

// One pixel those rules weigh, in the map's units: a pixel compared on depth (Agree,
// DepthError) where the map shows the truth's own surface and holds a depth of its quantity.
struct DeclaredPixel {
    double error;          // map − truth (the truth rounded to the declared grid, if any)
    double intrinsic;      // C·q + S·m + E, the tolerance of a map declaring nothing
    double declared;       // ValueAccuracy::declaredAt
    double relativeEyeZ;   // the declared accuracy as a fraction of the pixel's eye-z
    bool onGrid;           // within 1/1000 of Q (or four binary32 spacings) of a multiple of Q
    int col, row;
    double value;          // the map's
};
// Whether `value` (less `offset`) lies on the declared grid Q's multiples, as DeclaredPixel::onGrid says (Q > 0).
bool onDeclaredGrid(double value, double Q, double offset);
// The rules above over `all` (in scan order) and the report's holes: why the map's declarations
// cannot stand, or "" (also when it declares nothing). The one judgement of declared accuracies,
// for a linear camera's map (judgeDeclaredAccuracy) and a lens camera's (verifyLensMap).
std::string declaredAccuracyRefusal(const DepthMap& map, const ComparisonReport& report, const std::vector<DeclaredPixel>& all);

// The map's errors in its own units (report.mapErrors, mapError per pixel), from a comparison
// of it: MapVerifier::verify's last step (a diagnosis's readings skip it).
void measureMapErrors(const Camera& camera, const DepthMap& map, VerifyResult& run);

// The comparison of `map` against an already rendered ground truth `truth` (one BVH, one
// truth render, many readings of the map).
VerifyResult verifyAgainst(const Scene& scene, const Camera& camera, const DepthMap& map, RenderResult truth,
                           const VertexNeighbours& neighbours);

// Whether `map` certainly cannot be consistent with `truth`, judged on a sample: the pixels
// that do not simply agree with the truth's own surface are looked for on every fourth row
// and column, and an evenly spaced sample of at most 1024 of them is read and classified
// exactly as the full comparison would, in blocks, until 64 unexplained ones are found. An
// unexplained pixel proves the map inconsistent (a consistent map has none anywhere); the
// value returned then estimates how many pixels are unexplained, from the sample's share.
// std::nullopt: every sampled pixel is explained, or there are too few suspects to bother;
// only the full comparison can tell.
std::optional<std::int64_t> screenUnexplained(const Scene& scene, const Camera& camera, const DepthMap& map,
                                              const RenderResult& truth, const VertexNeighbours& neighbours);

}  // namespace zcheck
