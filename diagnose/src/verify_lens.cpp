// Verifying a map made through a lens model (lens.h): there is no depth buffer and no raster
// route, so the map is compared with the ray route as distances along the pixels' rays.
//
// Per pixel, with d the distance along the pixel centre's ray (an eye-z map's value divided by
// the ray's cosine to the axis, cos θ):
//   both hit     |d_map − d_ray| ≤ C·q + S·m + E + a: q the map's storage step at its value (its
//                file's, or binary32's; for eye-z, divided by cos θ), C = 1 for integer storage
//                and 4 for floating point (mapTolerance), m = |∂d/∂x| + |∂d/∂y| on the truth's
//                plane (the rays through the centre ± ½ px; a map sampled up to S off the centre
//                in both axes), S = 2^-8, E = 16·2^-52·d, a the accuracy the map declares at its
//                value (ValueAccuracy::declaredAt: grid, absolute, relative, 6σ of noise; for eye-z
//                divided by cos θ). Beyond it, a surface a ray within S of the centre meets (8 rays
//                around it) whose tolerance holds d_map explains it (an edge); otherwise a depth
//                error.
//   one hits     explained when the coverage changes within S of the centre: the truth alone —
//                one of the 8 rays misses; the map alone — one of them meets a surface whose
//                tolerance holds d_map. Holes the map declares (--allow-holes) are holes.
//   outside      the lens's field: no ray, so no truth; a map depth there is unexplained.
// Window and NDC maps cannot come from a lens (no depth buffer); eye-z does not exist 90° or
// more off the axis, so an eye-z value there is out of range. Declared accuracies are judged as
// a whole too, by the rules a linear camera's map meets (declaredAccuracyRefusal: holes, coarse,
// grid, bias), over the pixels compared on depth, in the map's units.
#include "verify_estimators.h"

#include "numerics.h"
#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <mutex>

namespace zcheck {

namespace {

constexpr double kSnap = 1.0 / 256;  // S: a map sampled up to 2^-8 px off the centre

// The distance along a unit world ray from `origin` to a triangle's plane (NaN if parallel).
double planeDistance(const Scene& scene, std::uint32_t primitive, const glm::dvec3& origin, const glm::dvec3& direction)
{
    const Scene::Plane plane = scene.worldPlane(primitive);
    const double s = glm::dot(plane.normal, plane.point - origin) / glm::dot(plane.normal, direction);
    return std::isfinite(s) ? s : NAN;
}

struct LensPixel {
    PixelClass pixelClass = PixelClass::BothMiss;
    double truth = NAN, map = NAN;  // distances
    double quantum = 0;  // the map's storage step there, as a distance
    double declared = 0;   // the accuracy the map declares there, as a distance (a)
    double intrinsic = 0;  // the tolerance less it (C·q + S·m + E), where both hit
    double errorQuanta = 0, tolerance = 0, errorOverTolerance = 0;
    std::uint32_t primitive = kNoPrimitive;  // the surface the map is taken to show
    bool outOfRange = false;
};

class LensPixelJudge {
public:
    LensPixelJudge(const Checker& checker, const Camera& camera, const DepthMap& map, const RenderResult& truth)
        : scene_(checker.scene()), rays_(checker.rayRenderer()), camera_(camera), map_(map), truth_(truth),
          eye_(camera.worldFromEye[3]), constant_(mapTolerance(map).storageConstant)
    {
    }

