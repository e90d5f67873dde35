#include "zcheck/verify.h"

#include "numerics.h"
#include "verify_estimators.h"
#include "zcheck/detail/clock.h"
#include "zcheck/drawn_polygon.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
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

// Whether a map's values are a unorm buffer's window or NDC depths held in binary32 (nothing
// stated of their storage step, `storageStep` 0), whose rounding mapPixelDepth allows for.
bool unormInBinary32(const Camera& camera, DepthQuantity quantity, double storageStep)
{
    return camera.depth().format != DepthFormat::Float32 &&
           (quantity == DepthQuantity::Window || quantity == DepthQuantity::Ndc) && storageStep == 0;
}

// The same for a whole map: no storage step stated for any of its values.
bool unormInBinary32(const Camera& camera, const DepthMap& map)
{
    return map.valueStep.empty() && unormInBinary32(camera, map.quantity, map.valueQuantum);
}

// Window depth of a triangle's plane (in the frame of `camera` and `ray`) where the pixel's ray
// meets it (NaN if it does not).
double planeWindowDepth(const Camera& camera, const Scene::Plane& plane, const EyePlaneRay& ray)
{
    const double s = glm::dot(plane.normal, plane.point - ray.origin) / glm::dot(plane.normal, ray.direction);
    return std::isfinite(s) ? windowFromWorld(camera, ray.origin + s * ray.direction).z : NAN;
}

}  // namespace


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
    if (judge.tolerance() != mapTolerance(map))
        throw std::logic_error("MapReader: the judge was not made with mapTolerance(map)");
}

