#include "zcheck/fit.h"

#include "numerics.h"
#include "verify_estimators.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/verify.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

namespace zcheck {

namespace {

// The map's value of the eye-space point under `camera`, as `quantity`.
double valueOfEyePoint(const Camera& camera, const glm::dvec3& pEye, DepthQuantity quantity)
{
    switch (quantity) {
    case DepthQuantity::Window: return windowFromEye(camera, pEye).z;
    case DepthQuantity::Ndc: return camera.ndcZFromWindowDepth(windowFromEye(camera, pEye).z);
    case DepthQuantity::EyeZ: return camera.eyeZOf(pEye);
    case DepthQuantity::Distance: return distanceOfEyePoint(camera, pEye);
    }
    return NAN;
}

// The value's change, as `quantity`, for a relative eye-z change at eye depth z (forward
// difference of 1e-6).
double valuePerRelativeEyeZ(const Camera& camera, const glm::dvec2& pWindow, double z, DepthQuantity quantity)
{
    return std::abs(depthValueFromEyeZ(camera, pWindow, z * (1 + 1e-6), quantity) - depthValueFromEyeZ(camera, pWindow, z, quantity)) / 1e-6;
}

bool isMissValue(const Camera& camera, const glm::dvec2&, double value, DepthQuantity quantity)
{
    return kindOfDepthValue(camera, quantity, value) == DepthValueKind::Miss;
}

// One sample pixel: the plane the truth shows there, the map's value and the value's scale.
struct Sample {
    int col, row;
    glm::dvec3 normal;  // world plane normal·x = offset
    double offset;
    double mapValue;
    double sigma;                // value change per relative eye-z change
    std::uint32_t primitive;     // the truth's surface there
    double tolerance = 0;        // the comparison's tolerance there (withTolerances), as a relative eye-z change
};

// The model: where camera c's ray through the sample's pixel centre (moved by `offset`, window
// pixels) meets the sample's plane, in c's eye space.
glm::dvec3 eyePointOnPlane(const Camera& c, const Sample& s, const glm::dvec2& offset = glm::dvec2(0.0))
{
    const EyePlaneRay ray = worldEyePlaneRayThroughWindow(c, windowFromPixelCentre(c, s.col, s.row) + offset);
    const double t = (s.offset - glm::dot(s.normal, ray.origin)) / glm::dot(s.normal, ray.direction);
    return glm::dvec3(c.eyeFromWorld * glm::dvec4(ray.origin + t * ray.direction, 1.0));
}

// A window depth as a line in u(z) (Problem::at, NearFar).
struct WindowLine {
    double a, b;
    static double u(const Camera& camera, double z) { return camera.spec().projection.isPerspective() ? 1 / z : z; }
    // The line through the window depths at the departure's near and far.
    static WindowLine of(const Camera& camera, const Departure& d)
    {
        const double n = d.nearDistance > 0 ? d.nearDistance : camera.nearDistance();
        const double f = d.farDistance > 0 ? d.farDistance : camera.farDistance();
        const double b = (camera.windowDepthNear() - camera.windowDepthFar()) / (u(camera, n) - u(camera, f));
        return {camera.windowDepthNear() - b * u(camera, n), b};
    }
    // The eye depth where the line reaches window depth w.
    double depthAt(const Camera& camera, double w) const
    {
        const double uz = (w - a) / b;
        return camera.spec().projection.isPerspective() ? 1 / uz : uz;
    }
    // `d` with the near and far where the line reaches the window's near and far depths; false
    // (d unchanged) where they make no camera.
    bool setNearFar(const Camera& camera, Departure& d) const
    {
        const double n = depthAt(camera, camera.windowDepthNear()), f = depthAt(camera, camera.windowDepthFar());
        if (!(n > 0 && f > n && std::isfinite(f))) return false;
        d.nearDistance = n, d.farDistance = f;
        return true;
    }
};

struct Problem {
    const Camera& camera;
    const DepthMap& map;
    FitFamily family;
    Departure base;       // the round's starting point; parameters are departures from it
    double sceneDepth;    // median eye-z of the samples (pose translations are in its units)
    double valueSpan;     // median |map value| (value offsets are in its units)
    std::vector<Sample> samples;
    bool inTolerances = false;  // what residuals() gives by default (below)