    LensPixel judge(int col, int row) const
    {
        LensPixel out;
        const std::size_t i = std::size_t(row) * camera_.width() + col;
        const glm::dvec2 pWindow = windowFromPixelCentre(camera_, col, row);
        const std::optional<glm::dvec3> dEye = eyeDirectionThroughWindow(camera_, pWindow);
        const double value = map_.value[i];
        const DepthValueKind kind = kindOfDepthValue(camera_, map_.quantity, value);
        out.outOfRange = kind == DepthValueKind::OutOfRange;
        const bool mapHasDepth = kind == DepthValueKind::Depth;
        if (!dEye) {  // outside the lens's field: no truth; a depth there is the map's invention
            out.pixelClass = mapHasDepth ? PixelClass::RasterOnly : PixelClass::BothMiss;
            out.map = mapHasDepth ? value : NAN;
            return out;
        }
        const double cosine = camera_.eyeZOf(*dEye);
        const bool eyeZ = map_.quantity == DepthQuantity::EyeZ;
        const bool mapHit = mapHasDepth && (!eyeZ || cosine > 0);
        if (mapHasDepth && !mapHit) out.outOfRange = true;  // eye-z 90° or more off the axis
        const double perValue = eyeZ ? 1 / cosine : 1.0;  // distance per unit of the map's value
        const ValueAccuracy accuracy = map_.accuracyAt(i);
        const double step = accuracy.step > 0 ? accuracy.step : storageQuantum(DepthFormat::Float32, value);
        out.map = mapHit ? value * perValue : NAN;
        const bool truthHit = truth_.hit(i);
        out.truth = truthHit ? truth_.windowDepth.value[i] : NAN;
        const glm::dvec3 direction(camera_.worldFromEye * glm::dvec4(*dEye, 0.0));
        const double quantum = step * perValue, declared = mapHit ? accuracy.declaredAt(value) * perValue : 0.0;
        out.quantum = quantum, out.declared = declared;
        if (truthHit && mapHit) {
            const std::uint32_t primitive = truth_.primitiveId[i];
            const double error = out.map - out.truth;
            // The slope's share only where the storage's and the declaration's alone do not hold
            // the error (4 rays).
            const double storage = constant_ * quantum + 16 * 0x1p-52 * out.truth;
            out.tolerance = std::abs(error) <= storage + declared ? storage + declared
                                                                  : toleranceOn(primitive, pWindow, quantum, out.truth, declared);
            out.intrinsic = out.tolerance - declared;
            out.errorQuanta = inQuanta(std::abs(error), quantum);
            out.errorOverTolerance = std::abs(error) / out.tolerance;
            out.primitive = primitive;
            if (std::abs(error) <= out.tolerance) {
                out.pixelClass = PixelClass::Agree;
            } else if (otherSurfaceHolds(pWindow, direction, primitive, out.map, quantum, declared)) {
                out.pixelClass = PixelClass::EdgeSurface;
            } else {
                out.pixelClass = PixelClass::DepthError;
            }
        } else if (truthHit) {
            const bool edge = anyRayAround(pWindow, [](std::uint32_t seen) { return seen == kNoPrimitive; });
            out.pixelClass = edge ? PixelClass::RayOnlyEdge : map_.accuracy.allowHoles ? PixelClass::Hole : PixelClass::RayOnly;
        } else if (mapHit) {
            const bool edge = otherSurfaceHolds(pWindow, direction, kNoPrimitive, out.map, quantum, declared);
            out.pixelClass = edge ? PixelClass::RasterOnlyEdge : PixelClass::RasterOnly;
        }
        return out;
    }

private:
    // C·q + S·m + E + a on `primitive`'s plane at the pixel centre pWindow.
    double toleranceOn(std::uint32_t primitive, const glm::dvec2& pWindow, double quantum, double distance,
                       double declared) const
    {
        double slope = 0;
        for (const glm::dvec2 axis : {glm::dvec2(0.5, 0), glm::dvec2(0, 0.5)}) {
            const std::optional<glm::dvec3> before = worldDirection(pWindow - axis), after = worldDirection(pWindow + axis);
            if (!before || !after) return INFINITY;  // at the field's edge: the slope cannot be bounded
            slope += std::abs(planeDistance(scene_, primitive, eye_, *after) - planeDistance(scene_, primitive, eye_, *before));
        }
        if (!std::isfinite(slope)) slope = INFINITY;
        return constant_ * quantum + kSnap * slope + 16 * 0x1p-52 * distance + declared;
    }

    std::optional<glm::dvec3> worldDirection(const glm::dvec2& pWindow) const
    {
        const std::optional<glm::dvec3> dEye = eyeDirectionThroughWindow(camera_, pWindow);
        if (!dEye) return std::nullopt;
        return glm::dvec3(camera_.worldFromEye * glm::dvec4(*dEye, 0.0));
    }

    // The 8 rays S around the centre (those inside the field): whether `test` holds for one.
    template <class Test>
    bool anyRayAround(const glm::dvec2& pWindow, Test&& test) const
    {
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (dx == 0 && dy == 0) continue;
                const glm::dvec2 p = pWindow + kSnap * glm::dvec2(dx, dy);
                if (!eyeDirectionThroughWindow(camera_, p)) continue;
                if (test(rays_.primitiveAt(camera_, p))) return true;
            }
        return false;
    }

    // Whether a surface other than `except` that a ray within S of the centre meets holds the
    // map's distance within its tolerance, measured along the centre's ray.
    bool otherSurfaceHolds(const glm::dvec2& pWindow, const glm::dvec3& direction, std::uint32_t except, double mapDistance,
                           double quantum, double declared) const
    {
        return anyRayAround(pWindow, [&](std::uint32_t seen) {
            if (seen == kNoPrimitive || seen == except) return false;
            const double there = planeDistance(scene_, seen, eye_, direction);
            return std::isfinite(there) && std::abs(mapDistance - there) <= toleranceOn(seen, pWindow, quantum, there, declared);
        });
    }