double linearizedBufferStep(const Camera& camera, double eyeZ)
{
    const double n = camera.nearDistance(), f = camera.farDistance();
    double u, slope;  // the buffer's value at eyeZ in [0, 1], and its derivative in eye-z
    if (camera.spec().projection.isPerspective()) {
        const double span = 1 / n - (std::isinf(f) ? 0.0 : 1 / f);
        u = (1 / n - 1 / eyeZ) / span, slope = 1 / (eyeZ * eyeZ * span);
    } else {
        u = (eyeZ - n) / (f - n), slope = 1 / (f - n);
    }
    return storageQuantum(DepthFormat::Float32, std::clamp(u, 0.0, 1.0)) / slope;
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
    const bool linear = quantity == DepthQuantity::EyeZ || quantity == DepthQuantity::Distance;
    const double depth = out.depth;
    // The storage step, carried into window units through the quantity's mapping.
    const double reference = std::isfinite(depth) ? depth : truthDepth;
    out.quantum = storageQuantum(camera.depth().format, reference);
    // The window change of a change of `step` in the stored value (either side that is a depth).
    auto windowChange = [&](double step) {
        double other = windowDepthOf(value + step);
        if (!std::isfinite(other)) other = windowDepthOf(value - step);
        return std::abs(other - depth);  // NaN where neither side is a depth
    };
    // A window or NDC value in binary32 (nothing stated of its storage) is rounded to binary32's
    // step at the value, in window units:
    const double binary32Change = !linear && accuracy.step == 0 && std::isfinite(depth)
                                      ? windowChange(storageQuantum(DepthFormat::Float32, value))
                                      : NAN;
    // at an NDC value near −1 of a [-1, 1] convention (window depth near 0) far coarser than the
    // depth buffer's step (window 10⁻⁴ of a float32 buffer: 2000 of its steps);
    if (quantity == DepthQuantity::Ndc && std::isfinite(binary32Change)) out.quantum = std::max(out.quantum, binary32Change);
    if (std::isfinite(depth) && (linear || accuracy.step > 0)) {
        const double step = accuracy.step > 0 ? accuracy.step : storageQuantum(DepthFormat::Float32, value);
        // A window or NDC value's step is at least binary32's at its window depth; a linear map's
        // is at least a linearized depth buffer's (linearizedBufferStep), whatever the camera's own.
        if (const double change = windowChange(step); std::isfinite(change)) {
            out.quantum = change;
            if (!linear) {
                out.quantum = std::max(out.quantum, storageQuantum(DepthFormat::Float32, depth));
            } else {
                const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
                const double z = eyeZFromWindowDepth(camera, pWindow, depth);
                const double buffer = windowDepthFromEyeZ(camera, pWindow, z + linearizedBufferStep(camera, z));
                if (std::isfinite(buffer)) out.quantum = std::max(out.quantum, std::abs(buffer - depth));
            }
        }
    }
    // The declared accuracy, the larger window change of the two sides that are depths.
    const double declared = accuracy.declaredAt(value);
    if (declared > 0 && std::isfinite(depth))
        for (const double side : {value - declared, value + declared})
            if (const double there = windowDepthOf(side); std::isfinite(there))
                out.allowance = std::max(out.allowance, std::abs(there - depth));
    // A unorm buffer's value held in binary32 (a float file, a buffer read back as GL_FLOAT) was
    // rounded once more, by up to half binary32's step, alike for neighbouring values: in [0.5, 1)
    // the step is one unorm24 code, and a buffer's code values at window depth 0.57 all round up
    // by 0.43 of a code, while exact depths stored the same way do not. A value that close to a
    // code's value may be either, so its distance from that code's value is allowed for: the
    // pixel's tolerance takes it, and where it is over a tenth of a code the bias test leaves the
    // pixel out. Near window depth 1 codes and binary32 values nearly coincide, the distance is
    // small, and a truncating buffer is still a bias there.
    if (unormInBinary32(camera, quantity, accuracy.step) && std::isfinite(binary32Change)) {
        const double fromCode = std::abs(depth - quantizeDepth(camera.depth().format, depth));
        if (fromCode <= 0.5 * binary32Change * (1 + 0x1p-20)) out.allowance += fromCode;
    }
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
    // The candidates' corners meet the camera in the scene's frame, as the judge's rules do.
    const Camera& local = judge_.cameraInSceneFrame();
    const EyePlaneRay ray = worldEyePlaneRayThroughWindow(local, pWindow);
    considered.clear();
    auto consider = [&](std::uint32_t candidate) {
        if (candidate == here || std::find(considered.begin(), considered.end(), candidate) != considered.end()) return;
        considered.push_back(candidate);
        const glm::uvec3 t = scene_.triangles[candidate];
        const glm::dvec3 a(scene_.positions[t[0]]), b(scene_.positions[t[1]]), c(scene_.positions[t[2]]);
        // The candidate's depths within S of the centre: its plane's depth on the pixel's ray,
        // give or take its tolerance; or, where that leaves the map's depth out, the depths its
        // drawn polygon takes within S, give or take the tolerance of a face-on surface. The
        // two agree for a triangle seen at an angle; only the second holds for one seen edge-on
        // or made a line by its binary32 corners, whose plane the ray meets anywhere or nowhere
        // (the regression "verify rejected the raster's sliver of a triangle without area").
        const double plane = planeWindowDepth(local, {glm::cross(b - a, c - a), a}, ray);
        const double tolerance = judge_.surfaceTolerance(candidate, q, allowance);
        double lo = plane - tolerance, hi = plane + tolerance, gap = std::abs(plane - depth);
        if (!(depth >= lo && depth <= hi)) {
            const WindowDepthRange drawn = drawnDepthsNear(local, a, b, c, pWindow, judge_.snapPixels());
            if (drawn.empty()) return;
            const double flat = judge_.toleranceForSlope(0, q, allowance);
            lo = drawn.lo - flat, hi = drawn.hi + flat;
            gap = std::max({drawn.lo - depth, depth - drawn.hi, 0.0});
        }
        if (here != kNoPrimitive) {
            const double truthTolerance = judge_.surfaceTolerance(here, q, allowance);
            lo = std::min(lo, truthDepth - truthTolerance), hi = std::max(hi, truthDepth + truthTolerance);
        }
        if (!(depth >= lo && depth <= hi) || gap >= closest) return;
        if (!insideDrawnTriangle(local, a, b, c, pWindow) && !judge_.nearEdge(candidate, pWindow)) return;
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
    // Nor them: one the rasterizer draws there (a sliver's or a triangle tip's snapped footprint
    // reaches the pixel centre while no ray within S does), in front of the truth's surface or
    // where no ray meets one (the regressions "verify rejected the raster route's own map at a
    // silhouette sliver" and "... at a sliver in front of a surface").
    if (closest == INFINITY && neighbours_.raster())
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
    // Allowances: what the map declares, and the binary32 rounding of a unorm buffer's window or
    // NDC values (mapPixelDepth).
    const bool declared = map.accuracy.anyAccuracy() ||
                          unormInBinary32(camera, map);
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
    const PixelJudge judge(scene, camera, mapTolerance(map), SlopeSource::EachCall);  // a sixteenth of the pixels
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
    constexpr int kGrid = 16, kSamples = kGrid * kGrid;
    const int W = camera.width(), H = camera.height();
    const PixelJudge judge(scene, camera, mapTolerance(map), SlopeSource::EachCall);  // a few hundred pixels
    std::atomic<int> agree{0}, seen{0};
    // One pixel: its single ray's surface against the map's value there.
    const auto probe = [&](int col, int row) {
        const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
        const std::uint32_t primitive = rays.primitiveAt(camera, pWindow);
        const double truthDepth = primitive == kNoPrimitive
                                      ? camera.clearDepth()
                                      : planeWindowDepth(camera, scene.worldPlane(primitive), worldEyePlaneRayThroughWindow(camera, pWindow));
        const MapPixel pixel = mapPixelDepth(camera, map, col, row, truthDepth);
        if (primitive == kNoPrimitive && !std::isfinite(pixel.depth)) return;  // background: says nothing
        ++seen;
        double bound = 0;
        if (primitive != kNoPrimitive && std::isfinite(pixel.depth) && std::isfinite(truthDepth) &&
            judge.bothHit(truthDepth, primitive, pixel.depth, primitive, pixel.quantum, pWindow, bound, pixel.allowance) ==
                PixelClass::Agree)
            ++agree;
    };
    tbb::parallel_for(0, kSamples, [&](int k) { probe((2 * (k % kGrid) + 1) * W / (2 * kGrid), (2 * (k / kGrid) + 1) * H / (2 * kGrid)); });
    double seenShare = double(seen) / kSamples;
    // A surface smaller than the grid's spacing falls between its pixels, and a grid that sees
    // (almost) nothing says nothing (it ruled out every camera of a map whose object covered
    // 0.6 % of the image: the regression "diagnose did not name a mistake in a map of a small
    // object"). Then the pixels where the map, read through this camera, holds a surface are
    // probed too: up to kSamples of them, found among at most 2^14 pixels read.
    if (seen < kGrid) {
        const int stride = std::max(1, int(std::ceil(std::sqrt(double(W) * H / 16384.0))));
        std::vector<std::pair<int, int>> surface;
        for (int row = stride / 2; row < H; row += stride)
            for (int col = stride / 2; col < W; col += stride)
                if (std::isfinite(mapPixelDepth(camera, map, col, row, camera.clearDepth()).depth)) surface.emplace_back(col, row);
        const std::size_t n = std::min<std::size_t>(surface.size(), kSamples);
        tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
            const auto [col, row] = surface[k * surface.size() / n];
            probe(col, row);
        });
        seenShare = std::max(seenShare, double(surface.size()) * stride * stride / (double(W) * H));
    }
    return {seen == 0 ? 0.0 : double(agree) / double(seen), std::min(seenShare, 1.0)};
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
    if (const LensModel* lens = camera.lens(); lens && (map.quantity == DepthQuantity::Window || map.quantity == DepthQuantity::Ndc))
        throw Error(name + ": a " + toString(map.quantity) + " map cannot come from a lens model (" + lens->spec().model +
                    "), which has no depth buffer: give --quantity eye-z or distance");
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
    const PixelJudge judge(scene, camera, mapTolerance(map));  // reads the map, then compares with the slopes it found
    run.map = renderResultFromMap(judge, map, run.truth, neighbours, quantum, allowance);
    const auto start = Clock::now();
    run.comparison = compareRoutes(judge, run.truth, run.map,
                                   {&quantum, allowance.empty() ? nullptr : &allowance, map.accuracy.allowHoles});
    run.report.timings.compareMs = millisecondsSince(start);
    run.report.timings.traceMs = run.truth.renderMilliseconds;
    run.report.describeInputs(scene, camera, mapTolerance(map));
    run.report.declared = map.accuracy;
    run.report.secondRoute = "map";
    run.report.outOfRangeRule = toString(map.quantity) + " map holds values in " + depthValueRange(camera, map.quantity);
    countOutOfRange(camera, map, run.comparison.report);
    judgeDeclaredAccuracy(judge, map, run.truth, run.map, quantum, run.comparison);
    run.report.comparison = run.comparison.report;
    return run;
}

