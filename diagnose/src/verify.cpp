#include "zcheck/verify.h"

#include "zcheck/declared_reading.h"
#include "zcheck/drawn_polygon.h"
#include "zcheck/error.h"
#include "zcheck/fit.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/mistakes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace zcheck {

namespace {

// Window depths of map values at one window point (NaN for a miss), with eyePointFromDepth's
// arithmetic; the viewing ray is built once for the point, however many values are read there
// (a value and its neighbour one storage step away). Misses are kindOfDepthValue's; a window or
// NDC value out of range keeps its depth for the comparison to judge, a negative eye-z or
// distance has none.
class WindowDepthAt {
public:
    WindowDepthAt(const Camera& camera, const glm::dvec2& pWindow, DepthQuantity quantity)
        : camera_(camera), pWindow_(pWindow), quantity_(quantity)
    {
    }

    double operator()(double value)
    {
        const DepthValueKind kind = kindOfDepthValue(camera_, quantity_, value);
        const bool linear = quantity_ == DepthQuantity::EyeZ || quantity_ == DepthQuantity::Distance;
        if (kind == DepthValueKind::Miss || (kind == DepthValueKind::OutOfRange && linear)) return NAN;
        switch (quantity_) {
        case DepthQuantity::Window: return value;
        case DepthQuantity::Ndc:
            return windowFromEye(camera_, eyeFromWindow(camera_, {pWindow_, camera_.windowDepthFromNdcZ(value)})).z;
        case DepthQuantity::EyeZ: {
            const Ray& r = ray();
            const double t = (value - camera_.eyeZOf(r.origin)) / camera_.eyeZOf(r.direction);
            return windowFromEye(camera_, r.origin + t * r.direction).z;
        }
        case DepthQuantity::Distance: {
            if (!planeRay_) planeRay_ = eyePlaneRayFrom(ray());
            return windowFromEye(camera_, planeRay_->origin + value * planeRay_->direction).z;
        }
        }
        return NAN;
    }

private:
    const Ray& ray()
    {
        if (!ray_) ray_ = eyeRayThroughWindow(camera_, pWindow_);
        return *ray_;
    }

    const Camera& camera_;
    glm::dvec2 pWindow_;
    DepthQuantity quantity_;
    std::optional<Ray> ray_;
    std::optional<EyePlaneRay> planeRay_;
};

}  // namespace

// Window depth of a triangle's plane where the pixel's ray meets it (NaN if it does not).
double planeWindowDepth(const Scene& scene, const Camera& camera, std::uint32_t primitive, const EyePlaneRay& ray)
{
    const glm::uvec3 t = scene.triangles[primitive];
    const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const double s = glm::dot(normal, a - ray.origin) / glm::dot(normal, ray.direction);
    return std::isfinite(s) ? windowFromWorld(camera, ray.origin + s * ray.direction).z : NAN;
}


VertexNeighbours::VertexNeighbours(const Scene& scene, const RayRenderer* rays, const RasterRenderer* raster)
    : scene_(scene), rays_(rays), raster_(raster)
{
    for (std::uint32_t t = 0; t < scene.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) around_[key(scene.positions[scene.triangles[t][k]])].push_back(t);
}

std::string VertexNeighbours::key(const glm::vec3& p) { return std::string(reinterpret_cast<const char*>(&p), sizeof p); }

MapReader::MapReader(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                     const VertexNeighbours& neighbours)
    : scene_(judge.scene()), camera_(judge.camera()), map_(map), truth_(truth), neighbours_(neighbours), judge_(judge)
{
    if (judge.tolerance() != mapTolerance())
        throw std::logic_error("MapReader: the judge was not made with mapTolerance()");
}

MapPixel mapPixelDepth(const Camera& camera, const DepthMap& map, int col, int row, double truthDepth)
{
    const std::size_t i = std::size_t(row) * camera.width() + col;
    return mapPixelDepth(camera, map.quantity, map.value[i], map.accuracyAt(i), col, row, truthDepth);
}

MapPixel mapPixelDepth(const Camera& camera, DepthQuantity quantity, double value, const ValueAccuracy& accuracy, int col,
                       int row, double truthDepth)
{
    MapPixel out;
    WindowDepthAt windowDepthOf(camera, windowFromPixelCentre(camera, col, row), quantity);
    out.depth = windowDepthOf(value);
    const double depth = out.depth;
    // The storage step, carried into window units through the quantity's mapping.
    const double reference = std::isfinite(depth) ? depth : truthDepth;
    if (quantity == DepthQuantity::Window && accuracy.step == 0) {
        out.quantum = storageQuantum(camera.depth().format, reference);
    } else if (std::isfinite(depth)) {
        const double step = accuracy.step > 0 ? accuracy.step
                                              : double(std::nextafter(float(std::abs(value)), INFINITY)) - std::abs(double(float(value)));
        const double other = windowDepthOf(value + step);
        out.quantum = std::isfinite(other) ? std::max(std::abs(other - depth), storageQuantum(DepthFormat::Float32, depth))
                                           : storageQuantum(camera.depth().format, depth);
    } else {
        out.quantum = storageQuantum(camera.depth().format, reference);
    }
    // The declared accuracy, the larger window change of the two sides that are depths.
    const double declared = accuracy.absolute + accuracy.relative * std::abs(value);
    if (declared > 0 && std::isfinite(depth))
        for (const double side : {value - declared, value + declared})
            if (const double there = windowDepthOf(side); std::isfinite(there))
                out.allowance = std::max(out.allowance, std::abs(there - depth));
    return out;
}

