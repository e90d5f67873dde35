#include "zcheck/compare.h"

#include "zcheck/camera_rays.h"
#include "zcheck/drawn_polygon.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/large_buffer.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace zcheck {

std::string toString(PixelClass pixelClass)
{
    switch (pixelClass) {
    case PixelClass::BothMiss: return "both-miss";
    case PixelClass::Agree: return "agree";
    case PixelClass::EdgeSurface: return "edge-surface";
    case PixelClass::DepthError: return "depth-error";
    case PixelClass::RayOnlyEdge: return "ray-only-edge";
    case PixelClass::RasterOnlyEdge: return "raster-only-edge";
    case PixelClass::RayOnlyAtClear: return "ray-only-at-clear";
    case PixelClass::AtClipPlane: return "at-clip-plane";
    case PixelClass::RayOnly: return "ray-only";
    case PixelClass::RasterOnly: return "raster-only";
    }
    return "?";
}

double ToleranceModel::constantQuanta(const DepthSettings& depth)
{
    switch (depth.format) {
    case DepthFormat::Unorm16: return 1.0;
    case DepthFormat::Unorm24: return 4.0;
    case DepthFormat::Float32: return depth.reversed ? 8.0 : 4.0;
    }
    return 4.0;
}

DepthSlopeFrame::DepthSlopeFrame(const Camera& camera)
    // The plane n·p + d = 0 in world space maps to clip space through the transpose of
    // worldFromClip; there a·x + b·y + c·z + d·w = 0, so in NDC z = −(a·x + b·y + d)/c.
    : clipPlaneFromWorldPlane(glm::transpose(camera.worldFromClip)),
      zWindowPerZNdc(std::abs(camera.windowFromNdc[2][2])),
      ndcPerPixelX(std::abs(camera.ndcFromWindow[0][0])),
      ndcPerPixelY(std::abs(camera.ndcFromWindow[1][1]))
{
}

double DepthSlopeFrame::slope(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) const
{
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const glm::dvec4 planeClip = clipPlaneFromWorldPlane * glm::dvec4(normal, -glm::dot(normal, a));
    if (planeClip.z == 0) return INFINITY;
    const double dzdx = zWindowPerZNdc * std::abs(planeClip.x / planeClip.z) * ndcPerPixelX;
    const double dzdy = zWindowPerZNdc * std::abs(planeClip.y / planeClip.z) * ndcPerPixelY;
    return std::max(dzdx, dzdy);
}

double windowDepthSlope(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return DepthSlopeFrame(camera).slope(a, b, c);
}

namespace {

// The 99th percentile of non-negative values held in several runs, without joining them:
// a radix select on the bit patterns (for non-negative floats they order as the values do),
// the top 16 bits first, then the values that share the chosen prefix.
// `parts`: (first value, count) pairs.
double percentile99(const std::vector<std::pair<const float*, std::size_t>>& parts)
{
    std::size_t count = 0;
    for (const auto& part : parts) count += part.second;
    if (count == 0) return 0.0;
    std::size_t k = std::min(count - 1, static_cast<std::size_t>(std::ceil(0.99 * double(count))) - 1);
    auto bits = [](float v) {
        std::uint32_t b;
        std::memcpy(&b, &v, sizeof b);
        return b;
    };
    std::vector<std::size_t> histogram(std::size_t(1) << 16, 0);
    for (const auto& [values, n] : parts)
        for (std::size_t j = 0; j < n; ++j) ++histogram[bits(values[j]) >> 16];
    std::uint32_t prefix = 0;
    while (k >= histogram[prefix]) k -= histogram[prefix++];
    std::vector<float> sharing;
    for (const auto& [values, n] : parts)
        for (std::size_t j = 0; j < n; ++j)
            if (bits(values[j]) >> 16 == prefix) sharing.push_back(values[j]);
    std::nth_element(sharing.begin(), sharing.begin() + std::ptrdiff_t(k), sharing.end());
    return sharing[k];
}

}  // namespace

