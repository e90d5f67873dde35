// The ray route's camera in its fast form: the affine rays (one unit of eye-z per unit of t)
// against the per-pixel rays from the definition, and the folded depth mapping against the
// inverse-projection module's, for every projection model of the examples and every
// convention.
#include "zcheck/camera_file.h"
#include "zcheck/camera_rays.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/ray_renderer.h"

#include "kernel_testing.h"

#include <catch2/catch.hpp>
#ifdef ZCHECK_X86_FORMS
#include <cpuid.h>
#endif

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <sstream>
#include <set>
#include <fstream>
#include <string>
#include <vector>

using namespace zcheck;

namespace {
const char* const kModels[] = {"perspective", "lens", "pinhole", "frustum", "orthographic", "oblique-cabinet",
                               "oblique-cavalier", "isometric", "infinite-far"};
const char* const kConventions[] = {"opengl", "direct3d", "vulkan", "metal", "opencv"};

// Calls visit(camera) for every example model, convention and Z direction.
template <class Visit>
void forEachExampleCamera(Visit&& visit)
{
    for (const char* model : kModels)
        for (const char* convention : kConventions)
            for (const bool reversed : {false, true}) {
                CameraSpec spec = readCameraFile(std::string(ZCHECK_TESTS_DIR) + "/../examples/" + model + ".json");
                spec.convention = Convention::preset(convention);
                spec.depth.reversed = reversed;
                INFO(model << " " << convention << (reversed ? " reversed" : ""));
                visit(Camera(spec));
            }
}
}  // namespace

TEST_CASE("affine rays are the definition's rays, with t equal to eye-z", "[camera_rays]")
{
    forEachExampleCamera([](const Camera& camera) {
        const CameraRays rays(camera);
        const auto affine = rays.affine();
        REQUIRE(affine.has_value());
        for (const glm::dvec2 pImage : {glm::dvec2(0.5, 0.5), glm::dvec2(camera.width() - 0.5, 0.5),
                                        glm::dvec2(17.25, camera.height() - 3.75),
                                        glm::dvec2(camera.width() / 2.0, camera.height() / 2.0)}) {
            const EyePlaneRay r = rays.worldRay(pImage).value();
            const glm::dvec3 origin = affine->originAt(pImage), direction = affine->directionAt(pImage);
            const double scale = 1.0 + glm::length(r.origin);
            REQUIRE(glm::length(origin - r.origin) <= 1e-12 * scale);
            REQUIRE(glm::length(glm::normalize(direction) - r.direction) <= 1e-13);
            // t along the affine direction is eye-z: the near plane at t = near, any point's
            // eye-z equal to its t.
            for (const double t : {camera.nearDistance(), 1.7 * camera.nearDistance() + 0.3}) {
                const glm::dvec3 pWorld = origin + t * direction;
                REQUIRE(rays.eyeZ(pWorld) == Approx(t).epsilon(1e-12));
            }
            REQUIRE(r.tNear * glm::dot(r.direction, direction) / glm::dot(direction, direction) ==
                    Approx(camera.nearDistance()).epsilon(1e-12));
        }
    });
}

TEST_CASE("the folded depth mapping is the inverse-projection module's, and its inverse round-trips", "[camera_rays]")
{
    forEachExampleCamera([](const Camera& camera) {
        const CameraRays rays(camera);
        const glm::dvec2 pImage(11.5, 7.5);
        const glm::dvec2 pWindow(pImage.x, camera.windowYFromImageY(pImage.y));
        const double n = camera.nearDistance();
        const double far = std::isinf(camera.farDistance()) ? 1000 * n : camera.farDistance();
        for (const double eyeZ : {n, 1.5 * n, 0.5 * (n + far), far}) {
            const double window = rays.windowDepth(pImage, eyeZ);
            // The matrices' route (clip_from_eye, viewport), an independent evaluation.
            REQUIRE(window == Approx(windowDepthFromEyeZ(camera, pWindow, eyeZ)).margin(1e-12));
            REQUIRE(rays.eyeZFromWindowDepth(pImage, window) == Approx(eyeZ).epsilon(1e-9));
            // The relative eye-z difference of a depth one part in 10^4 of the range away.
            const double other = window + 1e-4 * (camera.depth().rangeMax - camera.depth().rangeMin);
            const double zOther = rays.eyeZFromWindowDepth(pImage, other);
            REQUIRE(rays.relativeEyeZDifference(pImage, window, other) ==
                    Approx(std::abs(zOther - eyeZ) / eyeZ).epsilon(1e-6));
        }
        REQUIRE(rays.windowDepth(pImage, n) == Approx(camera.windowDepthNear()).margin(1e-14));
    });
}