MapPixel MapReader::read(int col, int row, bool search) const
{
    // Per thread, reused from pixel to pixel: the candidates considered and the surfaces seen.
    thread_local std::vector<std::uint32_t> considered, seen;
    const int W = camera_.width(), H = camera_.height();
    const std::size_t i = std::size_t(row) * W + col;
    const glm::dvec2 pWindow = windowFromPixelCentre(camera_, col, row);
    MapPixel out = mapPixelDepth(camera_, map_, col, row, truth_.windowDepth.value[i]);
    const double depth = out.depth;
    if (!std::isfinite(depth)) return out;
    // Which surface did the map see? The comparison's own rule decides (PixelJudge): the
    // truth's surface if the map's depth agrees with it; otherwise a surface drawn within S
    // of the pixel centre whose tolerance interval, joined with the truth's, holds the
    // map's depth, and under which the comparison explains the pixel. Every accepted set
    // is then an interval around the true depth, so a map nearer to the truth never fails
    // where a farther one passes (the regression "verify rejected a correct map at a
    // sliver's edge" in tests/test_verify.cpp).
    const std::uint32_t here = truth_.primitiveId[i];
    const double q = out.quantum, allowance = out.allowance;
    const double truthDepth = truth_.windowDepth.value[i];
    double bound = 0;
    if (here != kNoPrimitive && judge_.bothHit(truthDepth, here, depth, here, q, pWindow, bound, allowance) == PixelClass::Agree) {
        out.primitive = here;
        return out;
    }
    std::uint32_t primitive = here != kNoPrimitive ? here : kUnknownPrimitive;
    if (!search) {
        out.primitive = kUnknownPrimitive;
        return out;
    }
    double closest = INFINITY;
    const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera_, pWindow);
    considered.clear();
    auto consider = [&](std::uint32_t candidate) {
        if (candidate == here || std::find(considered.begin(), considered.end(), candidate) != considered.end()) return;
        considered.push_back(candidate);
        const double plane = planeWindowDepth(scene_, camera_, candidate, ray);
        if (!std::isfinite(plane)) return;
        const double tolerance = judge_.surfaceTolerance(candidate, q, allowance);
        double lo = plane - tolerance, hi = plane + tolerance;
        if (here != kNoPrimitive) {
            const double truthTolerance = judge_.surfaceTolerance(here, q, allowance);
            lo = std::min(lo, truthDepth - truthTolerance), hi = std::max(hi, truthDepth + truthTolerance);
        }
        const double gap = std::abs(plane - depth);
        if (!(depth >= lo && depth <= hi) || gap >= closest) return;
        const glm::uvec3 t = scene_.triangles[candidate];
        const glm::dvec3 a(scene_.positions[t[0]]), b(scene_.positions[t[1]]), c(scene_.positions[t[2]]);
        if (!insideDrawnTriangle(camera_, a, b, c, pWindow) && !judge_.nearEdge(candidate, pWindow)) return;
        const bool explained = here != kNoPrimitive
                                   ? judge_.bothHit(truthDepth, here, depth, candidate, q, pWindow, bound, allowance) != PixelClass::DepthError
                                   : judge_.nearEdge(candidate, pWindow) || judge_.atClipPlane(candidate, pWindow);
        if (explained) closest = gap, primitive = candidate;
    };
    seen.clear();
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
            const int c = col + dx, r = row + dy;
            if (c < 0 || c >= W || r < 0 || r >= H) continue;
            const std::uint32_t nearby = truth_.primitiveId[std::size_t(r) * W + c];
            if (nearby == kNoPrimitive || std::find(seen.begin(), seen.end(), nearby) != seen.end()) continue;
            seen.push_back(nearby);
            neighbours_.forEachNeighbour(nearby, consider);
        }
    // None of them: a surface seen only within S of the centre (behind a ridge, say)?
    if (closest == INFINITY)
        neighbours_.forEachSeenNear(camera_, pWindow, judge_.snapPixels(), [&](std::uint32_t seenNear) {
            if (std::find(seen.begin(), seen.end(), seenNear) != seen.end()) return;
            seen.push_back(seenNear);
            neighbours_.forEachNeighbour(seenNear, consider);
        });
    // Nor them: where no ray meets a surface, one the rasterizer draws there (a sliver's or a
    // triangle tip's snapped footprint reaches the pixel centre while no ray within S does; the
    // regression "verify rejected the raster route's own map at a silhouette sliver").
    if (closest == INFINITY && here == kNoPrimitive && neighbours_.raster())
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int c = col + dx, r = row + dy;
                if (c < 0 || c >= W || r < 0 || r >= H) continue;
                const std::uint32_t drawnThere = drawn().primitiveId[std::size_t(r) * W + c];
                if (drawnThere == kNoPrimitive || std::find(seen.begin(), seen.end(), drawnThere) != seen.end()) continue;
                seen.push_back(drawnThere);
                neighbours_.forEachNeighbour(drawnThere, consider);
            }
    out.primitive = primitive;
    return out;
}

const RenderResult& MapReader::drawn() const
{
    std::call_once(drawnOnce_, [&] { drawn_ = neighbours_.raster()->render(camera_); });
    return drawn_;
}

PixelClass MapReader::classify(int col, int row, const MapPixel& pixel) const
{
    const std::size_t i = std::size_t(row) * camera_.width() + col;
    const bool truthHit = truth_.hit(i), mapHit = pixel.primitive != kNoPrimitive;
    if (!truthHit && !mapHit) return PixelClass::BothMiss;
    const glm::dvec2 pWindow = windowFromPixelCentre(camera_, col, row);
    if (truthHit && mapHit) {
        double bound = 0;
        return judge_.bothHit(truth_.windowDepth.value[i], truth_.primitiveId[i], pixel.depth, pixel.primitive,
                              pixel.quantum, pWindow, bound, pixel.allowance);
    }
    return truthHit ? judge_.oneHit(true, truth_.windowDepth.value[i], truth_.primitiveId[i], pixel.quantum, pWindow,
                                    map_.accuracy.allowHoles)
                    : judge_.oneHit(false, pixel.depth, pixel.primitive, pixel.quantum, pWindow);
}

