#include "zcheck/ray_renderer.h"

#include "zcheck/camera_rays.h"
#include "zcheck/detail/clock.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/detail/streaming_stores.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/large_buffer.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <immintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <mutex>

namespace zcheck {

namespace {

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

// A packet of rays between its trace and its re-evaluation in double (traceRect keeps two
// in flight): its rays in double and as Embree traced them, and Embree's hits.
struct PacketInFlight {
    int col0, row0;  // the packet's top-left pixel
    alignas(64) int valid[kPacketRays];
    alignas(64) RTCRayHit16 packet;
    alignas(64) double imageX[kPacketRays], imageY[kPacketRays];  // the rays' image points
    alignas(64) double lane[6][kPacketRays];  // origin x, y, z and direction x, y, z, in double

    alignas(64) int hits[kPacketRays];  // after the trace: lane valid and hit, −1; else 0 (noteHits)

    glm::dvec2 pImage(int k) const { return {imageX[k], imageY[k]}; }
    glm::dvec3 origin(int k) const { return {lane[0][k], lane[1][k], lane[2][k]}; }
    glm::dvec3 direction(int k) const { return {lane[3][k], lane[4][k], lane[5][k]}; }
    // Once per packet, every lane at once (asked as `valid && hit` per lane, it compiled to two
    // branches per lane in every loop that asked).
    void noteHits()
    {
        for (int k = 0; k < kPacketRays; ++k)
            hits[k] = -int((valid[k] != 0) & (packet.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID));
    }
    bool hit(int k) const { return hits[k] != 0; }
};

// A triangle's plane as the re-evaluation reads it, made once per scene: the normal
// cross(b − a, c − a) in double and the first corner a, binary32 as the scene holds it (exact
// in double), so the same values the re-evaluation computed from the corners per hit before.
// A hit now reads one 40-byte entry, where it read an index triple and three vertices far
// apart, and computes no cross product.
struct HitPlane {
    double normal[3];
    float vertex[3];
    float unused;  // zero
};
static_assert(sizeof(HitPlane) == 40, "5 entries in 200 bytes: half of them span two cache lines");

// Triangle t's HitPlane, from its corners.
ZCHECK_ALWAYS_INLINE inline HitPlane hitPlaneOf(const Scene& scene, std::uint32_t t)
{
    const glm::uvec3& corners = scene.triangles[t];
    const glm::vec3& a = scene.positions[corners[0]];
    const glm::dvec3 b(scene.positions[corners[1]]), c(scene.positions[corners[2]]);
    const glm::dvec3 normal = glm::cross(b - glm::dvec3(a), c - glm::dvec3(a));
    HitPlane plane;
    for (int axis = 0; axis < 3; ++axis) plane.normal[axis] = normal[axis], plane.vertex[axis] = a[axis];
    plane.unused = 0;
    return plane;
}

LargeVector<HitPlane> hitPlanesOf(const Scene& scene)
{
    LargeVector<HitPlane> planes;  // on huge pages (40 MB for a million triangles)
    planes.resize(scene.triangles.size());  // uninitialised: each entry written below
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, scene.triangles.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i)
                              planes[i] = hitPlaneOf(scene, std::uint32_t(i));
                      });
    return planes;
}

// Where a hit's plane comes from: the table (a thorough build's, made with the BVH), or, without
// one (a quick build's: its 40 bytes a triangle are more to fault in than a one-frame check
// reads back), the hit triangle's corners, computed as the table is (the same bits).
struct PlaneSource {
    const HitPlane* table;  // by primitive id, or null
    const Scene& scene;
};

}  // namespace

struct RayRenderer::Embree {
    // Embree works in binary32 in a frame centred on the scene: world − frameOrigin. Rounding
    // a ray origin then errs by ~6e-8 of its distance to the scene, not of its distance to
    // the world origin (a mesh at x = 1000 would otherwise see its edges move by pixels).
    glm::dvec3 frameOrigin{0.0};
    ErrorLog errors;
    DeviceHandle device;
    SceneHandle scene;
    LargeVector<HitPlane> planes;  // by primitive id (hitPlanesOf); empty for a quick build (PlaneSource)

    void check(const char* step)
    {
        std::lock_guard<std::mutex> lock(errors.mutex);
        if (!errors.message.empty()) throw Error(std::string("Embree failed while ") + step + ": " + errors.message);
    }
};

BvhBuild bvhBuildFor(double expectedRays, std::size_t triangles)
{
    return expectedRays < kQuickBuildRaysPerTriangle * double(triangles) ? BvhBuild::Quick : BvhBuild::Thorough;
}

const char* nameOf(BvhBuild build) { return build == BvhBuild::Quick ? "quick" : "thorough"; }

