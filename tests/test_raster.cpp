// Rasterizer rules and analytic depths through both routes.
#include "zcheck/checker.h"

#include "zcheck/drawn_polygon.h"
#include "zcheck/inverse_projection.h"

#include "kernel_testing.h"
#include "raster_testing.h"
#include "sweep.h"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <random>
#include <string>

using namespace zcheck;

namespace {

Scene sceneOf(std::vector<glm::vec3> positions, std::vector<glm::uvec3> triangles)
{
    Scene scene;
    scene.name = "test";
    scene.positions = std::move(positions);
    scene.triangles = std::move(triangles);
    return scene;
}

// opengl orthographic camera whose window coordinates equal world x, y (origin bottom-left).
CameraSpec pixelExactCamera(int size)
{
    CameraSpec spec;
    spec.width = spec.height = size;
    spec.projection.type = ProjectionType::Orthographic;
    spec.projection.left = 0, spec.projection.right = size, spec.projection.bottom = 0, spec.projection.top = size;
    spec.projection.near = 0.5, spec.projection.far = 10;
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    return spec;
}

// Coverage count per pixel when each triangle of the fan is drawn alone.
std::vector<int> coverageCounts(const std::vector<glm::vec3>& positions, const std::vector<glm::uvec3>& triangles,
                                const Camera& camera)
{
    std::vector<int> count(std::size_t(camera.width()) * camera.height(), 0);
    for (const auto& triangle : triangles) {
        const Scene single = sceneOf(positions, {triangle});
        const RenderResult image = RasterRenderer(single).render(camera);
        for (std::size_t i = 0; i < count.size(); ++i) count[i] += image.hit(i) ? 1 : 0;
    }
    return count;
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Is p strictly inside the star-shaped fan polygon, more than `margin` from its outer boundary?
bool strictlyInsideFan(const glm::dvec2& p, const glm::dvec2& centre, const std::vector<glm::dvec2>& rim, double margin)
{
    bool inside = false;
    for (std::size_t k = 0; k < rim.size(); ++k) {
        const glm::dvec2 a = rim[k], b = rim[(k + 1) % rim.size()];
        const double edgeLength = glm::length(b - a);
        const double side = cross2(b - a, p - a) / edgeLength;  // signed distance to the rim edge
        const double s1 = cross2(a - centre, p - centre), s2 = cross2(p - centre, b - centre);
        if (s1 >= 0 && s2 >= 0 && side > margin) inside = true;
    }
    return inside;
}

void requireFanCoversEachPixelOnce(const glm::dvec2& centre, const std::vector<glm::dvec2>& rim, int size)
{
    std::vector<glm::vec3> positions = {glm::vec3(centre, -1.0)};
    std::vector<glm::uvec3> triangles;
    for (const auto& p : rim) positions.emplace_back(p, -1.0);
    for (std::uint32_t k = 0; k < rim.size(); ++k)
        triangles.push_back({0, 1 + k, 1 + (k + 1) % std::uint32_t(rim.size())});
    const Camera camera(pixelExactCamera(size));
    const std::vector<int> count = coverageCounts(positions, triangles, camera);
    const RenderResult whole = RasterRenderer(sceneOf(positions, triangles)).render(camera);
    int inside = 0;
    for (int row = 0; row < size; ++row)
        for (int col = 0; col < size; ++col) {
            const std::size_t i = std::size_t(row) * size + col;
            const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
            INFO("pixel " << col << ", " << row);
            REQUIRE(count[i] <= 1);  // never twice
            if (strictlyInsideFan(pWindow, centre, rim, 1e-6)) {
                ++inside;
                REQUIRE(count[i] == 1);  // no gaps
            }
            REQUIRE(whole.hit(i) == (count[i] == 1));
        }
    REQUIRE(inside > 100);
}

}  // namespace

TEST_CASE("a fan whose edges run through pixel centres covers each pixel exactly once", "[raster][fill-rule]")
{
    const glm::dvec2 centre(32.5, 32.5);  // a pixel centre
    const std::vector<glm::dvec2> rim = {{52.5, 32.5}, {46.5, 46.5}, {32.5, 52.5}, {18.5, 46.5},
                                         {12.5, 32.5}, {18.5, 18.5}, {32.5, 12.5}, {46.5, 18.5}};
    requireFanCoversEachPixelOnce(centre, rim, 64);
}

TEST_CASE("the top-left rule: centres on top and left edges are covered, on bottom and right edges not", "[raster][fill-rule]")
{
    // A square whose edges run exactly through pixel centres: image x and y in [10.5, 20.5],
    // i.e. columns and rows 10..20 lie on its boundary. With the top-left rule it covers
    // columns 10..19 and rows 10..19: the left column and top row, not the right and bottom.
    const int size = 32;
    const Camera camera(pixelExactCamera(size));  // opengl: image y = size − world y
    auto at = [&](double xImage, double yImage) { return glm::vec3(xImage, size - yImage, -1.0); };
    for (bool otherDiagonal : {false, true})
        for (bool reverseWinding : {false, true}) {
            std::vector<glm::vec3> corners = {at(10.5, 10.5), at(20.5, 10.5), at(20.5, 20.5), at(10.5, 20.5)};
            if (otherDiagonal) std::rotate(corners.begin(), corners.begin() + 1, corners.end());
            std::vector<glm::uvec3> triangles = {{0, 1, 2}, {0, 2, 3}};
            if (reverseWinding)
                for (auto& t : triangles) std::swap(t[1], t[2]);
            const RenderResult image = RasterRenderer(sceneOf(corners, triangles)).render(camera);
            for (int row = 0; row < size; ++row)
                for (int col = 0; col < size; ++col) {
                    INFO("pixel " << col << ", " << row << (otherDiagonal ? ", other diagonal" : "")
                                  << (reverseWinding ? ", reversed winding" : ""));
                    REQUIRE(image.hit(std::size_t(row) * size + col) == (col >= 10 && col <= 19 && row >= 10 && row <= 19));
                }
        }
}

TEST_CASE("random fans cover each pixel exactly once", "[raster][fill-rule][property]")
{
    std::mt19937_64 random(1988);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int fan = 0; fan < 20; ++fan) {
        // Vertices on a 1/16-pixel grid: many land exactly on pixel centres and edges.
        auto grid = [](double v) { return std::round(v * 16) / 16; };
        const glm::dvec2 centre(grid(20 + 24 * unit(random)), grid(20 + 24 * unit(random)));
        std::vector<glm::dvec2> rim;
        const int spokes = 5 + int(unit(random) * 12);
        for (int k = 0; k < spokes; ++k) {
            const double angle = 2 * M_PI * (k + 0.8 * unit(random)) / spokes;
            const double radius = 6 + 12 * unit(random);
            rim.push_back({grid(centre.x + radius * std::cos(angle)), grid(centre.y + radius * std::sin(angle))});
        }
        INFO("fan " << fan);
        requireFanCoversEachPixelOnce(centre, rim, 64);
    }
}