TEST_CASE("the depth mapping lane by lane is windowDepth's, bit for bit, a raw matrix has none", "[camera_rays]")
{
    forEachExampleCamera([](const Camera& camera) {
        const CameraRays rays(camera);
        const double n = camera.nearDistance();
        const double far = std::isinf(camera.farDistance()) ? 1000 * n : camera.farDistance();
        const std::vector<double> eyeZ = {n, 1.5 * n, 0.5 * (n + far), far, 0.3 * n, 2 * far, -n};
        std::vector<double> together(eyeZ.size(), -7.0);
        REQUIRE(rays.windowDepths(eyeZ.data(), eyeZ.size(), together.data()));
        for (std::size_t j = 0; j < eyeZ.size(); ++j) {
            INFO("eye-z " << eyeZ[j]);
            REQUIRE(testing::sameBits(std::vector<double>{together[j]},
                                      std::vector<double>{rays.windowDepth({11.5, 7.5}, eyeZ[j])}));
        }
    });
    CameraSpec matrix = readCameraFile(std::string(ZCHECK_TESTS_DIR) + "/../examples/matrix-direct3d.json");
    const Camera camera(matrix);
    const double eyeZ = 1.0;
    double out = -7.0;
    REQUIRE_FALSE(CameraRays(camera).windowDepths(&eyeZ, 1, &out));
    REQUIRE(out == -7.0);
}

TEST_CASE("each hit's depth is its triangle's plane met by the pixel's ray in double, recomputed from the corners",
          "[ray]")
{
    // The trace reads each hit triangle's plane from a table made with the BVH. Here the plane
    // comes from the scene's corners again, through the affine ray of the pixel centre, and the
    // depth must match bit for bit (-ffp-contract=off: the same operations round the same way).
    // A table entry from the wrong corners, triangle or precision would not.
    for (const bool inside : {true, false}) {
        const Scene soup = testing::triangleSoup(inside, inside ? 41 : 42);
        const RayRenderer renderer(soup);
        for (const char* convention : kConventions)
            for (const bool reversed : {false, true}) {
                const Camera camera(testing::kernelCamera(convention, DepthFormat::Float32, reversed, false));
                const CameraRays rays(camera);
                const AffineRays affine = *rays.affine();
                const RenderResult result = renderer.render(camera);
                std::size_t hits = 0;
                for (int row = 0; row < camera.height(); ++row)
                    for (int col = 0; col < camera.width(); ++col) {
                        const std::size_t i = std::size_t(row) * std::size_t(camera.width()) + std::size_t(col);
                        const std::uint32_t primitive = result.primitiveId[i];
                        if (primitive == kNoPrimitive) continue;
                        ++hits;
                        const glm::uvec3& corners = soup.triangles[primitive];
                        const glm::dvec3 a(soup.positions[corners[0]]), b(soup.positions[corners[1]]),
                            c(soup.positions[corners[2]]);
                        const glm::dvec3 normal = glm::cross(b - a, c - a);
                        const glm::dvec2 pImage(col + 0.5, row + 0.5);
                        const glm::dvec3 origin = affine.originAt(pImage), direction = affine.directionAt(pImage);
                        const double t = glm::dot(normal, a - origin) / glm::dot(normal, direction);
                        REQUIRE(std::isfinite(t));
                        const double expected = rays.windowDepth(pImage, rays.eyeZ(origin + t * direction));
                        INFO(convention << (reversed ? " reversed" : "") << " pixel (" << col << ", " << row
                                        << ") triangle " << primitive);
                        REQUIRE(testing::sameBits(std::vector<double>{result.windowDepth.value[i]},
                                                  std::vector<double>{expected}));
                    }
                REQUIRE(hits > 1000);
            }
    }
}