namespace {

// Embree's instruction sets by its names, each with what it adds to the one before it (as
// Embree's own, each set needs the ones before it too: its AVX2 kernels are AVX with F16C, AVX2,
// FMA, BMI1, BMI2 and LZCNT; its AVX-512 ones SKX's F, CD, DQ, BW and VL besides). `adds` says
// whether this processor has those (x86-64 only: elsewhere every set is refused and only auto
// is taken).
struct EmbreeSet {
    const char* name;
    const char* needs;
    bool (*adds)();
};
#ifdef ZCHECK_X86_FORMS
#define ZCHECK_HAS(feature) __builtin_cpu_supports(feature)
#else
#define ZCHECK_HAS(feature) false
#endif
constexpr EmbreeSet kEmbreeSets[] = {
    {"sse2", "SSE2", []() -> bool { return ZCHECK_HAS("sse2"); }},
    {"sse4.2", "SSE4.2 and POPCNT", []() -> bool { return ZCHECK_HAS("sse4.2") && ZCHECK_HAS("popcnt"); }},
    {"avx", "AVX, SSE4.2 and POPCNT", []() -> bool { return ZCHECK_HAS("avx"); }},
    {"avx2", "AVX2, FMA, F16C, BMI1, BMI2 and LZCNT besides AVX",
     []() -> bool {
         return ZCHECK_HAS("avx2") && ZCHECK_HAS("fma") && ZCHECK_HAS("f16c") && ZCHECK_HAS("bmi") && ZCHECK_HAS("bmi2") &&
                ZCHECK_HAS("lzcnt");
     }},
    {"avx512", "AVX-512 F, CD, DQ, BW and VL besides AVX2's",
     []() -> bool {
         return ZCHECK_HAS("avx512f") && ZCHECK_HAS("avx512cd") && ZCHECK_HAS("avx512dq") && ZCHECK_HAS("avx512bw") &&
                ZCHECK_HAS("avx512vl");
     }},
};
#undef ZCHECK_HAS

// Whether this processor runs Embree's set k: it has what each set up to k adds.
bool processorRuns(std::size_t k)
{
    for (std::size_t j = 0; j <= k; ++j)
        if (!kEmbreeSets[j].adds()) return false;
    return true;
}

// "auto, sse2, sse4.2, avx, avx2 or avx512".
std::string embreeSetNames()
{
    std::string names = "auto";
    const std::size_t n = std::size(kEmbreeSets);
    for (std::size_t k = 0; k < n; ++k) names += std::string(k + 1 < n ? ", " : " or ") + kEmbreeSets[k].name;
    return names;
}

}  // namespace

std::string embreeIsa()
{
    const char* requested = std::getenv("ZCHECK_EMBREE_ISA");
    if (!requested || !*requested || std::strcmp(requested, "auto") == 0) return "auto";
    for (std::size_t k = 0; k < std::size(kEmbreeSets); ++k) {
        const EmbreeSet& set = kEmbreeSets[k];
        if (std::strcmp(requested, set.name) != 0) continue;
        if (!processorRuns(k))
            throw Error(std::string("ZCHECK_EMBREE_ISA=") + requested + ": this processor cannot run Embree's " +
                        requested + " kernels (they need " + set.needs + "); use auto, or a set it has");
        return set.name;
    }
    throw Error(std::string("ZCHECK_EMBREE_ISA=") + requested + ": must be " + embreeSetNames());
}

std::string embreeAutoIsa()
{
    std::string widest;  // none off x86-64
    for (std::size_t k = 0; k < std::size(kEmbreeSets) && processorRuns(k); ++k) widest = kEmbreeSets[k].name;
    return widest;
}

std::string embreeDeviceConfig()
{
    const std::string isa = embreeIsa();
    return isa == "auto" ? std::string() : "isa=" + isa;
}