TEST_CASE("a triangle crossing the near plane and lying behind the camera is clipped, not wrapped", "[raster][clipping]")
{
    // Eye at the origin looking down −z, fovy 90°, 64×64, near 2, far 50. A floor triangle
    // at y = −1 with two vertices behind the camera (w < 0 there) and its side edges far
    // off-screen. The floor is at eye-z 1/|y_ndc|: rows 33..47 see it between near and far;
    // rows 48..63 would see it in front of the near plane (clipped), row 32 beyond far
    // (clipped), rows 0..31 look above the horizon. Unclipped, the part behind the camera
    // would wrap into the upper half.
    CameraSpec spec;
    spec.width = spec.height = 64;
    spec.projection.fovyDeg = 90;
    spec.projection.near = 2, spec.projection.far = 50;
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const Scene floor = sceneOf({{-500, -1, 10}, {500, -1, 10}, {0, -1, -500}}, {{0, 1, 2}});
    for (const auto& name : Convention::presetNames())
        for (bool reversed : {false, true}) {
            spec.convention = Convention::preset(name);
            spec.depth.reversed = reversed;
            const Camera camera(spec);
            const RenderResult image = RasterRenderer(floor).render(camera);
            for (int row = 0; row < 64; ++row)
                for (int col = 0; col < 64; ++col) {
                    const std::size_t i = std::size_t(row) * 64 + col;
                    const double yNdc = 1 - (row + 0.5) / 32;  // image up
                    INFO(name << (reversed ? " reversed" : "") << " pixel " << col << ", " << row);
                    REQUIRE(image.hit(i) == (row >= 33 && row <= 47));
                    if (!image.hit(i)) continue;
                    const double eyeZ = 1 / -yNdc, n = 2, f = 50;
                    const double expected = reversed ? n * (f - eyeZ) / (eyeZ * (f - n)) : f * (eyeZ - n) / (eyeZ * (f - n));
                    // Window depth is affine in y_ndc here, n·f/(f−n) per unit, 1/32 unit per
                    // row; vertex snapping may move it by up to 2^-8 of that slope.
                    const double slopePerRow = n * f / (f - n) / 32;
                    const double bound = 4 * storageQuantum(DepthFormat::Float32, expected) + slopePerRow / 256;
                    REQUIRE(std::abs(image.windowDepth.value[i] - expected) <= bound);
                }
            REQUIRE(Checker(floor).check(camera).report.comparison.consistent());
        }
}