RenderResult renderResultFromMap(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                                 const VertexNeighbours& neighbours, std::vector<double>& quantum,
                                 std::vector<double>& allowance)
{
    const Camera& camera = judge.camera();
    const int W = camera.width(), H = camera.height();
    RenderResult out = RenderResult::cleared(W, H, camera.clearDepth());
    quantum.assign(std::size_t(W) * H, 0.0);
    const bool declared = map.accuracy.relative > 0 || map.accuracy.absolute > 0;
    allowance.assign(declared ? std::size_t(W) * H : 0, 0.0);
    const MapReader reader(judge, map, truth, neighbours);
    // Rows in parallel: each pixel's choice reads only the truth and the map.
    tbb::parallel_for(0, H, [&](int row) {
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const MapPixel pixel = reader.read(col, row);
            quantum[i] = pixel.quantum;
            if (declared) allowance[i] = pixel.allowance;
            if (pixel.primitive == kNoPrimitive) continue;
            out.windowDepth.value[i] = pixel.depth;
            out.primitiveId[i] = pixel.primitive;
        }
    });
    return out;
}

DepthMap DepthMap::of(DepthMapFile file, DepthQuantity quantity, const DepthMapReading& reading)
{
    return {file.width,           file.height, quantity,      std::move(file.value), file.valueQuantum, std::move(file.valueStep),
            reading.accuracy, reading.scale, reading.offset};
}

void requireMapFits(const Camera& camera, const DepthMap& map)
{
    if (map.width != camera.width() || map.height != camera.height() ||
        map.value.size() != std::size_t(map.width) * std::size_t(map.height))
        throw Error("the depth map is " + std::to_string(map.width) + "x" + std::to_string(map.height) + " (" +
                    std::to_string(map.value.size()) + " values) but the camera's image is " +
                    std::to_string(camera.width()) + "x" + std::to_string(camera.height()));
}

std::optional<std::int64_t> screenUnexplained(const Scene& scene, const Camera& camera, const DepthMap& map,
                                              const RenderResult& truth, const VertexNeighbours& neighbours)
{
    // Any pixel found unexplained proves the map inconsistent, however it was found: the
    // suspects are looked for on every fourth row and column (a sixteenth of the pixels), and the
    // sample is read in blocks until enough unexplained pixels make the estimate.
    constexpr std::size_t kSample = 1024, kBlock = 128;
    constexpr std::int64_t kEnough = 64;
    constexpr int kStride = 4;
    const int W = camera.width(), H = camera.height();
    const PixelJudge judge(scene, camera, mapTolerance(), SlopeSource::EachCall);  // a sixteenth of the pixels
    const MapReader reader(judge, map, truth, neighbours);
    std::vector<std::vector<std::uint32_t>> suspectsOfRow(static_cast<std::size_t>(H));
    tbb::parallel_for(0, H, [&](int row) {
        if (row % kStride != 0) return;
        for (int col = 0; col < W; col += kStride) {
            const std::size_t i = std::size_t(row) * W + col;
            const MapPixel pixel = reader.read(col, row, false);
            const bool suspect = pixel.primitive == kNoPrimitive ? truth.hit(i) : pixel.primitive == kUnknownPrimitive;
            if (suspect) suspectsOfRow[std::size_t(row)].push_back(std::uint32_t(col));
        }
    });
    std::vector<std::uint32_t> suspects;  // pixel indices, in scan order
    for (int row = 0; row < H; ++row)
        for (std::uint32_t col : suspectsOfRow[std::size_t(row)]) suspects.push_back(std::uint32_t(row) * W + col);
    if (suspects.size() * kStride * kStride <= kSample) return std::nullopt;  // few: the full comparison is as cheap
    const std::size_t sample = std::min(kSample, suspects.size());
    // Spread over the suspects block by block: block b reads every blocks-th one from offset b.
    const std::size_t blocks = (sample + kBlock - 1) / kBlock;
    std::int64_t unexplained = 0;
    std::size_t read = 0;
    for (std::size_t block = 0; block < blocks && unexplained < kEnough; ++block) {
        std::atomic<std::int64_t> found{0};
        const std::size_t first = block, count = (sample - first + blocks - 1) / blocks;
        tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
            const std::uint32_t i = suspects[(first + k * blocks) * suspects.size() / sample];
            const int col = int(i % W), row = int(i / W);
            if (isUnexplained(reader.classify(col, row, reader.read(col, row)))) ++found;
        });
        unexplained += found, read += count;
    }
    if (unexplained == 0) return std::nullopt;
    // The strided pixels stand for all of them.
    const double suspectsInAll = double(suspects.size()) * double(W) * double(H) /
                                 (double((W + kStride - 1) / kStride) * double((H + kStride - 1) / kStride));
    return std::int64_t(std::llround(double(unexplained) / double(read) * suspectsInAll));
}