double truthValueAt(const Camera& camera, const RenderResult& truth, int col, int row, DepthQuantity quantity)
{
    const std::size_t i = std::size_t(row) * camera.width() + col;
    const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
    return depthValueFromEyeZ(camera, pWindow, eyeZFromWindowDepth(camera, pWindow, truth.windowDepth.value[i]), quantity);
}

namespace {

// The median of one field of `pixels`.
double medianOfField(const std::vector<DeclaredPixel>& pixels, double DeclaredPixel::*field)
{
    std::vector<double> values;
    values.reserve(pixels.size());
    for (const DeclaredPixel& c : pixels) values.push_back(c.*field);
    return medianOf(std::move(values));
}

// "12.5%": a fraction as a percentage to a tenth.
std::string percentText(double fraction) { return formatNumber(std::round(fraction * 1000) / 10) + "%"; }

// judgeDeclaredAccuracy's "holes": why allowed holes cannot stand (more than half the pixels
// where the surface is hit), or "".
std::string holesRefusal(const DepthMap& map, const ComparisonReport& report)
{
    // Holes are a sensor's few: a map that holds nothing where most of the surface is proves nothing.
    const std::int64_t surface = report.bothHit + report.rayOnly;
    if (map.accuracy.allowHoles && report.holes > 0 && report.holes * 2 > surface)
        return "holes at " + std::to_string(report.holes) + " of the " + std::to_string(surface) +
               " pixels where the surface is hit: --allow-holes accepts a sensor's few holes, "
               "not a map that holds nothing where most of the surface is";
    return "";
}

// The pixels judgeDeclaredAccuracy weighs, in scan order: compared on depth (Agree, DepthError),
// hit by the truth, the map showing the truth's own surface there (`mapRender`) and holding a
// depth of its quantity.
std::vector<DeclaredPixel> declaredPixels(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                                          const RenderResult& mapRender, const std::vector<double>& quantum,
                                          const Comparison& comparison)
{
    const Camera& camera = judge.camera();
    const int W = camera.width(), H = camera.height();
    const DepthQuantity quantity = map.quantity;
    const double Q = map.accuracy.quantum;
    std::vector<std::vector<DeclaredPixel>> rows(static_cast<std::size_t>(H));
    tbb::parallel_for(0, H, [&](int row) {
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const PixelClass c = comparison.pixelClass[i];
            const double v = map.value[i];
            if ((c != PixelClass::Agree && c != PixelClass::DepthError) || !truth.hit(i) ||
                mapRender.primitiveId[i] != truth.primitiveId[i] || kindOfDepthValue(camera, quantity, v) != DepthValueKind::Depth)
                continue;
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            const double truthWindow = truth.windowDepth.value[i];
            const double trueEyeZ = truthValueAt(camera, truth, col, row, DepthQuantity::EyeZ);
            // The map's value of a window depth at this pixel, and the eye-z of a map value.
            auto valueOfWindow = [&](double d) {
                return depthValueFromEyeZ(camera, pWindow, eyeZFromWindowDepth(camera, pWindow, d), quantity);
            };
            auto eyeZOfValue = [&](double value) -> double {
                switch (quantity) {
                case DepthQuantity::Window: return eyeZFromWindowDepth(camera, pWindow, value);
                case DepthQuantity::Ndc: return eyeZFromWindowDepth(camera, pWindow, camera.windowDepthFromNdcZ(value));
                case DepthQuantity::EyeZ: return value;
                case DepthQuantity::Distance: return eyeZFromDistance(camera, pWindow, value);
                }
                return NAN;
            };
            const double trueValue = truthValueAt(camera, truth, col, row, quantity);
            const double tolerance = judge.surfaceTolerance(truth.primitiveId[i], quantum[i]);
            double intrinsic = 0;
            for (const double side : {truthWindow - tolerance, truthWindow + tolerance})
                if (const double there = valueOfWindow(side); std::isfinite(there))
                    intrinsic = std::max(intrinsic, std::abs(there - trueValue));
            const double declared = map.accuracyAt(i).declaredAt(v);
            double relativeEyeZ = 0;
            for (const double side : {trueValue - declared, trueValue + declared}) {
                const double z = eyeZOfValue(side);
                relativeEyeZ = std::max(relativeEyeZ, std::isfinite(z) && z > 0 ? std::abs(z - trueEyeZ) / trueEyeZ : INFINITY);
            }
            const bool onGrid = Q > 0 ? onDeclaredGrid(v, Q, map.offset) : true;
            // Against the truth as the declared grid rounds it: a rounding's own error is not a bias.
            const double expected = Q > 0 ? std::round((trueValue - map.offset) / Q) * Q + map.offset : trueValue;
            rows[std::size_t(row)].push_back({v - expected, intrinsic, declared, relativeEyeZ, onGrid, col, row, v});
        }
    });
    std::vector<DeclaredPixel> all;
    for (auto& r : rows) all.insert(all.end(), r.begin(), r.end());
    return all;
}