TEST_CASE("a triangle wholly behind the camera draws nothing", "[raster][clipping]")
{
    CameraSpec spec;
    spec.width = spec.height = 32;
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const Scene behind = sceneOf({{-5, -5, 3}, {5, -5, 3}, {0, 5, 1}}, {{0, 1, 2}});
    const RenderResult image = RasterRenderer(behind).render(Camera(spec));
    for (std::size_t i = 0; i < image.primitiveId.size(); ++i) REQUIRE_FALSE(image.hit(i));
}

TEST_CASE("drawnDepthsNear: the window depths a triangle as drawn takes around a window point", "[raster][clipping]")
{
    // OpenGL, gluPerspective(90°, 1, 0.5, 10), 100 × 100, eye at the origin looking down −z: the
    // window point (50, 50) is the axis, and window x = 50 ± r is x_eye = ±(r / 50)·d at distance d.
    CameraSpec spec;
    spec.width = spec.height = 100;
    spec.projection = Projection::perspective(90.0, 0.5, 10.0);
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const Camera camera(spec);
    const double n = 0.5, f = 10.0, r = 1.0 / 256;
    const auto windowDepth = [&](double d) { return ((f + n) / (f - n) - 2 * f * n / ((f - n) * d) + 1) / 2; };  // textbook
    const glm::dvec2 axis(50, 50);

    // Face-on at distance 2: one depth.
    const WindowDepthRange faceOn = drawnDepthsNear(camera, {-1, -1, -2}, {1, -1, -2}, {0, 1, -2}, axis, r);
    REQUIRE(faceOn.lo == Approx(windowDepth(2)).epsilon(1e-13));
    REQUIRE(faceOn.hi == Approx(windowDepth(2)).epsilon(1e-13));

    // The plane z = −2 − x/2 across the whole square: d = 2 / (1 − x_ndc/2), x_ndc = ±r/50.
    const WindowDepthRange tilted = drawnDepthsNear(camera, {-1, -1, -1.5}, {1, -1, -2.5}, {0, 1, -2}, axis, r);
    REQUIRE(tilted.lo == Approx(windowDepth(2 / (1 + r / 100))).epsilon(1e-12));
    REQUIRE(tilted.hi == Approx(windowDepth(2 / (1 - r / 100))).epsilon(1e-12));
    REQUIRE(tilted.hi - tilted.lo > 1e-6);

    // Edge-on, its plane (y = 0) through the eye: a segment in the window, and at the axis the
    // triangle's whole cross-section along it, from distance 1 to distance 3. Its plane meets the
    // axis everywhere, so no single depth would do.
    const WindowDepthRange edgeOn = drawnDepthsNear(camera, {0, 0, -1}, {0, 0, -3}, {1, 0, -1}, axis, r);
    REQUIRE(edgeOn.lo == Approx(windowDepth(1)).epsilon(1e-13));
    REQUIRE(edgeOn.hi == Approx(windowDepth(3)).epsilon(1e-13));

    // No area at all (three points on a line) still has its depths where the line passes.
    const WindowDepthRange line = drawnDepthsNear(camera, {-1, 0, -2}, {0, 0, -2}, {1, 0, -2}, axis, r);
    REQUIRE(line.lo == Approx(windowDepth(2)).epsilon(1e-13));
    REQUIRE(line.hi == Approx(windowDepth(2)).epsilon(1e-13));

    // Nothing of it within r of the point (the triangle's nearest edge 2r away), or only behind
    // the near plane: empty.
    const double x = 2 * r / 50 * 2;  // x_eye of window x = 50 + 2r at distance 2
    REQUIRE(drawnDepthsNear(camera, {x, -1, -2}, {x + 1, -1, -2}, {x, 1, -2}, axis, r).empty());
    REQUIRE(drawnDepthsNear(camera, {-1, -1, -0.4}, {1, -1, -0.4}, {0, 1, -0.3}, axis, r).empty());
    // Cut by the near plane: only its part beyond it, from the near plane on.
    const WindowDepthRange cut = drawnDepthsNear(camera, {0, 0, -0.25}, {0, 0, -4}, {1, 0, -0.25}, axis, r);
    REQUIRE(cut.lo == Approx(windowDepth(n)).margin(1e-13));
    REQUIRE(cut.hi == Approx(windowDepth(4)).epsilon(1e-13));
}

TEST_CASE("the raster result is bit-identical for any number of threads", "[raster][determinism]")
{
    const Scene terrain = builtinScene("builtin:terrain?n=300");
    CameraSpec spec = terrain.defaultCamera;
    spec.width = 700, spec.height = 500;
    const Camera camera(spec);
    const RasterRenderer raster(terrain);
    RenderResult one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = raster.render(camera);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = raster.render(camera);
    }
    REQUIRE(one.primitiveId == two.primitiveId);
    REQUIRE(one.windowDepth.value == two.windowDepth.value);
}

