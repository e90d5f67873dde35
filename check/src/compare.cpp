#include "zcheck/compare.h"

#include "zcheck/drawn_polygon.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include <algorithm>
#include <cmath>

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

double windowDepthSlope(const Camera& camera, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    // The plane n·p + d = 0 in world space maps to clip space through the transpose of
    // worldFromClip; there a·x + b·y + c·z + d·w = 0, so in NDC z = −(a·x + b·y + d)/c.
    const glm::dvec3 normal = glm::cross(b - a, c - a);
    const glm::dvec4 planeWorld(normal, -glm::dot(normal, a));
    const glm::dvec4 planeClip = glm::transpose(camera.worldFromClip) * planeWorld;
    if (planeClip.z == 0) return INFINITY;
    const double zWindowPerZNdc = std::abs(camera.windowFromNdc[2][2]);
    const double dzdx = zWindowPerZNdc * std::abs(planeClip.x / planeClip.z) * std::abs(camera.ndcFromWindow[0][0]);
    const double dzdy = zWindowPerZNdc * std::abs(planeClip.y / planeClip.z) * std::abs(camera.ndcFromWindow[1][1]);
    return std::max(dzdx, dzdy);
}


namespace {

double percentile99(std::vector<double>& values)
{
    if (values.empty()) return 0.0;
    const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(std::ceil(0.99 * values.size())) - 1);
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
}

}  // namespace

PixelJudge::PixelJudge(const Scene& scene, const Camera& camera, const ToleranceModel& tolerance)
    : scene_(scene),
      camera_(camera),
      C_(ToleranceModel::constantQuanta(camera.depth())),
      S_(tolerance.snapPixels()),
      E_(16 * std::ldexp(1.0, -52) * std::max(std::abs(camera.depth().rangeMin), std::abs(camera.depth().rangeMax))),
      slopeCache_(scene.triangleCount(), NAN)
{
}

glm::dvec3 PixelJudge::vertex(std::uint32_t primitive, int corner) const
{
    return glm::dvec3(scene_.positions[scene_.triangles[primitive][corner]]);
}

// m is a property of the triangle's plane, the same at every pixel: computed once.
double PixelJudge::slope(std::uint32_t primitive) const
{
    if (!known(primitive)) return 0.0;
    double& m = slopeCache_[primitive];
    if (std::isnan(m)) m = windowDepthSlope(camera_, vertex(primitive, 0), vertex(primitive, 1), vertex(primitive, 2));
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

Comparison compareRoutes(const Scene& scene, const Camera& camera, const RenderResult& ray,
                         const RenderResult& raster, const ToleranceModel& tolerance,
                         const std::vector<double>* rasterQuantum)
{
    const int W = camera.width(), H = camera.height();
    Comparison out;
    ComparisonReport& r = out.report;
    r.width = W, r.height = H;
    out.pixelClass.assign(std::size_t(W) * H, PixelClass::BothMiss);
    out.errorOverTolerance.assign(std::size_t(W) * H, 0.0f);

    const PixelJudge judge(scene, camera, tolerance);
    const DepthFormat format = camera.depth().format;
    const double S = tolerance.snapPixels();
    std::vector<double> errorQuanta, relativeEyeZ;
    double signedErrorSum = 0;
    std::int64_t quarterCounts[4] = {0, 0, 0, 0};

    for (int row = 0; row < H; ++row) {
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const bool rayHit = ray.hit(i), rasterHit = raster.hit(i);
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            PixelFinding f;
            f.col = col, f.row = row;
            f.rayWindowDepth = ray.windowDepth.value[i];
            f.rasterWindowDepth = raster.windowDepth.value[i];
            f.rayPrimitive = ray.primitiveId[i];
            f.rasterPrimitive = raster.primitiveId[i];

            if (!rayHit && !rasterHit) {
                ++r.bothMiss;
                f.pixelClass = PixelClass::BothMiss;
            } else if (rayHit && rasterHit) {
                ++r.bothHit;
                const double q = rasterQuantum ? (*rasterQuantum)[i] : storageQuantum(format, f.rayWindowDepth);
                const double error = std::abs(f.rasterWindowDepth - f.rayWindowDepth);
                const bool samePrimitive = f.rayPrimitive == f.rasterPrimitive;
                double bound = 0;
                f.pixelClass = judge.bothHit(f.rayWindowDepth, f.rayPrimitive, f.rasterWindowDepth, f.rasterPrimitive, q,
                                             pWindow, bound);
                f.errorQuanta = error / q;
                f.toleranceQuanta = bound / q;
                const double ratio = bound > 0 ? error / bound : (error > 0 ? INFINITY : 0.0);
                if (samePrimitive && S * judge.slope(f.rayPrimitive) <= 0.1 * q) {
                    // Quantization dominates here: feed the bias test.
                    signedErrorSum += (f.rasterWindowDepth - f.rayWindowDepth) / q;
                    const double position = f.rayWindowDepth / q;
                    ++quarterCounts[std::clamp(int(4 * (position - std::floor(position))), 0, 3)];
                    ++r.biasSamples;
                }
                if (f.pixelClass == PixelClass::EdgeSurface) {
                    ++r.edgeSurface;
                } else {
                    f.pixelClass == PixelClass::Agree ? ++r.agree : ++r.depthErrors;
                    out.errorOverTolerance[i] = static_cast<float>(ratio);
                    errorQuanta.push_back(f.errorQuanta);
                    const double eyeZRay = ray.pEye.empty() ? eyeZFromWindowDepth(camera, pWindow, f.rayWindowDepth)
                                                            : camera.eyeZOf(ray.pEye[i]);
                    const double eyeZRaster = eyeZFromWindowDepth(camera, pWindow, f.rasterWindowDepth);
                    relativeEyeZ.push_back(std::abs(eyeZRaster - eyeZRay) / std::abs(eyeZRay));
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
            if (isUnexplained(f.pixelClass)) {
                if (r.unexplainedSamples.size() < 20) r.unexplainedSamples.push_back(f);
                if (r.unexplainedMaxCol < 0) {
                    r.unexplainedMinCol = r.unexplainedMaxCol = col;
                    r.unexplainedMinRow = r.unexplainedMaxRow = row;
                }
                r.unexplainedMinCol = std::min(r.unexplainedMinCol, col);
                r.unexplainedMaxCol = std::max(r.unexplainedMaxCol, col);
                r.unexplainedMinRow = std::min(r.unexplainedMinRow, row);
                r.unexplainedMaxRow = std::max(r.unexplainedMaxRow, row);
            }
        }
    }
    for (double v : relativeEyeZ) r.maxRelativeEyeZError = std::max(r.maxRelativeEyeZError, v);
    r.p99ErrorQuanta = percentile99(errorQuanta);
    if (r.biasSamples > 0) r.meanSignedErrorQuanta = signedErrorSum / double(r.biasSamples);
    const bool spread = std::all_of(std::begin(quarterCounts), std::end(quarterCounts),
                                    [&](std::int64_t n) { return n >= r.biasSamples / 10; });
    r.depthBias = r.biasSamples >= 1000 && spread && std::abs(r.meanSignedErrorQuanta) > 0.25;
    r.p99RelativeEyeZError = percentile99(relativeEyeZ);
    return out;
}

}  // namespace zcheck