// judgeDeclaredAccuracy's "coarse": why the declared accuracy, at the median of `all`, is too
// coarse to judge (a tenth of the eye-z or more), or "".
std::string coarseRefusal(const std::vector<DeclaredPixel>& all)
{
    const double relative = medianOfField(all, &DeclaredPixel::relativeEyeZ);
    if (relative < 0.1) return "";
    return "the declared accuracy is as coarse as the depths: ±" +
           fourSignificantDigits(medianOfField(all, &DeclaredPixel::declared)) + " at the median pixel, " +
           (std::isfinite(relative) ? percentText(relative) : std::string("beyond the far plane")) +
           " of its eye-z (a declaration zcheck can judge is under a tenth of the depth); a "
           "map of the wrong scale or quantity would pass it";
}

// judgeDeclaredAccuracy's "grid": why the declared quantum Q (> 0) is not the grid of the values
// of `all` (more than 1 % off it), or "" (also for Q = 0).
std::string gridRefusal(double Q, const std::vector<DeclaredPixel>& all)
{
    if (!(Q > 0)) return "";
    const auto off = std::count_if(all.begin(), all.end(), [](const DeclaredPixel& c) { return !c.onGrid; });
    if (off * 100 <= std::int64_t(all.size())) return "";
    const DeclaredPixel& first = *std::find_if(all.begin(), all.end(), [](const DeclaredPixel& c) { return !c.onGrid; });
    return "the declared quantum " + formatNumber(Q) + " is not the map's grid: " + percentText(double(off) / double(all.size())) +
           " of the values compared lie off its multiples (pixel (" + std::to_string(first.col) + ", " +
           std::to_string(first.row) + ") holds " + formatNumber(first.value) +
           "); --quantum states the step the values were rounded to";
}

