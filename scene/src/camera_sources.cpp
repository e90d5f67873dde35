#include "zcheck/camera_sources.h"

#include "zcheck/error.h"
#include "zcheck/input_file.h"
#include "zcheck/mesh_formats.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace zcheck {

namespace {

CameraSet parseGltfCameras(std::string_view bytes, const std::string& path)
{
    CameraSet set;
    set.cameras = readGltfCameraNodes(path, bytes);
    return set;
}

bool detectsGltf(const CameraFileHead& file)
{
    return file.head.substr(0, 4) == "glTF" || (file.looksLikeJson() && file.has("\"asset\""));
}

// glTF joins the table of camera formats when this file is linked (camera_formats.h).
const bool kGltfRegistered = registerCameraFormat(gltfCameraFormat());

}  // namespace

const CameraFormat& gltfCameraFormat()
{
    static const CameraFormat row = [] {
        CameraFormat f;
        f.name = "gltf";
        f.title = "glTF";
        f.extensions = {".gltf", ".glb"};
        f.files = "a .gltf or .glb's camera nodes, read with its scene (#node name or index)";
        f.example = "scene.glb#Camera";
        f.priority = 30;
        f.detects = detectsGltf;
        f.parse = parseGltfCameras;
        f.input = kMeshInput;
        return f;
    }();
    return row;
}

namespace {

// A vertex as the clipping sees it: clip x, y, w (linear in eye space) and eye-z.
struct ClipVertex {
    double x, y, w, d;
};

// The five planes of the view, as functions that are ≥ 0 inside: |x| ≤ w, |y| ≤ w, eye-z ≥ 0.
double planeValue(const ClipVertex& v, int plane)
{
    switch (plane) {
    case 0: return v.w - v.x;
    case 1: return v.w + v.x;
    case 2: return v.w - v.y;
    case 3: return v.w + v.y;
    default: return v.d;
    }
}

// The eye-z range of a triangle clipped to the view (Sutherland–Hodgman); false when nothing
// of it is inside. Clip coordinates and eye-z are linear in eye space, so interpolating them
// along an edge is exact.
bool clippedRange(const ClipVertex (&corner)[3], double& lo, double& hi)
{
    ClipVertex polygon[8], next[8];
    int count = 3;
    std::copy(corner, corner + 3, polygon);
    for (int plane = 0; plane < 5 && count > 0; ++plane) {
        int kept = 0;
        for (int i = 0; i < count; ++i) {
            const ClipVertex& a = polygon[i];
            const ClipVertex& b = polygon[(i + 1) % count];
            const double fa = planeValue(a, plane), fb = planeValue(b, plane);
            if (fa >= 0) next[kept++] = a;
            if ((fa >= 0) != (fb >= 0)) {
                const double t = fa / (fa - fb);
                next[kept++] = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.w + t * (b.w - a.w), a.d + t * (b.d - a.d)};
            }
        }
        count = kept;
        std::copy(next, next + count, polygon);
    }
    if (count == 0) return false;
    for (int i = 0; i < count; ++i) lo = std::min(lo, polygon[i].d), hi = std::max(hi, polygon[i].d);
    return true;
}

}  // namespace