Probe probeAgreement(const Scene& scene, const RayRenderer& rays, const Camera& camera, const DepthMap& map)
{
    constexpr int kGrid = 16;
    const int W = camera.width(), H = camera.height();
    const PixelJudge judge(scene, camera, mapTolerance(), SlopeSource::EachCall);  // 256 pixels
    std::atomic<int> agree{0}, seen{0};
    tbb::parallel_for(0, kGrid * kGrid, [&](int k) {
        const int col = (2 * (k % kGrid) + 1) * W / (2 * kGrid), row = (2 * (k / kGrid) + 1) * H / (2 * kGrid);
        const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
        const std::uint32_t primitive = rays.primitiveAt(camera, pWindow);
        const double truthDepth = primitive == kNoPrimitive
                                      ? camera.clearDepth()
                                      : planeWindowDepth(scene, camera, primitive, worldEyePlaneRayThroughWindow(camera, pWindow));
        const MapPixel pixel = mapPixelDepth(camera, map, col, row, truthDepth);
        if (primitive == kNoPrimitive && !std::isfinite(pixel.depth)) return;  // background: says nothing
        ++seen;
        double bound = 0;
        if (primitive != kNoPrimitive && std::isfinite(pixel.depth) && std::isfinite(truthDepth) &&
            judge.bothHit(truthDepth, primitive, pixel.depth, primitive, pixel.quantum, pWindow, bound, pixel.allowance) ==
                PixelClass::Agree)
            ++agree;
    });
    return {seen == 0 ? 0.0 : double(agree) / double(seen), double(seen) / (kGrid * kGrid)};
}

void countOutOfRange(const Camera& camera, const DepthMap& map, ComparisonReport& report)
{
    const int W = camera.width();
    for (std::size_t i = 0; i < map.value.size(); ++i)
        if (kindOfDepthValue(camera, map.quantity, map.value[i]) == DepthValueKind::OutOfRange && report.outOfRange++ == 0) {
            report.outOfRangeCol = int(i % W), report.outOfRangeRow = int(i / W);
            report.outOfRangeValue = map.storedOf(map.value[i]);
        }
}

void requireDepthsInRange(const Camera& camera, const DepthMap& map, const std::string& name)
{
    for (const double v : map.value)
        if (kindOfDepthValue(camera, map.quantity, v) == DepthValueKind::Depth) return;
    ComparisonReport count;  // only misses and values out of range: which, and where the first is
    countOutOfRange(camera, map, count);
    if (count.outOfRange == 0) return;
    throw Error(name + ": it holds no " + toString(map.quantity) + " depth — " + std::to_string(count.outOfRange) +
                " values lie outside " + depthValueRange(camera, map.quantity) +
                " (e.g. " + formatNumber(count.outOfRangeValue) + " at pixel (" + std::to_string(count.outOfRangeCol) +
                ", " + std::to_string(count.outOfRangeRow) + ")), the rest are misses: is the quantity right?");
}

VerifyResult verifyAgainst(const Scene& scene, const Camera& camera, const DepthMap& map, RenderResult truth,
                           const VertexNeighbours& neighbours)
{
    requireMapFits(camera, map);
    VerifyResult run;
    run.truth = std::move(truth);
    std::vector<double> quantum, allowance;
    const PixelJudge judge(scene, camera, mapTolerance());  // reads the map, then compares with the slopes it found
    run.map = renderResultFromMap(judge, map, run.truth, neighbours, quantum, allowance);
    const auto start = std::chrono::steady_clock::now();
    run.comparison = compareRoutes(judge, run.truth, run.map,
                                   {&quantum, allowance.empty() ? nullptr : &allowance, map.accuracy.allowHoles});
    run.report.timings.compareMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    run.report.timings.traceMs = run.truth.renderMilliseconds;
    run.report.describeInputs(scene, camera, mapTolerance());
    run.report.declared = map.accuracy;
    run.report.secondRoute = "map";
    run.report.outOfRangeRule = toString(map.quantity) + " map holds values in " + depthValueRange(camera, map.quantity);
    countOutOfRange(camera, map, run.comparison.report);
    run.report.comparison = run.comparison.report;
    return run;
}

namespace {

// The value at rank ⌈q·n⌉ − 1 of `values` (reordered), 0 for none.
double quantileOf(std::vector<double>& values, double q)
{
    if (values.empty()) return 0;
    const std::size_t rank = std::size_t(std::max(0.0, std::ceil(q * double(values.size())) - 1));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank), values.end());
    return values[rank];
}

}  // namespace

void measureMapErrors(const Camera& camera, const DepthMap& map, VerifyResult& run)
{
    const int W = camera.width(), H = camera.height();
    MapErrors& e = run.report.mapErrors;
    e = MapErrors{};
    const bool linear = map.quantity == DepthQuantity::EyeZ || map.quantity == DepthQuantity::Distance;
    e.quantity = linear ? toString(map.quantity) : "eye-z";
    e.eyeZEquivalent = !linear;
    run.mapError.assign(std::size_t(W) * H, NAN);
    std::vector<double> truthOf(std::size_t(W) * H, NAN), mineOf(std::size_t(W) * H, NAN);
    tbb::parallel_for(0, H, [&](int row) {
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const PixelClass c = run.comparison.pixelClass[i];
            if (c != PixelClass::Agree && c != PixelClass::DepthError) continue;
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            const double trueEyeZ = eyeZFromWindowDepth(camera, pWindow, run.truth.windowDepth.value[i]);
            truthOf[i] = linear ? depthValueFromEyeZ(camera, pWindow, trueEyeZ, map.quantity) : trueEyeZ;
            mineOf[i] = linear ? map.value[i] : eyeZFromWindowDepth(camera, pWindow, run.map.windowDepth.value[i]);
        }
    });
    std::vector<double> absolute, relative;
    for (std::size_t i = 0; i < truthOf.size(); ++i) {
        const double error = mineOf[i] - truthOf[i];
        if (!std::isfinite(error)) continue;
        run.mapError[i] = float(error);
        absolute.push_back(std::abs(error));
        relative.push_back(truthOf[i] != 0 ? std::abs(error / truthOf[i]) : 0.0);
        if (std::abs(error) > e.maxAbs || e.worstCol < 0) {
            e.maxAbs = std::abs(error);
            e.worstCol = int(i % W), e.worstRow = int(i / W), e.worstMap = mineOf[i], e.worstTrue = truthOf[i];
        }
    }
    e.compared = std::int64_t(absolute.size());
    e.p99Abs = quantileOf(absolute, 0.99), e.medianAbs = quantileOf(absolute, 0.5);
    e.p99Rel = quantileOf(relative, 0.99), e.medianRel = quantileOf(relative, 0.5);
    e.maxRel = relative.empty() ? 0 : *std::max_element(relative.begin(), relative.end());
}