// The fewest pixels compared on which a declared accuracy is judged: two a sample of the bias's
// sixteen on average. Fewer cannot tell noise from a wrong scale, and are refused (fewRefusal).
constexpr std::size_t kFewestToJudge = 32;

// judgeDeclaredAccuracy's "few": why `all` are too few to judge a declared accuracy by, or "".
std::string fewRefusal(const std::vector<DeclaredPixel>& all)
{
    if (all.size() >= kFewestToJudge) return "";
    return "only " + std::to_string(all.size()) + " pixels are compared, too few to tell rounding or noise from a wrong "
           "scale or offset (a declared accuracy is judged on " + std::to_string(kFewestToJudge) +
           " or more); declare none, or verify a larger part of the map";
}

// judgeDeclaredAccuracy's "bias": why the mean error of `all` (kFewestToJudge pixels or more) is
// beyond what an unbiased map shows, or "" (also for a single interleaved sample).
std::string biasRefusal(double Q, const std::vector<DeclaredPixel>& all)
{
    // The mean's own sampling error, from the means of 16 interleaved samples (pixel
    // (col, row) in sample 4·(row mod 4) + col mod 4, each spread over the whole image).
    std::array<double, 16> sum{}, count{};
    double bias = 0;
    for (const DeclaredPixel& c : all) {
        const std::size_t k = std::size_t(4 * (c.row % 4) + c.col % 4);
        sum[k] += c.error, count[k] += 1, bias += c.error / double(all.size());
    }
    std::vector<double> means;
    for (std::size_t k = 0; k < sum.size(); ++k)
        if (count[k] > 0) means.push_back(sum[k] / count[k]);
    if (means.size() < 2) return "";  // one sample (an image one pixel wide and tall): no spread to judge by
    double centre = 0, squares = 0;
    for (double m : means) centre += m / double(means.size());
    for (double m : means) squares += (m - centre) * (m - centre);
    const double sampling = std::sqrt(squares / double(means.size() - 1) / double(means.size()));
    const double exact = medianOfField(all, &DeclaredPixel::intrinsic);
    const double allowed = exact + 6 * sampling;
    if (std::abs(bias) <= allowed) return "";
    return "the map's errors are systematic: their mean is " + fourSignificantDigits(bias) + " (map units" +
           (Q > 0 ? ", against the truth rounded to the grid" : "") + "), beyond the ±" + fourSignificantDigits(allowed) +
           " an unbiased map may show (an exact map's median tolerance " + fourSignificantDigits(exact) +
           ", and six times the mean's sampling error " + fourSignificantDigits(sampling) +
           "); a declared accuracy absorbs rounding and noise, never a wrong scale, quantity, offset or pose";
}

}  // namespace