RayRenderer::RayRenderer(const Scene& scene, BvhBuild build)
    : embree_(std::make_unique<Embree>()), scene_(scene), form_(kernelForm()), build_(build)
{
    validateScene(scene);
    const auto start = Clock::now();
    const std::string config = embreeDeviceConfig();
    embree_->device.reset(rtcNewDevice(config.empty() ? nullptr : config.c_str()));
    if (!embree_->device) throw Error("cannot create an Embree device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    // Install the error callback first, so every later failure is seen.
    rtcSetDeviceErrorFunction(embree_->device.get(), recordError, &embree_->errors);

    embree_->scene.reset(rtcNewScene(embree_->device.get()));
    const bool quick = build == BvhBuild::Quick;
    rtcSetSceneFlags(embree_->scene.get(),
                     quick ? RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT) : RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(embree_->scene.get(), quick ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);

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
    const glm::dvec3 centre = (scene.boundsMin() + scene.boundsMax()) / 2.0;
    embree_->frameOrigin = {roundedToBinary32(centre.x), roundedToBinary32(centre.y), roundedToBinary32(centre.z)};
    for (std::size_t v = 0; v < scene.positions.size(); ++v)
        for (int k = 0; k < 3; ++k)
            vertices[3 * v + k] = float(double(scene.positions[v][k]) - embree_->frameOrigin[k]);
    // The mesh's own BVH: the scene's quality sets only the level above it (Embree builds the
    // mesh's at MEDIUM unless told; only this made the quick build quick: 10 M triangles ~0.7 s
    // against ~3 s).
    rtcSetGeometryBuildQuality(geometry.get(), quick ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitGeometry(geometry.get());  // commit before attaching, or no intersections
    rtcAttachGeometryByID(embree_->scene.get(), geometry.get(), 0);
    rtcCommitScene(embree_->scene.get());
    embree_->check("building the BVH");
    if (!quick) embree_->planes = hitPlanesOf(scene);  // a quick build's trace reads the corners (PlaneSource)
    buildMilliseconds_ = millisecondsSince(start);
}

RayRenderer::~RayRenderer() = default;

int RayRenderer::embreeNativePacket() const
{
    RTCDevice device = embree_->device.get();
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) return 16;
    if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) return 8;
    return 4;
}

std::uint32_t RayRenderer::primitiveAt(const Camera& camera, const glm::dvec2& pWindow) const
{
    const EyePlaneRay r = worldEyePlaneRayThroughWindow(camera, pWindow);
    const glm::dvec3 origin = r.origin - scene_.origin;  // in the scene's frame (the same bits at a zero origin)
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    alignas(16) RTCRayHit hit{};
    hit.ray.org_x = float(origin.x - embree_->frameOrigin.x);
    hit.ray.org_y = float(origin.y - embree_->frameOrigin.y);
    hit.ray.org_z = float(origin.z - embree_->frameOrigin.z);
    hit.ray.dir_x = float(r.direction.x), hit.ray.dir_y = float(r.direction.y), hit.ray.dir_z = float(r.direction.z);
    hit.ray.tnear = float(std::max(0.0, r.tNear));  // see traceRect
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
    const CameraInSceneFrame local(scene_, camera);
    RenderResult result = RenderResult::allocated(W, H);  // traceRect writes every pixel, hit or not
    if (eyePoints == EyePoints::Keep) result.pEye.resize(std::size_t(W) * H);  // uninitialised: traceRect writes each
    // 64×64 regions in parallel (a region's set-up, the camera's rays, is made once). Each is
    // traced into a buffer of the worker's own and then copied into the image a row at a time:
    // written straight into the image, a packet's four rows went to eight cache lines far apart
    // that were not in the cache, and the stores waiting on them stalled the packets behind
    // (the trace 88–92 → 70–79 ms for the speed workload); streaming stores where they can
    // (large_buffer.h) made it ~5 % faster again. Eye points too (a lens check's trace, whose
    // eye points written straight cost it a third more: 128 against 91 ms on the panorama workload).
    const TileGrid regions(W, H, kRegion);
    tbb::parallel_for(0, regions.count(), [&](int region) {
        const PixelRect rect = regions.rect(region);
        const std::size_t first = regions.firstPixel(region);
        alignas(64) thread_local double depth[kRegion * kRegion];
        alignas(64) thread_local std::uint32_t primitive[kRegion * kRegion];
        alignas(64) thread_local glm::dvec3 eye[kRegion * kRegion];
        const bool keep = eyePoints == EyePoints::Keep;
        traceRectInSceneFrame(local.get(), rect, depth, primitive, kRegion, fault, keep ? eye : nullptr);
        for (int r = 0; r < rect.height(); ++r) {
            const std::size_t to = first + std::size_t(r) * std::size_t(W), from = std::size_t(r) * kRegion;
            copyRowStreaming(depth + from, std::size_t(rect.width()), result.windowDepth.value.data() + to);
            copyRowStreaming(primitive + from, std::size_t(rect.width()), result.primitiveId.data() + to);
            if (keep)
                copyRowStreaming(&eye[from].x, 3 * std::size_t(rect.width()), &result.pEye[to].x);  // x, y, z doubles
        }
        finishStreamingCopies();
    });
    result.renderMilliseconds = millisecondsSince(start);
    return result;
}

