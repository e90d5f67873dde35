#include "verify.h"

#include "zcheck/inverse_projection.h"

#include <algorithm>
#include <chrono>
#include <unordered_map>
#include <cmath>
#include <functional>

namespace zcheck {

namespace {

// Window depth of a map value at a window point, or NaN for a miss.
double windowDepthOfValue(const Camera& camera, const glm::dvec2& pWindow, double value, DepthQuantity quantity)
{
    if (quantity == DepthQuantity::Window) {
        if (!std::isfinite(value) || value == camera.clearDepth() || value == camera.windowDepthFar()) return NAN;
        return value;
    }
    const auto pEye = eyePointFromDepth(camera, pWindow, value, quantity);
    return pEye ? windowFromEye(camera, *pEye).z : NAN;
}

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


VertexNeighbours::VertexNeighbours(const Scene& scene) : scene_(scene)
{
    for (std::uint32_t t = 0; t < scene.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) around_[key(scene.positions[scene.triangles[t][k]])].push_back(t);
}

std::string VertexNeighbours::key(const glm::vec3& p) { return std::string(reinterpret_cast<const char*>(&p), sizeof p); }

RenderResult renderResultFromMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map,
                                 const RenderResult& truth, const VertexNeighbours& neighbours,
                                 std::vector<double>& quantum)
{
    const int W = camera.width(), H = camera.height();
    RenderResult out;
    out.windowDepth = {W, H, DepthQuantity::Window, std::vector<double>(std::size_t(W) * H, camera.clearDepth())};
    out.primitiveId.assign(std::size_t(W) * H, kNoPrimitive);
    quantum.assign(std::size_t(W) * H, 0.0);
    const PixelJudge judge(scene, camera);
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            const double value = map.value[i];
            const double depth = windowDepthOfValue(camera, pWindow, value, map.quantity);
            // The storage step, carried into window units through the quantity's mapping.
            const double reference = std::isfinite(depth) ? depth : truth.windowDepth.value[i];
            if (map.quantity == DepthQuantity::Window && map.valueQuantum == 0) {
                quantum[i] = storageQuantum(camera.depth().format, reference);
            } else if (std::isfinite(depth)) {
                const double step = map.valueQuantum > 0 ? map.valueQuantum
                                                         : double(std::nextafter(float(std::abs(value)), INFINITY)) - std::abs(double(float(value)));
                const double other = windowDepthOfValue(camera, pWindow, value + step, map.quantity);
                quantum[i] = std::isfinite(other) ? std::max(std::abs(other - depth), storageQuantum(DepthFormat::Float32, depth))
                                                  : storageQuantum(camera.depth().format, depth);
            } else {
                quantum[i] = storageQuantum(camera.depth().format, reference);
            }
            if (!std::isfinite(depth)) continue;
            out.windowDepth.value[i] = depth;
            // Which surface did the map see? The comparison's own rule decides (PixelJudge): the
            // truth's surface if the map's depth agrees with it; otherwise a surface drawn within S
            // of the pixel centre whose tolerance interval, joined with the truth's, holds the
            // map's depth, and under which the comparison explains the pixel. Every accepted set
            // is then an interval around the true depth, so a map nearer to the truth never fails
            // where a farther one passes (the regression "verify rejected a correct map at a
            // sliver's edge" in tests/test_verify.cpp).
            const std::uint32_t here = truth.primitiveId[i];
            const double q = quantum[i];
            const double truthDepth = truth.windowDepth.value[i];
            double bound = 0;
            if (here != kNoPrimitive &&
                judge.bothHit(truthDepth, here, depth, here, q, pWindow, bound) == PixelClass::Agree) {
                out.primitiveId[i] = here;
                continue;
            }
            std::uint32_t primitive = here != kNoPrimitive ? here : kUnknownPrimitive;
            double closest = INFINITY;
            const EyePlaneRay ray = worldEyePlaneRayThroughWindow(camera, pWindow);
            std::vector<std::uint32_t> considered;
            auto consider = [&](std::uint32_t candidate) {
                if (candidate == here || std::find(considered.begin(), considered.end(), candidate) != considered.end())
                    return;
                considered.push_back(candidate);
                const double plane = planeWindowDepth(scene, camera, candidate, ray);
                if (!std::isfinite(plane)) return;
                const double tolerance = judge.surfaceTolerance(candidate, q);
                double lo = plane - tolerance, hi = plane + tolerance;
                if (here != kNoPrimitive) {
                    const double truthTolerance = judge.surfaceTolerance(here, q);
                    lo = std::min(lo, truthDepth - truthTolerance), hi = std::max(hi, truthDepth + truthTolerance);
                }
                const double gap = std::abs(plane - depth);
                if (!(depth >= lo && depth <= hi) || gap >= closest) return;
                const glm::uvec3 t = scene.triangles[candidate];
                const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
                if (!insideDrawnTriangle(camera, a, b, c, pWindow) && !judge.nearEdge(candidate, pWindow)) return;
                const bool explained = here != kNoPrimitive
                                           ? judge.bothHit(truthDepth, here, depth, candidate, q, pWindow, bound) !=
                                                 PixelClass::DepthError
                                           : judge.nearEdge(candidate, pWindow) || judge.atClipPlane(candidate, pWindow);
                if (explained) closest = gap, primitive = candidate;
            };
            std::vector<std::uint32_t> seen;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    const int c = col + dx, r = row + dy;
                    if (c < 0 || c >= W || r < 0 || r >= H) continue;
                    const std::uint32_t nearby = truth.primitiveId[std::size_t(r) * W + c];
                    if (nearby == kNoPrimitive || std::find(seen.begin(), seen.end(), nearby) != seen.end()) continue;
                    seen.push_back(nearby);
                    neighbours.forEachNeighbour(nearby, consider);
                }
            out.primitiveId[i] = primitive;
        }
    return out;
}