namespace {

// Near and far around the scene's nearest and farthest [lo, hi]: 1 % beyond each, near held at
// far/10⁷ or more — `floorNote` says so when it is.
SceneNearFar planesAround(double lo, double hi, const std::string& floorNote)
{
    SceneNearFar planes;
    planes.far = hi * 1.01;
    planes.near = lo * 0.99;
    const double floor = planes.far * 1e-7;
    if (!(planes.near >= floor)) planes.near = floor, planes.note = floorNote;
    return planes;
}

// A lens camera's near and far are distances along its rays (camera.h): the nearest and farthest
// any part of the scene can be from the eye, bounded by the boxes of its chunks of triangles (a
// box holding the eye bounds the nearest at 0). Rays are traced in double between them, so a
// generous range costs no precision.
SceneNearFar lensNearFar(const Scene& scene, const Camera& camera)
{
    const glm::dvec3 eye(camera.worldFromEye[3]);
    const std::shared_ptr<const TriangleChunks> chunks = scene.chunks ? scene.chunks : triangleChunksOf(scene);
    double lo = INFINITY, hi = 0;
    for (std::size_t c = 0; c < chunks->lo.size(); ++c) {
        const glm::dvec3 a(chunks->lo[c]), b(chunks->hi[c]);
        lo = std::min(lo, glm::length(glm::clamp(eye, a, b) - eye));
        hi = std::max(hi, glm::length(glm::max(glm::abs(a - eye), glm::abs(b - eye))));
    }
    if (!(hi > 0)) throw Error("scene '" + scene.name + "' has no extent around the camera: near and far cannot be taken from it");
    return planesAround(lo, hi, "the scene's bounds reach the eye, so near (a distance along the rays) is held at far/1e7");
}

}  // namespace

SceneNearFar sceneNearFar(const Scene& scene, const CameraSpec& spec)
{
    const Camera given(spec);  // its near and far may be placeholders: the side planes do not depend on them
    const CameraInSceneFrame local(scene, given);  // the chunks' boxes and the positions are the scene's frame
    const Camera& camera = local.get();
    if (camera.lens()) return lensNearFar(scene, camera);
    const glm::dmat4 clipFromWorld = camera.clipFromEye * camera.eyeFromWorld;
    const glm::dvec4 eyeZRow(camera.eyeFromWorld[0][2] * camera.convention().eyeForwardZ,
                             camera.eyeFromWorld[1][2] * camera.convention().eyeForwardZ,
                             camera.eyeFromWorld[2][2] * camera.convention().eyeForwardZ,
                             camera.eyeFromWorld[3][2] * camera.convention().eyeForwardZ);
    auto clipVertex = [&](const glm::dvec3& pWorld) {
        const glm::dvec4 p(pWorld, 1.0);
        const glm::dvec4 pClip = clipFromWorld * p;
        return ClipVertex{pClip.x, pClip.y, pClip.w, glm::dot(eyeZRow, p)};
    };
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto visitTriangle = [&](const glm::uvec3& t) {
        const ClipVertex corner[3] = {clipVertex(glm::dvec3(scene.positions[t[0]])), clipVertex(glm::dvec3(scene.positions[t[1]])),
                                      clipVertex(glm::dvec3(scene.positions[t[2]]))};
        int inside = 0;
        for (int plane = 0; plane < 5; ++plane) {
            int in = 0;
            for (const ClipVertex& v : corner) in += planeValue(v, plane) >= 0;
            if (in == 0) return;  // wholly outside one plane
            inside += in == 3;
        }
        if (inside == 5) {
            for (const ClipVertex& v : corner) lo = std::min(lo, v.d), hi = std::max(hi, v.d);
        } else {
            clippedRange(corner, lo, hi);
        }
    };
    // Chunks of triangles by their boxes: a chunk wholly outside one plane is skipped; the others
    // are visited in the order of the nearest eye-z their box allows, until no box can lower the
    // near end, then in the order of the farthest, until none can raise the far end. The answer
    // is the one a visit of every triangle gives.
    const std::shared_ptr<const TriangleChunks> chunks = scene.chunks ? scene.chunks : triangleChunksOf(scene);
    struct Candidate {
        std::size_t chunk;
        double nearest, farthest;
    };
    std::vector<Candidate> candidates;
    for (std::size_t c = 0; c < chunks->lo.size(); ++c) {
        const glm::dvec3 a(chunks->lo[c]), b(chunks->hi[c]);
        ClipVertex corners[8];
        for (int k = 0; k < 8; ++k) corners[k] = clipVertex({k & 1 ? b.x : a.x, k & 2 ? b.y : a.y, k & 4 ? b.z : a.z});
        bool outside = false;
        for (int plane = 0; plane < 5 && !outside; ++plane) {
            outside = true;
            for (const ClipVertex& v : corners) outside = outside && planeValue(v, plane) < 0;
        }
        if (outside) continue;
        double nearest = INFINITY, farthest = -INFINITY;
        for (const ClipVertex& v : corners) nearest = std::min(nearest, v.d), farthest = std::max(farthest, v.d);
        candidates.push_back({c, nearest, farthest});
    }
    std::vector<char> visited(chunks->lo.size(), 0);
    auto visitChunk = [&](std::size_t c) {
        if (visited[c]) return;
        visited[c] = 1;
        const std::size_t end = std::min(scene.triangles.size(), (c + 1) * TriangleChunks::kSize);
        for (std::size_t t = c * TriangleChunks::kSize; t < end; ++t) visitTriangle(scene.triangles[t]);
    };
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) { return x.nearest < y.nearest; });
    for (const Candidate& c : candidates) {
        if (c.nearest >= lo) break;  // no triangle of this box (nor of any later) is nearer
        visitChunk(c.chunk);
    }
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) { return x.farthest > y.farthest; });
    for (const Candidate& c : candidates) {
        if (c.farthest <= hi) break;
        visitChunk(c.chunk);
    }
    if (!(hi > 0))
        throw Error("the camera sees none of scene '" + scene.name +
                    "', so near and far cannot be taken from it (is the pose inverted, or in other axes?)");
    return planesAround(lo, hi, "the scene reaches the eye (eye-z " + formatNumber(std::max(lo, 0.0)) + "), so near is held at far/1e7");
}