namespace {

using testing::kernelCamera;
using testing::triangleSoup;

// raster.render() in kernel form `form` (ZCHECK_KERNELS; nullptr: unset, the default choice).
RenderResult renderWithKernel(const RasterRenderer& raster, const Camera& camera, const char* form,
                              const RasterFaults& faults = {})
{
    return testing::inForm(form, [&] { return raster.render(camera, faults); });
}

}  // namespace

TEST_CASE("the vector kernels are bit-identical to the scalar loops", "[raster][kernel]")
{
    const std::vector<const char*> forms = testing::vectorFormsToTest();
    // Two soups of triangles from sub-pixel slivers to ones spanning several 64×64 tiles, with
    // exact duplicates under other ids (equal keys: the first drawn keeps the pixel) and both
    // windings. In the first, every triangle lies between the near and far planes, anywhere in
    // the view and past its edges (boxes cut by the image): the vector set-up takes them eight
    // at a time. In the second, most cross the near or far plane (clipped, depths at the ends
    // of the range), so most runs of eight hold one that needs clipping and go to the scalar
    // set-up. Every convention, format, reversed-Z and a narrowed depth range, on an image
    // the tiles cut on both edges; and with the fault "no near clipping", whose depths in front
    // of the near plane leave the depth range (the clamp to it then decides), and two other
    // faults of the vertex stage. Compared bit for bit (memcmp), so a signed zero would show.
    // (A sweep, sweep.h: each soup a round, each of its setups a case.)
    const Scene soups[2] = {triangleSoup(true, 20261126), triangleSoup(false, 20261127)};
    for (std::size_t round = 0; round < 2; ++round) {
        const Scene& soup = soups[round];
        const RasterRenderer raster(soup);
        std::size_t item = 0;
        for (const char* convention : {"opengl", "direct3d", "vulkan", "metal", "opencv"})
            for (DepthFormat format : {DepthFormat::Unorm16, DepthFormat::Unorm24, DepthFormat::Float32})
                for (bool reversed : {false, true})
                    for (int variant = 0; variant < 5; ++variant) {
                        if (!testing::sweepTakes(round, item++)) continue;
                        const bool narrowRange = variant == 1;
                        RasterFaults faults;
                        faults.noNearClip = variant == 2;
                        faults.viewportMinusOne = variant == 3;
                        faults.screenLinearEyeZ = variant == 4;  // the scalar loops only
                        const CameraSpec spec = kernelCamera(convention, format, reversed, narrowRange);
                        const Camera camera(spec);
                        INFO((&soup == &soups[0] ? "inside" : "clipped") << " soup, " << convention << ' ' << toString(format)
                                                                          << (reversed ? " reversed" : "")
                                                                          << (narrowRange ? " range [0.25, 0.75]" : "")
                                                                          << (faults.noNearClip ? " no near clipping" : "")
                                                                          << (faults.viewportMinusOne ? " viewport − 1" : "")
                                                                          << (faults.screenLinearEyeZ ? " eye-z in screen space" : ""));
                        const RenderResult scalar = renderWithKernel(raster, camera, "baseline", faults);
                        const std::size_t pixels = std::size_t(spec.width) * spec.height;
                        REQUIRE(std::count_if(scalar.primitiveId.begin(), scalar.primitiveId.end(), [](std::uint32_t id) {
                                    return id != kNoPrimitive;
                                }) > std::ptrdiff_t(pixels / 2));
                        for (const char* form : forms) {
                            INFO("the " << form << " form");
                            const RenderResult vector = renderWithKernel(raster, camera, form, faults);
                            REQUIRE(std::memcmp(scalar.primitiveId.data(), vector.primitiveId.data(), pixels * sizeof(std::uint32_t)) == 0);
                            REQUIRE(std::memcmp(scalar.windowDepth.value.data(), vector.windowDepth.value.data(),
                                                pixels * sizeof(double)) == 0);
                        }
                    }
    }
}