VerifyRun verifyDepthMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map, RayRenderer& rays)
{
    return verifyDepthMap(scene, camera, map, rays, VertexNeighbours(scene));
}

VerifyRun verifyDepthMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map, RayRenderer& rays,
                         const VertexNeighbours& neighbours)
{
    VerifyRun run;
    run.truth = rays.render(camera);
    std::vector<double> quantum;
    run.map = renderResultFromMap(scene, camera, map, run.truth, neighbours, quantum);
    const auto start = std::chrono::steady_clock::now();
    run.comparison = compareRoutes(scene, camera, run.truth, run.map, {}, &quantum);
    run.report.timings.compareMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    run.report.timings.bvhBuildMs = rays.buildMilliseconds();
    run.report.timings.traceMs = run.truth.renderMilliseconds;
    run.report.scene = scene.name;
    run.report.triangles = scene.triangleCount();
    run.report.camera = camera.spec();
    run.report.comparison = run.comparison.report;
    return run;
}

std::vector<Hypothesis> diagnoseDepthMap(const Scene& scene, const Camera& camera, const ExternalDepthMap& map,
                                         RayRenderer& rays)
{
    std::vector<Hypothesis> out;
    const int W = camera.width(), H = camera.height();
    const VertexNeighbours neighbours(scene);  // one scene, many comparisons: built once
    auto test = [&](const std::string& name, const std::string& explanation, const Camera& hypothesisCamera,
                    const ExternalDepthMap& hypothesisMap, const RayFaults& sampling = {}) {
        rays.sampling = sampling;
        const VerifyRun run = verifyDepthMap(scene, hypothesisCamera, hypothesisMap, rays, neighbours);
        rays.sampling = RayFaults{};
        out.push_back({name, explanation, run.comparison.report.consistent(), run.comparison.report.unexplained()});
    };
    auto remapped = [&](const std::function<double(int col, int row, double value)>& f, DepthQuantity quantity) {
        ExternalDepthMap m = map;
        m.quantity = quantity;
        for (int row = 0; row < H; ++row)
            for (int col = 0; col < W; ++col) {
                const std::size_t i = std::size_t(row) * W + col;
                m.value[i] = f(col, row, map.value[i]);
            }
        return m;
    };
    auto at = [&](int col, int row) { return map.value[std::size_t(row) * W + col]; };
    // A camera variant, or nothing when the variant is not a valid camera.
    auto variant = [&](const std::function<void(CameraSpec&)>& change, auto&& use) {
        CameraSpec spec = camera.spec();
        change(spec);
        try {
            use(Camera(spec));
        } catch (const std::exception&) {
        }
    };
    auto matrixVariant = [&](const std::string& name, const std::string& explanation, const glm::dmat4& clipFromEye) {
        variant([&](CameraSpec& spec) {
            spec.projection.type = ProjectionType::Matrix;
            spec.projection.clipFromEye = clipFromEye;
        }, [&](const Camera& c) { test(name, explanation, c, map); });
    };

    // Orientation and sampling.
    test("vertical-flip", "consistent if flipped vertically (the window's y origin is the other corner)", camera,
         remapped([&](int col, int row, double) { return at(col, H - 1 - row); }, map.quantity));
    test("horizontal-flip", "consistent if flipped horizontally (a mirrored x axis)", camera,
         remapped([&](int col, int row, double) { return at(W - 1 - col, row); }, map.quantity));
    for (auto [dx, dy, what] : {std::tuple{-0.5, -0.5, "x and y"}, std::tuple{-0.5, 0.0, "x"}, std::tuple{0.0, -0.5, "y"},
                                std::tuple{0.5, 0.5, "x and y (the other way)"}}) {
        RayFaults shifted;
        shifted.shiftPixels = {dx, dy};
        test(std::string("half-pixel-shift ") + what,
             std::string("consistent if rendered with pixel centres half a pixel off in ") + what +
                 " (the +0.5 pixel-centre offset missing or doubled)",
             camera, map, shifted);
    }
    // What the numbers are.
    if (map.quantity == DepthQuantity::EyeZ)
        test("distance-as-eye-z", "consistent if read as ray distance instead of eye-z", camera,
             remapped([](int, int, double v) { return v; }, DepthQuantity::Distance));
    if (map.quantity == DepthQuantity::Distance)
        test("eye-z-as-distance", "consistent if read as eye-z (planar depth) instead of ray distance", camera,
             remapped([](int, int, double v) { return v; }, DepthQuantity::EyeZ));
    if (map.quantity == DepthQuantity::Window) {
        test("eye-z-as-window", "consistent if read as eye-z (linear, scene units) instead of window depth", camera,
             remapped([](int, int, double v) { return v; }, DepthQuantity::EyeZ));
        test("distance-as-window", "consistent if read as ray distance instead of window depth", camera,
             remapped([](int, int, double v) { return v; }, DepthQuantity::Distance));
        const double n = camera.nearDistance(), f = camera.farDistance();
        if (!camera.farIsInfinite()) {
            const double lo = camera.depth().rangeMin, span = camera.depth().rangeMax - camera.depth().rangeMin;
            test("linear-window", "consistent if read as linear depth (z − near)/(far − near) instead of window depth", camera,
                 remapped([&](int, int, double v) {
                     return std::isfinite(v) && v != camera.clearDepth() ? n + (v - lo) / span * (f - n) : INFINITY;
                 }, DepthQuantity::EyeZ));
        }
    }
    // The projection: the other NDC depth range, reversed-Z, transposed, other-handed.
    if (camera.spec().projection.type != ProjectionType::Matrix) {
        variant([](CameraSpec& spec) {
            spec.convention.ndcDepth = spec.convention.ndcDepth == NdcDepthRange::ZeroToOne ? NdcDepthRange::MinusOneToOne
                                                                                            : NdcDepthRange::ZeroToOne;
        }, [&](const Camera& other) {
            matrixVariant("other-ndc-range",
                          std::string("consistent if the projection maps depth to ") +
                              (camera.convention().ndcDepth == NdcDepthRange::ZeroToOne ? "[-1,1] (an OpenGL-style matrix)"
                                                                                        : "[0,1] (a Direct3D-style matrix)") +
                              " while the viewport expects the convention's range",
                          other.clipFromEye);
        });
        variant([](CameraSpec& spec) { spec.depth.reversed = !spec.depth.reversed; }, [&](const Camera& c) {
            test("reversed", std::string("consistent if read as ") + (camera.depth().reversed ? "standard" : "reversed-Z") + " depth",
                 c, map);
        });
    }
    matrixVariant("transposed", "consistent if the projection matrix is transposed (row- vs column-major)",
                  glm::transpose(camera.clipFromEye));
    {
        glm::dmat4 mirror(1.0);
        mirror[0][0] = -1;
        matrixVariant("other-handed", "consistent if the eye's x axis is mirrored (a left- vs right-handed view)",
                      camera.clipFromEye * mirror);
    }
    // Small errors of field of view and aspect.
    if (camera.spec().projection.type == ProjectionType::Perspective) {
        for (double factor : {0.98, 0.99, 0.995, 1.005, 1.01, 1.02}) {
            variant([&](CameraSpec& spec) { spec.projection.fovyDeg *= factor; }, [&](const Camera& c) {
                char text[160];
                std::snprintf(text, sizeof text, "consistent with a vertical field of view of %.4g° instead of %.4g°",
                              c.spec().projection.fovyDeg, camera.spec().projection.fovyDeg);
                test("fovy", text, c, map);
            });
        }
        variant([&](CameraSpec& spec) { spec.projection.aspect = double(camera.height()) / camera.width(); }, [&](const Camera& c) {
            test("aspect-inverted", "consistent if the aspect ratio is height/width instead of width/height", c, map);
        });
    }
    return out;
}

}  // namespace zcheck