bool onDeclaredGrid(double value, double Q, double offset)
{
    const double u = value - offset;
    const float f = float(std::abs(value));
    const double spacing = double(std::nextafter(f, INFINITY)) - double(f);
    return std::abs(u / Q - std::round(u / Q)) * Q <= std::max(1e-3 * Q, 4 * spacing);
}

std::string declaredAccuracyRefusal(const DepthMap& map, const ComparisonReport& report, const std::vector<DeclaredPixel>& all)
{
    std::string refused = holesRefusal(map, report);
    if (!refused.empty() || !map.accuracy.anyAccuracy() || all.empty()) return refused;
    refused = fewRefusal(all);
    if (refused.empty()) refused = coarseRefusal(all);
    if (refused.empty()) refused = gridRefusal(map.accuracy.quantum, all);
    if (refused.empty()) refused = biasRefusal(map.accuracy.quantum, all);
    return refused;
}

void judgeDeclaredAccuracy(const PixelJudge& judge, const DepthMap& map, const RenderResult& truth,
                           const RenderResult& mapRender, const std::vector<double>& quantum, Comparison& comparison)
{
    const bool weighs = holesRefusal(map, comparison.report).empty() && map.accuracy.anyAccuracy();
    const std::vector<DeclaredPixel> all =
        weighs ? declaredPixels(judge, map, truth, mapRender, quantum, comparison) : std::vector<DeclaredPixel>{};
    comparison.report.declaredAccuracyRefused = declaredAccuracyRefusal(map, comparison.report, all);
}

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
            // In the units mapErrors reports: the map's own for eye-z and distance, eye-z for the others.
            truthOf[i] = truthValueAt(camera, run.truth, col, row, linear ? map.quantity : DepthQuantity::EyeZ);
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
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

bool hitAllAround(const RenderResult& truth, int width, int height, int col, int row)
{
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (!truth.hit(std::size_t(std::clamp(row + dy, 0, height - 1)) * width + std::clamp(col + dx, 0, width - 1)))
                return false;
    return true;
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

}  // namespace zcheck