TEST_CASE("the vector set-up keeps the fill rule where pixel centres lie on edges, eight triangles at a time",
          "[raster][kernel]")
{
    // A grid through the pixel centres, seen orthographically one eye unit a pixel (every
    // mapping a power of two: exact): each vertex on a centre, so that centres lie on
    // horizontal, vertical and diagonal edges, where the top-left rule alone says which
    // triangle draws them. Cells of 1 to 3 pixels, both diagonals and both windings in turn,
    // the depth varying from vertex to vertex; hundreds of triangles a tile, so that the vector
    // set-up takes them eight at a time. Without its bias on the edges that are neither top
    // nor left, two triangles drew such centres and the one drawn first kept them.
    const int W = 130, H = 70;
    Scene grid;
    grid.name = "grid through the pixel centres";
    std::mt19937 random(46);
    std::uniform_int_distribution<int> cell(1, 3), depthStep(0, 64);
    std::vector<float> xs, ys;
    for (int x = 0; x < W; x += cell(random)) xs.push_back(float(x) + 0.5f - W / 2.0f);
    for (int y = 0; y < H; y += cell(random)) ys.push_back(float(y) + 0.5f - H / 2.0f);
    for (float y : ys)
        for (float x : xs) grid.positions.push_back({x, y, -2.0f - float(depthStep(random)) / 64.0f});
    const auto at = [&](std::size_t col, std::size_t row) { return std::uint32_t(row * xs.size() + col); };
    for (std::size_t row = 0; row + 1 < ys.size(); ++row)
        for (std::size_t col = 0; col + 1 < xs.size(); ++col) {
            const std::uint32_t a = at(col, row), b = at(col + 1, row), c = at(col + 1, row + 1), d = at(col, row + 1);
            const bool flip = (row + col) % 2 == 1, otherWinding = (row * 7 + col) % 3 == 0;
            const glm::uvec3 first = flip ? glm::uvec3(a, b, d) : glm::uvec3(a, b, c);
            const glm::uvec3 second = flip ? glm::uvec3(b, c, d) : glm::uvec3(a, c, d);
            grid.triangles.push_back(otherWinding ? glm::uvec3(first.x, first.z, first.y) : first);
            grid.triangles.push_back(otherWinding ? second : glm::uvec3(second.x, second.z, second.y));
        }
    const RasterRenderer raster(grid);
    for (const char* convention : {"opengl", "vulkan"})
        for (DepthFormat format : {DepthFormat::Unorm24, DepthFormat::Float32}) {
            CameraSpec spec;
            spec.convention = Convention::preset(convention);
            spec.width = W, spec.height = H;
            spec.projection.type = ProjectionType::Orthographic;
            spec.projection.left = -W / 2.0, spec.projection.right = W / 2.0;
            spec.projection.bottom = -H / 2.0, spec.projection.top = H / 2.0;
            spec.projection.near = 1, spec.projection.far = 5;
            spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
            spec.depth.format = format;
            const Camera camera(spec);
            INFO(convention << ' ' << toString(format));
            const RenderResult scalar = renderWithKernel(raster, camera, "baseline");
            // Every centre inside the grid's outline is drawn (no crack between two triangles); the
            // outline taken 3 pixels in, so that it holds whichever way a convention's rows run.
            std::size_t inside = 0, drawn = 0;
            for (int row = 0; row < H; ++row)
                for (int col = 0; col < W; ++col) {
                    const double x = col + 0.5 - W / 2.0, y = H / 2.0 - (row + 0.5);
                    if (x < xs.front() + 3 || x > xs.back() - 3 || y < ys.front() + 3 || y > ys.back() - 3) continue;
                    ++inside;
                    drawn += scalar.hit(std::size_t(row) * W + col);
                }
            REQUIRE(inside > std::size_t(W * H / 2));
            REQUIRE(drawn == inside);
            for (const char* form : testing::vectorFormsToTest()) {
                INFO("the " << form << " form");
                const RenderResult vector = renderWithKernel(raster, camera, form);
                REQUIRE(testing::sameBits(scalar.primitiveId, vector.primitiveId));
                REQUIRE(testing::sameBits(scalar.windowDepth.value, vector.windowDepth.value));
            }
        }
}

