#include "zcheck/embree_reference.h"

#include "zcheck/camera_rays.h"
#include "zcheck/detail/clock.h"
#include "zcheck/error.h"
#include "zcheck/ray_renderer.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace zcheck::reference {

namespace {

constexpr int kTile = 8;    // pixels per tile side
constexpr int kPacket = 4;  // a packet covers 4×4 pixels

// The ray route's own affine rays (camera_rays.h). A raw matrix has no such form in general:
// there, the affine rays through three pixels' rays (origin and near-plane point), exact for
// the usual perspective and orthographic matrices, and all a yardstick needs.
AffineRays yardstickRays(const Camera& camera)
{
    const CameraRays cameraRays(camera);
    if (const std::optional<AffineRays> rays = cameraRays.affine()) return *rays;
    auto at = [&](double x, double y, glm::dvec3& origin, glm::dvec3& direction) {
        const EyePlaneRay r = *cameraRays.worldRay({x, y});  // a raw matrix has a ray at every point
        origin = r.origin, direction = r.tNear * r.direction;
    };
    glm::dvec3 o00, d00, o10, d10, o01, d01;
    at(0.0, 0.0, o00, d00);
    at(1.0, 0.0, o10, d10);
    at(0.0, 1.0, o01, d01);
    return {o00, o10 - o00, o01 - o00, d00, d10 - d00, d01 - d00};
}

}  // namespace

struct EmbreeReference::Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    glm::dvec3 frameOrigin{0.0};  // as the ray route: binary32 coordinates centred on the scene
    glm::dvec3 worldFrameOrigin{0.0};  // that centre in the world (the scene may be held about Scene::origin)

    ~Embree()
    {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

EmbreeReference::EmbreeReference(const Scene& scene) : embree_(std::make_unique<Embree>())
{
    const auto start = Clock::now();
    const std::string config = embreeDeviceConfig();  // ZCHECK_EMBREE_ISA, as the check's trace takes it
    embree_->device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (!embree_->device) throw Error("reference: cannot create an Embree device");
    embree_->scene = rtcNewScene(embree_->device);
    rtcSetSceneFlags(embree_->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(embree_->scene, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), scene.positions.size()));
    // Indices shared, not copied, as the ray route does (the best an Embree user can do).
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, scene.triangles.data(), 0,
                               sizeof(glm::uvec3), scene.triangles.size());
    if (!vertices || rtcGetDeviceError(embree_->device) != RTC_ERROR_NONE) {
        rtcReleaseGeometry(geometry);
        throw Error("reference: Embree could not allocate geometry buffers");
    }
    embree_->frameOrigin = glm::dvec3(glm::vec3((scene.boundsMin() + scene.boundsMax()) / 2.0));
    embree_->worldFrameOrigin = scene.worldFromScene(embree_->frameOrigin);
    for (std::size_t v = 0; v < scene.positions.size(); ++v)
        for (int k = 0; k < 3; ++k) vertices[3 * v + k] = float(double(scene.positions[v][k]) - embree_->frameOrigin[k]);
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(embree_->scene, geometry, 0);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(embree_->scene);
    if (rtcGetDeviceError(embree_->device) != RTC_ERROR_NONE) throw Error("reference: Embree failed to build the BVH");
    buildMilliseconds_ = millisecondsSince(start);
}

EmbreeReference::~EmbreeReference() = default;

double EmbreeReference::trace(const Camera& camera, std::vector<std::uint32_t>& primitiveId) const
{
    primitiveId.resize(std::size_t(camera.width()) * camera.height());
    return trace(camera, primitiveId.data());
}

