#include "zcheck/ray_renderer.h"

#include "zcheck/error.h"
#include "zcheck/camera_rays.h"
#include "zcheck/inverse_projection.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <chrono>
#include <cmath>
#include <mutex>

namespace zcheck {

namespace {

using Clock = std::chrono::steady_clock;
double millisecondsSince(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct DeviceDeleter {
    void operator()(RTCDevice device) const { rtcReleaseDevice(device); }
};
struct SceneDeleter {
    void operator()(RTCScene scene) const { rtcReleaseScene(scene); }
};
struct GeometryDeleter {
    void operator()(RTCGeometry geometry) const { rtcReleaseGeometry(geometry); }
};
using DeviceHandle = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using SceneHandle = std::unique_ptr<RTCSceneTy, SceneDeleter>;
using GeometryHandle = std::unique_ptr<RTCGeometryTy, GeometryDeleter>;

// The first error Embree reports; checked after every set-up step.
struct ErrorLog {
    std::mutex mutex;
    std::string message;
};

void recordError(void* userPtr, RTCError code, const char* text)
{
    auto* log = static_cast<ErrorLog*>(userPtr);
    std::lock_guard<std::mutex> lock(log->mutex);
    if (log->message.empty())
        log->message = "Embree error " + std::to_string(int(code)) + (text ? std::string(": ") + text : "");
}

// Flush denormals to zero while tracing (Embree's recommendation); restores the caller's mode.
class FlushDenormals {
public:
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040); }  // FTZ | DAZ
    ~FlushDenormals() { _mm_setcsr(saved_); }

private:
    unsigned saved_;
};

constexpr int kRegion = 64;      // render() traces 64×64 regions in parallel
constexpr int kPacketSide = 4;   // a packet covers 4×4 pixels (rtcIntersect16)
constexpr int kPacketRays = kPacketSide * kPacketSide;

}  // namespace

struct RayRenderer::Embree {
    // Embree works in binary32 in a frame centred on the scene: world − frameOrigin. Rounding
    // a ray origin then errs by ~6e-8 of its distance to the scene, not of its distance to
    // the world origin (a mesh at x = 1000 would otherwise see its edges move by pixels).
    glm::dvec3 frameOrigin{0.0};
    ErrorLog errors;
    DeviceHandle device;
    SceneHandle scene;

    void check(const char* step)
    {
        std::lock_guard<std::mutex> lock(errors.mutex);
        if (!errors.message.empty()) throw Error(std::string("Embree failed while ") + step + ": " + errors.message);
    }
};