TEST_CASE("the trace's AVX2 and AVX-512 forms are bit-identical to its baseline form", "[ray][kernel]")
{
    // RayRenderer::traceRect is one source compiled per form (kernel_choice.h): rays generated,
    // traced, and every hit re-evaluated in double against its triangle's plane. Two soups of
    // triangles (one wholly between the near and far planes, one mostly across them), through
    // the soups' perspective camera in every convention, reversed or not, with a narrowed
    // depth range, and through every example projection model (the raw matrix one takes
    // per-pixel rays, not affine ones) looking at the soup; with no fault and with each of
    // the ray route's faults; window depths, primitive ids and eye points compared bit for bit.
    const std::vector<const char*> forms = testing::vectorFormsToTest();

    std::vector<CameraSpec> cameras;
    for (const char* convention : kConventions)
        for (const bool reversed : {false, true})
            for (const bool narrowRange : {false, true})
                cameras.push_back(testing::kernelCamera(convention, DepthFormat::Float32, reversed, narrowRange));
    for (const char* model : {"perspective", "lens", "pinhole", "frustum", "orthographic", "oblique-cabinet",
                              "oblique-cavalier", "isometric", "dimetric", "trimetric", "infinite-far", "matrix-direct3d"}) {
        CameraSpec spec = readCameraFile(std::string(ZCHECK_TESTS_DIR) + "/../examples/" + model + ".json");
        spec.width = 203, spec.height = 141;
        spec.view = View::lookAt({0.3, -0.2, 1.0}, {0, 0, -4}, {0, 1, 0});
        cameras.push_back(spec);
    }
    {  // rows of whole cache lines (width a multiple of 16): render() copies them with streaming stores
        CameraSpec spec = testing::kernelCamera("vulkan", DepthFormat::Unorm24, false, false);
        spec.width = 272, spec.height = 141;
        cameras.push_back(spec);
    }
    RayFaults shifted, rowsFlipped, colsFlipped, distance;
    shifted.shiftPixels = {0.5, -0.25};
    rowsFlipped.flipRows = true;
    colsFlipped.flipCols = true;
    distance.distanceAsEyeZ = true;

    std::int64_t misses = 0;  // over all renders: the misses' lanes are compared too
    for (const bool inside : {true, false}) {
        const Scene soup = testing::triangleSoup(inside, inside ? 31 : 32);
        // The form is chosen when a renderer is made.
        auto rendererIn = [&](const char* form) {
            return testing::inForm(form, [&] { return std::make_unique<RayRenderer>(soup); });
        };
        const std::unique_ptr<RayRenderer> baselineForm = rendererIn("baseline");
        std::vector<std::unique_ptr<RayRenderer>> vectorForms;
        for (const char* form : forms) vectorForms.push_back(rendererIn(form));
        for (const CameraSpec& spec : cameras) {
            const Camera camera(spec);
            for (const RayFaults& faults : {RayFaults{}, shifted, rowsFlipped, colsFlipped, distance}) {
                const RenderResult baseline = baselineForm->render(camera, faults, EyePoints::Keep);
                INFO((inside ? "soup inside, " : "soup across, ") << spec.convention.name << " " << spec.width << "x"
                     << spec.height << (spec.depth.reversed ? " reversed" : "") << " fault shift/rows/cols/distance "
                     << faults.shiftPixels.x << "/" << faults.flipRows << "/" << faults.flipCols << "/"
                     << faults.distanceAsEyeZ);
                const auto hits = std::count_if(baseline.primitiveId.begin(), baseline.primitiveId.end(),
                                                [](std::uint32_t id) { return id != kNoPrimitive; });
                REQUIRE(hits > 100);  // not an empty picture
                misses += std::int64_t(baseline.primitiveId.size()) - hits;
                for (std::size_t f = 0; f < forms.size(); ++f) {
                    INFO("the " << forms[f] << " form");
                    const RenderResult vector = vectorForms[f]->render(camera, faults, EyePoints::Keep);
                    REQUIRE(testing::sameBits(vector.primitiveId, baseline.primitiveId));
                    REQUIRE(testing::sameBits(vector.windowDepth.value, baseline.windowDepth.value));
                    REQUIRE(testing::sameBits(vector.pEye, baseline.pEye));
                    // Without eye points, each 64×64 region is traced into a buffer of its own and
                    // copied into the image: the same pixels (regions cut at the image's edges too).
                    const RenderResult staged = vectorForms[f]->render(camera, faults, EyePoints::Omit);
                    REQUIRE(testing::sameBits(staged.primitiveId, vector.primitiveId));
                    REQUIRE(testing::sameBits(staged.windowDepth.value, vector.windowDepth.value));
                }
            }
        }
    }
    REQUIRE(misses > 10000);
}