    int parameterCount() const
    {
        switch (family) {
        case FitFamily::SampleOffset: return 2;
        case FitFamily::FieldOfView: return 1;
        case FitFamily::Intrinsics: return 4;
        case FitFamily::NearFar: return 2;
        case FitFamily::DepthScale: return 2;
        case FitFamily::Pose: return 6;
        }
        return 0;
    }

    // The departure at parameters p (dimensionless: pixels, relative scales, radians,
    // fractions of the scene's depth or of the values' size).
    Departure at(const std::vector<double>& p) const
    {
        Departure d = base;
        switch (family) {
        case FitFamily::SampleOffset: d.sampleOffset += glm::dvec2(p[0], p[1]); break;
        case FitFamily::FieldOfView: d.focalScale *= 1 + p[0]; break;
        case FitFamily::Intrinsics:
            d.focalScale *= glm::dvec2(1 + p[0], 1 + p[1]);
            d.principalShift += glm::dvec2(p[2], p[3]);
            break;
        case FitFamily::NearFar: {
            // Window depth is a + b·u(z) in the eye depth z, u(z) = 1/z for a perspective
            // projection and z otherwise, and the map's values are linear in a and b: fitted
            // there, the problem is linear (near and far themselves are badly conditioned:
            // far moves a perspective map's values by n/f of their size). Near and far are
            // where a + b·u(z) reaches the window's near and far depths.
            const WindowLine base = WindowLine::of(camera, d);
            const WindowLine line{base.a + p[0] * (camera.windowDepthFar() - camera.windowDepthNear()), base.b * (1 + p[1])};
            if (!line.setNearFar(camera, d)) d.nearDistance = d.farDistance = -1;  // no camera
            break;
        }
        case FitFamily::DepthScale:
            d.valueScale *= 1 + p[0];
            d.valueOffset += p[1] * valueSpan;
            break;
        case FitFamily::Pose:
            d.eyeShift += glm::dvec3(p[0], p[1], p[2]) * sceneDepth;
            d.eyeTurn += glm::dvec3(p[3], p[4], p[5]);
            break;
        }
        return d;
    }