double EmbreeReference::trace(const Camera& camera, std::uint32_t* primitiveId) const
{
    const int W = camera.width(), H = camera.height();
    // The rays (set up outside the timing) in binary32 and the scene-centred frame: affine in the
    // pixel, or a lens model's from a table of every pixel's direction (NaN outside its field).
    const bool lens = camera.lens() != nullptr;
    const AffineRays rays = lens ? AffineRays{} : yardstickRays(camera);
    const glm::vec3 dOdx(rays.originPerX), dOdy(rays.originPerY), dDdx(rays.directionPerX), dDdy(rays.directionPerY);
    glm::vec3 o00(rays.originAt({0.5, 0.5}) - embree_->worldFrameOrigin), d00(rays.directionAt({0.5, 0.5}));
    std::vector<glm::vec3> directions;
    if (lens) {
        const CameraRays cameraRays(camera);
        directions.resize(std::size_t(W) * H);
        tbb::parallel_for(0, H, [&](int row) {
            for (int col = 0; col < W; ++col) {
                const std::optional<EyePlaneRay> ray = cameraRays.worldRay({col + 0.5, row + 0.5});
                directions[std::size_t(row) * W + col] = ray ? glm::vec3(ray->direction) : glm::vec3(NAN);
            }
        });
        for (std::size_t i = 0; i < directions.size(); ++i)  // every ray starts at the eye
            if (const std::optional<EyePlaneRay> ray = cameraRays.worldRay({i % W + 0.5, i / W + 0.5})) {
                o00 = glm::vec3(ray->origin - embree_->worldFrameOrigin);
                break;
            }
    }

    const int tilesX = (W + kTile - 1) / kTile, tilesY = (H + kTile - 1) / kTile;
    RTCScene scene = embree_->scene;
    const auto start = Clock::now();
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 4), [&](const tbb::blocked_range<int>& tiles) {
        const unsigned savedCsr = _mm_getcsr();
        _mm_setcsr(savedCsr | 0x8040);  // flush denormals, as Embree recommends
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(64) int valid[16];
        bool inImage[16];
        alignas(64) RTCRayHit16 packet;
        for (int tile = tiles.begin(); tile != tiles.end(); ++tile) {
            const int tileX = (tile % tilesX) * kTile, tileY = (tile / tilesX) * kTile;
            for (int py = 0; py < kTile; py += kPacket)
                for (int px = 0; px < kTile; px += kPacket) {
                    for (int k = 0; k < 16; ++k) {
                        const int col = tileX + px + k % kPacket, row = tileY + py + k / kPacket;
                        inImage[k] = col < W && row < H;
                        valid[k] = inImage[k] ? -1 : 0;
                        const float x = float(col), y = float(row);
                        glm::vec3 o = o00, d;
                        if (!lens) {
                            o = o00 + x * dOdx + y * dOdy, d = d00 + x * dDdx + y * dDdy;
                        } else if (valid[k]) {
                            d = directions[std::size_t(row) * W + col];
                            if (std::isnan(d.x)) valid[k] = 0, d = glm::vec3(0, 0, 1);
                        } else {
                            d = glm::vec3(0, 0, 1);
                        }
                        packet.ray.org_x[k] = o.x, packet.ray.org_y[k] = o.y, packet.ray.org_z[k] = o.z;
                        packet.ray.dir_x[k] = d.x, packet.ray.dir_y[k] = d.y, packet.ray.dir_z[k] = d.z;
                        packet.ray.tnear[k] = 0.0f;
                        packet.ray.tfar[k] = INFINITY;
                        packet.ray.time[k] = 0.0f;
                        packet.ray.mask[k] = 0xFFFFFFFFu;
                        packet.ray.id[k] = unsigned(k);
                        packet.ray.flags[k] = 0;
                        packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    }
                    rtcIntersect16(valid, scene, &context, &packet);
                    for (int k = 0; k < 16; ++k)  // a lens's pixel outside its field: no ray, nothing hit
                        if (inImage[k])
                            primitiveId[std::size_t(tileY + py + k / kPacket) * W + tileX + px + k % kPacket] =
                                packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? 0xFFFFFFFFu : packet.hit.primID[k];
                }
        }
        _mm_setcsr(savedCsr);
    });
    return millisecondsSince(start);
}

}  // namespace zcheck::reference