TEST_CASE("the trace reads ZCHECK_KERNELS when its renderer is made and refuses a bad value", "[ray][kernel]")
{
    const Scene soup = testing::triangleSoup(true, 33);
    const Camera camera(testing::kernelCamera("opengl", DepthFormat::Unorm24, false, false));
    auto renderWith = [&](const char* form) {  // read when the renderer is made
        return testing::inForm(form, [&] { return RayRenderer(soup).render(camera); });
    };
    REQUIRE_NOTHROW(renderWith("auto"));
    REQUIRE_NOTHROW(renderWith(""));
    REQUIRE_NOTHROW(renderWith("baseline"));
    REQUIRE_THROWS_WITH(renderWith("sse2"), Catch::Equals("ZCHECK_KERNELS=sse2: must be auto, baseline, avx2 or avx512"));
}

TEST_CASE("ZCHECK_EMBREE_ISA has Embree run one instruction set's kernels, finding the same hits, and refuses a bad value",
          "[ray][kernel]")
{
    // Embree's native packet width tells which set it runs: 4 (SSE), 8 (AVX, AVX2), 16 (AVX-512).
    // Every set it runs finds the same closest hits; zcheck recomputes each hit's depth from the
    // triangle's plane, so a pixel with the same triangle has the same bits. Only a tie (two
    // triangles at exactly one distance: a ray through an edge they share) may go either way.
    const Scene scene = builtinScene("builtin:default");
    CameraSpec spec = scene.defaultCamera;
    spec.width = 160, spec.height = 120;
    const Camera camera(spec);
    const auto isa = [](const char* value) { return testing::withEnvironment("ZCHECK_EMBREE_ISA", value, [] { return embreeIsa(); }); };
    REQUIRE(isa(nullptr) == "auto");
    REQUIRE(isa("") == "auto");
    REQUIRE(isa("auto") == "auto");
    REQUIRE(testing::withEnvironment("ZCHECK_EMBREE_ISA", "auto", [] { return embreeDeviceConfig(); }).empty());
    for (const char* bad : {"AVX2", "sse4", "avx512f", "bogus", "isa=avx2"})
        REQUIRE_THROWS_WITH(testing::withEnvironment("ZCHECK_EMBREE_ISA", bad, [&] { return RayRenderer(scene); }),
                            Catch::Equals(std::string("ZCHECK_EMBREE_ISA=") + bad +
                                          ": must be auto, sse2, sse4.2, avx, avx2 or avx512"));
    const RenderResult byDefault = RayRenderer(scene).render(camera);
    const std::size_t hits = std::size_t(std::count_if(byDefault.primitiveId.begin(), byDefault.primitiveId.end(),
                                                       [](std::uint32_t id) { return id != kNoPrimitive; }));
    REQUIRE(hits > byDefault.primitiveId.size() / 4);
    struct Set {
        const char* name;
        bool has;
        int packet;
    };
#ifdef ZCHECK_X86_FORMS
    // What the processor has, as Linux lists it (/proc/cpuinfo's flags): another source than
    // the compiler's __builtin_cpu_supports, which zcheck asks. Each set needs the ones before
    // it, as Embree's do. LZCNT, which Embree's AVX2 needs, from the CPUID instruction itself
    // (leaf 0x80000001, ECX bit 5, Linux's "abm"): a Firecracker guest on a Zen 5 (kernel 6.18)
    // listed no "abm" though CPUID had it and lzcnt ran, and Embree ran its AVX-512 kernels.
    std::set<std::string> flags;
    {
        std::ifstream cpuinfo("/proc/cpuinfo");
        std::string line;
        while (std::getline(cpuinfo, line) && flags.empty())
            if (line.rfind("flags", 0) == 0) {
                std::istringstream words(line.substr(line.find(':') + 1));
                for (std::string word; words >> word;) flags.insert(word);
            }
    }
    REQUIRE(flags.count("sse2"));
    const auto has = [&](std::initializer_list<const char*> names) {
        return std::all_of(names.begin(), names.end(), [&](const char* name) { return flags.count(name) > 0; });
    };
    const bool sse42 = has({"sse4_2", "popcnt"}), avx = sse42 && has({"avx"});
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    const bool lzcnt = __get_cpuid(0x80000001u, &eax, &ebx, &ecx, &edx) && (ecx >> 5 & 1u);
    const bool avx2 = avx && lzcnt && has({"avx2", "fma", "f16c", "bmi1", "bmi2"});
    const bool avx512 = avx2 && has({"avx512f", "avx512cd", "avx512dq", "avx512bw", "avx512vl"});
    const Set sets[] = {{"sse2", true, 4}, {"sse4.2", sse42, 4}, {"avx", avx, 8}, {"avx2", avx2, 8}, {"avx512", avx512, 16}};
#else
    const Set sets[] = {{"sse2", false, 4}, {"avx2", false, 8}};
#endif
    // auto runs the widest set the processor has: its packet width is that set's.
    const Set* widest = nullptr;
    for (const Set& set : sets)
        if (set.has) widest = &set;
    REQUIRE(embreeAutoIsa() == (widest ? widest->name : ""));
    if (widest) REQUIRE(RayRenderer(scene).embreeNativePacket() == widest->packet);
    for (const Set& set : sets) {
        INFO("ZCHECK_EMBREE_ISA=" << set.name);
        if (!set.has) {
            REQUIRE_THROWS_WITH(testing::withEnvironment("ZCHECK_EMBREE_ISA", set.name, [&] { return RayRenderer(scene); }),
                                Catch::StartsWith(std::string("ZCHECK_EMBREE_ISA=") + set.name +
                                                  ": this processor cannot run Embree's " + set.name + " kernels"));
            WARN("this processor lacks Embree's " << set.name << " kernels: only their refusal is tested");
            continue;
        }
        REQUIRE(isa(set.name) == set.name);
        const auto rays = testing::withEnvironment("ZCHECK_EMBREE_ISA", set.name, [&] { return std::make_unique<RayRenderer>(scene); });
        REQUIRE(rays->embreeNativePacket() == set.packet);
        const RenderResult render = rays->render(camera);
        std::size_t sameTriangle = 0, otherDepth = 0;
        for (std::size_t i = 0; i < render.primitiveId.size(); ++i) {
            if (render.primitiveId[i] != byDefault.primitiveId[i]) continue;
            ++sameTriangle;
            otherDepth += std::memcmp(&render.windowDepth.value[i], &byDefault.windowDepth.value[i], sizeof(double)) != 0;
        }
        REQUIRE(otherDepth == 0);
        REQUIRE(sameTriangle >= render.primitiveId.size() - render.primitiveId.size() / 1000);
    }
}