    // Residuals (predicted − map) / sigma at the departure, relative eye depths; empty where
    // it is no camera. `inTolerances`: each divided by its pixel's tolerance, which is what the
    // fit weighs: a steep surface's value may sit up to its slope credit off (a raster's snapped
    // vertices, a sample off the centre), a face-on one only a few ulps, and a fit that let the
    // steep pixels pull it would leave the face-on ones beyond their tolerance.
    std::vector<double> residuals(const Departure& d) const { return residuals(d, inTolerances); }
    std::vector<double> residuals(const Departure& d, bool inTolerances) const
    {
        if (d.nearDistance < 0) return {};  // Problem::at: no camera
        std::optional<Camera> departed;
        try {
            departed.emplace(departedCameraSpec(camera, d));
        } catch (const Error&) {
            return {};
        }
        const Camera& c = *departed;  // its image moved by the sample offset (departedCameraSpec)
        std::vector<double> r(samples.size());
        tbb::parallel_for(std::size_t(0), samples.size(), [&](std::size_t k) {
            const Sample& s = samples[k];
            const double predicted = d.valueScale * valueOfEyePoint(c, eyePointOnPlane(c, s), map.quantity) + d.valueOffset;
            r[k] = (predicted - s.mapValue) / (s.sigma * std::abs(d.valueScale)) / (inTolerances ? s.tolerance : 1.0);
            if (!std::isfinite(r[k])) r[k] = 1e30;
        });
        return r;
    }
};

// Levenberg–Marquardt (numerics.h) from the problem's base, at most `iterations` steps; returns
// the departure reached. The cost is Cauchy's, refreshed every step, or with `weights` the
// weighted sum of squares. Converged: in tolerances, when no residual moved by a hundredth of
// one (a step size says nothing there: a face-on pixel's tolerance is 1e-7 of its depth);
// otherwise at a millionth of a pixel, of a scale, of the depth. Cauchy's scale is floored at
// binary32's resolution or at a hundredth of a tolerance.
Departure solved(const Problem& problem, const std::vector<double>* weights = nullptr, int iterations = 30)
{
    LevenbergMarquardtOptions options;
    options.iterations = iterations;
    options.scaleFloor = problem.inTolerances ? 1e-2 : 1e-7;
    options.residualChange = problem.inTolerances ? 1e-2 : 0;
    options.weights = weights;
    const std::optional<std::vector<double>> p = levenbergMarquardt(
        problem.parameterCount(), [&](const std::vector<double>& q) { return problem.residuals(problem.at(q)); }, options);
    return p ? problem.at(*p) : problem.base;
}

// The start of the two families whose values are linear in their parameters, found globally
// (leastMedianLine) before the local fit. Near and far: a window or NDC map's values lie on a
// line in u(z) (WindowLine), z the eye depth of each sample's plane, which near and far do not
// move; a local fit from the declared near and far stops short where the map's nearer near
// plane clipped geometry (those pixels show a surface behind, and their residuals grow as the
// fit walks toward the answer). A scale and offset: the map's values on a line in the values
// the declared reading expects, where a unit mistake of 1000 leaves a local fit's start far
// off. Other families, and a line that gives no camera, keep the base.
Departure linearStart(const Problem& problem)
{
    if (problem.family != FitFamily::NearFar && problem.family != FitFamily::DepthScale) return problem.base;
    const Camera& camera = problem.camera;
    const Camera departed(departedCameraSpec(camera, problem.base));
    const bool ndc = problem.map.quantity == DepthQuantity::Ndc;
    const double windowPerValue = ndc ? std::abs(camera.windowFromNdc[2][2]) : 1.0;
    std::vector<LinePoint> points;
    for (const Sample& s : problem.samples) {
        const glm::dvec3 pEye = eyePointOnPlane(departed, s);
        const double z = departed.eyeZOf(pEye);
        if (!(z > 0)) continue;
        if (problem.family == FitFamily::NearFar)
            points.push_back({WindowLine::u(camera, z), ndc ? camera.windowDepthFromNdcZ(s.mapValue) : s.mapValue,
                              s.sigma * windowPerValue});
        else
            points.push_back({valueOfEyePoint(departed, pEye, problem.map.quantity), s.mapValue, s.sigma});
    }
    Departure start = problem.base;
    if (problem.family == FitFamily::DepthScale) {
        const Line line = leastMedianLine(points, {problem.base.valueOffset, problem.base.valueScale});
        if (!(line.b != 0) || !std::isfinite(line.a) || !std::isfinite(line.b)) return problem.base;
        start.valueScale = line.b, start.valueOffset = line.a;
        return start;
    }
    const WindowLine base = WindowLine::of(camera, problem.base);
    const Line line = leastMedianLine(points, {base.a, base.b});
    WindowLine{line.a, line.b}.setNearFar(camera, start);  // the base where the line makes no camera
    return start;
}

// The samples that, read through the departure, the comparison would judge as hits, with
// their tolerance (PixelJudge's, on the truth's surface) as a relative eye-z change.
std::vector<Sample> withTolerances(const Scene& scene, const Camera& declared, const DepthMap& map, const Departure& d,
                                   std::vector<Sample> samples)
{
    const Camera departed(departedCameraSpec(declared, d));
    const PixelJudge judge(scene, departed, mapTolerance(map), SlopeSource::EachCall);  // ~16,000 samples
    tbb::parallel_for(std::size_t(0), samples.size(), [&](std::size_t k) {
        Sample& s = samples[k];
        ValueAccuracy accuracy = map.accuracyAt(std::size_t(s.row) * map.width + s.col);
        // What the map declares at its value, in the departed reading's units.
        accuracy.absolute = (accuracy.declaredAt(s.mapValue) - accuracy.relative * std::abs(s.mapValue)) / std::abs(d.valueScale);
        accuracy.step /= std::abs(d.valueScale), accuracy.grid = 0, accuracy.noise = {};
        const MapPixel pixel = mapPixelDepth(departed, map.quantity, (s.mapValue - d.valueOffset) / d.valueScale, accuracy,
                                             s.col, s.row, NAN);
        const glm::dvec2 pWindow = windowFromPixelCentre(departed, s.col, s.row);
        const double z = eyeZFromWindowDepth(departed, pWindow, pixel.depth);
        const double windowSigma = valuePerRelativeEyeZ(departed, pWindow, z, DepthQuantity::Window);
        s.tolerance = judge.surfaceTolerance(s.primitive, pixel.quantum, pixel.allowance) / windowSigma;
    });
    samples.erase(std::remove_if(samples.begin(), samples.end(),
                                 [](const Sample& s) { return !(s.tolerance > 0) || !std::isfinite(s.tolerance); }),
                  samples.end());
    return samples;
}

// The rounds' fit refined in the comparison's own terms: every residual in its pixel's
// tolerance (Problem::residuals), which the confirmation asks each pixel to stay within, and
// Cauchy's fit again in those units. Then, where most samples are within their tolerance but
// an inlier (≤ 4 tolerances) is beyond 0.9 of its own (a raster's snapped vertices move a
// whole triangle's values the same way, and the robust sum's optimum can leave a patch of
// face-on pixels just beyond their tolerance), the inliers' largest residual is minimised by
// Lawson's iteration: weighted least squares, each weight multiplied by its residual, which
// converges to the minimax fit. Returns the departure with the smallest largest inlier
// residual seen.
Departure polished(const Scene& scene, Problem problem, const Departure& start)
{
    problem.samples = withTolerances(scene, problem.camera, problem.map, start, std::move(problem.samples));
    if (problem.samples.size() < 16) return start;
    problem.inTolerances = true;
    problem.base = start;
    Departure best = solved(problem);
    const std::vector<double> r1 = problem.residuals(best);
    if (r1.empty()) return start;
    std::vector<double> weights(r1.size());
    for (std::size_t k = 0; k < r1.size(); ++k) weights[k] = std::abs(r1[k]) <= 4 ? 1.0 : 0.0;
    double bestLargest = largestOf(r1, weights);
    if (medianAbsolute(r1) > 1) return best;
    problem.base = best;
    for (int iteration = 0; iteration < 12 && bestLargest > 0.9; ++iteration) {
        const Departure d = solved(problem, &weights, 3);  // the weights change anyway
        const std::vector<double> r = problem.residuals(d);
        if (r.empty()) break;
        const double most = largestOf(r, weights);
        if (most < bestLargest) best = d, bestLargest = most;
        double sum = 0;
        for (std::size_t k = 0; k < r.size(); ++k)
            if (weights[k] > 0) sum += weights[k] *= std::max(std::abs(r[k]), 1e-3 * most);
        if (!(sum > 0)) break;
        for (double& w : weights) w /= sum;
        problem.base = d;
    }
    return best;
}

// Which neighbourhoods a sample pixel needs: on one smooth surface (onePlaneAround), for the
// families that move the image, whose samples must see their surface a little way off; or only
// hit all round (no silhouette), for those that change the values alone.
enum class SampleRule { OnePlane, InsideSurface };

// The sample pixels of a truth render: hit, with a map value, and a 3×3 neighbourhood as `rule`
// asks, at most 4096 evenly spaced.
std::vector<Sample> samplesOf(const Scene& scene, const Camera& declared, const Camera& departed,
                              const DepthMap& map, const RenderResult& truth, SampleRule rule = SampleRule::OnePlane)
{
    const int W = declared.width(), H = declared.height();
    const int stride = std::max(1, int(std::sqrt(double(W) * H / 16384.0)));
    std::vector<std::vector<Sample>> ofRow(static_cast<std::size_t>(H));
    tbb::parallel_for(1, H - 1, [&](int row) {
        if (row % stride != 0) return;
        for (int col = 1; col < W - 1; col += stride) {
            const std::size_t i = std::size_t(row) * W + col;
            if (!truth.hit(i)) continue;
            const glm::dvec2 pWindow = windowFromPixelCentre(declared, col, row);
            if (isMissValue(declared, pWindow, map.value[i], map.quantity)) continue;
            const Scene::Plane plane = scene.worldPlane(truth.primitiveId[i]);
            if (rule == SampleRule::OnePlane ? !onePlaneAround(truth, W, H, col, row) : !hitAllAround(truth, W, H, col, row))
                continue;
            const double z = eyeZFromWindowDepth(departed, windowFromPixelCentre(departed, col, row), truth.windowDepth.value[i]);
            const double sigma = valuePerRelativeEyeZ(declared, pWindow, z, map.quantity);
            if (!(sigma > 0) || !std::isfinite(sigma)) continue;
            ofRow[std::size_t(row)].push_back({col, row, plane.normal, glm::dot(plane.normal, plane.point), map.value[i], sigma,
                                               truth.primitiveId[i]});
        }
    });
    std::vector<Sample> all;
    for (auto& row : ofRow) all.insert(all.end(), row.begin(), row.end());
    constexpr std::size_t kMost = 4096;
    if (all.size() <= kMost) return all;
    std::vector<Sample> kept;
    kept.reserve(kMost);
    for (std::size_t k = 0; k < kMost; ++k) kept.push_back(all[k * all.size() / kMost]);
    return kept;
}

}  // namespace

std::string toString(FitFamily family)
{
    switch (family) {
    case FitFamily::SampleOffset: return "sample-offset";
    case FitFamily::FieldOfView: return "field-of-view";
    case FitFamily::Intrinsics: return "intrinsics";
    case FitFamily::NearFar: return "near-far";
    case FitFamily::DepthScale: return "depth-scale";
    case FitFamily::Pose: return "pose";
    }
    return "?";
}

std::vector<FitFamily> fitFamilies(const Camera& camera, const DepthMap& map)
{
    // Fewest parameters first: the diagnosis ranks equally good fits in this order.
    std::vector<FitFamily> out = {FitFamily::FieldOfView, FitFamily::SampleOffset};
    const bool windowLike = map.quantity == DepthQuantity::Window || map.quantity == DepthQuantity::Ndc;
    if (windowLike && !isRawMatrix(camera) && !camera.farIsInfinite()) out.push_back(FitFamily::NearFar);
    out.push_back(FitFamily::DepthScale);
    out.push_back(FitFamily::Intrinsics);
    out.push_back(FitFamily::Pose);
    return out;
}

double medianResidual(const Scene& scene, const Camera& camera, const DepthMap& map, const RenderResult& truth)
{
    const Problem problem{camera, map, FitFamily::DepthScale, {}, 1, 1, samplesOf(scene, camera, camera, map, truth)};
    if (problem.samples.size() < 16) return INFINITY;
    return medianAbsolute(problem.residuals({}, false));
}

glm::dvec2 wholeImageShift(const Camera& camera, const DepthMap& map, const RenderResult& truth)
{
    const int W = camera.width(), H = camera.height();
    // Each pixel's depth as a number both sides share: the distance for a distance map, else
    // eye-z (window and NDC values turned into it); NaN where nothing is seen.
    const bool distance = map.quantity == DepthQuantity::Distance;
    std::vector<double> mine(std::size_t(W) * H, NAN), theirs(std::size_t(W) * H, NAN);
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            if (truth.hit(i)) {
                const double z = eyeZFromWindowDepth(camera, pWindow, truth.windowDepth.value[i]);
                theirs[i] = distance ? distanceFromEyeZ(camera, pWindow, z) : z;
            }
            if (const auto p = eyePointFromDepth(camera, pWindow, map.value[i], map.quantity))
                mine[i] = distance ? map.value[i] : camera.eyeZOf(*p);
        }
    // A grid of about 4096 sample pixels. A sample agrees under a shift when its depth lies within
    // 0.2 % of the range of the truth's at the pixel it moves to and that pixel's two neighbours
    // along the shift (a fractional shift falls between them).
    const int stride = std::max(1, int(std::sqrt(double(W) * H / 4096.0)));
    std::vector<glm::ivec2> samples;
    for (int row = stride / 2; row < H; row += stride)
        for (int col = stride / 2; col < W; col += stride)
            if (std::isfinite(mine[std::size_t(row) * W + col])) samples.emplace_back(col, row);
    auto agrees = [&](const glm::ivec2& at, int sx, int sy) {
        const double m = mine[std::size_t(at.y) * W + at.x];
        double lo = INFINITY, hi = -INFINITY;
        for (int k = -1; k <= 1; ++k) {
            const int c = at.x + sx + (sx != 0 ? k : 0), r = at.y + sy + (sy != 0 ? k : 0);
            if (c < 0 || c >= W || r < 0 || r >= H) continue;
            const double t = theirs[std::size_t(r) * W + c];
            if (std::isfinite(t)) lo = std::min(lo, t), hi = std::max(hi, t);
            if (sx == 0 && sy == 0) break;
        }
        return lo <= hi && m >= lo * (1 - 2e-3) && m <= hi * (1 + 2e-3);
    };
    // The samples the declared sampling leaves unexplained; a shift gains those it explains and
    // loses those it breaks (a ground plane seen without roll agrees at every shift along x).
    std::vector<char> declared(samples.size());
    std::size_t suspects = 0;
    for (std::size_t k = 0; k < samples.size(); ++k) suspects += (declared[k] = agrees(samples[k], 0, 0)) ? 0 : 1;
    glm::ivec2 best{0, 0};
    long bestGain = 0;
    auto consider = [&](int sx, int sy) {
        long gain = 0;
        for (std::size_t k = 0; k < samples.size(); ++k) gain += (agrees(samples[k], sx, sy) ? 1 : 0) - (declared[k] ? 1 : 0);
        if (gain > bestGain) bestGain = gain, best = {sx, sy};
    };
    for (int sx = -W / 3; sx <= W / 3; ++sx)
        if (std::abs(sx) > 1) consider(sx, 0);
    for (int sy = -H / 3; sy <= H / 3; ++sy)
        if (std::abs(sy) > 1) consider(0, sy);
    // It must explain most of what the declared sampling does not (shifts of a pixel or two are
    // the local fit's).
    if (suspects < 16 || 2 * bestGain < long(suspects)) return glm::dvec2(0.0);
    return glm::dvec2(best);
}