PixelJudge::PixelJudge(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance)
    : scene_(scene),
      camera_(camera),
      C_(ToleranceModel::constantQuanta(camera.depth())),
      S_(tolerance.snapPixels()),
      E_(16 * std::ldexp(1.0, -52) * std::max(std::abs(camera.depth().rangeMin), std::abs(camera.depth().rangeMax))),
      slopeFrame_(camera),
      slopeCache_(new std::atomic<double>[scene.triangleCount()])  // not touched yet
{
    adviseHugePages(slopeCache_.get(), scene.triangleCount() * sizeof(std::atomic<double>));
    for (std::size_t t = 0; t < scene.triangleCount(); ++t) slopeCache_[t].store(NAN, std::memory_order_relaxed);
}

glm::dvec3 PixelJudge::vertex(std::uint32_t primitive, int corner) const
{
    return glm::dvec3(scene_.positions[scene_.triangles[primitive][corner]]);
}

// m is a property of the triangle's plane, the same at every pixel: computed once.
double PixelJudge::slope(std::uint32_t primitive) const
{
    if (!known(primitive)) return 0.0;
    std::atomic<double>& cached = slopeCache_[primitive];
    double m = cached.load(std::memory_order_relaxed);
    if (std::isnan(m)) {
        m = slopeFrame_.slope(vertex(primitive, 0), vertex(primitive, 1), vertex(primitive, 2));
        cached.store(m, std::memory_order_relaxed);
    }
    return m;
}

double PixelJudge::surfaceTolerance(std::uint32_t primitive, double q) const { return C_ * q + S_ * slope(primitive) + E_; }

// Does the primitive's plane cross the pixel's ray at the near or far plane, to within
// binary32 rounding (2^-20 relative) of the distances where the routes clip?
bool PixelJudge::atClipPlane(std::uint32_t primitive, const glm::dvec2& pWindow) const
{
    if (!known(primitive)) return false;
    const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera_, pWindow);
    const glm::dvec3 a = vertex(primitive, 0);
    const glm::dvec3 normal = glm::cross(vertex(primitive, 1) - a, vertex(primitive, 2) - a);
    const double t = glm::dot(normal, a - ray.origin) / glm::dot(normal, ray.direction);
    const double epsilon = std::ldexp(1.0, -20);
    // An infinite far plane has no surface to lie on (inf <= inf must not explain anything).
    return std::isfinite(t) && (std::abs(t - ray.tNear) <= epsilon * std::abs(ray.tNear) ||
                                (std::isfinite(ray.tFar) && std::abs(t - ray.tFar) <= epsilon * ray.tFar));
}

bool PixelJudge::nearEdge(std::uint32_t primitive, const glm::dvec2& pWindow) const
{
    if (!known(primitive)) return false;
    return distanceToDrawnEdge(camera_, vertex(primitive, 0), vertex(primitive, 1), vertex(primitive, 2), pWindow) <= S_;
}

PixelClass PixelJudge::bothHit(double rayDepth, std::uint32_t rayPrimitive, double rasterDepth,
                               std::uint32_t rasterPrimitive, double q, const glm::dvec2& pWindow, double& bound) const
{
    const double error = std::abs(rasterDepth - rayDepth);
    // Different surfaces: the raster's may legitimately win where the two lie within both
    // tolerances of each other, so the bound is their sum.
    const bool samePrimitive = rayPrimitive == rasterPrimitive;
    bound = surfaceTolerance(rayPrimitive, q) + (samePrimitive ? 0.0 : surfaceTolerance(rasterPrimitive, q));
    if (error <= bound) return PixelClass::Agree;
    if (!samePrimitive && (nearEdge(rayPrimitive, pWindow) || nearEdge(rasterPrimitive, pWindow) ||
                           atClipPlane(rayPrimitive, pWindow) || atClipPlane(rasterPrimitive, pWindow)))
        return PixelClass::EdgeSurface;
    return PixelClass::DepthError;
}