TEST_CASE("the vector draw kernel's depth arithmetic equals the scalar loop's to 2^-52", "[raster][kernel]")
{
    // White-box: a last-bit difference in a pixel's interpolated depth would almost never
    // survive unorm or float32 quantization, so both kernels draw with depth keys of 2^52
    // steps (rasterRenderWithFineKeysForTesting): such a difference then shows in about half
    // the pixels it touches. The soup wholly inside the depth range, every convention,
    // standard and reversed-Z, the full and a narrowed depth range.
    const Scene soup = triangleSoup(true, 52);
    const std::vector<const char*> forms = testing::vectorFormsToTest();
    auto fineKeys = [&](const char* form, const Camera& camera) {
        return testing::inForm(form, [&] { return rasterRenderWithFineKeysForTesting(soup, camera); });
    };
    std::size_t distinct = 0;
    for (const char* convention : {"opengl", "direct3d", "vulkan", "metal", "opencv"})
        for (bool reversed : {false, true})
            for (bool narrowRange : {false, true}) {
                const Camera camera(kernelCamera(convention, DepthFormat::Unorm24, reversed, narrowRange));
                INFO(convention << (reversed ? " reversed" : "") << (narrowRange ? " range [0.25, 0.75]" : ""));
                const RenderResult scalar = fineKeys("baseline", camera);
                const std::size_t pixels = scalar.windowDepth.value.size();
                for (const char* form : forms) {
                    INFO("the " << form << " form");
                    const RenderResult vector = fineKeys(form, camera);
                    REQUIRE(std::memcmp(scalar.primitiveId.data(), vector.primitiveId.data(), pixels * sizeof(std::uint32_t)) == 0);
                    REQUIRE(std::memcmp(scalar.windowDepth.value.data(), vector.windowDepth.value.data(), pixels * sizeof(double)) == 0);
                }
                // The fine keys do resolve depth far below unorm24's quantum (the test can see a last bit).
                for (std::size_t i = 0; i < pixels; ++i)
                    if (scalar.primitiveId[i] != kNoPrimitive &&
                        scalar.windowDepth.value[i] != quantizeDepth(DepthFormat::Unorm24, scalar.windowDepth.value[i]))
                        ++distinct;
            }
    REQUIRE(distinct > 100000);
}

TEST_CASE("the vector vertex stage computes every vertex bit for bit as the scalar loop", "[raster][kernel]")
{
    // White-box: window depth and fixed-point position per vertex, compared before anything
    // quantizes them (a last-bit difference in z would almost never reach a stored depth).
    // Positions of every magnitude and sign, many behind the eye or beyond the far plane or
    // the guard band; perspective, orthographic and raw-matrix cameras under every convention;
    // the faults that change the vertex stage's matrices or planes.
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<glm::vec3> positions;
    for (int k = 0; k < 20003; ++k) {  // not a multiple of eight: the scalar tail runs too
        const float scale = std::pow(10.0f, unit(random) * 3.0f);  // 0.001 to 1000
        positions.emplace_back(unit(random) * scale, unit(random) * scale, unit(random) * scale - 0.5f * scale);
    }
    positions[5] = {0, 0, 0};  // the eye itself (w = 0)
    const Scene cloud = sceneOf(positions, {{0, 1, 2}});
    const std::vector<const char*> forms = testing::vectorFormsToTest();
    int snappedCount = 0;
    for (const char* convention : {"opengl", "direct3d", "vulkan", "metal", "opencv"})
        for (ProjectionType type : {ProjectionType::Perspective, ProjectionType::Orthographic})
            for (int variant = 0; variant < 5; ++variant) {
                CameraSpec spec;
                spec.convention = Convention::preset(convention);
                spec.width = 1920, spec.height = 1080;
                spec.projection.type = type;
                spec.projection.fovyDeg = 50, spec.projection.near = 0.1, spec.projection.far = 300;
                spec.projection.left = -40, spec.projection.right = 40, spec.projection.bottom = -25, spec.projection.top = 25;
                spec.view = View::lookAt({0.3, 0.2, 2.0}, {0, 0, -1}, {0, 1, 0});
                spec.depth.reversed = variant == 1;
                RasterFaults faults;
                faults.noNearClip = variant == 2;
                faults.viewportMinusOne = variant == 3;
                if (variant == 4) {  // a wrong matrix: the projection of another field of view
                    CameraSpec other = spec;
                    other.projection.fovyDeg = 71;
                    faults.overrideClipFromWorld = true;
                    faults.clipFromWorld = Camera(other).clipFromWorld;
                }
                const Camera camera(spec);
                INFO(convention << ' ' << toString(type) << " variant " << variant);
                const std::vector<RasterVertexForTesting> scalar = rasterVertexStageForTesting(cloud, camera, faults, false);
                REQUIRE(scalar.size() == positions.size());
                for (std::size_t v = 0; v < scalar.size(); ++v) snappedCount += scalar[v].X != INT32_MIN;
                for (const char* form : forms) {
                    INFO("the " << form << " form");
                    const std::vector<RasterVertexForTesting> vector =
                        testing::inForm(form, [&] { return rasterVertexStageForTesting(cloud, camera, faults, true); });
                    for (std::size_t v = 0; v < scalar.size(); ++v) {
                        INFO("vertex " << v);
                        REQUIRE(vector[v].outcode == scalar[v].outcode);
                        REQUIRE(vector[v].X == scalar[v].X);
                        REQUIRE(vector[v].Y == scalar[v].Y);
                        REQUIRE(std::memcmp(&vector[v].z, &scalar[v].z, sizeof(double)) == 0);
                    }
                }
            }
    REQUIRE(snappedCount > 50 * 2000);  // most cameras see a good part of the cloud

    // Ties: an orthographic camera whose world-to-subpixel scale is a power of two puts
    // x = (k + ½)/4096 − 64 exactly halfway between two 16.8 positions, X = k + ½; snapping
    // rounds half away from zero (llround), so X = k + 1, and −(k + 1) on the other side.
    CameraSpec exact;
    exact.width = 2048, exact.height = 1024;
    exact.projection.type = ProjectionType::Orthographic;
    exact.projection.left = -64, exact.projection.right = 64, exact.projection.bottom = -32, exact.projection.top = 32;
    exact.projection.near = 0.5, exact.projection.far = 10;
    exact.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    std::vector<glm::vec3> ties;
    for (int k = 0; k < 403; ++k) {
        const float half = (float(k) + 0.5f) / 4096.0f;
        ties.emplace_back(-64.0f + half, 0.0f, -2.0f);  // window x·256 = k + ½
        ties.emplace_back(-64.0f - half, 0.0f, -2.0f);  // window x·256 = −(k + ½)
    }
    const Scene tieCloud = sceneOf(ties, {{0, 1, 2}});
    std::vector<const char*> everyForm = forms;
    everyForm.push_back("baseline");
    for (const char* form : everyForm) {
        const std::vector<RasterVertexForTesting> snapped =
            testing::inForm(form, [&] { return rasterVertexStageForTesting(tieCloud, Camera(exact), {}, true); });
        for (int k = 0; k < 403; ++k) {
            INFO("the " << form << " form, k = " << k);
            REQUIRE(snapped[2 * k].X == k + 1);
            REQUIRE(snapped[2 * k + 1].X == -(k + 1));
        }
    }
}