FitResult fitDeparture(const Scene& scene, const Camera& camera, const DepthMap& map, const RenderResult& truth,
                       FitFamily family, const TruthRender& render)
{
    FitResult out;
    out.family = family;
    Departure d;
    std::optional<RenderResult> rendered;  // the truth through the departed camera, from round 2
    // An image shifted by many pixels (a principal point far off) starts there, with its own truth.
    bool shiftedStart = false;
    if (family == FitFamily::SampleOffset)
        if (const glm::dvec2 shift = wholeImageShift(camera, map, truth); shift != glm::dvec2(0.0)) {
            try {
                d.sampleOffset = shift;
                rendered = render(Camera(departedCameraSpec(camera, d)), RayFaults{});
                out.initialResidual = medianResidual(scene, camera, map, truth);
                shiftedStart = true;
            } catch (const Error&) {
                d = Departure{}, rendered.reset();
            }
        }
    double previous = 0;                   // the last round's residual
    std::unique_ptr<Problem> last;         // the last round's
    for (int round = 0; round < 3; ++round) {
        const Camera departed(departedCameraSpec(camera, d));
        Problem problem{camera, map, family, d, 1, 1, samplesOf(scene, camera, departed, map, rendered ? *rendered : truth)};
        // A small or coarsely tessellated object seen small has few pixels whose neighbours lie on
        // one plane (a cow of 5,856 triangles over 7 % of a 96 × 120 image had too few to fit
        // anything: the regressions "diagnose did not name a depth scale on a small curved
        // object" and "... a focal length on a small curved object"). Then every pixel inside the
        // silhouette is a sample: a family that changes the values alone needs no plane around
        // it, and one that moves the rays takes the plane of the triangle it hit, the next round
        // the planes where the moved rays land (a fit is confirmed by a full comparison).
        if (problem.samples.size() < 64)
            problem.samples = samplesOf(scene, camera, departed, map, rendered ? *rendered : truth, SampleRule::InsideSurface);
        if (shiftedStart) {
            // Along a long shift only surfaces whose depth changes along it tell one shift from the
            // next; where most do not (a ground plane seen without roll, along x), their near-zero
            // residuals would set the robust scale and leave the telling ones out as outliers.
            const glm::dvec2 along = windowFromImageOffset(camera, d.sampleOffset.x != 0 ? glm::dvec2(1, 0) : glm::dvec2(0, 1));
            std::vector<Sample> telling;
            for (const Sample& sample : problem.samples) {
                const double before = departed.eyeZOf(eyePointOnPlane(departed, sample, -0.5 * along));
                const double after = departed.eyeZOf(eyePointOnPlane(departed, sample, 0.5 * along));
                if (std::abs(after - before) > 1e-3 * std::abs(after + before) / 2) telling.push_back(sample);
            }
            if (telling.size() >= 64) problem.samples = std::move(telling);
        }
        if (problem.samples.size() < 16) break;
        std::vector<double> values;
        for (const Sample& s : problem.samples) values.push_back(std::abs(s.mapValue));
        problem.valueSpan = std::max(medianOf(values), 1e-12);
        // The median eye depth of the samples, for the pose's translations.
        std::vector<double> z;
        for (const Sample& s : problem.samples) z.push_back(std::abs(departed.eyeZOf(eyePointOnPlane(departed, s))));
        problem.sceneDepth = std::max(medianOf(z), 1e-12);
        if (round == 0 && !shiftedStart) out.initialResidual = medianAbsolute(problem.residuals(d, false));
        if (family == FitFamily::SampleOffset && round == 0) {
            // Whole-pixel shifts first: the best of the offsets within two pixels.
            double best = INFINITY;
            Departure start = d;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    Departure trial = d;
                    trial.sampleOffset = d.sampleOffset + glm::dvec2(dx, dy);
                    const std::vector<double> r = problem.residuals(trial, false);
                    const double cost = robustCost(r, 1e-3);
                    if (cost < best) best = cost, start = trial;
                }
            problem.base = start;
        }
        if (round == 0) problem.base = linearStart(problem);
        const Departure next = solved(problem);
        out.samples = problem.samples.size();
        out.residual = medianAbsolute(problem.residuals(next, false));
        const bool moved = (shiftedStart && round == 0) || glm::length(next.sampleOffset - d.sampleOffset) > 1e-4 ||
                           glm::length(next.focalScale - d.focalScale) > 1e-6 ||
                           glm::length(next.principalShift - d.principalShift) > 1e-4 ||
                           glm::length(next.eyeShift - d.eyeShift) > 1e-6 * problem.sceneDepth ||
                           glm::length(next.eyeTurn - d.eyeTurn) > 1e-7 || next.nearDistance != d.nearDistance ||
                           next.farDistance != d.farDistance;
        const double before = round == 0 ? out.initialResidual : previous;
        previous = out.residual;
        d = next;
        last = std::make_unique<Problem>(problem);
        // Another round (new planes where surfaces moved) only for a fit that explains much of
        // the map and still improves; a scale and offset move no surface.
        if (!moved || family == FitFamily::DepthScale || out.residual > 0.5 * out.initialResidual ||
            out.residual > 0.9 * before)
            break;
        try {
            rendered = render(Camera(departedCameraSpec(camera, d)), RayFaults{});
        } catch (const Error&) {
            break;
        }
    }
    // The rounds weigh every sample pixel alike (relative depth: that finds a gross departure);
    // a fit that explains much of the map is then polished in the comparison's own terms.
    if (last && out.residual <= 0.5 * out.initialResidual) {
        d = polished(scene, *last, d);
        out.residual = medianAbsolute(last->residuals(d, false));
    }
    out.departure = d;
    return out;
}

}  // namespace zcheck