namespace {

bool isUnexplained(PixelClass c)
{
    return c == PixelClass::DepthError || c == PixelClass::RayOnly || c == PixelClass::RasterOnly;
}

}  // namespace

namespace {

// What one block of rows contributes to the report; blocks are merged in scan order.
struct BlockTally {
    ComparisonReport report;  // counts, maxima, worst pixel, samples, bounding box, bias samples
    std::size_t compared = 0;  // pixels compared on depth; their statistics start at the block's first pixel
    double signedErrorSum = 0;
    std::int64_t quarterCounts[4] = {0, 0, 0, 0};
};

constexpr int kBlockRows = 8;  // rows per block: fixed, so the merge order never depends on threads
constexpr std::size_t kUnexplainedSamples = 20;  // the first ones in scan order (compare.h)

// Grows the bounding box of the unexplained pixels to hold (col, row).
void extendUnexplainedBox(ComparisonReport& r, int col, int row)
{
    if (r.unexplainedMaxCol < 0) {
        r.unexplainedMinCol = r.unexplainedMaxCol = col;
        r.unexplainedMinRow = r.unexplainedMaxRow = row;
    }
    r.unexplainedMinCol = std::min(r.unexplainedMinCol, col);
    r.unexplainedMaxCol = std::max(r.unexplainedMaxCol, col);
    r.unexplainedMinRow = std::min(r.unexplainedMinRow, row);
    r.unexplainedMaxRow = std::max(r.unexplainedMaxRow, row);
}

void noteUnexplained(ComparisonReport& r, const PixelFinding& f)
{
    if (r.unexplainedSamples.size() < kUnexplainedSamples) r.unexplainedSamples.push_back(f);
    extendUnexplainedBox(r, f.col, f.row);
}

// Appends `block` (the rows after those of `total`) to `total`.
void merge(BlockTally& total, BlockTally& block)
{
    ComparisonReport& r = total.report;
    const ComparisonReport& b = block.report;
    const bool firstCompared = r.agree + r.depthErrors == 0 && b.agree + b.depthErrors > 0;
    if (firstCompared || b.maxErrorOverTolerance > r.maxErrorOverTolerance) {
        r.maxErrorOverTolerance = std::max(r.maxErrorOverTolerance, b.maxErrorOverTolerance);
        r.worst = b.worst;
    }
    r.bothHit += b.bothHit, r.bothMiss += b.bothMiss, r.rayOnly += b.rayOnly, r.rasterOnly += b.rasterOnly;
    r.agree += b.agree, r.edgeSurface += b.edgeSurface, r.depthErrors += b.depthErrors;
    r.coverageExplained += b.coverageExplained, r.lostAtClearValue += b.lostAtClearValue;
    r.atClipPlane += b.atClipPlane, r.coverageUnexplained += b.coverageUnexplained;
    r.maxErrorQuanta = std::max(r.maxErrorQuanta, b.maxErrorQuanta);
    r.maxRelativeEyeZError = std::max(r.maxRelativeEyeZError, b.maxRelativeEyeZError);
    r.biasSamples += b.biasSamples;
    for (const PixelFinding& f : b.unexplainedSamples)
        if (r.unexplainedSamples.size() < kUnexplainedSamples) r.unexplainedSamples.push_back(f);
    if (b.unexplainedMaxCol >= 0) {  // the box of all of them, not only of the samples
        extendUnexplainedBox(r, b.unexplainedMinCol, b.unexplainedMinRow);
        extendUnexplainedBox(r, b.unexplainedMaxCol, b.unexplainedMaxRow);
    }
    total.signedErrorSum += block.signedErrorSum;
    total.compared += block.compared;
    for (int k = 0; k < 4; ++k) total.quarterCounts[k] += block.quarterCounts[k];
}

}  // namespace