RayRenderer::RayRenderer(const Scene& scene) : embree_(std::make_unique<Embree>()), scene_(scene)
{
    validateScene(scene);
    const auto start = Clock::now();
    embree_->device.reset(rtcNewDevice(nullptr));
    if (!embree_->device) throw Error("cannot create an Embree device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    // Install the error callback first, so every later failure is seen.
    rtcSetDeviceErrorFunction(embree_->device.get(), recordError, &embree_->errors);

    embree_->scene.reset(rtcNewScene(embree_->device.get()));
    rtcSetSceneFlags(embree_->scene.get(), RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(embree_->scene.get(), RTC_BUILD_QUALITY_MEDIUM);

    // Released when this scope ends, after the scene has taken its own reference (or on a throw).
    const GeometryHandle geometry(rtcNewGeometry(embree_->device.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
    embree_->check("creating the triangle geometry");
    // The vertices are Embree's own copy, in a frame centred on the scene, padded as Embree
    // requires (vertex reads may run 16 bytes past the end: rtcSetNewGeometryBuffer pads).
    // The indices are the scene's own (12-byte triples, as Embree reads them; a Scene outlives
    // its renderers): 12 MB less to copy and fault in for a million triangles.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0,
                                                                 RTC_FORMAT_FLOAT3, 3 * sizeof(float), scene.positions.size()));
    static_assert(sizeof(glm::uvec3) == 3 * sizeof(unsigned), "indices are shared as tight triples");
    rtcSetSharedGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, scene.triangles.data(), 0,
                               sizeof(glm::uvec3), scene.triangles.size());
    embree_->check("setting the geometry buffers");
    if (!vertices) throw Error("Embree could not allocate geometry buffers");
    embree_->frameOrigin = glm::dvec3(glm::vec3((scene.boundsMin() + scene.boundsMax()) / 2.0));
    for (std::size_t v = 0; v < scene.positions.size(); ++v)
        for (int k = 0; k < 3; ++k)
            vertices[3 * v + k] = float(double(scene.positions[v][k]) - embree_->frameOrigin[k]);
    rtcCommitGeometry(geometry.get());  // commit before attaching, or no intersections
    rtcAttachGeometryByID(embree_->scene.get(), geometry.get(), 0);
    rtcCommitScene(embree_->scene.get());
    embree_->check("building the BVH");
    buildMilliseconds_ = millisecondsSince(start);
}

RayRenderer::~RayRenderer() = default;

std::uint32_t RayRenderer::primitiveAt(const Camera& camera, const glm::dvec2& pWindow) const
{
    const EyePlaneRay r = worldEyePlaneRayThroughWindow(camera, pWindow);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    alignas(16) RTCRayHit hit{};
    hit.ray.org_x = float(r.origin.x - embree_->frameOrigin.x);
    hit.ray.org_y = float(r.origin.y - embree_->frameOrigin.y);
    hit.ray.org_z = float(r.origin.z - embree_->frameOrigin.z);
    hit.ray.dir_x = float(r.direction.x), hit.ray.dir_y = float(r.direction.y), hit.ray.dir_z = float(r.direction.z);
    hit.ray.tnear = float(r.tNear);
    hit.ray.tfar = std::isinf(r.tFar) ? INFINITY : float(r.tFar);
    hit.ray.mask = 0xFFFFFFFFu;
    hit.hit.geomID = hit.hit.primID = RTC_INVALID_GEOMETRY_ID;
    hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(embree_->scene.get(), &context, &hit);
    return hit.hit.geomID == RTC_INVALID_GEOMETRY_ID ? kNoPrimitive : hit.hit.primID;
}

RenderResult RayRenderer::render(const Camera& camera, const RayFaults& fault, EyePoints eyePoints) const
{
    const auto start = Clock::now();
    const int W = camera.width(), H = camera.height();
    RenderResult result = RenderResult::cleared(W, H, camera.clearDepth());
    if (eyePoints == EyePoints::Keep) assignLarge(result.pEye, std::size_t(W) * H, glm::dvec3(NAN));
    // 64×64 regions in parallel (a region's set-up, the camera's rays, is made once).
    const int regionsX = (W + kRegion - 1) / kRegion, regionsY = (H + kRegion - 1) / kRegion;
    tbb::parallel_for(0, regionsX * regionsY, [&](int region) {
        const int col0 = (region % regionsX) * kRegion, row0 = (region / regionsX) * kRegion;
        const std::size_t first = std::size_t(row0) * W + col0;
        traceRect(camera, col0, row0, std::min(W, col0 + kRegion), std::min(H, row0 + kRegion),
                  result.windowDepth.value.data() + first, result.primitiveId.data() + first, std::size_t(W), fault,
                  eyePoints == EyePoints::Keep ? result.pEye.data() + first : nullptr);
    });
    result.renderMilliseconds = millisecondsSince(start);
    return result;
}

void RayRenderer::traceRect(const Camera& camera, int col0, int row0, int col1, int row1, double* windowDepth,
                            std::uint32_t* primitiveId, std::size_t stride, const RayFaults& fault, glm::dvec3* pEye) const
{
    const int W = camera.width(), H = camera.height();
    RTCScene rtcScene = embree_->scene.get();
    const CameraRays cameraRays(camera);
    const std::optional<AffineRays> affine = cameraRays.affine();
    const double near = camera.nearDistance(), far = camera.farDistance(), clearDepth = camera.clearDepth();
    const glm::dvec3 frameOrigin = embree_->frameOrigin;

    FlushDenormals flush;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) int valid[kPacketRays];
    alignas(64) RTCRayHit16 packet;
    alignas(64) double imageX[kPacketRays], imageY[kPacketRays];  // the rays' image points
    alignas(64) double lane[6][kPacketRays];  // origin x, y, z and direction x, y, z, in double
    auto originOf = [&](int k) { return glm::dvec3(lane[0][k], lane[1][k], lane[2][k]); };
    auto directionOf = [&](int k) { return glm::dvec3(lane[3][k], lane[4][k], lane[5][k]); };
    auto pImageOf = [&](int k) { return glm::dvec2(imageX[k], imageY[k]); };

    for (int py = row0; py < row1; py += kPacketSide) {
        for (int px = col0; px < col1; px += kPacketSide) {
            // Lanes as plain arrays, one quantity at a time, so that the compiler can compute
            // several lanes per instruction. Every field of every lane is initialised, valid
            // or not; an invalid lane (outside the rectangle) is a zero-length ray.
            for (int k = 0; k < kPacketRays; ++k) {
                const int col = px + k % kPacketSide, row = py + k / kPacketSide;
                valid[k] = (col < col1 && row < row1) ? -1 : 0;
                const int sampleRow = fault.flipRows ? H - 1 - row : row;
                const int sampleCol = fault.flipCols ? W - 1 - col : col;
                const glm::dvec2 pWindow = windowFromPixelCentre(camera, sampleCol, sampleRow) + fault.shiftPixels;
                imageX[k] = pWindow.x, imageY[k] = camera.imageYFromWindowY(pWindow.y);
            }
            float tNear[kPacketRays], tFar[kPacketRays];
            if (affine) {  // t is eye-z: the near and far planes lie at t = near and far
                for (int c = 0; c < 3; ++c) {
                    const double o = affine->origin[c], oX = affine->originPerX[c], oY = affine->originPerY[c];
                    const double d = affine->direction[c], dX = affine->directionPerX[c], dY = affine->directionPerY[c];
                    for (int k = 0; k < kPacketRays; ++k) {
                        lane[c][k] = o + imageX[k] * oX + imageY[k] * oY;
                        lane[3 + c][k] = d + imageX[k] * dX + imageY[k] * dY;
                    }
                }
                const float nearT = float(near), farT = std::isinf(far) ? INFINITY : float(far);
                for (int k = 0; k < kPacketRays; ++k) tNear[k] = nearT, tFar[k] = farT;
            } else {
                for (int k = 0; k < kPacketRays; ++k) {
                    const EyePlaneRay r = cameraRays.worldRay(pImageOf(k));
                    for (int c = 0; c < 3; ++c) lane[c][k] = r.origin[c], lane[3 + c][k] = r.direction[c];
                    tNear[k] = float(r.tNear), tFar[k] = std::isinf(r.tFar) ? INFINITY : float(r.tFar);
                }
            }
            for (int k = 0; k < kPacketRays; ++k) {
                if (valid[k]) continue;
                for (int c = 0; c < 3; ++c) lane[c][k] = frameOrigin[c], lane[3 + c][k] = c == 2 ? 1.0 : 0.0;
                tNear[k] = 0, tFar[k] = 0;
            }
            for (int k = 0; k < kPacketRays; ++k) {
                packet.ray.org_x[k] = float(lane[0][k] - frameOrigin.x);
                packet.ray.org_y[k] = float(lane[1][k] - frameOrigin.y);
                packet.ray.org_z[k] = float(lane[2][k] - frameOrigin.z);
                packet.ray.dir_x[k] = float(lane[3][k]);
                packet.ray.dir_y[k] = float(lane[4][k]);
                packet.ray.dir_z[k] = float(lane[5][k]);
                packet.ray.tnear[k] = tNear[k];
                packet.ray.tfar[k] = tFar[k];
                packet.ray.time[k] = 0.0f;
                packet.ray.mask[k] = 0xFFFFFFFFu;  // Debian's Embree has ray masks on
                packet.ray.id[k] = unsigned(k);
                packet.ray.flags[k] = 0;
                packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                packet.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
                packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, rtcScene, &context, &packet);
            // The hit triangles' indices and vertices lie scattered over the scene's arrays:
            // ask for all of them before using any, so their cache misses overlap.
            auto hitAt = [&](int k) { return valid[k] && packet.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID; };
            for (int k = 0; k < kPacketRays; ++k)
                if (hitAt(k)) __builtin_prefetch(&scene_.triangles[packet.hit.primID[k]]);
            for (int k = 0; k < kPacketRays; ++k)
                if (hitAt(k))
                    for (int corner = 0; corner < 3; ++corner)
                        __builtin_prefetch(&scene_.positions[scene_.triangles[packet.hit.primID[k]][corner]]);
            // Neighbouring rays mostly hit the same triangle: its plane is kept.
            std::uint32_t planeOf = RTC_INVALID_GEOMETRY_ID;
            glm::dvec3 a(0.0), normal(0.0);
            for (int k = 0; k < kPacketRays; ++k) {
                if (!valid[k]) continue;
                const std::size_t i = std::size_t(py + k / kPacketSide - row0) * stride + std::size_t(px + k % kPacketSide - col0);
                if (!hitAt(k)) {  // every pixel of the rectangle is written
                    primitiveId[i] = kNoPrimitive;
                    windowDepth[i] = clearDepth;
                    if (pEye) pEye[i] = glm::dvec3(NAN);
                    continue;
                }
                const std::uint32_t primitive = packet.hit.primID[k];
                if (primitive != planeOf) {
                    const glm::uvec3& tri = scene_.triangles[primitive];
                    a = glm::dvec3(scene_.positions[tri[0]]);
                    normal = glm::cross(glm::dvec3(scene_.positions[tri[1]]) - a, glm::dvec3(scene_.positions[tri[2]]) - a);
                    planeOf = primitive;
                }
                // The hit again, in double: the ray against the hit triangle's plane.
                const glm::dvec3 origin = originOf(k), direction = directionOf(k);
                double t = glm::dot(normal, a - origin) / glm::dot(normal, direction);
                if (!std::isfinite(t)) t = packet.ray.tfar[k];
                const glm::dvec3 pWorld = origin + t * direction;
                primitiveId[i] = primitive;
                if (pEye) pEye[i] = cameraRays.eyeFromWorld(pWorld);
                // The fault "distance as eye-z" takes the distance along the ray for eye-z.
                const double eyeZ = fault.distanceAsEyeZ ? t * glm::length(direction) : cameraRays.eyeZ(pWorld);
                windowDepth[i] = cameraRays.windowDepth(pImageOf(k), eyeZ);
            }
        }
    }
}

}  // namespace zcheck