TEST_CASE("regression: a raw matrix whose near plane crosses the eye plane gave Embree a negative tnear", "[rays][regression]")
{
    // The diagnosis builds such cameras (a tilted depth row) and probes them with single rays;
    // Embree's assertion `ray.tnear() >= 0` aborted zcheck. The camera sees nothing behind its eye
    // plane: both the probe and a full render start there.
    const Scene scene = builtinScene("builtin:default");
    const RayRenderer rays(scene);
    CameraSpec spec = scene.defaultCamera;
    spec.width = 64, spec.height = 48;
    const Camera straight(spec);
    spec.projection.type = ProjectionType::Matrix;
    spec.projection.clipFromEye = straight.clipFromEye;
    spec.projection.clipFromEye[0][2] += 3.0 * straight.clipFromEye[3][2];  // depth tilted with eye x
    const Camera tilted(spec);
    bool behind = false;
    for (int col = 0; col < 64; ++col)
        behind = behind || worldEyePlaneRayThroughWindow(tilted, windowFromPixelCentre(tilted, col, 24)).tNear < 0;
    REQUIRE(behind);
    const RenderResult render = rays.render(tilted);
    REQUIRE(render.primitiveId.size() == 64u * 48u);
    for (int col = 0; col < 64; ++col) (void)rays.primitiveAt(tilted, windowFromPixelCentre(tilted, col, 24));
}