    const Scene& scene_;
    const RayRenderer& rays_;
    const Camera& camera_;
    const DepthMap& map_;
    const RenderResult& truth_;
    glm::dvec3 eye_;
    double constant_;
};

// A pixel as the report shows it: the truth as the ray, the map as the second route (distances).
PixelFinding finding(const LensPixel& p, int col, int row)
{
    return {col, row, p.pixelClass, p.truth, p.map, p.errorQuanta, p.quantum > 0 ? inQuanta(p.tolerance, p.quantum) : 0,
            p.pixelClass == PixelClass::RasterOnly || p.pixelClass == PixelClass::RasterOnlyEdge ? kNoPrimitive : p.primitive,
            p.primitive};
}

}  // namespace

LensSample judgeLensMapOnGrid(const Checker& checker, const Camera& camera, const DepthMap& map, int stride)
{
    requireMapFits(camera, map);
    const RenderResult truth = checker.renderRay(camera);
    const LensPixelJudge judge(checker, camera, map, truth);
    const int W = camera.width(), H = camera.height();
    const int rows = (H + stride - 1) / stride;
    std::vector<LensSample> perRow(static_cast<std::size_t>(rows));
    tbb::parallel_for(0, rows, [&](int r) {
        for (int col = stride / 2; col < W; col += stride) {
            const PixelClass c = judge.judge(col, std::min(H - 1, r * stride + stride / 2)).pixelClass;
            perRow[std::size_t(r)].judged += 1;
            perRow[std::size_t(r)].compared += c != PixelClass::BothMiss;
            perRow[std::size_t(r)].unexplained += isUnexplained(c);
        }
    });
    LensSample out;
    for (const LensSample& r : perRow) out.judged += r.judged, out.compared += r.compared, out.unexplained += r.unexplained;
    return out;
}