ImportedCamera importCamera(const std::string& reference, const CameraFormat* format)
{
    (void)kGltfRegistered;
    const auto [file, frame] = splitCameraReference(reference);
    const CameraSet set = readCameraSet(file, format);
    return set.cameras[set.find(frame)];
}

CameraSpec completeCamera(const ImportedCamera& camera, const Scene* scene, const CameraCompletion& given)
{
    if (!camera.refusal.empty()) throw Error(camera.refusal);
    CameraSpec spec = camera.spec;
    std::vector<std::string>& notes = spec.notes;
    if (given.width.has_value() != given.height.has_value())
        throw Error("give both the image width and height, or neither");
    if (given.width) {
        spec.width = *given.width, spec.height = *given.height;
        if (camera.projectionForSize) spec.projection = camera.projectionForSize(spec.width, spec.height);
    } else if (!camera.hasImageSize) {
        notes.push_back("the camera file gives no image size: " + std::to_string(spec.width) + "x" +
                        std::to_string(spec.height) + " (--width and --height set it; verify takes the depth map's)");
    }
    const bool isMatrix = spec.projection.type == ProjectionType::Matrix;
    if (isMatrix && (given.near || given.far))
        throw Error("a raw projection matrix holds its own near and far: --near and --far do not apply");
    if (!isMatrix) {
        if (!camera.hasClipPlanes && !(given.near && given.far)) {
            if (!scene && !given.mapEyeZ)
                throw Error("camera '" + camera.name +
                            "' has no near and far in its file, and there is no scene to take them from: give near and far");
            std::optional<SceneNearFar> planes;
            std::string sceneFailure;
            if (scene) {
                try {
                    planes = sceneNearFar(*scene, spec);
                } catch (const Error& e) {
                    sceneFailure = e.what();
                }
            }
            if (!planes && !given.mapEyeZ) throw Error(sceneFailure);
            const bool sawScene = planes.has_value();
            std::string from = "the scene as the camera sees it";
            if (given.mapEyeZ) {  // the map's depths too: what the renderer saw must not be clipped
                const double lo = given.mapEyeZ->first * 0.99, hi = given.mapEyeZ->second * 1.01;
                SceneNearFar widened = planes.value_or(SceneNearFar{lo, hi, ""});
                widened.near = std::max(std::min(widened.near, lo), hi * 1e-7);
                widened.far = std::max(widened.far, hi);
                planes = widened;
                from = sawScene ? from + " and the map's depths"
                       : scene  ? "the map's depths (the camera sees none of the scene)"
                                : "the depths given (no scene; eye-z and distance do not depend on them)";
            }
            spec.projection.near = given.near.value_or(planes->near);
            spec.projection.far = given.far.value_or(planes->far);
            notes.push_back("near and far are not in the camera file: taken from " + from + " (near " +
                            formatNumber(spec.projection.near) + ", far " + formatNumber(spec.projection.far) +
                            (planes->note.empty() ? "" : "; " + planes->note) + "); pass --near and --far to set them");
        } else {
            if (given.near) spec.projection.near = *given.near;
            if (given.far) spec.projection.far = *given.far;
        }
    }
    try {
        Camera validated(spec);
    } catch (const Error& e) {
        throw Error("camera '" + camera.name + "': " + e.what());
    }
    return spec;
}