TEST_CASE("ZCHECK_KERNELS takes auto or a form the processor has, and nothing else", "[raster][kernel]")
{
    const Scene triangle = sceneOf({{0, 0, -1}, {1, 0, -1}, {0, 1, -1}}, {{0, 1, 2}});
    const RasterRenderer raster(triangle);  // keeps a reference to the scene
    const Camera camera(pixelExactCamera(8));
    REQUIRE_NOTHROW(renderWithKernel(raster, camera, "auto"));
    REQUIRE_NOTHROW(renderWithKernel(raster, camera, "baseline"));
    for (KernelForm form : {KernelForm::Avx2, KernelForm::Avx512}) {
        INFO(nameOf(form));
        if (kernelFormSupported(form)) {
            REQUIRE_NOTHROW(renderWithKernel(raster, camera, nameOf(form)));
            REQUIRE(testing::inForm(nameOf(form), [] { return kernelForm(); }) == form);
        } else {
            REQUIRE_THROWS_WITH(renderWithKernel(raster, camera, nameOf(form)),
                                Catch::Contains(std::string("ZCHECK_KERNELS=") + nameOf(form)) &&
                                    Catch::Contains("this processor cannot run"));
        }
    }
    REQUIRE_THROWS_WITH(renderWithKernel(raster, camera, "scalar"),
                        Catch::Equals("ZCHECK_KERNELS=scalar: must be auto, baseline, avx2 or avx512"));
    REQUIRE_THROWS_WITH(renderWithKernel(raster, camera, "AVX2"), Catch::Contains("must be auto, baseline, avx2 or avx512"));
    // auto takes the widest form the processor has.
    const KernelForm widest = kernelFormSupported(KernelForm::Avx512) ? KernelForm::Avx512
                              : kernelFormSupported(KernelForm::Avx2) ? KernelForm::Avx2
                                                                       : KernelForm::Baseline;
    REQUIRE(testing::inForm("auto", [] { return kernelForm(); }) == widest);
    REQUIRE(testing::inForm(nullptr, [] { return kernelForm(); }) == widest);
    REQUIRE(testing::inForm("", [] { return kernelForm(); }) == widest);
}