namespace {

#ifdef ZCHECK_X86_FORMS
// The vector forms' reading of a packet's planes (the baseline form reads them lane by lane):
// four entries at a time, each as one 32-byte load (the normal and the vertex's x and y) and
// one of 8 bytes (its z), transposed into the lanes. The same values: only the loads differ.
// (Lane by lane, GCC made 96 scalar loads and as many inserts per packet.)
ZCHECK_INTRINSICS_BEGIN
ZCHECK_TARGET_AVX2 inline void planesInLanes(const HitPlane* planes, const std::uint32_t* triangle,
                                                     double (*plane)[kPacketRays])
{
    static_assert(kPacketRays % 4 == 0 && offsetof(HitPlane, vertex) == 24, "four entries at a time, as laid out");
    for (int k = 0; k < kPacketRays; k += 4) {
        const double* e[4];
        __m256d r[4];  // nx ny nz (vx vy)
        for (int j = 0; j < 4; ++j) e[j] = reinterpret_cast<const double*>(planes + triangle[k + j]), r[j] = _mm256_loadu_pd(e[j]);
        const __m256d x0x1z0z1 = _mm256_unpacklo_pd(r[0], r[1]), y0y1v0v1 = _mm256_unpackhi_pd(r[0], r[1]);
        const __m256d x2x3z2z3 = _mm256_unpacklo_pd(r[2], r[3]), y2y3v2v3 = _mm256_unpackhi_pd(r[2], r[3]);
        _mm256_store_pd(plane[3] + k, _mm256_permute2f128_pd(x0x1z0z1, x2x3z2z3, 0x20));
        _mm256_store_pd(plane[4] + k, _mm256_permute2f128_pd(y0y1v0v1, y2y3v2v3, 0x20));
        _mm256_store_pd(plane[5] + k, _mm256_permute2f128_pd(x0x1z0z1, x2x3z2z3, 0x31));
        // The vertices: x0 y0 x1 y1 x2 y2 x3 y3 as binary32, then x0..x3 and y0..y3; z0..z3 from
        // the second loads (z and the unused word of each entry).
        const __m256 xy = _mm256_castpd_ps(_mm256_permute2f128_pd(y0y1v0v1, y2y3v2v3, 0x31));
        const __m256 xxyy = _mm256_permutevar8x32_ps(xy, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
        const __m128 z01 = _mm_castpd_ps(_mm_loadh_pd(_mm_load_sd(e[0] + 4), e[1] + 4));
        const __m128 z23 = _mm_castpd_ps(_mm_loadh_pd(_mm_load_sd(e[2] + 4), e[3] + 4));
        _mm256_store_pd(plane[0] + k, _mm256_cvtps_pd(_mm256_castps256_ps128(xxyy)));
        _mm256_store_pd(plane[1] + k, _mm256_cvtps_pd(_mm256_extractf128_ps(xxyy, 1)));
        _mm256_store_pd(plane[2] + k, _mm256_cvtps_pd(_mm_shuffle_ps(z01, z23, _MM_SHUFFLE(2, 0, 2, 0))));
    }
}
ZCHECK_INTRINSICS_END
#endif

// RayRenderer::traceRect's work, inlined into one function per form (kernel_choice.h). Its
// per-packet steps below, and the lambdas of traceRectBody that call them, are inlined too (the
// entry functions flatten them), or they would stay baseline code. The arrays that finish's
// steps share are declared in its lambda and passed by reference, as arrays: so every form
// compiles to the code the uncut body did (declared inside the steps, as
// triangle and tEmbree were, or passed as pointers, GCC laid out and scheduled the loop anew).

// A rectangle as the per-packet steps read it, made once: its pixels [col0, col1) × [row0, row1)
// of the W×H image and where they go (traceRect's contract), the camera's depths and window origin.
struct RectSetUp {
    int col0, row0, col1, row1;
    int W, H;
    double near, far, clearDepth;  // in the order they are read from the camera
    bool windowOriginTop;          // else y_image = H − y_window
    double height;                 // H
    double* windowDepth;
    std::uint32_t* primitiveId;
    std::size_t stride;
    glm::dvec3* pEye;  // may be null
};

// Packet p at pixel (px, py): which of its lanes lie in the rectangle (p.valid), each lane's image point.
ZCHECK_ALWAYS_INLINE inline void imagePointsOfPacket(PacketInFlight& p, int px, int py, const RectSetUp& setUp,
                                                     const RayFaults& fault)
{
    p.col0 = px, p.row0 = py;
    // The image points: windowFromPixelCentre plus the shift, then imageYFromWindowY,
    // spelt out so that this loop too computes several lanes per instruction.
    for (int k = 0; k < kPacketRays; ++k) {
        const int col = px + k % kPacketSide, row = py + k / kPacketSide;
        p.valid[k] = (col < setUp.col1 && row < setUp.row1) ? -1 : 0;
        const int sampleRow = fault.flipRows ? setUp.H - 1 - row : row;
        const int sampleCol = fault.flipCols ? setUp.W - 1 - col : col;
        const double yImage = sampleRow + 0.5;
        const double xWindow = (sampleCol + 0.5) + fault.shiftPixels.x;
        const double yWindow = (setUp.windowOriginTop ? yImage : setUp.height - yImage) + fault.shiftPixels.y;
        p.imageX[k] = xWindow, p.imageY[k] = setUp.windowOriginTop ? yWindow : setUp.height - yWindow;
    }
}

// Each lane's ray through its image point, in double (p.lane), and its [tnear, tfar] for Embree.
ZCHECK_ALWAYS_INLINE inline void raysOfPacket(PacketInFlight& p, const std::optional<AffineRays>& affine,
                                              const CameraRays& cameraRays, const RectSetUp& setUp)
{
    RTCRay16& ray = p.packet.ray;
    if (affine) {  // t is eye-z: the near and far planes lie at t = near and far
        for (int c = 0; c < 3; ++c) {
            const double o = affine->origin[c], oX = affine->originPerX[c], oY = affine->originPerY[c];
            const double d = affine->direction[c], dX = affine->directionPerX[c], dY = affine->directionPerY[c];
            // Origins and directions in loops apart: in one loop, GCC made the origins lane by lane.
            for (int k = 0; k < kPacketRays; ++k) p.lane[c][k] = o + p.imageX[k] * oX + p.imageY[k] * oY;
            for (int k = 0; k < kPacketRays; ++k) p.lane[3 + c][k] = d + p.imageX[k] * dX + p.imageY[k] * dY;
        }
        const float nearT = float(setUp.near), farT = std::isinf(setUp.far) ? INFINITY : float(setUp.far);
        for (int k = 0; k < kPacketRays; ++k) ray.tnear[k] = nearT, ray.tfar[k] = farT;
    } else if (cameraRays.lens()) {  // t is the distance along a unit ray from the eye
        const glm::dvec3& eye = cameraRays.eye();
        const float nearT = float(setUp.near), farT = std::isinf(setUp.far) ? INFINITY : float(setUp.far);
        for (int k = 0; k < kPacketRays; ++k) {
            if (!p.valid[k]) continue;
            // A pixel centre (every lane but a fault's shifted one) from the lens's table.
            const int col = int(p.imageX[k]), row = int(p.imageY[k]);
            glm::dvec3 direction;
            if (col + 0.5 == p.imageX[k] && row + 0.5 == p.imageY[k] && col < setUp.W && row < setUp.H) {
                if (!cameraRays.lensDirectionAtPixel(col, row, direction)) {
                    p.valid[k] = 0;  // outside the lens's field: no ray, a miss (embreeLanesOfPacket fills the lane)
                    continue;
                }
            } else if (const std::optional<EyePlaneRay> ray1 = cameraRays.worldRay(p.pImage(k))) {
                direction = ray1->direction;
            } else {
                p.valid[k] = 0;
                continue;
            }
            for (int c = 0; c < 3; ++c) p.lane[c][k] = eye[c], p.lane[3 + c][k] = direction[c];
            ray.tnear[k] = nearT, ray.tfar[k] = farT;
        }
    } else {
        for (int k = 0; k < kPacketRays; ++k) {
            if (!p.valid[k]) continue;
            const std::optional<EyePlaneRay> ray1 = cameraRays.worldRay(p.pImage(k));
            if (!ray1) {  // outside a lens's field: no ray, a miss (embreeLanesOfPacket fills the lane)
                p.valid[k] = 0;
                continue;
            }
            const EyePlaneRay& r = *ray1;
            for (int c = 0; c < 3; ++c) p.lane[c][k] = r.origin[c], p.lane[3 + c][k] = r.direction[c];
            // A raw matrix whose near plane crosses the eye plane puts it behind the eye at
            // some pixels: the camera sees nothing behind its eye plane (and Embree takes no
            // negative tnear).
            ray.tnear[k] = float(std::max(0.0, r.tNear)), ray.tfar[k] = std::isinf(r.tFar) ? INFINITY : float(r.tFar);
        }
    }
}

// The rest of every lane for Embree: an invalid one a zero-length ray, all in binary32 in Embree's frame, no hit.
ZCHECK_ALWAYS_INLINE inline void embreeLanesOfPacket(PacketInFlight& p, const glm::dvec3& frameOrigin)
{
    RTCRay16& ray = p.packet.ray;
    for (int k = 0; k < kPacketRays; ++k) {
        if (p.valid[k]) continue;
        for (int c = 0; c < 3; ++c) p.lane[c][k] = frameOrigin[c], p.lane[3 + c][k] = c == 2 ? 1.0 : 0.0;
        ray.tnear[k] = 0, ray.tfar[k] = 0;
    }
    for (int k = 0; k < kPacketRays; ++k) {
        ray.org_x[k] = float(p.lane[0][k] - frameOrigin.x);
        ray.org_y[k] = float(p.lane[1][k] - frameOrigin.y);
        ray.org_z[k] = float(p.lane[2][k] - frameOrigin.z);
        ray.dir_x[k] = float(p.lane[3][k]);
        ray.dir_y[k] = float(p.lane[4][k]);
        ray.dir_z[k] = float(p.lane[5][k]);
        ray.time[k] = 0.0f;
        ray.mask[k] = 0xFFFFFFFFu;  // Debian's Embree has ray masks on
        ray.id[k] = unsigned(k);
        ray.flags[k] = 0;
        p.packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        p.packet.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
        p.packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
}

// Traces the packet (Embree's hits in p.packet, then p.hits) and asks for the hit planes its finish reads.
ZCHECK_ALWAYS_INLINE inline void intersectPacket(PacketInFlight& p, RTCScene rtcScene, RTCIntersectContext& context,
                                                 const PlaneSource& planes)
{
    rtcIntersect16(p.valid, rtcScene, &context, &p.packet);
    p.noteHits();
    for (int k = 0; k < kPacketRays; ++k)  // the hit planes asked for: both ends of each entry (or the index triple)
        if (p.hit(k)) {
            const char* entry = planes.table ? reinterpret_cast<const char*>(planes.table + p.packet.hit.primID[k])
                                             : reinterpret_cast<const char*>(&planes.scene.triangles[p.packet.hit.primID[k]]);
            __builtin_prefetch(entry);
            __builtin_prefetch(entry + (planes.table ? sizeof(HitPlane) : sizeof(glm::uvec3)) - 1);
        }
}

// Each lane's triangle (a miss: 0) and that triangle's plane: plane[0..2] a vertex, plane[3..5] the normal.
template <KernelForm kForm>
ZCHECK_ALWAYS_INLINE inline void hitPlanesOfPacket(const PacketInFlight& p, const PlaneSource& planes,
                                                   std::uint32_t (&triangle)[kPacketRays],
                                                   double (&plane)[6][kPacketRays])
{
    // The planes, every lane's own, without a branch, from the table (HitPlane). (Keeping
    // a plane while the next lanes hit the same triangle, as this did before, cost more in
    // mispredicted branches than the arithmetic it saved.) A miss takes triangle 0's plane
    // (a scene has one, RayRenderer checked), and its result is not used.
    for (int k = 0; k < kPacketRays; ++k) triangle[k] = p.hit(k) ? p.packet.hit.primID[k] : 0;
    if (!planes.table) {  // from the corners (PlaneSource)
        for (int k = 0; k < kPacketRays; ++k) {
            const HitPlane h = hitPlaneOf(planes.scene, triangle[k]);
            for (int axis = 0; axis < 3; ++axis)
                plane[axis][k] = double(h.vertex[axis]), plane[3 + axis][k] = h.normal[axis];
        }
        return;
    }
#ifdef ZCHECK_X86_FORMS
    if constexpr (kForm != KernelForm::Baseline) planesInLanes(planes.table, triangle, plane);
#endif
    if constexpr (kForm == KernelForm::Baseline)
        for (int k = 0; k < kPacketRays; ++k) {
            const HitPlane& h = planes.table[triangle[k]];
            for (int axis = 0; axis < 3; ++axis)
                plane[axis][k] = double(h.vertex[axis]), plane[3 + axis][k] = h.normal[axis];
        }
}

// Each lane's hit again, in double: tEmbree Embree's t, t the ray's at its plane (else Embree's), eyeZ t's eye-z.
ZCHECK_ALWAYS_INLINE inline void hitsInDouble(const PacketInFlight& p, const double (&plane)[6][kPacketRays],
                                              const CameraRays& cameraRays, const RayFaults& fault,
                                              double (&tEmbree)[kPacketRays], double (&t)[kPacketRays],
                                              double (&eyeZ)[kPacketRays])
{
    // Lane by lane in plain arrays (several lanes per instruction): the ray parameter t
    // of the hit (Embree's, where the plane gives none) and its eye-z.
    for (int k = 0; k < kPacketRays; ++k) tEmbree[k] = p.packet.ray.tfar[k];  // apart: the loop below stays SIMD
    for (int k = 0; k < kPacketRays; ++k) {
        const glm::dvec3 vertex(plane[0][k], plane[1][k], plane[2][k]), n(plane[3][k], plane[4][k], plane[5][k]);
        const double tPlane = glm::dot(n, vertex - p.origin(k)) / glm::dot(n, p.direction(k));
        t[k] = std::abs(tPlane) <= std::numeric_limits<double>::max() ? tPlane : tEmbree[k];  // isfinite, branch-free
    }
    if (fault.distanceAsEyeZ) {  // the fault "distance as eye-z": the distance along the ray for eye-z
        for (int k = 0; k < kPacketRays; ++k) eyeZ[k] = t[k] * glm::length(p.direction(k));
    } else {
        for (int k = 0; k < kPacketRays; ++k) eyeZ[k] = cameraRays.eyeZ(p.origin(k) + t[k] * p.direction(k));
    }
}

// The packet's pixels inside the rectangle written: window depth, primitive and, where asked, eye point.
ZCHECK_ALWAYS_INLINE inline void writePacketPixels(const PacketInFlight& p, const double (&t)[kPacketRays],
                                                   const double (&eyeZ)[kPacketRays], const CameraRays& cameraRays,
                                                   const RectSetUp& setUp)
{
    // The pixels, lane by lane into plain arrays, then a row of the packet at a time: four
    // adjacent pixels, copied whole where all four lie in the rectangle. Every lane's window
    // depth at once where the camera has a closed form (a miss's is computed too, from
    // triangle 0's plane, and not used); a raw-matrix camera's, hits only.
    alignas(64) double depthOf[kPacketRays];
    alignas(64) std::uint32_t primitiveOf[kPacketRays];
    const bool closedForm = cameraRays.windowDepths(eyeZ, kPacketRays, depthOf);
    for (int k = 0; k < kPacketRays; ++k) primitiveOf[k] = p.hit(k) ? p.packet.hit.primID[k] : kNoPrimitive;
    if (cameraRays.lens()) {  // no window depth: the distance along the unit ray
        for (int k = 0; k < kPacketRays; ++k) depthOf[k] = p.hit(k) ? t[k] : setUp.clearDepth;
    } else if (closedForm) {
        for (int k = 0; k < kPacketRays; ++k) depthOf[k] = p.hit(k) ? depthOf[k] : setUp.clearDepth;
    } else {
        for (int k = 0; k < kPacketRays; ++k)
            depthOf[k] = p.hit(k) ? cameraRays.windowDepth(p.pImage(k), eyeZ[k]) : setUp.clearDepth;
    }
    const int cols = std::min(kPacketSide, setUp.col1 - p.col0), rows = std::min(kPacketSide, setUp.row1 - p.row0);
    for (int r = 0; r < rows; ++r) {
        const std::size_t i = std::size_t(p.row0 + r - setUp.row0) * setUp.stride + std::size_t(p.col0 - setUp.col0);
        const int k = r * kPacketSide;
        if (cols == kPacketSide) {
            std::memcpy(setUp.windowDepth + i, depthOf + k, sizeof(double) * kPacketSide);
            std::memcpy(setUp.primitiveId + i, primitiveOf + k, sizeof(std::uint32_t) * kPacketSide);
        } else {
            std::copy(depthOf + k, depthOf + k + cols, setUp.windowDepth + i);
            std::copy(primitiveOf + k, primitiveOf + k + cols, setUp.primitiveId + i);
        }
        if (setUp.pEye)
            for (int j = 0; j < cols; ++j)
                setUp.pEye[i + j] = p.hit(k + j)
                                        ? cameraRays.eyeFromWorld(p.origin(k + j) + t[k + j] * p.direction(k + j))
                                        : glm::dvec3(NAN);
    }
}

// traceRect for one rectangle, packet by packet through the steps above, in form kForm.
template <KernelForm kForm>
ZCHECK_ALWAYS_INLINE inline void traceRectBody(RTCScene rtcScene, const glm::dvec3& frameOrigin, const PlaneSource& planes,
                                        const Camera& camera, const PixelRect& rect, double* windowDepth,
                                        std::uint32_t* primitiveId, std::size_t stride, const RayFaults& fault,
                                        glm::dvec3* pEye)
{
    const int col0 = rect.col0, row0 = rect.row0, col1 = rect.col1, row1 = rect.row1;
    const int W = camera.width(), H = camera.height();
    const CameraRays cameraRays(camera);
    const std::optional<AffineRays> affine = cameraRays.affine();
    const RectSetUp setUp{col0, row0, col1, row1, W, H, camera.nearDistance(), camera.farDistance(),
                          camera.clearDepth(), camera.convention().windowOriginTop, double(H),
                          windowDepth, primitiveId, stride, pEye};

    FlushDenormals flush;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;

    // Rays made and traced: lanes as plain arrays, one quantity at a time, so that the
    // compiler can compute several lanes per instruction. Every field of every lane is
    // initialised, valid or not; an invalid lane (outside the rectangle) is a zero-length ray.
    auto trace = [&](PacketInFlight& p, int px, int py) ZCHECK_ALWAYS_INLINE {
        imagePointsOfPacket(p, px, py, setUp, fault);
        raysOfPacket(p, affine, cameraRays, setUp);
        embreeLanesOfPacket(p, frameOrigin);
        intersectPacket(p, rtcScene, context, planes);
    };
    // Each hit again, in double: the ray against the hit triangle's plane; then the pixels written.
    auto finish = [&](const PacketInFlight& p) ZCHECK_ALWAYS_INLINE {
        std::uint32_t triangle[kPacketRays];
        alignas(64) double plane[6][kPacketRays];
        hitPlanesOfPacket<kForm>(p, planes, triangle, plane);
        alignas(64) double tEmbree[kPacketRays], t[kPacketRays], eyeZ[kPacketRays];
        hitsInDouble(p, plane, cameraRays, fault, tEmbree, t, eyeZ);
        writePacketPixels(p, t, eyeZ, cameraRays, setUp);
    };

    // Packets row by row over the rectangle, two in flight: packet i is traced and its hit
    // planes asked for; while packet i + 1 is traced they arrive, and packet i is finished.
    // (Finishing each packet straight after its trace waited on those reads. With the corners
    // read through the index triples, a third packet in flight fetched the vertices.)
    constexpr int kInFlight = 2;
    PacketInFlight inFlight[kInFlight];
    const int packetsX = (col1 - col0 + kPacketSide - 1) / kPacketSide;
    const int packets = packetsX * ((row1 - row0 + kPacketSide - 1) / kPacketSide);
    for (int i = 0; i < packets + kInFlight - 1; ++i) {
        if (i < packets)
            trace(inFlight[i % kInFlight], col0 + (i % packetsX) * kPacketSide, row0 + (i / packetsX) * kPacketSide);
        if (i >= 1) finish(inFlight[(i - 1) % kInFlight]);
    }
}


void traceRectBaseline(RTCScene rtcScene, const glm::dvec3& frameOrigin, const PlaneSource& planes, const Camera& camera,
                       const PixelRect& rect, double* windowDepth, std::uint32_t* primitiveId, std::size_t stride,
                       const RayFaults& fault, glm::dvec3* pEye)
{
    traceRectBody<KernelForm::Baseline>(rtcScene, frameOrigin, planes, camera, rect, windowDepth, primitiveId, stride,
                                        fault, pEye);
}

#ifdef ZCHECK_X86_FORMS
#define ZCHECK_TRACE_FORM(Entry, Form)                                                                                \
    Entry void traceRect##Form(RTCScene rtcScene, const glm::dvec3& frameOrigin, const PlaneSource& planes,            \
                               const Camera& camera, const PixelRect& rect, double* windowDepth,                       \
                               std::uint32_t* primitiveId, std::size_t stride, const RayFaults& fault, glm::dvec3* pEye) \
    {                                                                                                                 \
        traceRectBody<KernelForm::Form>(rtcScene, frameOrigin, planes, camera, rect, windowDepth, primitiveId, stride, \
                                        fault, pEye);                                                                 \
    }
ZCHECK_TRACE_FORM(ZCHECK_KERNEL_ENTRY_AVX2, Avx2)
ZCHECK_TRACE_FORM(ZCHECK_KERNEL_ENTRY_AVX512, Avx512)
#undef ZCHECK_TRACE_FORM
#endif

}  // namespace

void RayRenderer::traceRect(const Camera& camera, const PixelRect& rect, double* windowDepth, std::uint32_t* primitiveId,
                            std::size_t stride, const RayFaults& fault, glm::dvec3* pEye) const
{
    traceRectInSceneFrame(CameraInSceneFrame(scene_, camera).get(), rect, windowDepth, primitiveId, stride, fault, pEye);
}

void RayRenderer::traceRectInSceneFrame(const Camera& camera, const PixelRect& rect, double* windowDepth,
                                        std::uint32_t* primitiveId, std::size_t stride, const RayFaults& fault,
                                        glm::dvec3* pEye) const
{
    auto* form = &traceRectBaseline;
#ifdef ZCHECK_X86_FORMS
    form = formOf(form_, form, &traceRectAvx2, &traceRectAvx512);
#endif
    const PlaneSource planes{embree_->planes.empty() ? nullptr : embree_->planes.data(), scene_};
    form(embree_->scene.get(), embree_->frameOrigin, planes, camera, rect, windowDepth, primitiveId,
         stride, fault, pEye);
}

}  // namespace zcheck