CameraForMap completeCameraForMap(const ImportedCamera& camera, const Scene* scene, CameraCompletion given,
                                  DepthQuantity quantity, const std::function<DepthMapFile(int width, int height)>& read)
{
    if (!camera.refusal.empty()) throw Error(camera.refusal);
    CameraForMap out;
    const bool sized = given.width.has_value() || camera.hasImageSize;
    out.map = sized ? read(given.width.value_or(camera.spec.width), given.height.value_or(camera.spec.height)) : read(0, 0);
    if (!sized) given.width = out.map.width, given.height = out.map.height;
    // The eye-z range the map holds, for eye-z and distance maps (window and NDC maps need the
    // renderer's near and far anyway).
    if (!camera.hasClipPlanes && (quantity == DepthQuantity::EyeZ || quantity == DepthQuantity::Distance)) {
        double lo = INFINITY, hi = 0;
        for (double v : out.map.value)
            if (std::isfinite(v) && v > 0) lo = std::min(lo, v), hi = std::max(hi, v);
        if (hi > 0) {
            if (quantity == DepthQuantity::Distance) {
                // eye-z = distance · cos θ ≥ distance · cos θ at the image's corners (perspective);
                // parallel projections measure distance from the eye plane: eye-z itself.
                CameraSpec sizedSpec = camera.spec;
                sizedSpec.width = given.width.value_or(sizedSpec.width), sizedSpec.height = given.height.value_or(sizedSpec.height);
                if (camera.projectionForSize) sizedSpec.projection = camera.projectionForSize(sizedSpec.width, sizedSpec.height);
                const Camera c(sizedSpec);
                if (c.lens()) {
                    // a lens's near and far are distances (camera.h): mapEyeZ holds the map's distances
                } else if (sizedSpec.projection.isPerspective()) {
                    const double n = c.nearDistance();
                    const double x = std::max(std::abs(c.left()), std::abs(c.right())), y = std::max(std::abs(c.top()), std::abs(c.bottom()));
                    lo *= n / std::sqrt(x * x + y * y + n * n);
                }
            }
            if (quantity == DepthQuantity::EyeZ && camera.spec.projection.type == ProjectionType::NonLinear) {
                // A lens's near and far are distances: an eye-z z lies on a ray at distance z / cos θ,
                // θ up to the field's angle (at most 89.9°, beyond which eye-z does not exist).
                CameraSpec sizedSpec = camera.spec;
                sizedSpec.width = given.width.value_or(sizedSpec.width), sizedSpec.height = given.height.value_or(sizedSpec.height);
                if (camera.projectionForSize) sizedSpec.projection = camera.projectionForSize(sizedSpec.width, sizedSpec.height);
                hi /= std::cos(std::min(Camera(sizedSpec).lens()->fieldAngle(), 89.9 * 3.14159265358979323846 / 180));
            }
            given.mapEyeZ = std::pair{lo, hi};
        }
    }
    out.spec = completeCamera(camera, scene, given);
    return out;
}

}  // namespace zcheck