const VertexNeighbours& Checker::neighbours() const
{
    std::call_once(neighboursOnce_, [&] { neighbours_ = std::make_shared<const VertexNeighbours>(scene_, &rays_, &raster_); });
    return *neighbours_;
}

VerifyResult Checker::verify(const Camera& camera, const DepthMap& map) const
{
    VerifyResult run = verifyAgainst(scene_, camera, map, renderRay(camera), neighbours());
    run.report.timings.bvhBuildMs = bvhBuildMilliseconds();
    measureMapErrors(camera, map, run);
    return run;
}

namespace {

// A hypothesis not judged yet.
Hypothesis hypothesis(std::string name, std::string variant, std::string explanation)
{
    Hypothesis h;
    h.name = std::move(name), h.variant = std::move(variant), h.explanation = std::move(explanation);
    return h;
}

}  // namespace

bool Hypothesis::consistentExceptEdges() const
{
    return !consistent && !estimated && unexplained > 0 && unexplainedAtEdges == unexplained && compared > 0 &&
           unexplained <= compared / 10;
}

bool onePlaneAround(const RenderResult& truth, int width, int height, int col, int row)
{
    const std::size_t i = std::size_t(row) * width + col;
    bool one = true;
    auto depthAt = [&](int dx, int dy) {
        const std::size_t j = std::size_t(std::clamp(row + dy, 0, height - 1)) * width + std::clamp(col + dx, 0, width - 1);
        if (truth.hit(j) != truth.hit(i)) one = false;
        return truth.windowDepth.value[j];
    };
    const double centre = truth.windowDepth.value[i];
    for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, -1}}) {
        const double before = depthAt(-dx, -dy), after = depthAt(dx, dy);
        if (!(std::abs(before - 2 * centre + after) <= 0.1 * std::abs(after - before) + 1e-12)) one = false;
    }
    return one;
}

EdgeTally tallyEdges(const Camera& camera, const RenderResult& truth, const RenderResult& map, const Comparison& comparison)
{
    const int W = camera.width(), H = camera.height();
    EdgeTally tally;
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            if (!isUnexplained(comparison.pixelClass[i])) continue;
            if (onePlaneAround(truth, W, H, col, row)) continue;
            // The range of the truth's depths around it, the clear value for a miss.
            double lo = INFINITY, hi = -INFINITY;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const std::size_t j = std::size_t(std::clamp(row + dy, 0, H - 1)) * W + std::clamp(col + dx, 0, W - 1);
                    const double d = truth.hit(j) ? truth.windowDepth.value[j] : camera.clearDepth();
                    lo = std::min(lo, d), hi = std::max(hi, d);
                }
            ++tally.atEdges;
            const double d = map.hit(i) ? map.windowDepth.value[i] : camera.clearDepth();
            if (d >= lo && d <= hi) ++tally.blends;
        }
    return tally;
}