Comparison compareRoutes(const Scene& scene, const Camera& camera, const RenderResult& ray,
                         const RenderResult& raster, const ToleranceModel& tolerance,
                         const std::vector<double>* rasterQuantum)
{
    const int W = camera.width(), H = camera.height();
    Comparison out;
    assignLarge(out.pixelClass, std::size_t(W) * H, PixelClass::BothMiss);
    assignLarge(out.errorOverTolerance, std::size_t(W) * H, 0.0f);

    const PixelJudge judge(scene, camera, tolerance);
    const CameraRays cameraRays(camera);  // eye-z of a window depth in closed form
    // Per pixel compared on depth, for the 99th percentiles (binary32 suffices for statistics);
    // each block of rows fills its own rows' range from the start.
    std::vector<float> errorQuanta, relativeEyeZ;
    assignLarge(errorQuanta, std::size_t(W) * H, 0.0f);
    assignLarge(relativeEyeZ, std::size_t(W) * H, 0.0f);
    const DepthFormat format = camera.depth().format;
    const double S = tolerance.snapPixels();

    auto compareBlock = [&](int firstRow, int lastRow, BlockTally& tally) {
        ComparisonReport& r = tally.report;
        float* const blockErrorQuanta = &errorQuanta[std::size_t(firstRow) * W];
        float* const blockRelativeEyeZ = &relativeEyeZ[std::size_t(firstRow) * W];
        for (int row = firstRow; row < lastRow; ++row) {
            for (int col = 0; col < W; ++col) {
                const std::size_t i = std::size_t(row) * W + col;
                const bool rayHit = ray.hit(i), rasterHit = raster.hit(i);
                if (!rayHit && !rasterHit) {
                    ++r.bothMiss;  // pixelClass is BothMiss already
                    continue;
                }
                const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
                PixelFinding f;
                f.col = col, f.row = row;
                f.rayWindowDepth = ray.windowDepth.value[i];
                f.rasterWindowDepth = raster.windowDepth.value[i];
                f.rayPrimitive = ray.primitiveId[i];
                f.rasterPrimitive = raster.primitiveId[i];

                if (rayHit && rasterHit) {
                    ++r.bothHit;
                    const double q = rasterQuantum ? (*rasterQuantum)[i] : storageQuantum(format, f.rayWindowDepth);
                    const double error = std::abs(f.rasterWindowDepth - f.rayWindowDepth);
                    const bool samePrimitive = f.rayPrimitive == f.rasterPrimitive;
                    double bound = 0;
                    f.pixelClass = judge.bothHit(f.rayWindowDepth, f.rayPrimitive, f.rasterWindowDepth,
                                                 f.rasterPrimitive, q, pWindow, bound);
                    f.errorQuanta = error / q;
                    f.toleranceQuanta = bound / q;
                    const double ratio = bound > 0 ? error / bound : (error > 0 ? INFINITY : 0.0);
                    if (samePrimitive && S * judge.slope(f.rayPrimitive) <= 0.1 * q) {
                        // Quantization dominates here: feed the bias test.
                        tally.signedErrorSum += (f.rasterWindowDepth - f.rayWindowDepth) / q;
                        const double position = f.rayWindowDepth / q;
                        ++tally.quarterCounts[std::clamp(int(4 * (position - std::floor(position))), 0, 3)];
                        ++r.biasSamples;
                    }
                    if (f.pixelClass == PixelClass::EdgeSurface) {
                        ++r.edgeSurface;
                    } else {
                        f.pixelClass == PixelClass::Agree ? ++r.agree : ++r.depthErrors;
                        out.errorOverTolerance[i] = static_cast<float>(ratio);
                        blockErrorQuanta[tally.compared] = float(f.errorQuanta);
                        const glm::dvec2 pImage(col + 0.5, row + 0.5);
                        const double relative =
                            ray.pEye.empty()
                                ? cameraRays.relativeEyeZDifference(pImage, f.rayWindowDepth, f.rasterWindowDepth)
                                : std::abs(cameraRays.eyeZFromWindowDepth(pImage, f.rasterWindowDepth) -
                                           camera.eyeZOf(ray.pEye[i])) /
                                      std::abs(camera.eyeZOf(ray.pEye[i]));
                        blockRelativeEyeZ[tally.compared++] = float(relative);
                        r.maxRelativeEyeZError = std::max(r.maxRelativeEyeZError, relative);
                        r.maxErrorQuanta = std::max(r.maxErrorQuanta, f.errorQuanta);
                        if (ratio > r.maxErrorOverTolerance || r.agree + r.depthErrors == 1) {
                            r.maxErrorOverTolerance = std::max(r.maxErrorOverTolerance, ratio);
                            r.worst = f;
                        }
                    }
                } else {
                    // Coverage mismatch: only one route sees a surface. Explained at an edge of its
                    // triangle, (ray route only) at the clear value, or on the near/far plane.
                    rayHit ? ++r.rayOnly : ++r.rasterOnly;
                    const std::uint32_t primitive = rayHit ? f.rayPrimitive : f.rasterPrimitive;
                    const double q = rasterQuantum ? (*rasterQuantum)[i] : storageQuantum(format, f.rayWindowDepth);
                    const bool atClear =
                        rayHit && std::abs(f.rayWindowDepth - camera.clearDepth()) <= judge.surfaceTolerance(primitive, q);
                    if (judge.nearEdge(primitive, pWindow)) {
                        f.pixelClass = rayHit ? PixelClass::RayOnlyEdge : PixelClass::RasterOnlyEdge;
                    } else if (atClear) {
                        f.pixelClass = PixelClass::RayOnlyAtClear;
                        ++r.lostAtClearValue;
                    } else if (judge.atClipPlane(primitive, pWindow)) {
                        f.pixelClass = PixelClass::AtClipPlane;
                        ++r.atClipPlane;
                    } else {
                        f.pixelClass = rayHit ? PixelClass::RayOnly : PixelClass::RasterOnly;
                    }
                    isUnexplained(f.pixelClass) ? ++r.coverageUnexplained : ++r.coverageExplained;
                }
                out.pixelClass[i] = f.pixelClass;
                if (isUnexplained(f.pixelClass)) noteUnexplained(r, f);
            }
        }
    };

    std::vector<BlockTally> blocks(std::size_t((H + kBlockRows - 1) / kBlockRows));
    tbb::parallel_for(std::size_t(0), blocks.size(), [&](std::size_t b) {
        compareBlock(int(b) * kBlockRows, std::min(H, int(b + 1) * kBlockRows), blocks[b]);
    });
    BlockTally total;
    for (BlockTally& block : blocks) merge(total, block);
    std::vector<std::pair<const float*, std::size_t>> errorQuantaParts, relativeEyeZParts;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
        const std::size_t first = b * kBlockRows * std::size_t(W);
        errorQuantaParts.emplace_back(&errorQuanta[first], blocks[b].compared);
        relativeEyeZParts.emplace_back(&relativeEyeZ[first], blocks[b].compared);
    }
    blocks.clear();

    out.report = std::move(total.report);
    ComparisonReport& r = out.report;
    r.width = W, r.height = H;
    r.p99ErrorQuanta = percentile99(errorQuantaParts);
    if (r.biasSamples > 0) r.meanSignedErrorQuanta = total.signedErrorSum / double(r.biasSamples);
    const bool spread = std::all_of(std::begin(total.quarterCounts), std::end(total.quarterCounts),
                                    [&](std::int64_t n) { return n >= r.biasSamples / 10; });
    r.depthBias = r.biasSamples >= 1000 && spread && std::abs(r.meanSignedErrorQuanta) > 0.25;
    r.p99RelativeEyeZError = percentile99(relativeEyeZParts);
    return out;
}

}  // namespace zcheck