VerifyResult verifyLensMap(const Checker& checker, const Camera& camera, const DepthMap& map)
{
    requireMapFits(camera, map);
    const int W = camera.width(), H = camera.height();
    VerifyResult run;
    run.truth = checker.renderRay(camera);
    const auto start = Clock::now();
    const LensPixelJudge judge(checker, camera, map, run.truth);
    std::vector<LensPixel> pixels(std::size_t(W) * H);
    tbb::parallel_for(0, H, [&](int row) {
        for (int col = 0; col < W; ++col) pixels[std::size_t(row) * W + col] = judge.judge(col, row);
    });

    // The report, in scan order.
    Comparison& comparison = run.comparison;
    ComparisonReport& c = comparison.report;
    c.width = W, c.height = H;
    comparison.pixelClass.resize(pixels.size());
    comparison.errorOverTolerance.assign(pixels.size(), 0.0f);
    run.map = RenderResult::cleared(W, H, camera.clearDepth());
    run.mapError.assign(pixels.size(), NAN);
    std::vector<double> quanta, relative, absolute, relativeToTruth;
    MapErrors& e = run.report.mapErrors;
    e.quantity = toString(map.quantity);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const LensPixel& p = pixels[i];
        const int col = int(i % W), row = int(i / W);
        comparison.pixelClass[i] = p.pixelClass;
        comparison.errorOverTolerance[i] = float(p.errorOverTolerance);
        if (std::isfinite(p.map)) run.map.windowDepth.value[i] = p.map, run.map.primitiveId[i] = p.primitive == kNoPrimitive ? kUnknownPrimitive : p.primitive;
        if (p.outOfRange && c.outOfRange++ == 0)
            c.outOfRangeCol = col, c.outOfRangeRow = row, c.outOfRangeValue = map.storedOf(map.value[i]);
        switch (p.pixelClass) {
        case PixelClass::BothMiss: ++c.bothMiss; break;
        case PixelClass::Agree: ++c.bothHit, ++c.agree; break;
        case PixelClass::EdgeSurface: ++c.bothHit, ++c.edgeSurface; break;
        case PixelClass::DepthError: ++c.bothHit, ++c.depthErrors; break;
        case PixelClass::RayOnlyEdge: ++c.rayOnly, ++c.coverageExplained; break;
        case PixelClass::Hole: ++c.rayOnly, ++c.coverageExplained, ++c.holes; break;
        case PixelClass::RayOnly: ++c.rayOnly, ++c.coverageUnexplained; break;
        case PixelClass::RasterOnlyEdge: ++c.rasterOnly, ++c.coverageExplained; break;
        case PixelClass::RasterOnly: ++c.rasterOnly, ++c.coverageUnexplained; break;
        default: break;
        }
        if (isUnexplained(p.pixelClass)) {
            if (c.unexplainedSamples.size() < 20)
                c.unexplainedSamples.push_back(finding(p, col, row));
            if (c.unexplainedMaxCol < 0) c.unexplainedMinCol = col, c.unexplainedMinRow = row;
            c.unexplainedMinCol = std::min(c.unexplainedMinCol, col), c.unexplainedMaxCol = std::max(c.unexplainedMaxCol, col);
            c.unexplainedMinRow = std::min(c.unexplainedMinRow, row), c.unexplainedMaxRow = std::max(c.unexplainedMaxRow, row);
        }
        if (p.pixelClass != PixelClass::Agree && p.pixelClass != PixelClass::DepthError) continue;
        quanta.push_back(p.errorQuanta);
        relative.push_back(std::abs(p.map - p.truth) / p.truth);
        if (p.errorOverTolerance >= c.maxErrorOverTolerance) c.maxErrorOverTolerance = p.errorOverTolerance, c.worst = finding(p, col, row);
        // The map's error in its own units: distance, or eye-z (the truth's distance times cos θ).
        const double perValue = map.value[i] > 0 ? p.map / map.value[i] : 1.0;
        const double truthValue = p.truth / perValue, error = map.value[i] - truthValue;
        run.mapError[i] = float(error);
        absolute.push_back(std::abs(error));
        relativeToTruth.push_back(std::abs(error / truthValue));
        if (std::abs(error) > e.maxAbs || e.worstCol < 0)
            e.maxAbs = std::abs(error), e.worstCol = col, e.worstRow = row, e.worstMap = map.value[i], e.worstTrue = truthValue;
    }
    c.maxErrorQuanta = quanta.empty() ? 0 : *std::max_element(quanta.begin(), quanta.end());
    c.p99ErrorQuanta = quantileOf(quanta, 0.99);
    c.maxRelativeEyeZError = relative.empty() ? 0 : *std::max_element(relative.begin(), relative.end());
    c.p99RelativeEyeZError = quantileOf(relative, 0.99);
    e.compared = std::int64_t(absolute.size());
    e.p99Abs = quantileOf(absolute, 0.99), e.medianAbs = quantileOf(absolute, 0.5);
    e.p99Rel = quantileOf(relativeToTruth, 0.99), e.medianRel = quantileOf(relativeToTruth, 0.5);
    e.maxRel = relativeToTruth.empty() ? 0 : *std::max_element(relativeToTruth.begin(), relativeToTruth.end());
    // The declarations as a whole, over the pixels compared on depth, in the map's units.
    std::vector<DeclaredPixel> declared;
    const double Q = map.accuracy.quantum;
    for (std::size_t i = 0; map.accuracy.anyAccuracy() && i < pixels.size(); ++i) {
        const LensPixel& p = pixels[i];
        if (p.pixelClass != PixelClass::Agree && p.pixelClass != PixelClass::DepthError) continue;
        const double v = map.value[i], perValue = p.map / v, truthValue = p.truth / perValue;
        // Against the truth as the declared grid rounds it: a rounding's own error is not a bias.
        const double expected = Q > 0 ? std::round((truthValue - map.offset) / Q) * Q + map.offset : truthValue;
        declared.push_back({v - expected, p.intrinsic / perValue, p.declared / perValue,
                            p.declared / p.truth,  // along one ray, eye-z and distance scale alike
                            Q > 0 ? onDeclaredGrid(v, Q, map.offset) : true, int(i % W), int(i / W), v});
    }
    c.declaredAccuracyRefused = declaredAccuracyRefusal(map, c, declared);
    run.report.timings.compareMs = millisecondsSince(start);
    run.report.timings.traceMs = run.truth.renderMilliseconds;
    run.report.timings.bvhBuildMs = checker.bvhBuildMilliseconds();
    run.report.describeInputs(checker.scene(), camera, mapTolerance(map));
    run.report.declared = map.accuracy;
    run.report.secondRoute = "map";
    run.report.outOfRangeRule = toString(map.quantity) + " map of a lens model holds values > 0" +
                                std::string(map.quantity == DepthQuantity::EyeZ ? ", on rays less than 90° off the axis" : "");
    run.report.comparison = c;
    return run;
}

}  // namespace zcheck