TEST_CASE("both routes write every pixel of a render, whose buffers are not cleared first", "[raster][ray][allocated]")
{
    // RenderResult::allocated leaves the buffers as the allocator found them: a pixel a route
    // failed to write would show what the memory held. A triangle facing the eye at eye depth
    // D covers part of an image cut by the 64×64 tiles on both edges; memory of the same size
    // is filled with garbage and freed before each render, so that it may be handed back.
    // Rows that are whole cache lines (a width of 192) are copied into the image with streaming
    // stores, others (131) with ordinary ones.
    const double D = 3.5;
    const Scene tri = sceneOf({{-1, -1, float(-D)}, {1.5f, -0.5f, float(-D)}, {0, 1.2f, float(-D)}}, {{0, 1, 2}});
    const int width = GENERATE(131, 192);
    CameraSpec spec;
    spec.width = width, spec.height = 70;
    spec.projection.fovyDeg = 45, spec.projection.near = 0.5, spec.projection.far = 20;
    spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    spec.depth.format = DepthFormat::Float32;
    const Camera camera(spec);
    const double expected = 20 * (D - 0.5) / (D * (20 - 0.5));  // gluPerspective's window depth at eye depth D
    const Checker checker(tri);
    const std::size_t pixels = std::size_t(spec.width) * spec.height;
    for (int route = 0; route < 2; ++route) {
        {
            LargeVector<double> depthGarbage(pixels, -123.0);
            LargeVector<std::uint32_t> idGarbage(pixels, 77u);
        }
        const RenderResult image = route == 0 ? checker.renderRay(camera) : checker.renderRaster(camera);
        INFO((route == 0 ? "ray" : "raster") << " " << width << "x70");
        std::size_t hits = 0;
        for (std::size_t i = 0; i < pixels; ++i) {
            if (image.primitiveId[i] == kNoPrimitive) {
                REQUIRE(image.windowDepth.value[i] == camera.clearDepth());
            } else {
                REQUIRE(image.primitiveId[i] == 0u);
                REQUIRE(image.windowDepth.value[i] == Approx(expected).epsilon(1e-6));
                ++hits;
            }
        }
        REQUIRE(hits > pixels / 10);   // the triangle is there
        REQUIRE(hits < pixels / 2);    // and so are misses
    }
}

TEST_CASE("a plane at a known eye depth yields exactly that depth through each route", "[analytic]")
{
    // Eye at the origin looking down −z; a quad at z = −D covers the whole view. The expected
    // window depth is written out from the textbook mappings, independent of the code.
    const double D = 7.25, n = 0.5, f = 40;
    const Scene wall = sceneOf({{-100, -100, float(-D)}, {100, -100, float(-D)}, {100, 100, float(-D)}, {-100, 100, float(-D)}},
                               {{0, 1, 2}, {0, 2, 3}});
    const Checker checker(wall);
    for (const auto& name : Convention::presetNames())
        for (auto [type, far] : {std::pair{ProjectionType::Perspective, f}, std::pair{ProjectionType::Perspective, double(INFINITY)},
                                 std::pair{ProjectionType::Orthographic, f}})
            for (const auto& format : depthFormatNames())
                for (bool reversed : {false, true})
                    for (auto range : {std::pair{0.0, 1.0}, std::pair{0.25, 0.75}}) {
                        CameraSpec spec;
                        spec.convention = Convention::preset(name);
                        spec.width = 61, spec.height = 47;
                        spec.projection.type = type;
                        spec.projection.fovyDeg = 50;
                        spec.projection.left = -3, spec.projection.right = 4, spec.projection.bottom = -2.5,
                        spec.projection.top = 2;
                        spec.projection.near = n, spec.projection.far = far;
                        spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
                        spec.depth = {depthFormatFromName(format), reversed, range.first, range.second};
                        const Camera camera(spec);
                        // Infinite far plane: the limits f → ∞ of the perspective formulas.
                        const double unit = type == ProjectionType::Orthographic
                                                ? (reversed ? (f - D) / (f - n) : (D - n) / (f - n))
                                            : std::isinf(far)
                                                ? (reversed ? n / D : (D - n) / D)
                                                : (reversed ? n * (f - D) / (D * (f - n)) : f * (D - n) / (D * (f - n)));
                        const double expected = range.first + (range.second - range.first) * unit;
                        const double q = storageQuantum(spec.depth.format, expected);
                        const RenderResult byRay = checker.renderRay(camera, {}, EyePoints::Keep), byRaster = checker.renderRaster(camera);
                        INFO(name << " " << toString(type) << " far " << far << " " << format << (reversed ? " reversed" : "")
                                  << " range [" << range.first << "," << range.second << "]");
                        for (std::size_t i = 0; i < byRay.primitiveId.size(); ++i) {
                            REQUIRE(byRay.hit(i));
                            REQUIRE(byRaster.hit(i));
                            REQUIRE(byRay.windowDepth.value[i] == Approx(expected).epsilon(1e-13).margin(1e-15));
                            REQUIRE(camera.eyeZOf(byRay.pEye[i]) == Approx(D).epsilon(1e-13));
                            // The stored value is the format's rounding of the exact depth (or
                            // its neighbour, when the exact depth sits on a rounding boundary).
                            REQUIRE(std::abs(byRaster.windowDepth.value[i] - quantizeDepth(spec.depth.format, expected)) <=
                                    (std::abs(quantizeDepth(spec.depth.format, expected * (1 + 1e-12)) -
                                              quantizeDepth(spec.depth.format, expected * (1 - 1e-12))) > 0 ? q * 1.0001 : 0.0));
                        }
                    }
}