std::vector<Hypothesis> Checker::diagnose(const Camera& camera, const DepthMap& map) const
{
    requireMapFits(camera, map);
    const RenderResult truth = renderRay(camera);
    // One hypothesis judged against `truthUsed` (the truth through `hypothesisCamera`), the map
    // as re-read.
    auto judgeAgainst = [&](Hypothesis h, const Camera& hypothesisCamera, const DepthMap& hypothesisMap,
                            const RenderResult& truthUsed) {
        // Most hypotheses are plainly wrong: a sample of the pixels that need the surface
        // search proves it without searching them all (screenUnexplained).
        // A hypothesis failing at a few pixels only (at most a tenth of the truth's surface,
        // by the estimate) is compared in full all the same: it may fail only at edges.
        const std::optional<std::int64_t> estimate = screenUnexplained(scene_, hypothesisCamera, hypothesisMap, truthUsed, neighbours());
        if (estimate && *estimate * 10 > std::count_if(truthUsed.primitiveId.begin(), truthUsed.primitiveId.end(),
                                                       [](std::uint32_t p) { return p != kNoPrimitive; })) {
            h.unexplained = *estimate, h.estimated = true;
        } else {
            const VerifyResult run = verifyAgainst(scene_, hypothesisCamera, hypothesisMap, truthUsed, neighbours());
            // Consistent only where something is compared: a view that sees nothing does not
            // explain a map that holds nothing.
            const ComparisonReport& r = run.comparison.report;
            h.consistent = r.consistent() && r.bothHit > 0, h.unexplained = r.unexplained();
            h.compared = r.bothHit + r.rayOnly + r.rasterOnly;
            if (!h.consistent && !r.depthBias) {
                const EdgeTally edges = tallyEdges(hypothesisCamera, run.truth, run.map, run.comparison);
                h.unexplainedAtEdges = edges.atEdges, h.blendsAtEdges = edges.blends;
            }
        }
        return h;
    };
    // The catalogue's readings, judged side by side (each judgement is parallel inside too;
    // side by side they also overlap each other's serial parts). A reading that changes the
    // camera or the sampling keeps its truth, for the pairs below.
    struct Candidate {
        const Mistake* mistake;
        Rereading reading;
        std::optional<Camera> camera;       // the reading's camera, once built
        std::optional<RenderResult> truth;  // when not the declared camera's
        std::optional<Hypothesis> judged;
        bool readsMapOnly() const { return !reading.camera && reading.truthFaults.none(); }
        const DepthMap& mapOr(const DepthMap& given) const { return reading.map ? *reading.map : given; }
    };
    std::vector<Candidate> candidates;
    for (const Mistake& mistake : mistakeCatalogue())
        if (mistake.reread)
            for (Rereading& reading : mistake.reread(camera, map)) candidates.push_back({&mistake, std::move(reading), {}, {}, {}});
    // A hypothesis a probe ruled out, its count estimated from the probe.
    auto probedOut = [&](Hypothesis h, const Probe& probe) {
        h.unexplained = probe.unexplainedOf(double(camera.width()) * camera.height());
        h.estimated = true;
        return h;
    };
    auto changesCameraOnly = [](const Candidate& c) { return c.camera && c.reading.camera && c.reading.truthFaults.none() && !c.reading.map; };
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
        Candidate& c = candidates[k];
        // A variant that is not a valid camera (a near plane behind the eye) is no hypothesis.
        try {
            c.camera.emplace(c.reading.camera ? *c.reading.camera : camera.spec());
            Hypothesis h = hypothesis(c.mistake->name, c.reading.variant, c.reading.explanation);
            // Another camera needs a truth of its own, unless a probe rules it out first: then
            // its count is estimated from the probe (a pair with it is probed in turn below).
            if (changesCameraOnly(c)) {
                const Probe probe = probeAgreement(scene_, rays_, *c.camera, map);
                if (probe.rulesOut()) {
                    c.judged = probedOut(std::move(h), probe);
                    return;
                }
            }
            if (!c.readsMapOnly()) c.truth = renderRay(*c.camera, c.reading.truthFaults);
            c.judged = judgeAgainst(std::move(h), *c.camera, c.mapOr(map), c.truth ? *c.truth : truth);
        } catch (const Error&) {
            c.camera.reset(), c.truth.reset();
        }
    });
    std::vector<Hypothesis> out;
    for (const Candidate& c : candidates)
        if (c.judged) out.push_back(*c.judged);
    // The map as declared, when only edge pixels fail: anti-aliased depth if each of them holds
    // a blend of the surfaces either side.
    if (Hypothesis asDeclared = judgeAgainst(hypothesis("", "", ""), camera, map, truth);
        asDeclared.consistentExceptEdges()) {
        const bool blends = asDeclared.blendsAtEdges == asDeclared.unexplainedAtEdges;
        asDeclared.name = blends ? "anti-aliased" : "edge-pixels";
        asDeclared.explanation =
            blends ? "consistent except at edges, whose depths lie between the surfaces either side: anti-aliased or "
                     "resolved multisample depth (keep one sample's depth, or resolve depth with min or max, not an "
                     "average)"
                   : "consistent except at edges";
        out.insert(out.begin(), std::move(asDeclared));  // before readings that only rename the same values
    }
    // What the reading should have declared (declared_reading.h): each finding alone, and all
    // of them together, judged as any hypothesis.
    ReadingFindings findings = findReading(camera, map, truth);
    Declared found;
    found.missValue = findings.missValue.has_value(), found.grid = findings.grid > 0;
    {  // holes: the pixels left unexplained where only the truth hits, once the miss value is read as one
        const VerifyResult run = verifyAgainst(scene_, camera, declaredReading(map, findings, found), truth, neighbours());
        findings.holes = std::count(run.comparison.pixelClass.begin(), run.comparison.pixelClass.end(), PixelClass::RayOnly);
        found.holes = findings.holes > 0 && !map.accuracy.allowHoles;
    }
    auto judgeReading = [&](const Declared& use, const DepthMap& read, const std::string& extra) {
        std::string because = describeFindings(findings, use);
        if (!extra.empty()) because += (because.empty() ? "" : "; ") + extra;
        return judgeAgainst(hypothesis(use.name(), "", "consistent if read as declared: " + because), camera, read, truth);
    };
    {
        std::vector<Declared> readings;  // each finding alone, then all of them
        for (const auto member : {&Declared::missValue, &Declared::grid, &Declared::holes})
            if (found.*member) {
                Declared alone;
                alone.*member = true;
                readings.push_back(alone);
            }
        if (readings.size() > 1) readings.push_back(found);
        std::vector<Hypothesis> judged(readings.size());
        tbb::parallel_for(std::size_t(0), readings.size(), [&](std::size_t k) {
            judged[k] = judgeReading(readings[k], declaredReading(map, findings, readings[k]), "");
        });
        out.insert(out.end(), judged.begin(), judged.end());
    }
    // The continuous families, fitted side by side, each confirmed by a full comparison; not
    // needed where a mistake of the catalogue explains the map whole.
    // `reading` (a catalogue mistake that re-reads the map, or none) names the map fitted.
    const TruthRender render = [&](const Camera& c, const RayFaults& faults) { return renderRay(c, faults); };
    auto fitEach = [&](const DepthMap& fittedMap, const Candidate* reading) {
        const std::vector<FitFamily> families = fitFamilies(camera, fittedMap);
        std::vector<std::optional<Hypothesis>> fitted(families.size());
        tbb::parallel_for(std::size_t(0), families.size(), [&](std::size_t k) {
            try {
                const FitResult fit = fitDeparture(scene_, camera, fittedMap, truth, families[k], render);
                if (fit.samples == 0) return;  // too few pixels on one plane to fit anything
                // After a re-reading, only a fit that explains much of the map is worth its
                // confirmation (a render and a comparison): a consistent one leaves residuals at
                // the map's rounding, far under half those under the declared camera.
                if (reading && !(fit.residual <= 0.5 * fit.initialResidual)) return;
                const Camera fittedCamera(departedCameraSpec(camera, fit.departure));
                Hypothesis h = reading ? hypothesis(reading->mistake->name + " + " + toString(families[k]), reading->reading.variant,
                                                    reading->reading.explanation + ", and with " + describeFit(camera, fittedMap, fit))
                                       : hypothesis(toString(families[k]), "", "consistent with " + describeFit(camera, fittedMap, fit));
                h.fitted = fittedValues(camera, fittedMap, fit);
                fitted[k] = judgeAgainst(std::move(h), fittedCamera, departedReading(camera, fittedMap, fit.departure),
                                         renderRay(fittedCamera));
            } catch (const Error&) {
            }
        });
        for (auto& h : fitted)
            if (h) out.push_back(std::move(*h));
    };
    if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) { return h.consistent; })) fitEach(map, nullptr);
    const bool explained = std::any_of(out.begin(), out.end(), [](const Hypothesis& h) {
        return h.consistent || h.consistentExceptEdges();
    });
    // Two mistakes at once (flipped and reversed, say), when no single one, no fit and no
    // edge-only reading explains the map: a reading of the map composed with a reading of the
    // map or of the camera, judged against the truth already rendered for the latter; and two
    // camera mistakes, below.
    auto pairHypothesis = [&](const Candidate& first, const Candidate& second) {
        std::string also = second.reading.explanation;
        if (also.rfind("consistent if ", 0) == 0) also = also.substr(14);
        return hypothesis(first.mistake->name + " + " + second.mistake->name, second.reading.variant,
                          first.reading.explanation + ", and " + also);
    };
    if (!explained) {
        std::vector<std::pair<std::size_t, std::size_t>> pairs;
        auto changesQuantity = [&](const Candidate& c) { return c.reading.map && c.reading.map->quantity != map.quantity; };
        for (std::size_t a = 0; a < candidates.size(); ++a)
            for (std::size_t b = 0; b < candidates.size(); ++b) {
                const Candidate &first = candidates[a], &second = candidates[b];
                if (!first.camera || !second.camera || first.mistake == second.mistake || !first.readsMapOnly() ||
                    first.mistake->alone || second.mistake->alone)
                    continue;
                if (second.readsMapOnly() && (b <= a || (changesQuantity(first) && changesQuantity(second)))) continue;
                pairs.emplace_back(a, b);
            }
        // The first re-reads the map; the second then re-reads that, or changes the camera.
        auto mapOfPair = [&](const Candidate& first, const Candidate& second) -> std::optional<DepthMap> {
            const DepthMap& firstMap = first.mapOr(map);
            std::vector<Rereading> again = second.mistake->reread(camera, firstMap);
            const auto same = std::find_if(again.begin(), again.end(), [&](const Rereading& r) { return r.variant == second.reading.variant; });
            if (same == again.end()) return std::nullopt;
            return same->map ? *same->map : firstMap;
        };
        // A pair whose camera the catalogue's probe ruled out (it has no truth yet) is probed
        // itself; only those it keeps get the truth rendered, once per camera.
        std::vector<std::optional<Hypothesis>> paired(pairs.size());
        std::vector<char> kept(pairs.size(), 1);
        tbb::parallel_for(std::size_t(0), pairs.size(), [&](std::size_t k) {
            const Candidate &first = candidates[pairs[k].first], &second = candidates[pairs[k].second];
            if (second.readsMapOnly() || second.truth) return;
            try {
                const std::optional<DepthMap> both = mapOfPair(first, second);
                if (!both) return;
                const Probe probe = probeAgreement(scene_, rays_, *second.camera, *both);
                if (!probe.rulesOut()) return;
                kept[k] = 0;
                paired[k] = probedOut(pairHypothesis(first, second), probe);
            } catch (const Error&) {
                kept[k] = 0;
            }
        });
        std::vector<std::size_t> untraced;
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            const std::size_t b = pairs[k].second;
            if (kept[k] && !candidates[b].readsMapOnly() && !candidates[b].truth &&
                std::find(untraced.begin(), untraced.end(), b) == untraced.end())
                untraced.push_back(b);
        }
        tbb::parallel_for(std::size_t(0), untraced.size(), [&](std::size_t k) {
            Candidate& c = candidates[untraced[k]];
            try {
                c.truth = renderRay(*c.camera, c.reading.truthFaults);
            } catch (const Error&) {
            }
        });
        tbb::parallel_for(std::size_t(0), pairs.size(), [&](std::size_t k) {
            const Candidate &first = candidates[pairs[k].first], &second = candidates[pairs[k].second];
            if (!kept[k] || (!second.readsMapOnly() && !second.truth)) return;  // probed out, or no truth
            try {
                if (const std::optional<DepthMap> both = mapOfPair(first, second))
                    paired[k] = judgeAgainst(pairHypothesis(first, second), *second.camera, *both, second.truth ? *second.truth : truth);
            } catch (const Error&) {
            }
        });
        for (auto& h : paired)
            if (h) out.push_back(std::move(*h));
        // Two camera mistakes (a reversed-Z renderer with a left-handed view, say): the second
        // applied to the first's camera. A truth for each of a few hundred cameras would cost
        // seconds; a grid of single rays (probeAgreement) rules out almost all of them first,
        // and a camera that two orders of the same pair both make is judged once.
        struct CameraPair {
            std::size_t first, second;
            std::optional<Camera> camera;
        };
        std::vector<CameraPair> cameraPairs;
        for (std::size_t a = 0; a < candidates.size(); ++a)
            for (std::size_t b = 0; b < candidates.size(); ++b)
                if (candidates[a].mistake != candidates[b].mistake && changesCameraOnly(candidates[a]) && changesCameraOnly(candidates[b]))
                    cameraPairs.push_back({a, b, {}});
        tbb::parallel_for(std::size_t(0), cameraPairs.size(), [&](std::size_t k) {
            CameraPair& pair = cameraPairs[k];
            const Candidate& second = candidates[pair.second];
            try {
                for (const Rereading& r : second.mistake->reread(*candidates[pair.first].camera, map))
                    if (r.variant == second.reading.variant && r.camera) {
                        Camera composed(*r.camera);
                        if (!probeAgreement(scene_, rays_, composed, map).rulesOut()) pair.camera.emplace(std::move(composed));
                    }
            } catch (const Error&) {
            }
        });
        std::vector<std::size_t> survivors;
        for (std::size_t k = 0; k < cameraPairs.size(); ++k) {
            const Camera* c = cameraPairs[k].camera ? &*cameraPairs[k].camera : nullptr;
            if (c && std::none_of(survivors.begin(), survivors.end(), [&](std::size_t j) {
                    const Camera& other = *cameraPairs[j].camera;
                    return other.worldFromClip == c->worldFromClip && other.windowFromNdc == c->windowFromNdc &&
                           other.depth().reversed == c->depth().reversed;
                }))
                survivors.push_back(k);
        }
        std::vector<std::optional<Hypothesis>> pairedCameras(survivors.size());
        tbb::parallel_for(std::size_t(0), survivors.size(), [&](std::size_t k) {
            const CameraPair& pair = cameraPairs[survivors[k]];
            try {
                pairedCameras[k] = judgeAgainst(pairHypothesis(candidates[pair.first], candidates[pair.second]), *pair.camera, map,
                                                renderRay(*pair.camera));
            } catch (const Error&) {
            }
        });
        for (auto& h : pairedCameras)
            if (h) out.push_back(std::move(*h));
        // A re-reading of the map and a fitted departure (a flipped map of one MSAA sample, say),
        // when no pair explains it either: the fits run again on the map as the re-reading
        // reads it that comes closest to the truth where the truth is one plane (medianResidual),
        // if that is under half of how close the map as declared comes — a re-reading that is
        // half the answer leaves only the departure's own small residuals.
        if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) { return h.consistent || h.consistentExceptEdges(); })) {
            std::vector<double> residual(candidates.size(), INFINITY);
            tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
                const Candidate& c = candidates[k];
                if (c.camera && c.readsMapOnly() && c.reading.map) residual[k] = medianResidual(scene_, camera, *c.reading.map, truth);
            });
            const auto closest = std::min_element(residual.begin(), residual.end());
            if (closest != residual.end() && *closest < 0.5 * medianResidual(scene_, camera, map, truth)) {
                const Candidate& reading = candidates[std::size_t(closest - residual.begin())];
                fitEach(*reading.reading.map, &reading);
            }
        }
    }
    // A stated accuracy, last, and only where no convention explains the map (a uniform offset,
    // which the depth-scale fit measures, may be the map's stated accuracy): the tolerance that
    // would accept the map as read with the findings above.
    if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) {
            return (h.consistent || h.consistentExceptEdges()) && h.name != "depth-scale";
        })) {
        const DepthMap read = declaredReading(map, findings, found);
        if (const std::optional<MapAccuracy> accuracy = toleranceFinding(camera, read, truth)) {
            DepthMap declared = read;
            declared.accuracy = *accuracy;
            const bool relative = accuracy->relative > map.accuracy.relative;  // else absolute (toleranceFinding)
            const double value = relative ? accuracy->relative : accuracy->absolute;
            const std::string option = std::string(relative ? "--rel-tolerance " : "--abs-tolerance ") + formatNumber(value);
            const std::string within = "±" + formatNumber(value) + " of the truth" + (relative ? " (relative)" : "");
            Hypothesis h = judgeReading(found, declared,
                                        "its values lie within " + within + " everywhere: pass " + option +
                                            " if your renderer or sensor is good only to that (a tolerance is for "
                                            "accuracy, never for a convention mistake)");
            h.name = h.name.empty() ? "tolerance" : h.name + " + tolerance";
            h.fitted.push_back({relative ? "rel_tolerance" : "abs_tolerance", value,
                                relative ? map.accuracy.relative : map.accuracy.absolute});
            out.push_back(std::move(h));
        }
    }
    // A map with no surface at all, as read, is evidence for nothing: say so first.
    const bool anySurface = !explained && [&] {
        for (int row = 0; row < map.height; ++row)
            for (int col = 0; col < map.width; ++col)
                if (kindOfDepthValue(camera, map.quantity, map.value[std::size_t(row) * map.width + col]) != DepthValueKind::Miss)
                    return true;
        return false;
    }();
    if (!explained && !anySurface)
        out.insert(out.begin(), hypothesis("empty-map", "",
                                           "the map holds no surface as read: every value is a miss (check --quantity, "
                                           "--channel, --miss and --scale)"));
    std::stable_sort(out.begin(), out.end(), [](const Hypothesis& a, const Hypothesis& b) {
        if (a.consistent != b.consistent) return a.consistent;
        if (a.consistentExceptEdges() != b.consistentExceptEdges()) return a.consistentExceptEdges();
        return a.unexplained < b.unexplained;
    });
    return out;
}

}  // namespace zcheck
