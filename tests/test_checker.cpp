// The Checker as a library: one object per scene, const and shareable between threads; faults
// as arguments; one mistake catalogue for injection and diagnosis.
#include "zcheck/checker.h"
#include "zcheck/camera_file.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/detail/kernel_choice.h"
#include "zcheck/map_verifier.h"
#include "zcheck/mesh_loader.h"
#include "zcheck/mistakes.h"
#include "zcheck/report.h"
#include "zcheck/verify.h"

#include "diagnosis_helpers.h"
#include "compare_rows.h"  // check/src: the comparison's private parts, tested white-box
#include "percentile.h"
#include "slope_table.h"
#include "kernel_testing.h"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <random>

#include <set>
#include <thread>
#include <tuple>

using namespace zcheck;

namespace {
CameraSpec smallCamera(const Scene& scene)
{
    CameraSpec spec = scene.defaultCamera;
    spec.width = 160, spec.height = 120;
    return spec;
}

// windowDepthSlope of triangle t of the scene, through the camera.
double slopeOfTriangle(const Scene& scene, const Camera& camera, std::uint32_t t)
{
    const auto& tri = scene.triangles[t];
    return windowDepthSlope(camera, glm::dvec3(scene.positions[tri[0]]), glm::dvec3(scene.positions[tri[1]]),
                            glm::dvec3(scene.positions[tri[2]]));
}

// smallCamera at a size the 64×64 tiles cut on both edges.
CameraSpec tileCutCamera(const Scene& scene)
{
    CameraSpec spec = smallCamera(scene);
    spec.width = 203, spec.height = 131;
    return spec;
}

// A check clean, with the ray's rows flipped (thousands of unexplained pixels), and with the
// raster's unorm depths truncated (a depth bias).
std::vector<CheckOptions> cleanFlippedAndBiased()
{
    std::vector<CheckOptions> runs(3);
    runs[1].faults.ray.flipRows = true;
    runs[2].faults.raster.truncateUnorm = true;
    return runs;
}
}  // namespace

TEST_CASE("one Checker used from several threads at once gives each the same answer", "[checker][threads]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    const Camera camera(smallCamera(checker.scene()));
    const CheckResult alone = checker.check(camera);
    REQUIRE(alone.report.comparison.consistent());
    std::vector<CheckResult> results(4);
    std::vector<VerifyResult> verified(4);
    const LargeVector<double>& drawn = alone.raster.windowDepth.value;
    DepthMap map = DepthMap::exact(camera.width(), camera.height(), DepthQuantity::Window, {drawn.begin(), drawn.end()});
    std::vector<std::thread> threads;
    for (std::size_t k = 0; k < results.size(); ++k)
        threads.emplace_back([&, k] {
            results[k] = checker.check(camera);
            verified[k] = verifier.verify(camera, map);  // builds the vertex index once, under call_once
        });
    for (auto& thread : threads) thread.join();
    for (std::size_t k = 0; k < results.size(); ++k) {
        REQUIRE(results[k].raster.windowDepth.value == alone.raster.windowDepth.value);
        REQUIRE(results[k].ray.windowDepth.value == alone.ray.windowDepth.value);
        REQUIRE(results[k].comparison.pixelClass == alone.comparison.pixelClass);
        REQUIRE(verified[k].comparison.report.consistent());
    }
}

TEST_CASE("faults are arguments of a render: a faulty render leaves the next clean one clean", "[checker]")
{
    const Checker checker(builtinScene("builtin:default"));
    const Camera camera(smallCamera(checker.scene()));
    RayFaults flipped;
    flipped.flipRows = true;
    CheckOptions faulty;
    faulty.faults.ray = flipped;
    REQUIRE_FALSE(checker.check(camera, faulty).report.comparison.consistent());
    REQUIRE(checker.check(camera).report.comparison.consistent());
    // The flipped render is the clean one upside down, pixel for pixel.
    const RenderResult clean = checker.renderRay(camera), upsideDown = checker.renderRay(camera, flipped);
    for (int row = 0; row < camera.height(); ++row)
        for (int col = 0; col < camera.width(); ++col)
            REQUIRE(upsideDown.windowDepth.at(col, row) == clean.windowDepth.at(col, camera.height() - 1 - row));
}

TEST_CASE("one mistake catalogue: unique names, each injectable or re-readable, both for most", "[checker][mistakes]")
{
    std::set<std::string> names;
    int both = 0;
    for (const Mistake& mistake : mistakeCatalogue()) {
        INFO(mistake.name);
        REQUIRE(names.insert(mistake.name).second);
        REQUIRE((mistake.inject || mistake.reread));
        both += mistake.inject && mistake.reread ? 1 : 0;
    }
    REQUIRE(both >= 12);
    REQUIRE(injectableMistakes().size() == 21);
    // The names the suite and the diagnosis used to spell differently are one name now.
    for (const char* gone : {"vertical-flip", "other-handed", "other-ndc-range"}) REQUIRE(names.count(gone) == 0);
    for (const char* kept : {"y-flip", "handedness", "ndc-range"}) REQUIRE(names.count(kept) == 1);
}

TEST_CASE("a map rendered under a mistake is diagnosed as that mistake, for every mistake with both uses",
          "[checker][mistakes][diagnose]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    CameraSpec spec = smallCamera(checker.scene());
    spec.convention = Convention::preset("vulkan");
    const Camera camera(spec);
    int diagnosed = 0;
    for (const Mistake& mistake : mistakeCatalogue()) {
        RouteFaults faults;
        if (!mistake.inject || !mistake.reread || !mistake.inject(camera, faults)) continue;
        // The mistaken route stands in for a renderer that made the mistake.
        const RenderResult wrong = checker.render(camera, mistake.route, faults);
        // A map with no surface at all is no evidence for one mistake over another (a view
        // turned away, a transposed projection): the diagnosis names none (test below).
        if (!testing::anyHit(wrong)) continue;
        const DepthMap map = testing::windowMapOf(camera, wrong);
        if (verifier.verify(camera, map).comparison.report.consistent()) continue;  // invisible here
        const bool named = testing::diagnosedAs(verifier, camera, map, mistake.name);
        INFO(mistake.name);
        CHECK(named);
        diagnosed += named ? 1 : 0;
    }
    REQUIRE(diagnosed >= 10);
}

TEST_CASE("verify refuses a map whose size is not the camera's", "[checker]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    const Camera camera(smallCamera(checker.scene()));
    const DepthMap map = DepthMap::exact(10, 10, DepthQuantity::EyeZ, std::vector<double>(100, 1.0));
    REQUIRE_THROWS_WITH(verifier.verify(camera, map), Catch::Contains("10x10") && Catch::Contains("160x120"));
}

// The comparison runs in fixed 64×64 tiles merged in tile order; its report must not
// depend on the thread count, and its statistics must equal the ones computed the plain way.
TEST_CASE("the comparison's report is the same for 1 and 2 threads, and its p99 is the sorted one", "[checker][threads]")
{
    const Checker checker(builtinScene("builtin:default"));
    CameraSpec spec = smallCamera(checker.scene());
    spec.depth.format = DepthFormat::Unorm16;  // errors of a few quanta: a spread to rank
    const Camera camera(spec);
    CheckResult one, two;
    {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = checker.check(camera);
    }
    {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = checker.check(camera);
    }
    const ComparisonReport& a = one.report.comparison;
    const ComparisonReport& b = two.report.comparison;
    REQUIRE(one.comparison.pixelClass == two.comparison.pixelClass);
    REQUIRE(a.agree == b.agree);
    REQUIRE(a.edgeSurface == b.edgeSurface);
    REQUIRE(a.coverageExplained == b.coverageExplained);
    REQUIRE(a.worst.col == b.worst.col);
    REQUIRE(a.worst.row == b.worst.row);
    REQUIRE(a.maxErrorOverTolerance == b.maxErrorOverTolerance);
    REQUIRE(a.meanSignedErrorQuanta == b.meanSignedErrorQuanta);
    REQUIRE(a.p99ErrorQuanta == b.p99ErrorQuanta);
    REQUIRE(a.p99RelativeEyeZError == b.p99RelativeEyeZError);

    // p99 of |d_raster − d_ray| / q over the pixels compared on depth, by sorting.
    std::vector<float> errorQuanta;
    const std::size_t n = one.ray.primitiveId.size();
    float maxRatio = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const PixelClass c = one.comparison.pixelClass[i];
        if (c != PixelClass::Agree && c != PixelClass::DepthError) continue;
        const double ray = one.ray.windowDepth.value[i], raster = one.raster.windowDepth.value[i];
        errorQuanta.push_back(float(inQuanta(std::abs(raster - ray), storageQuantum(spec.depth.format, ray))));
        maxRatio = std::max(maxRatio, one.comparison.errorOverTolerance[i]);
    }
    REQUIRE(errorQuanta.size() > 1000);
    std::sort(errorQuanta.begin(), errorQuanta.end());
    REQUIRE(errorQuanta.back() > errorQuanta.front());
    const std::size_t k = std::size_t(std::ceil(0.99 * double(errorQuanta.size()))) - 1;
    REQUIRE(a.p99ErrorQuanta == double(errorQuanta[k]));
    // The worst pixel holds the largest error / tolerance.
    REQUIRE(one.comparison.errorOverTolerance[std::size_t(a.worst.row) * std::size_t(camera.width()) +
                                              std::size_t(a.worst.col)] == maxRatio);
}

// `zcheck check` without pictures draws, traces and compares tile by tile; its report must be
// the full-frame check's, field for field, clean or not, for any thread count.
TEST_CASE("a check tile by tile reports what the full-frame check reports", "[checker][threads]")
{
    for (const char* name : {"builtin:default", "builtin:near-crossing", "builtin:terrain?n=40"}) {
        const Checker checker(builtinScene(name));
        CameraSpec spec = tileCutCamera(checker.scene());
        for (const DepthFormat format : {DepthFormat::Unorm16, DepthFormat::Float32}) {
            spec.depth.format = format;
            const Camera camera(spec);
            std::vector<CheckOptions> runs = cleanFlippedAndBiased();
            runs[2].faults.ray.shiftPixels = {0.5, 0.0};
            for (CheckOptions& options : runs) {
                CheckResult full = checker.check(camera, options);
                options.keepPixels = false;
                for (const int threads : {1, 2}) {
                    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
                    CheckResult tiled = checker.check(camera, options);
                    INFO(name << ", " << toString(format) << ", " << threads << " threads");
                    REQUIRE(tiled.report.timings.tileByTile);
                    REQUIRE(tiled.ray.primitiveId.empty());
                    REQUIRE(tiled.comparison.pixelClass.empty());
                    tiled.report.timings = full.report.timings = Timings{};
                    REQUIRE(checkReportJson(tiled.report) == checkReportJson(full.report));
                    REQUIRE(formatSummary(tiled.report) == formatSummary(full.report));
                }
            }
        }
    }
}

// The comparison's percentiles keep only each thread's largest values; the one selected must
// be the sorted one whatever the order the values arrive in and however they are split.
TEST_CASE("the 99th percentile from the largest values kept is the sorted one, in any order and split", "[compare]")
{
    std::mt19937 random(11);
    for (const int n : {1, 2, 99, 100, 101, 250, 5000, 100000}) {
        std::vector<float> values(static_cast<std::size_t>(n));
        std::uniform_int_distribution<int> fewDistinct(0, 40);  // ties, and a spread
        for (float& v : values) v = float(fewDistinct(random)) * 0.25f + (n % 2 ? 0.0f : float(random() % 1000) * 1e-3f);
        std::vector<float> sorted = values;
        std::sort(sorted.begin(), sorted.end());
        const double expected = sorted[std::size_t(std::ceil(0.99 * n)) - 1];
        std::vector<std::vector<float>> orders = {values, sorted, std::vector<float>(sorted.rbegin(), sorted.rend())};
        for (const std::vector<float>& order : orders)
            for (const int parts : {1, 3})
                for (const std::size_t slack : {1, 2}) {
                    // n is the most the keepers see; n/100 + 1 the fewest they may keep (every
                    // value a keeper's shrinking drops wrongly is then missed)
                    const std::size_t keep = std::size_t(n) / 100 + slack;
                    std::vector<LargestValues> keepers(static_cast<std::size_t>(parts), LargestValues(keep));
                    // Contiguous runs per keeper, as threads take runs of tiles.
                    for (std::size_t k = 0; k < order.size(); ++k) keepers[k * std::size_t(parts) / order.size()].add(order[k]);
                    std::vector<const LargestValues*> all;
                    for (const LargestValues& keeper : keepers) all.push_back(&keeper);
                    INFO("n " << n << ", " << parts << " keepers of " << keep);
                    REQUIRE(LargestValues::percentile99(all) == expected);
                    // Given a row at a time with a mask, as the comparison gives them, among larger
                    // values masked out: the same, with and without a floor. Rows of a tile's 64
                    // pixels, of more (taken 64 at a time) and of a few (less than eight bytes).
                    for (const float floor : {0.0f, float(expected)}) {
                        std::vector<LargestValues> byRow(static_cast<std::size_t>(parts), LargestValues(keep, floor));
                        for (std::size_t part = 0; part < std::size_t(parts); ++part) {
                            std::vector<float> row;
                            std::vector<std::uint8_t> use;
                            std::size_t rows = 0;
                            auto flush = [&] {
                                byRow[part].add(row.data(), use.data(), row.size());
                                row.clear(), use.clear(), ++rows;
                            };
                            for (std::size_t k = 0; k < order.size(); ++k) {
                                if (k * std::size_t(parts) / order.size() != part) continue;
                                row.push_back(order[k]), use.push_back(1);
                                row.push_back(1e30f), use.push_back(0);
                                const std::size_t rowLength[] = {64, 150, 6};
                                if (row.size() == rowLength[rows % 3]) flush();
                            }
                            flush();
                        }
                        std::vector<const LargestValues*> allByRow;
                        std::size_t counted = 0;
                        for (const LargestValues& keeper : byRow) allByRow.push_back(&keeper), counted += keeper.count();
                        REQUIRE(counted == std::size_t(n));
                        REQUIRE(LargestValues::percentile99(allByRow) == expected);
                    }
                    // With a floor at or below the percentile, the same; above it, no answer.
                    for (const float floor : {float(expected), float(expected) + 0.125f}) {
                        std::vector<LargestValues> floored(static_cast<std::size_t>(parts), LargestValues(keep, floor));
                        for (std::size_t k = 0; k < order.size(); ++k) floored[k * std::size_t(parts) / order.size()].add(order[k]);
                        std::vector<const LargestValues*> allFloored;
                        for (const LargestValues& keeper : floored) allFloored.push_back(&keeper);
                        const std::optional<double> p99 = LargestValues::percentile99(allFloored);
                        if (floor == float(expected)) REQUIRE(p99 == expected);
                        else if (sorted.back() > expected) REQUIRE_FALSE(p99.has_value());
                    }
                }
    }
    REQUIRE(LargestValues::percentile99({}) == 0.0);
    // Kept too few for the rank: no answer, not a wrong one.
    LargestValues tooFew(1);
    for (int k = 0; k < 1000; ++k) tooFew.add(float(k));
    REQUIRE_FALSE(LargestValues::percentile99({&tooFew}).has_value());
    // A sample's floor lies at its 97th percentile.
    std::vector<float> sample(2000);
    for (std::size_t k = 0; k < sample.size(); ++k) sample[k] = float(sample.size() - k);
    REQUIRE(LargestValues::floorBelowPercentile99(sample) == 1941.0f);
    std::vector<float> small(999, 5.0f);
    REQUIRE(LargestValues::floorBelowPercentile99(small) == 0.0f);
}

// The keepers select by counting bit patterns (kthSmallestBits); std::nth_element is the
// independent expectation, over patterns that differ only in their lowest bits, only in their
// highest, everywhere, and in a few values repeated; in one array, and in parts.
TEST_CASE("the k-th smallest by counting bits is nth_element's", "[compare]")
{
    std::mt19937 random(5);
    auto uniformBits = [&](std::uint32_t mask, std::uint32_t base) { return base | (std::uint32_t(random()) & mask); };
    const std::vector<std::function<std::uint32_t()>> kinds = {
        [&] { return uniformBits(0x3FFu, 0x40490000u); },   // the lowest 10 bits alone
        [&] { return uniformBits(0xFFFFu, 0x40490000u); },  // the low half alone (the second count's)
        [&] { return uniformBits(0xFFFF0000u, 0x5u); },     // the high half alone, sign bit included
        [&] { return uniformBits(0xFFE00000u, 0x5u); },     // the top 11 bits alone
        [&] { return uniformBits(0xFFFFFFFFu, 0); },        // everywhere
        [&] { return std::uint32_t(random() % 3) * 0x00210401u; },  // three values, differing in both halves
        [&] { return 0x3F800000u; },                        // one value only
    };
    for (const auto& kind : kinds)
        for (const std::size_t n : {std::size_t(1), std::size_t(2), std::size_t(37), std::size_t(5000)}) {
            std::vector<std::uint32_t> bits(n);
            for (std::uint32_t& b : bits) b = kind();
            for (const std::size_t k : {std::size_t(0), n / 3, n * 97 / 100, n - 1}) {
                std::vector<std::uint32_t> sorted = bits;
                std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(k), sorted.end());
                INFO("n " << n << ", k " << k);
                REQUIRE(kthSmallestBits({{bits.data(), n}}, k) == sorted[k]);
                // The same patterns in three parts, one of them empty, as three threads' keepers.
                const std::vector<BitsSpan> parts = {{bits.data(), n / 3}, {bits.data() + n / 3, 0}, {bits.data() + n / 3, n - n / 3}};
                REQUIRE(kthSmallestBits(parts, k) == sorted[k]);
            }
        }
}

TEST_CASE("a judge's slopes are each triangle's own, for its camera, one at a time and a row at a time", "[checker][compare]")
{
    // A judge with a table computes a block of 64 consecutive triangles' slopes the first time
    // one of them is asked for, several per instruction (the last block partial here); one
    // without computes each when asked. Each slope must equal windowDepthSlope of that triangle
    // alone, for the judge's own camera (judges of two cameras alive at once), in both kernel
    // forms, and a row of primitives must get them lane by lane (0 for no triangle): asked of a
    // fresh judge (its blocks not computed yet), and again once every block is.
    const Scene scene = builtinScene("builtin:terrain?n=60");
    REQUIRE(scene.triangleCount() % 64 != 0);
    CameraSpec wide = smallCamera(scene), narrow = wide;
    wide.projection = Projection::perspective(90.0, 0.1, 100.0);
    narrow.projection = Projection::perspective(20.0, 0.1, 100.0);
    const Camera wideCamera(wide), narrowCamera(narrow);
    auto expected = [&](const Camera& camera, std::uint32_t t) { return slopeOfTriangle(scene, camera, t); };
    const std::uint32_t last = std::uint32_t(scene.triangleCount() - 1);
    const std::vector<std::uint32_t> row = {4096, 4096, 0, 1, 1, kNoPrimitive, 4097, 1, 0, 5120, 1024,
                                            last, kUnknownPrimitive, last + 1, last - 64};
    for (const char* form : testing::everyFormToTest()) {
        for (const SlopeSource source : {SlopeSource::TableOfSeen, SlopeSource::EachCall}) {
            const char* sourceName = source == SlopeSource::TableOfSeen ? "table" : "each call";
            auto judge = [&](const Camera& camera) {
                return testing::inForm(form, [&] {
                    return std::make_unique<PixelJudge>(scene, camera, ToleranceModel{}, source);
                });
            };
            const std::unique_ptr<PixelJudge> aMade = judge(wideCamera), bMade = judge(narrowCamera);
            const PixelJudge &a = *aMade, &b = *bMade;
            auto requireRow = [&](const char* when) {
                for (const auto& [rowJudge, camera] : {std::pair{&a, &wideCamera}, std::pair{&b, &narrowCamera}}) {
                    std::vector<double> slope(row.size(), -1.0);
                    slopesOf(*rowJudge, row.data(), row.size(), slope.data());
                    for (std::size_t j = 0; j < row.size(); ++j) {
                        INFO(form << ", " << sourceName << ", " << when << ": lane " << j << ", primitive " << row[j]);
                        REQUIRE(slope[j] == (row[j] < scene.triangleCount() ? expected(*camera, row[j]) : 0.0));
                    }
                }
            };
            requireRow("asked first");
            for (std::uint32_t t = 0; t < scene.triangleCount(); ++t) {
                INFO(form << ", " << sourceName << ": triangle " << t);
                REQUIRE(expected(wideCamera, t) != expected(narrowCamera, t));
                REQUIRE(a.slope(t) == expected(wideCamera, t));
                REQUIRE(b.slope(t) == expected(narrowCamera, t));
            }
            requireRow("every block computed");
        }
    }
}

TEST_CASE("a judge's table of slopes filled from several threads at once holds each triangle's own", "[checker][compare]")
{
    // Rows of a frame's kind (runs of neighbouring triangles, some lanes with none), asked in a
    // random order from every worker of fresh judges, so that threads meet blocks another one is
    // computing: every answer must still be the triangle's own slope.
    const Scene scene = builtinScene("builtin:terrain?n=60");
    const Camera camera(smallCamera(scene));
    const std::uint32_t n = std::uint32_t(scene.triangleCount());
    std::vector<double> expected(n);
    for (std::uint32_t t = 0; t < n; ++t) expected[t] = slopeOfTriangle(scene, camera, t);
    std::mt19937 random(7);
    std::vector<std::vector<std::uint32_t>> rows(4000, std::vector<std::uint32_t>(64));
    for (auto& r : rows) {
        std::uint32_t t = std::uint32_t(random() % n);
        for (std::uint32_t& p : r) {
            if (random() % 4 == 0) t = std::uint32_t(random() % n);
            p = random() % 16 == 0 ? kNoPrimitive : t;
        }
    }
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 4);
    for (const char* form : testing::everyFormToTest())
        for (int round = 0; round < 20; ++round) {
            const std::unique_ptr<PixelJudge> judge = testing::inForm(
                form, [&] { return std::make_unique<PixelJudge>(scene, camera); });
            std::atomic<std::size_t> wrong{0};
            tbb::parallel_for(std::size_t(0), rows.size(), [&](std::size_t k) {
                const std::vector<std::uint32_t>& r = rows[(k * 2654435761u + std::size_t(round)) % rows.size()];
                double slope[64];
                if (k % 3 == 0) {
                    for (std::size_t j = 0; j < r.size(); ++j) slope[j] = judge->slope(r[j]);
                } else {
                    slopesOf(*judge, r.data(), r.size(), slope);
                }
                for (std::size_t j = 0; j < r.size(); ++j)
                    if (slope[j] != (r[j] < n ? expected[r[j]] : 0.0)) ++wrong;
            });
            INFO(form << ", round " << round);
            REQUIRE(wrong == 0);
        }
}

TEST_CASE("camera-pose mistakes: an inverted extrinsic and OpenCV axes used as OpenGL's are diagnosed by name", "[checker][mistakes][diagnose]")
{
    // builtin:near-crossing has geometry all around its eye, so a camera turned 180° about its
    // x axis, or placed by the inverse of its view, still sees surfaces.
    const Checker checker(builtinScene("builtin:near-crossing"));
    const MapVerifier verifier(checker);
    for (const std::string convention : {"opengl", "opencv"}) {
        CameraSpec spec = smallCamera(checker.scene());
        spec.convention = Convention::preset(convention);
        spec.view.eye = {0.3, 0.4, 0.2};  // off the origin, so that the inverse view is another pose
        const Camera camera(spec);
        for (const char* name : {"inverted-extrinsic", "opencv-opengl-axes"}) {
            INFO(convention << ": " << name);
            const Mistake& mistake = testing::mistakeNamed(name);
            RouteFaults faults;
            REQUIRE(mistake.inject(camera, faults));
            const RenderResult wrong = checker.render(camera, mistake.route, faults);
            const auto hits = std::count_if(wrong.primitiveId.begin(), wrong.primitiveId.end(),
                                            [](std::uint32_t id) { return id != kNoPrimitive; });
            REQUIRE(hits > camera.width() * camera.height() / 10);
            const DepthMap map = testing::windowMapOf(camera, wrong);
            REQUIRE_FALSE(verifier.verify(camera, map).comparison.report.consistent());
            REQUIRE(testing::diagnosedAs(verifier, camera, map, name));
        }
    }
}

TEST_CASE("a map with no surface is explained by no hypothesis (a view that sees nothing explains nothing)", "[checker][diagnose]")
{
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    const Camera camera(smallCamera(checker.scene()));
    const DepthMap empty = DepthMap::exact(camera.width(), camera.height(), DepthQuantity::Window,
                                           std::vector<double>(std::size_t(camera.width()) * camera.height(), camera.clearDepth()));
    const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, empty);
    for (const Hypothesis& h : diagnosis) {
        INFO(h.name << " " << h.variant);
        REQUIRE_FALSE(h.consistent);
    }
    // ... and the diagnosis says that it is empty, first, not which hypothesis came closest.
    REQUIRE(diagnosis.front().name == "empty-map");
    REQUIRE(formatDiagnosis(diagnosis, /*compared=*/0).find("holds no surface") != std::string::npos);
}

namespace {
// A check's report as `zcheck check --json` gives it, without its timings.
std::string reportWithoutTimings(CheckReport report)
{
    report.timings = Timings{};
    return checkReportJson(report);
}
}  // namespace

TEST_CASE("the comparison's AVX2 and AVX-512 forms are bit-identical to its baseline form", "[compare][kernel]")
{
    // TileComparison's row loop is one source compiled twice (kernel_choice.h), and the slopes
    // of a row's triangles are computed together, several per instruction. Both forms over
    // three built-in scenes and a triangle soup (sliver to tile-sized triangles, duplicates
    // under other ids), each through its camera at 203×131 (tiles cut on both edges) in two
    // conventions, three formats, reversed or not, and through the orthographic and raw-matrix
    // projections; clean, with rows flipped (unexplained pixels), with truncated unorm and a
    // half-pixel shift (a depth bias), and with distance stored as eye-z. The whole report
    // (every count, maximum, percentile, the worst pixel and the samples) and the per-pixel
    // classes and ratios compared bit for bit; also compareRoutes given the ray's eye points
    // and the raster's own per-pixel quanta (verify's inputs).
    const std::vector<const char*> forms = testing::vectorFormsToTest();
    auto inForm = [](const char* form, auto run) { return testing::inForm(form, run); };

    std::vector<CheckOptions> runs(4);
    runs[1].faults.ray.flipRows = true;
    runs[2].faults.raster.truncateUnorm = true;
    runs[2].faults.ray.shiftPixels = {0.5, 0.0};
    runs[3].faults.ray.distanceAsEyeZ = true;
    std::int64_t agree = 0, unexplained = 0, explained = 0, biased = 0;
    for (const char* name : {"builtin:default", "builtin:near-crossing", "builtin:terrain?n=40", "soup"}) {
        const bool soup = std::string(name) == "soup";
        const Checker checker(soup ? testing::triangleSoup(false, 41) : builtinScene(name));
        CameraSpec base = soup ? testing::kernelCamera("opengl", DepthFormat::Unorm24, false, false)
                               : checker.scene().defaultCamera;
        base.width = 203, base.height = 131;
        std::vector<CameraSpec> cameras;
        for (const char* convention : {"opengl", "opencv"})
            for (const DepthFormat format : {DepthFormat::Unorm16, DepthFormat::Unorm24, DepthFormat::Float32})
                for (const bool reversed : {false, true}) {
                    CameraSpec spec = base;
                    spec.convention = Convention::preset(convention);
                    spec.depth.format = format, spec.depth.reversed = reversed;
                    cameras.push_back(spec);
                }
        for (const char* model : {"orthographic", "matrix-direct3d"}) {
            const CameraSpec example = readCameraFile(std::string(ZCHECK_TESTS_DIR) + "/../examples/" + model + ".json");
            CameraSpec spec = base;  // the scene's view, the example's projection, convention and depth
            spec.projection = example.projection, spec.convention = example.convention, spec.depth = example.depth;
            cameras.push_back(spec);
        }
        for (const CameraSpec& spec : cameras) {
            const Camera camera(spec);
            for (std::size_t k = 0; k < runs.size(); ++k) {
                INFO(name << ", " << spec.convention.name << ", " << toString(spec.depth.format)
                          << (spec.depth.reversed ? " reversed" : "") << ", projection " << int(spec.projection.type)
                          << ", run " << k);
                const CheckResult baseline = inForm("baseline", [&] { return checker.check(camera, runs[k]); });
                for (const char* form : forms) {
                    INFO("the " << form << " form");
                    const CheckResult chosen = inForm(form, [&] { return checker.check(camera, runs[k]); });
                    REQUIRE(reportWithoutTimings(chosen.report) == reportWithoutTimings(baseline.report));
                    REQUIRE(testing::sameBits(chosen.comparison.pixelClass, baseline.comparison.pixelClass));
                    REQUIRE(testing::sameBits(chosen.comparison.errorOverTolerance, baseline.comparison.errorOverTolerance));
                }
                const ComparisonReport& r = baseline.report.comparison;
                agree += r.agree, unexplained += r.unexplained(), explained += r.coverageExplained + r.edgeSurface;
                biased += r.depthBias ? 1 : 0;
            }
            // With the ray's eye points (the relative eye-z error from them) and the raster's
            // own quanta, as verify passes them.
            const RenderResult ray = checker.renderRay(camera, {}, EyePoints::Keep), raster = checker.renderRaster(camera);
            std::vector<double> quanta(raster.windowDepth.value.size());
            for (std::size_t i = 0; i < quanta.size(); ++i)
                quanta[i] = storageQuantum(DepthFormat::Float32, raster.windowDepth.value[i]) * double(1 + i % 5);
            // And a map's declared allowance (verify --rel-tolerance), some pixels' large enough to
            // turn a depth error into agreement, holes allowed.
            std::vector<double> allowance(quanta.size());
            for (std::size_t i = 0; i < allowance.size(); ++i) allowance[i] = quanta[i] * double(i % 7) * double(i % 3 == 0 ? 1000 : 1);
            const std::vector<double>* ownQuanta = &quanta;
            const std::vector<DeclaredMap> declarations = {{ownQuanta, nullptr, false}, {nullptr, nullptr, false},
                                                           {ownQuanta, &allowance, true}, {nullptr, &allowance, false}};
            for (const DeclaredMap& declared : declarations) {
                const Comparison b = inForm("baseline", [&] { return compareRoutes(checker.scene(), camera, ray, raster, {}, declared); });
                for (const char* form : forms) {
                    INFO("the " << form << " form");
                    const Comparison c = inForm(form, [&] { return compareRoutes(checker.scene(), camera, ray, raster, {}, declared); });
                    CheckReport byBaseline, byChosen;
                    byBaseline.comparison = b.report, byChosen.comparison = c.report;
                    REQUIRE(checkReportJson(byChosen) == checkReportJson(byBaseline));
                    REQUIRE(testing::sameBits(c.pixelClass, b.pixelClass));
                    REQUIRE(testing::sameBits(c.errorOverTolerance, b.errorOverTolerance));
                }
            }
        }
    }
    // Every kind of pixel was there to compare.
    REQUIRE(agree > 100000);
    REQUIRE(unexplained > 1000);
    REQUIRE(explained > 1000);
    REQUIRE(biased > 0);
}

namespace {
// Two routes' results made up by a test, with the raster's own quanta (as verify passes them).
struct MadeUpRoutes {
    MadeUpRoutes(const Camera& camera)
        : ray(RenderResult::cleared(camera.width(), camera.height(), camera.clearDepth())),
          raster(RenderResult::cleared(camera.width(), camera.height(), camera.clearDepth())),
          quantum(ray.primitiveId.size(), storageQuantum(camera.depth().format, 0.0))
    {
    }
    // Pixel i: both routes on `primitive` at these depths, quantum q.
    void setCommon(std::size_t i, std::uint32_t primitive, double rayDepth, double rasterDepth, double q)
    {
        ray.primitiveId[i] = raster.primitiveId[i] = primitive;
        ray.windowDepth.value[i] = rayDepth, raster.windowDepth.value[i] = rasterDepth, quantum[i] = q;
    }
    RenderResult ray, raster;
    std::vector<double> quantum;
};

// The routes compared tile by tile in every kernel form, with the keepers' floors given: the
// reports (both there or both not) and the per-pixel results must be the same bit for bit.
// Returns the baseline form's report.
std::optional<ComparisonReport> requireFormsAgree(const Scene& scene, const Camera& camera, const MadeUpRoutes& routes,
                                                  float errorQuantaFloor = 0.0f, float relativeEyeZFloor = 0.0f)
{
    RoutePixels ray = RoutePixels::of(routes.ray), raster = RoutePixels::of(routes.raster);
    raster.quantum = routes.quantum.data();
    auto compare = [&](const char* form, Comparison& perPixel) {
        return testing::inForm(form, [&] {
            const PixelJudge judge(scene, camera);
            TileComparison tiles(judge, &perPixel, errorQuantaFloor, relativeEyeZFloor);
            for (int tile = 0; tile < tiles.tiles().count(); ++tile) tiles.compareTile(tile, ray, raster);
            return tiles.finish();
        });
    };
    auto json = [](const ComparisonReport& comparison) {
        CheckReport report;
        report.comparison = comparison;
        return checkReportJson(report);
    };
    Comparison byBaseline;
    const std::optional<ComparisonReport> baseline = compare("baseline", byBaseline);
    for (const char* form : testing::vectorFormsToTest()) {
        INFO("the " << form << " form");
        Comparison byChosen;
        const std::optional<ComparisonReport> chosen = compare(form, byChosen);
        REQUIRE(bool(chosen) == bool(baseline));
        if (baseline) REQUIRE(json(*chosen) == json(*baseline));
        REQUIRE(testing::sameBits(byChosen.pixelClass, byBaseline.pixelClass));
        REQUIRE(testing::sameBits(byChosen.errorOverTolerance, byBaseline.errorOverTolerance));
    }
    return baseline;
}
}  // namespace

TEST_CASE("the comparison's vector forms are bit-identical to its baseline form on edge values too", "[compare][kernel]")
{
    // The vector forms' lane pass is written out over lane types (check/src/compare_rows.cpp), so renders alone,
    // which hold few of the values where two ways of computing a lane part, do not pin it.
    // Here the routes' arrays are made up: rows of 5, 67 and 203 pixels (every tile's row ends in a
    // part of eight lanes), hits on one side, on neither and on two triangles, and in the common
    // case |Δ| exactly at its bound, one step above and below it, NaN and infinite depths, and
    // quanta that are zero, negative, NaN or large (the bound's sum, C·q + S·m + E, then rounds
    // differently in another order). Then again with the keepers' floors exactly at the two
    // 99th percentiles: a value equal to a floor must be kept.
    const Scene scene = builtinScene("builtin:terrain?n=8");
    const std::uint32_t triangles = std::uint32_t(scene.triangleCount());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t ties = 0, orderMatters = 0;
    for (const int width : {5, 67, 203}) {
        INFO("width " << width);
        CameraSpec spec = scene.defaultCamera;
        spec.width = width, spec.height = 70;
        const Camera camera(spec);
        const PixelJudge judge(scene, camera);
        const PixelJudge::ToleranceTerms terms = judge.toleranceTerms();
        MadeUpRoutes routes(camera);
        std::mt19937 random{std::uint32_t(width)};
        auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
        for (std::size_t i = 0; i < routes.quantum.size(); ++i) {
            const std::uint32_t t = random() % triangles, u = (t + 1 + random() % (triangles - 1)) % triangles;
            // Mostly a format's kind of quantum; some zero, negative or NaN; some large enough
            // that E falls below a unit in the last place of C·q + S·m.
            const double edgeQuanta[] = {0.0, -std::ldexp(1.0, -20), nan};
            const int kind = int(random() % 128);
            const double q = kind == 0 ? edgeQuanta[random() % 3]
                             : kind < 48 ? std::ldexp(1.0 + random() % 7, 2 + int(random() % 8))
                                         : std::ldexp(1.0 + random() % 7, -24 + int(random() % 12));
            const double bound = terms.of(judge.slope(t), q);
            double rayDepth = uniform(0.0, 1.0), rasterDepth = rayDepth + uniform(-3.0, 3.0) * bound;
            switch (random() % 8) {
            case 0: rayDepth = 0.0, rasterDepth = bound; break;  // |Δ| is the bound
            case 1: rayDepth = 0.0, rasterDepth = std::nextafter(bound, INFINITY); break;
            case 2: rayDepth = 0.0, rasterDepth = std::nextafter(bound, 0.0); break;
            case 3: rasterDepth = rayDepth; break;
            case 4:
                if (random() % 64 == 0) (random() % 2 ? rayDepth : rasterDepth) = random() % 2 ? nan : INFINITY;
                break;
            default: break;
            }
            routes.setCommon(i, t, rayDepth, rasterDepth, q);
            switch (random() % 8) {
            case 0: routes.raster.primitiveId[i] = kNoPrimitive; break;
            case 1: routes.ray.primitiveId[i] = kNoPrimitive; break;
            case 2: routes.ray.primitiveId[i] = routes.raster.primitiveId[i] = kNoPrimitive; break;
            case 3: routes.raster.primitiveId[i] = u; break;
            default:
                if (rayDepth == 0.0 && rasterDepth == bound && bound > 0) {
                    ++ties;
                    // The bound's sum in another order rounds below it here: that form would call it a depth error.
                    orderMatters += terms.C * q + (terms.S * judge.slope(t) + terms.E) < bound;
                }
            }
        }
        const std::optional<ComparisonReport> report = requireFormsAgree(scene, camera, routes);
        REQUIRE(report);
        REQUIRE(report->agree > 0);
        REQUIRE(report->depthErrors > 0);
        REQUIRE(report->unexplained() > 0);
        const float errorQuantaFloor = float(report->p99ErrorQuanta), relativeEyeZFloor = float(report->p99RelativeEyeZError);
        REQUIRE(errorQuantaFloor > 0);
        REQUIRE(relativeEyeZFloor > 0);
        const std::optional<ComparisonReport> atFloors =
            requireFormsAgree(scene, camera, routes, errorQuantaFloor, relativeEyeZFloor);
        REQUIRE(atFloors);
        REQUIRE(atFloors->p99ErrorQuanta == report->p99ErrorQuanta);
        REQUIRE(atFloors->p99RelativeEyeZError == report->p99RelativeEyeZError);
    }
    REQUIRE(ties > 500);
    REQUIRE(orderMatters > 0);
}

namespace {

// A row's lane pass by one form's kernel, with keepers of 64 values.
using RowLanesKernel = void (*)(const RowInputs&, const PixelJudge::ToleranceTerms&, StatisticCounts&, RowLanes&);
RowLanes rowPassBy(RowLanesKernel kernel, const RowInputs& in, const PixelJudge::ToleranceTerms& terms)
{
    StatisticCounts counts{LargestValues(64), LargestValues(64)};
    RowLanes out{};
    kernel(in, terms, counts, out);
    return out;
}

// The row's lane pass by each vector form the processor has, named.
std::vector<std::pair<const char*, RowLanes>> rowPassesOfVectorForms([[maybe_unused]] const RowInputs& in,
                                                                    [[maybe_unused]] const PixelJudge::ToleranceTerms& terms)
{
    std::vector<std::pair<const char*, RowLanes>> byForm;
#ifdef ZCHECK_X86_FORMS
    if (kernelFormSupported(KernelForm::Avx2)) byForm.emplace_back("avx2", rowPassBy(rowLanesAvx2, in, terms));
    if (kernelFormSupported(KernelForm::Avx512)) byForm.emplace_back("avx512", rowPassBy(rowLanesAvx512, in, terms));
#endif
    return byForm;
}

// A row of n lanes from its arrays, without allowances.
RowInputs rowInputsOf(const std::uint32_t* rayPrimitive, const std::uint32_t* rasterPrimitive, const std::uint32_t* surface,
                      const double* rayDepth, const double* rasterDepth, const double* slope, const double* quantum,
                      const double* relative, int n)
{
    RowInputs in;
    in.rayPrimitive = rayPrimitive, in.rasterPrimitive = rasterPrimitive, in.surface = surface;
    in.rayDepth = rayDepth, in.rasterDepth = rasterDepth, in.slope = slope, in.quantum = quantum;
    in.allowance = kNoAllowance, in.relative = relative, in.n = n;
    return in;
}

}  // namespace

TEST_CASE("the row pass's maxima leave out NaN and the lanes not in common, in every form", "[compare][kernel]")
{
    // RowLanes::largest: the largest |Δ|/q, relative error and ratio of a row's common lanes,
    // -1 where none counts (NaN left out). Rows of exact agreement (+0), of NaN only, of misses
    // only, and their mixtures are where a form that masks lanes or finds the maxima another
    // way could part from the baseline (a +0 taken for "none", or a NaN or a miss's value for
    // a maximum); each form's RowLanes (its masks, maxima and per-lane measures) is compared
    // with the baseline's, and the maxima with the values expected. (No per-pixel outputs are
    // kept here: the comparison tests compare those.)
    const Scene scene = builtinScene("builtin:terrain?n=8");
    const Camera camera(smallCamera(scene));
    const PixelJudge::ToleranceTerms terms = PixelJudge(scene, camera).toleranceTerms();
    const double nan = std::numeric_limits<double>::quiet_NaN(), q = std::ldexp(1.0, -24);
    enum Lane { Miss, Exact, NaNDepth, Error };
    struct Row {
        const char* name;
        std::vector<Lane> lanes;
        double expected;  // each maximum: -1 (none counts), 0, or the one Error lane's values (> 0)
    };
    auto row = [](int n, std::function<Lane(int)> lane) {
        std::vector<Lane> lanes(n);
        for (int j = 0; j < n; ++j) lanes[j] = lane(j);
        return lanes;
    };
    std::vector<Row> rows;
    for (const int n : {64, 13, 8, 1}) {
        rows.push_back({"misses only", row(n, [](int) { return Miss; }), -1});
        rows.push_back({"exact only", row(n, [](int) { return Exact; }), 0});
        rows.push_back({"NaN only", row(n, [](int) { return NaNDepth; }), -1});
        rows.push_back({"NaN and misses", row(n, [](int j) { return j % 3 ? NaNDepth : Miss; }), -1});
        rows.push_back({"exact, NaN and misses", row(n, [n](int j) { return j == n - 1 ? Exact : j % 2 ? NaNDepth : Miss; }), 0});
        rows.push_back({"one error among NaN and misses", row(n, [n](int j) { return j == n / 2 ? Error : j % 2 ? NaNDepth : Miss; }), 1});
    }
    for (const Row& r : rows) {
        const int n = int(r.lanes.size());
        INFO(r.name << ", " << n << " lanes");
        alignas(64) std::uint32_t rayPrimitive[kLanes], rasterPrimitive[kLanes], surface[kLanes];
        alignas(64) double rayDepth[kLanes], rasterDepth[kLanes], slope[kLanes], quantum[kLanes], relative[kLanes];
        for (int j = 0; j < kLanes; ++j) {
            const Lane lane = j < n ? r.lanes[std::size_t(j)] : Miss;
            rayPrimitive[j] = 3, rasterPrimitive[j] = lane == Miss ? kNoPrimitive : 3;
            surface[j] = lane == Miss ? kNoPrimitive : 3;
            rayDepth[j] = lane == NaNDepth ? nan : 0.5;
            rasterDepth[j] = lane == Error ? 0.5 + 1024 * q : 0.5;
            slope[j] = 0.25, quantum[j] = q;
            relative[j] = lane == NaNDepth ? nan : lane == Error ? 0.125 : lane == Exact ? 0.0 : 0.75;  // a miss's is never read
        }
        const RowInputs in =
            rowInputsOf(rayPrimitive, rasterPrimitive, surface, rayDepth, rasterDepth, slope, quantum, relative, n);
        const RowLanes baseline = rowPassBy(rowLanesBaseline, in, terms);
        auto value = [](std::int64_t bits) {
            double x;
            std::memcpy(&x, &bits, sizeof x);
            return bits < 0 ? -1.0 : x;
        };
        const double bound = terms.of(0.25, q);
        const double expected[3] = {r.expected > 0 ? 1024.0 : r.expected, r.expected > 0 ? 0.125 : r.expected,
                                    r.expected > 0 ? ((0.5 + 1024 * q) - 0.5) / bound : r.expected};
        for (int k = 0; k < 3; ++k) {
            INFO("maximum " << k);
            REQUIRE(value(baseline.largest[k]) == expected[k]);
            if (expected[k] < 0) REQUIRE(baseline.largest[k] == -1);
        }
        for (const auto& [form, lanes] : rowPassesOfVectorForms(in, terms)) {
            INFO("the " << form << " form");
            for (int k = 0; k < 3; ++k) REQUIRE(lanes.largest[k] == baseline.largest[k]);
            REQUIRE(lanes.common == baseline.common);
            REQUIRE(lanes.agree == baseline.agree);
            REQUIRE(lanes.hit == baseline.hit);
            REQUIRE(lanes.bias == baseline.bias);
            const std::size_t bytes = std::size_t(n) * sizeof(double);
            REQUIRE(std::memcmp(lanes.ratio, baseline.ratio, bytes) == 0);
            REQUIRE(std::memcmp(lanes.errorQuanta, baseline.errorQuanta, bytes) == 0);
            REQUIRE(std::memcmp(lanes.bound, baseline.bound, bytes) == 0);
            REQUIRE(std::memcmp(lanes.signedErrorQuanta, baseline.signedErrorQuanta, bytes) == 0);
        }
    }
}

TEST_CASE("|d_raster - d_ray| in a unorm format's quanta is the difference times 2^N - 1, in every form", "[compare][kernel]")
{
    // A unorm format's quantum is exactly 1/(2^N - 1); its double q only rounds it. inQuanta (and
    // so the row pass) takes a difference in such quanta as the difference times 2^N - 1, one
    // rounding of the exact quotient, where a division by q would round twice; any other quantum
    // divides, NaN, zero and negative ones too. A row of lanes with unorm24's, unorm16's, a
    // float32-like quantum and those (the row's own array: the lane-by-lane rule), and differences
    // among which the two ways part.
    const Scene scene = builtinScene("builtin:terrain?n=8");
    const Camera camera(smallCamera(scene));
    const PixelJudge::ToleranceTerms terms = PixelJudge(scene, camera).toleranceTerms();
    const double q24 = storageQuantum(DepthFormat::Unorm24, 0.5), q16 = storageQuantum(DepthFormat::Unorm16, 0.5);
    const double qOther = std::ldexp(1.0, -25);
    const std::vector<double> quanta = {q24, q16, qOther, std::numeric_limits<double>::quiet_NaN(), 0.0, -0.0, -q24};
    std::mt19937_64 random(46);
    std::uniform_real_distribution<double> depth(0.0, 1.0);
    // Pairs of depths whose difference in unorm16 quanta parts from the division (~3 in 10,000:
    // unorm24's double quantum is so near 1/(2^24 - 1) that random differences almost never
    // part), one put in a unorm16 lane each round.
    std::vector<std::pair<double, double>> parting;
    for (int tries = 0; tries < 10000000 && parting.size() < 16; ++tries) {
        const double ray = depth(random), raster = depth(random);
        if ((raster - ray) / q16 != (raster - ray) * 65535.0) parting.emplace_back(ray, raster);
    }
    REQUIRE(parting.size() == 16);
    int parted = 0;  // lanes where Δ/q and Δ·(2^N - 1) differ
    for (int round = 0; round < 200; ++round) {
        alignas(64) std::uint32_t primitive[kLanes];
        alignas(64) double rayDepth[kLanes], rasterDepth[kLanes], slope[kLanes], quantum[kLanes], relative[kLanes];
        for (int j = 0; j < kLanes; ++j) {
            primitive[j] = 3;
            rayDepth[j] = depth(random), rasterDepth[j] = depth(random);
            slope[j] = 0.25, relative[j] = 0.5;
            quantum[j] = quanta[std::size_t(j) % quanta.size()];
        }
        std::tie(rayDepth[1], rasterDepth[1]) = parting[std::size_t(round) % parting.size()];  // lane 1: q16
        const RowInputs in =
            rowInputsOf(primitive, primitive, primitive, rayDepth, rasterDepth, slope, quantum, relative, kLanes);
        const RowLanes baseline = rowPassBy(rowLanesBaseline, in, terms);
        for (int j = 0; j < kLanes; ++j) {
            const double difference = rasterDepth[j] - rayDepth[j], q = quantum[j];
            const double expected = q == q24 ? difference * 16777215.0 : q == q16 ? difference * 65535.0 : difference / q;
            INFO("lane " << j << ", round " << round << ", quantum " << q);
            REQUIRE(std::memcmp(&baseline.signedErrorQuanta[j], &expected, sizeof expected) == 0);
            parted += (q == q24 || q == q16) && difference / q != expected;
        }
        for (const auto& [form, lanes] : rowPassesOfVectorForms(in, terms)) {
            INFO("the " << form << " form");
            const std::size_t bytes = std::size_t(kLanes) * sizeof(double);
            REQUIRE(std::memcmp(lanes.signedErrorQuanta, baseline.signedErrorQuanta, bytes) == 0);
            REQUIRE(std::memcmp(lanes.errorQuanta, baseline.errorQuanta, bytes) == 0);
        }
    }
    REQUIRE(parted > 0);  // the rule is not the division under another name
}

TEST_CASE("the comparison's vector forms on rows of NaN, a zero bound and the bias rule's edge",
          "[compare][kernel]")
{
    // Rows of eleven pixels, every one on one triangle in both routes. First: a NaN depth in its
    // first pixel (compared first, so visited whatever its ratio), then pixel 1 with the row's
    // largest |Δ|/q, relative error and ratio (0.9: it agrees, so only the row's maxima can make
    // it the worst pixel), then small errors. Second: with the quantum for which the bound is
    // exactly 0 (C·q = −S·m − E): equal depths have ratio 0, others +inf. Third: the bias
    // test's rule met with equality.
    const Scene scene = builtinScene("builtin:terrain?n=8");
    CameraSpec spec = scene.defaultCamera;
    spec.width = 11, spec.height = 1;
    const Camera camera(spec);
    const PixelJudge judge(scene, camera);
    const PixelJudge::ToleranceTerms terms = judge.toleranceTerms();
    const std::uint32_t t = 0;
    const double m = judge.slope(t);
    REQUIRE(m > 0);

    const double q = std::ldexp(1.0, -24), bound = terms.of(m, q);
    MadeUpRoutes withNaN(camera);
    withNaN.setCommon(0, t, std::numeric_limits<double>::quiet_NaN(), 0.5, q);
    withNaN.setCommon(1, t, 0.5, 0.5 + 0.9 * bound, q);
    for (std::size_t i = 2; i < 11; ++i) withNaN.setCommon(i, t, 0.5, 0.5 + 0.1 * bound, q);
    const std::optional<ComparisonReport> report = requireFormsAgree(scene, camera, withNaN);
    REQUIRE(report);
    REQUIRE(report->worst.col == 1);
    REQUIRE(report->maxErrorOverTolerance == ((0.5 + 0.9 * bound) - 0.5) / bound);
    REQUIRE(report->maxErrorQuanta == ((0.5 + 0.9 * bound) - 0.5) / q);
    REQUIRE(report->maxRelativeEyeZError > 0);

    const double zeroBoundQ = (-(terms.S * m) - terms.E) / terms.C;
    REQUIRE(terms.of(m, zeroBoundQ) == 0.0);
    MadeUpRoutes zeroBound(camera);
    for (std::size_t i = 0; i < 11; ++i) zeroBound.setCommon(i, t, 0.5, i % 2 ? 0.5 : std::nextafter(0.5, 1.0), zeroBoundQ);
    const std::optional<ComparisonReport> zeroReport = requireFormsAgree(scene, camera, zeroBound);
    REQUIRE(zeroReport);
    REQUIRE(zeroReport->agree == 5);
    REQUIRE(zeroReport->depthErrors == 6);
    REQUIRE(zeroReport->maxErrorOverTolerance == INFINITY);

    // A quantum at which the bias test's rule, S·m <= 0.1·q, holds with equality: every pixel
    // of the row is a bias sample.
    double tieQ = terms.S * m / 0.1;
    for (int step = 0; step < 64 && 0.1 * tieQ != terms.S * m; ++step)
        tieQ = std::nextafter(tieQ, 0.1 * tieQ < terms.S * m ? INFINITY : 0.0);
    REQUIRE(0.1 * tieQ == terms.S * m);
    MadeUpRoutes atBiasRule(camera);
    for (std::size_t i = 0; i < 11; ++i) atBiasRule.setCommon(i, t, 0.5, 0.5 + tieQ * double(i % 3), tieQ);
    const std::optional<ComparisonReport> biasReport = requireFormsAgree(scene, camera, atBiasRule);
    REQUIRE(biasReport);
    REQUIRE(biasReport->biasSamples == 11);
}

namespace {
// Each pixel's class in both kernel forms (TileComparison over `ray` and `raster`, with the raster's
// quanta and allowances) must be what PixelJudge says of that pixel alone (EachCall: no table),
// its ratio |Δ| / bound in the common case, and the bias samples those where the bias rule holds.
// Counts the classes met into `seen`.
void requireJudgesRule(const Scene& scene, const Camera& camera, const RenderResult& rayRender, const RenderResult& rasterRender,
                       const std::vector<double>& quantum, const std::vector<double>& allowance,
                       std::map<PixelClass, std::int64_t>& seen)
{
    const PixelJudge judge(scene, camera, {}, SlopeSource::EachCall);
    const PixelJudge::ToleranceTerms terms = judge.toleranceTerms();
    RoutePixels ray = RoutePixels::of(rayRender), raster = RoutePixels::of(rasterRender);
    raster.quantum = quantum.data(), raster.allowance = allowance.data();
    for (const char* form : testing::everyFormToTest()) {
        INFO(form);
        Comparison perPixel;
        const std::optional<ComparisonReport> report = testing::inForm(form, [&] {
            const PixelJudge tableJudge(scene, camera);
            TileComparison tiles(tableJudge, &perPixel);
            for (int tile = 0; tile < tiles.tiles().count(); ++tile) tiles.compareTile(tile, ray, raster);
            return tiles.finish();
        });
        REQUIRE(report);
        std::int64_t biasSamples = 0;
        for (int row = 0; row < camera.height(); ++row)
            for (int col = 0; col < camera.width(); ++col) {
                const std::size_t i = std::size_t(row) * std::size_t(camera.width()) + std::size_t(col);
                const std::uint32_t a = rayRender.primitiveId[i], b = rasterRender.primitiveId[i];
                const double d = rayRender.windowDepth.value[i], e = rasterRender.windowDepth.value[i], q = quantum[i];
                const glm::dvec2 pWindow = windowFromPixelCentre(camera, col, row);
                PixelClass expected = PixelClass::BothMiss;
                double bound = 0;
                if (a != kNoPrimitive && b != kNoPrimitive)
                    expected = judge.bothHit(d, a, e, b, q, pWindow, bound, allowance[i]);
                else if (a != kNoPrimitive || b != kNoPrimitive)
                    expected = judge.oneHit(a != kNoPrimitive, a != kNoPrimitive ? d : e, a != kNoPrimitive ? a : b, q, pWindow);
                INFO("pixel (" << col << ", " << row << ")");
                REQUIRE(perPixel.pixelClass[i] == expected);
                ++seen[expected];
                if (a != kNoPrimitive && a == b) {
                    REQUIRE(perPixel.errorOverTolerance[i] == float(std::abs(e - d) / bound));
                    bool dominates;
                    terms.quantizationDominates(judge.slope(a), q, allowance[i], dominates);
                    biasSamples += dominates;
                }
            }
        REQUIRE(report->biasSamples == biasSamples);
    }
}
}  // namespace

TEST_CASE("the tolerance rule is one: PixelJudge's, the baseline row pass's and the vector row passes' classes agree on every pixel",
          "[compare][kernel][tolerance]")
{
    // The tolerance C·q + S·m + E + a and the bias test's rule are written once (compare.h,
    // ToleranceTerms) and instantiated for one pixel and for eight lanes. Made-up routes (every
    // coverage case, |Δ| at, above and below the bound, declared allowances, quanta of every
    // kind), then real renders of builtin:default and of a soup of slivers, clean, with rows
    // flipped and with the ray's samples moved by under the snapping (surfaces meeting at edges,
    // coverage explained and not).
    std::map<PixelClass, std::int64_t> seen;
    {
        const Scene scene = builtinScene("builtin:terrain?n=8");
        const std::uint32_t triangles = std::uint32_t(scene.triangleCount());
        CameraSpec spec = scene.defaultCamera;
        spec.width = 131, spec.height = 67;
        const Camera camera(spec);
        const PixelJudge judge(scene, camera, {}, SlopeSource::EachCall);
        MadeUpRoutes routes(camera);
        std::vector<double> allowance(routes.quantum.size());
        std::mt19937 random{7};
        auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
        for (std::size_t i = 0; i < routes.quantum.size(); ++i) {
            const std::uint32_t t = random() % triangles, u = (t + 1 + random() % (triangles - 1)) % triangles;
            // Quanta of a format's kind, and large ones, where E falls below a unit in the last
            // place of C·q + S·m (the sum in another order then rounds differently).
            const double q = random() % 3 == 0 ? std::ldexp(1.0 + random() % 7, 2 + int(random() % 8))
                                               : std::ldexp(1.0 + random() % 7, -24 + int(random() % 12));
            allowance[i] = random() % 3 == 0 ? q * double(random() % 40) : 0.0;
            double bound;
            judge.toleranceTerms().bound(judge.slope(t), q, allowance[i], bound);
            double rayDepth = uniform(0.01, 0.99), rasterDepth = rayDepth + uniform(-2.0, 2.0) * bound;
            if (random() % 3 == 0) rayDepth = 0.0, rasterDepth = random() % 2 ? bound : std::nextafter(bound, INFINITY);  // |Δ| at the bound
            routes.setCommon(i, t, rayDepth, rasterDepth, q);
            switch (random() % 6) {
            case 0: routes.raster.primitiveId[i] = kNoPrimitive; break;
            case 1: routes.ray.primitiveId[i] = kNoPrimitive; break;
            case 2: routes.ray.primitiveId[i] = routes.raster.primitiveId[i] = kNoPrimitive; break;
            case 3: routes.raster.primitiveId[i] = u; break;
            default: break;
            }
        }
        requireJudgesRule(scene, camera, routes.ray, routes.raster, routes.quantum, allowance, seen);
    }
    for (const bool soup : {false, true}) {
        const Checker checker(soup ? testing::triangleSoup(false, 41) : builtinScene("builtin:default"));
        const Camera camera(soup ? testing::kernelCamera("opengl", DepthFormat::Unorm24, false, false)
                                 : checker.scene().defaultCamera);
        for (const int fault : {0, 1, 2}) {
            RayFaults faults;  // none; rows flipped; samples a fraction of the snapping off the centre
            faults.flipRows = fault == 1;
            if (fault == 2) faults.shiftPixels = {0.003, -0.002};
            const RenderResult ray = checker.renderRay(camera, faults), raster = checker.renderRaster(camera);
            std::vector<double> quantum(ray.primitiveId.size()), allowance(ray.primitiveId.size(), 0.0);
            for (std::size_t i = 0; i < quantum.size(); ++i)
                quantum[i] = storageQuantum(camera.depth().format, ray.windowDepth.value[i]);
            requireJudgesRule(checker.scene(), camera, ray, raster, quantum, allowance, seen);
        }
    }
    for (const PixelClass c : {PixelClass::BothMiss, PixelClass::Agree, PixelClass::DepthError, PixelClass::EdgeSurface,
                               PixelClass::RayOnly, PixelClass::RasterOnly, PixelClass::RayOnlyEdge, PixelClass::RasterOnlyEdge}) {
        INFO(toString(c));
        REQUIRE(seen[c] > 0);
    }
}

// compareRoutes gives its keepers floors from a sample of rows (the 97th percentile of the
// values of evenly spaced rows, ~16,000 pixels: here every 4th row of 64 pixels): the
// percentiles come out exact only if a floor that proves too high is found out and the
// comparison run again without. Renders of the built-in scenes take that path too, but are
// checked only as whole reports; here it is taken on purpose, and the percentile checked
// against the sorted values. Every 128th row holds errors a hundred times the rest: 0.78 % of
// the image, so its 99th percentile lies among the small errors, but 3.1 % of the rows the
// sample takes (as of every 8th, 32nd or 64th), which lifts its 97th percentile among them.
TEST_CASE("a comparison whose sampled floors lie above its percentiles runs again and gives them exactly", "[compare]")
{
    const Scene scene = builtinScene("builtin:terrain?n=8");
    CameraSpec spec = scene.defaultCamera;
    spec.width = 64, spec.height = 1024;
    const Camera camera(spec);
    MadeUpRoutes routes(camera);
    const double q = std::ldexp(1.0, -20);
    std::vector<float> errorQuanta;  // |Δ|/q of every pixel: exact binary fractions
    for (int row = 0; row < spec.height; ++row)
        for (int col = 0; col < spec.width; ++col) {
            const std::size_t i = std::size_t(row) * std::size_t(spec.width) + std::size_t(col);
            const double quanta = row % 128 == 0 ? 100.0 + (i % 50) : std::ldexp(double(i * 7 % 1000 + 1), -10);
            routes.setCommon(i, std::uint32_t(i % scene.triangleCount()), 0.5, 0.5 + quanta * q, q);
            errorQuanta.push_back(float(quanta));
        }
    std::vector<float> sorted = errorQuanta;
    std::sort(sorted.begin(), sorted.end());
    const float expectedP99 = sorted[std::size_t(std::ceil(0.99 * double(sorted.size()))) - 1];
    REQUIRE(expectedP99 < 1.0f);  // among the small errors

    // Keepers floored at the large errors keep too few to give the percentile ...
    const PixelJudge judge(scene, camera);
    RoutePixels ray = RoutePixels::of(routes.ray), raster = RoutePixels::of(routes.raster);
    raster.quantum = routes.quantum.data();
    auto tileByTile = [&](float errorQuantaFloor) {
        TileComparison tiles(judge, nullptr, errorQuantaFloor, 0.0f);
        for (int tile = 0; tile < tiles.tiles().count(); ++tile) tiles.compareTile(tile, ray, raster);
        return tiles.finish();
    };
    REQUIRE_FALSE(tileByTile(100.0f).has_value());
    // ... and compareRoutes, whose sample's floor lies there, gives what keepers without a
    // floor give, with the sorted percentile.
    const std::optional<ComparisonReport> unfloored = tileByTile(0.0f);
    REQUIRE(unfloored.has_value());
    REQUIRE(unfloored->p99ErrorQuanta == double(expectedP99));
    const Comparison full = compareRoutes(judge, routes.ray, routes.raster, {&routes.quantum});
    REQUIRE(full.report.p99ErrorQuanta == double(expectedP99));
    CheckReport fromRoutes, fromTiles;
    fromRoutes.comparison = full.report, fromTiles.comparison = *unfloored;
    REQUIRE(checkReportJson(fromRoutes) == checkReportJson(fromTiles));
}

TEST_CASE("a check refuses a bad ZCHECK_KERNELS in one line", "[compare][kernel]")
{
    const Checker checker(builtinScene("builtin:default"));
    const Camera camera(smallCamera(checker.scene()));
    auto checkWith = [&](const char* form) {
        return testing::inForm(form, [&] { return checker.check(camera); });
    };
    REQUIRE_NOTHROW(checkWith("auto"));
    REQUIRE_NOTHROW(checkWith("baseline"));
    REQUIRE_THROWS_WITH(checkWith("scalar"), Catch::Equals("ZCHECK_KERNELS=scalar: must be auto, baseline, avx2 or avx512"));
}

TEST_CASE("the comparison writes every pixel's class and ratio, whose arrays are not cleared first", "[compare][allocated]")
{
    // TileComparison sizes the per-pixel arrays without clearing them and each tile writes all
    // of its pixels: a pixel it failed to write would show what the arrays held. They are
    // handed to it full of garbage already at their size (resizing keeps it). On
    // an image the 64×64 tiles cut on both edges, clean and with rows flipped (depth errors and
    // coverage mismatches), every class's pixels must number what the report counts, and only
    // the pixels compared on depth may carry a ratio.
    const Checker checker(builtinScene("builtin:near-crossing"));
    CameraSpec spec = checker.scene().defaultCamera;
    spec.width = 131, spec.height = 70;
    const Camera camera(spec);
    const std::size_t pixels = std::size_t(spec.width) * spec.height;
    for (const bool flipRows : {false, true}) {
        RayFaults faults;
        faults.flipRows = flipRows;
        const RenderResult ray = checker.renderRay(camera, faults), raster = checker.renderRaster(camera);
        Comparison c;
        c.pixelClass.assign(pixels, PixelClass::RayOnly);
        c.errorOverTolerance.assign(pixels, -5.0f);
        TileComparison tiles(checker.scene(), camera, {}, &c);
        for (int tile = 0; tile < tiles.tiles().count(); ++tile)
            tiles.compareTile(tile, RoutePixels::of(ray), RoutePixels::of(raster));
        const std::optional<ComparisonReport> report = tiles.finish();
        REQUIRE(report.has_value());
        const ComparisonReport& r = *report;
        INFO((flipRows ? "rows flipped" : "clean"));
        std::int64_t count[10] = {};
        float maxRatio = 0;
        for (std::size_t i = 0; i < pixels; ++i) {
            const PixelClass k = c.pixelClass[i];
            REQUIRE(int(k) < 10);
            ++count[int(k)];
            if (k == PixelClass::Agree || k == PixelClass::DepthError) {
                REQUIRE(c.errorOverTolerance[i] >= 0.0f);
                maxRatio = std::max(maxRatio, c.errorOverTolerance[i]);
            } else {
                REQUIRE(c.errorOverTolerance[i] == 0.0f);
            }
        }
        REQUIRE(count[int(PixelClass::BothMiss)] == r.bothMiss);
        REQUIRE(count[int(PixelClass::Agree)] == r.agree);
        REQUIRE(count[int(PixelClass::DepthError)] == r.depthErrors);
        REQUIRE(count[int(PixelClass::EdgeSurface)] == r.edgeSurface);
        REQUIRE(count[int(PixelClass::RayOnly)] + count[int(PixelClass::RasterOnly)] == r.coverageUnexplained);
        REQUIRE(count[int(PixelClass::RayOnlyEdge)] + count[int(PixelClass::RasterOnlyEdge)] +
                    count[int(PixelClass::RayOnlyAtClear)] + count[int(PixelClass::AtClipPlane)] ==
                r.coverageExplained);
        REQUIRE(maxRatio == float(r.maxErrorOverTolerance));
        REQUIRE(r.bothMiss > 0);
        REQUIRE(r.agree > 1000);
        if (flipRows) REQUIRE(r.unexplained() > 100);
    }
}

// A quad of two triangles seen by a 200×150 unorm24 camera (64×64 tiles cut at both edges),
// with the raster's depths set to the ray's wherever both routes hit: a comparison without
// any error, for tests to plant their own.
struct ErrorFreeQuad {
    static Scene quad()
    {
        Scene s;
        s.name = "quad";
        s.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
        s.triangles = {{0, 1, 2}, {0, 2, 3}};
        return frameScene(s, "the test quad");
    }
    static Camera camera200x150(const Scene& scene)
    {
        CameraSpec spec = scene.defaultCamera;
        spec.width = 200, spec.height = 150;
        spec.depth.format = DepthFormat::Unorm24;
        return Camera(spec);
    }
    ErrorFreeQuad() : checker(quad()), camera(camera200x150(checker.scene())), ray(checker.renderRay(camera, {}))
    {
        raster = checker.renderRaster(camera);
        for (std::size_t i = 0; i < ray.primitiveId.size(); ++i)
            if (ray.hit(i) && raster.hit(i)) raster.windowDepth.value[i] = ray.windowDepth.value[i];
    }
    const Checker checker;
    const Camera camera;
    const RenderResult ray;
    RenderResult raster;
};

// The comparison tallies the common case (both routes on one triangle) lane by lane and visits
// in scan order only the pixels that may change the worst one (compare.cpp, noteWorst): the
// worst must still be the first pixel in scan order with the largest ratio, in a row, across
// rows and across tiles. On a quad without error (ErrorFreeQuad), the same exact error planted
// at pixels of one triangle (ties in double: the depths with and without it lie in one
// binade), then a larger one; beyond the tolerance and within it.
TEST_CASE("the worst pixel is the first in scan order with the largest ratio, in a row, across rows and tiles",
          "[compare][worst]")
{
    const ErrorFreeQuad quad;
    const Checker& checker = quad.checker;
    const Camera& camera = quad.camera;
    const RenderResult& ray = quad.ray;
    const std::uint32_t triangle = ray.primitiveId[std::size_t(75) * 200 + 100];
    REQUIRE(triangle != kNoPrimitive);
    std::vector<std::pair<const char*, double>> formsAndErrors;
    for (const double error : {0x1p-12, 0x1p-26})
        for (const char* form : testing::everyFormToTest()) formsAndErrors.push_back({form, error});
    for (const auto& [form, error] : formsAndErrors) {
        // 2^-12 ≈ 4000 q of unorm24, a depth error; 2^-26 ≈ q/4, within the tolerance (agree)
        INFO(form << ", error " << error);
        const PixelClass expectedClass = error > 0x1p-20 ? PixelClass::DepthError : PixelClass::Agree;
        testing::inForm(form, [&] {
            const RenderResult& raster = quad.raster;
            std::vector<std::size_t> onTriangle;  // in scan order
            for (std::size_t i = 0; i < ray.primitiveId.size(); ++i) {
                const double d = ray.windowDepth.value[i];
                if (ray.primitiveId[i] != triangle || raster.primitiveId[i] != triangle) continue;
                if (d >= 0.5 && d + 2 * error < 1.0) onTriangle.push_back(i);
            }
            REQUIRE(onTriangle.size() > 2000);
            auto col = [](std::size_t i) { return int(i % 200); };
            auto row = [](std::size_t i) { return int(i / 200); };
            // a, then b later in a's row, c in a later row and tile, d left of a in the next row
            const std::size_t a = onTriangle[onTriangle.size() / 8];
            std::size_t b = a, c = a, d = a;
            for (std::size_t i : onTriangle) {
                if (row(i) == row(a) && col(i) > col(a) + 3 && b == a) b = i;
                if (row(i) / 64 > row(a) / 64 && c == a) c = i;  // a tile below a's
                if (row(i) == row(a) + 1 && col(i) < col(a) && d == a) d = i;
            }
            REQUIRE((b != a && c != a && d != a));
            auto worstOf = [&](const std::vector<std::pair<std::size_t, double>>& planted) {
                RenderResult withErrors = raster;
                for (auto [i, e] : planted) withErrors.windowDepth.value[i] = ray.windowDepth.value[i] + e;
                return compareRoutes(checker.scene(), camera, ray, withErrors).report.worst;
            };
            // With no error anywhere, every ratio is 0: the first pixel both routes hit.
            std::size_t firstBothHit = 0;
            while (!(ray.hit(firstBothHit) && raster.hit(firstBothHit))) ++firstBothHit;
            const PixelFinding none = worstOf({});
            CHECK(none.col == col(firstBothHit));
            CHECK(none.row == row(firstBothHit));
            for (const auto& [planted, expected] :
                 std::vector<std::pair<std::vector<std::pair<std::size_t, double>>, std::size_t>>{
                     {{{c, error}, {d, error}, {b, error}, {a, error}}, a},
                     {{{c, error}, {d, error}, {b, error}}, b},
                     {{{c, error}, {d, error}}, d},
                     {{{a, error}, {b, 2 * error}, {c, error}}, b},
                     {{{a, error}, {c, 2 * error}, {d, error}}, c},
                 }) {
                const PixelFinding worst = worstOf(planted);
                CHECK(worst.col == col(expected));
                CHECK(worst.row == row(expected));
                CHECK(worst.pixelClass == expectedClass);
            }
        });
    }
}

// A NaN depth (a map's, in verify) is compared and fails, as std::max and the keepers take it:
// a depth error, sampled as unexplained in scan order, never a maximum nor, once a pixel was
// compared before it, the worst.
TEST_CASE("a NaN depth is a depth error and never the largest error", "[compare][worst]")
{
    const ErrorFreeQuad quad;
    const std::size_t row = 75, width = 200;
    // both on one triangle, both routes: the common case
    const std::size_t a = row * width + 100, b = a + 5;
    for (const std::size_t i : {a, b}) {
        REQUIRE(quad.ray.hit(i));
        REQUIRE(quad.ray.primitiveId[i] == quad.raster.primitiveId[i]);
    }
    for (const char* form : testing::everyFormToTest()) {
        INFO(form);
        testing::inForm(form, [&] {
            RenderResult raster = quad.raster;
            raster.windowDepth.value[a] = NAN;
            raster.windowDepth.value[b] = quad.ray.windowDepth.value[b] + 0x1p-12;
            const ComparisonReport r = compareRoutes(quad.checker.scene(), quad.camera, quad.ray, raster).report;
            const double q = storageQuantum(DepthFormat::Unorm24, quad.ray.windowDepth.value[b]);
            CHECK(r.depthErrors == 2);
            REQUIRE(r.unexplainedSamples.size() == 2);
            CHECK(r.unexplainedSamples[0].col == int(a % width));
            CHECK(r.unexplainedSamples[1].col == int(b % width));
            REQUIRE(q == storageQuantum(DepthFormat::Unorm24, 0.0));  // unorm24's: in quanta, |Δ|·(2^24 - 1)
            CHECK(r.maxErrorQuanta == std::abs(raster.windowDepth.value[b] - quad.ray.windowDepth.value[b]) * 16777215.0);
            CHECK(std::isfinite(r.maxRelativeEyeZError));
            CHECK(r.maxRelativeEyeZError > 0);
            CHECK(std::isfinite(r.maxErrorOverTolerance));
            CHECK(r.worst.col == int(b % width));
            CHECK(r.worst.row == int(row));
            CHECK(r.p99ErrorQuanta == 0.0);
        });
    }
}

TEST_CASE("a comparison through a judge of the caller's, asked before, reports what one through its own does", "[compare]")
{
    // verify reads a map with a judge and compares through the same judge, so that the slopes
    // computed while reading serve the comparison. A judge used for one comparison (and so
    // holding that one's slopes) must give the next, of other renders, the report and pixels
    // a judge of its own gives: clean, with rows flipped (the rows' surfaces then differ), and
    // with a depth bias; with both slope credits (on a terrain, where they differ).
    const Checker checker(builtinScene("builtin:terrain?n=60"));
    const Camera camera(tileCutCamera(checker.scene()));
    auto json = [&](const Comparison& c, const ToleranceModel& tolerance) {
        CheckReport report;
        report.describeInputs(checker.scene(), camera, tolerance);
        report.comparison = c.report;
        return checkReportJson(report);
    };
    for (const ToleranceModel& tolerance : {ToleranceModel{}, mapTolerance(DepthMap{}), mapTolerance(DepthMap::exact(1, 1, DepthQuantity::EyeZ, {1.0}))}) {
        const PixelJudge shared(checker.scene(), camera, tolerance);
        for (const CheckOptions& options : cleanFlippedAndBiased()) {
            const RenderResult ray = checker.renderRay(camera, options.faults.ray);
            const RenderResult raster = checker.renderRaster(camera, options.faults.raster);
            const Comparison own = compareRoutes(checker.scene(), camera, ray, raster, tolerance);
            const Comparison borrowed = compareRoutes(shared, ray, raster);
            INFO("slope credit " << int(tolerance.slopeCredit) << ", rows flipped " << options.faults.ray.flipRows
                                 << ", truncated " << options.faults.raster.truncateUnorm);
            REQUIRE(own.report.bothHit > 1000);
            if (tolerance.slopeCredit == SlopeCredit::SampleOffset)  // the credits differ here
                REQUIRE(compareRoutes(checker.scene(), camera, ray, raster).report.maxErrorOverTolerance !=
                        own.report.maxErrorOverTolerance);
            REQUIRE(json(borrowed, tolerance) == json(own, tolerance));
            REQUIRE(testing::sameBits(borrowed.pixelClass, own.pixelClass));
            REQUIRE(testing::sameBits(borrowed.errorOverTolerance, own.errorOverTolerance));
        }
    }
    // A map is read only with map tolerances.
    const PixelJudge rasterJudge(checker.scene(), camera);
    const RenderResult truth = checker.renderRay(camera);
    const DepthMap map = testing::windowMapOf(camera, truth);
    const VertexNeighbours neighbours(checker.scene(), nullptr);
    REQUIRE_THROWS_AS(MapReader(rasterJudge, map, truth, neighbours), std::logic_error);
}

TEST_CASE("a tile compared a few rows at a time, tiles interleaved, reports what whole tiles report", "[compare][rows]")
{
    // compareRoutes compares a band of tiles image row by image row (compareBandRows); a tile's
    // rows may also arrive in several calls, between other tiles' calls (compareTileRows). Whole
    // tiles in reverse order against pieces of 1 to 9 rows, the next piece taken from a random
    // unfinished tile, and against bands from the bottom in pieces of 1 to 9 rows:
    // the same report (counts, maxima, percentiles, bias, the worst pixel and the unexplained
    // samples in scan order) and the same per-pixel classes and ratios, clean and with rows
    // flipped (thousands of unexplained pixels) or a depth bias, on tiles cut by both edges.
    const Checker checker(builtinScene("builtin:default"));
    const Camera camera(tileCutCamera(checker.scene()));
    std::mt19937 random(5);
    for (const CheckOptions& options : cleanFlippedAndBiased()) {
        const RenderResult ray = checker.renderRay(camera, options.faults.ray);
        const RenderResult raster = checker.renderRaster(camera, options.faults.raster);
        enum class Order { WholeTiles, TilePieces, BandPieces };
        auto reportOf = [&](Comparison& c, Order order) {
            TileComparison tiles(checker.scene(), camera, {}, &c);
            const TileGrid& grid = tiles.tiles();
            if (order == Order::WholeTiles) {
                for (int tile = grid.count() - 1; tile >= 0; --tile)
                    tiles.compareTile(tile, RoutePixels::of(ray), RoutePixels::of(raster));
            } else if (order == Order::BandPieces) {  // bands from the bottom, each in pieces of 1 to 9 rows
                for (int band = grid.tilesY() - 1; band >= 0; --band) {
                    const PixelRect first = grid.rect(band * grid.tilesX());
                    for (int from = first.row0; from < first.row1;) {
                        const int to = from + 1 + int(random() % 9);
                        tiles.compareBandRows(band, from, to, RoutePixels::of(ray), RoutePixels::of(raster));
                        from = to;
                    }
                }
            } else {
                std::vector<int> nextRow(std::size_t(grid.count()));
                for (int tile = 0; tile < grid.count(); ++tile) nextRow[std::size_t(tile)] = grid.rect(tile).row0;
                for (;;) {
                    std::vector<int> open;
                    for (int tile = 0; tile < grid.count(); ++tile)
                        if (nextRow[std::size_t(tile)] < grid.rect(tile).row1) open.push_back(tile);
                    if (open.empty()) break;
                    const int tile = open[random() % open.size()];
                    const int from = nextRow[std::size_t(tile)], to = from + 1 + int(random() % 9);
                    tiles.compareTileRows(tile, from, to, RoutePixels::of(ray), RoutePixels::of(raster));
                    nextRow[std::size_t(tile)] = std::min(to, grid.rect(tile).row1);
                }
            }
            CheckReport report;
            report.describeInputs(checker.scene(), camera, {});
            report.comparison = tiles.finish().value();
            return report;
        };
        Comparison whole, pieces, bands;
        const CheckReport byTiles = reportOf(whole, Order::WholeTiles), byPieces = reportOf(pieces, Order::TilePieces);
        const CheckReport byBands = reportOf(bands, Order::BandPieces);
        INFO("faults: rows flipped " << options.faults.ray.flipRows << ", truncated " << options.faults.raster.truncateUnorm);
        REQUIRE(byTiles.comparison.bothHit > 1000);
        if (options.faults.ray.flipRows) REQUIRE(byTiles.comparison.unexplainedSamples.size() == 20);
        REQUIRE(checkReportJson(byPieces) == checkReportJson(byTiles));
        REQUIRE(testing::sameBits(pieces.pixelClass, whole.pixelClass));
        REQUIRE(testing::sameBits(pieces.errorOverTolerance, whole.errorOverTolerance));
        REQUIRE(checkReportJson(byBands) == checkReportJson(byTiles));
        REQUIRE(testing::sameBits(bands.pixelClass, whole.pixelClass));
        REQUIRE(testing::sameBits(bands.errorOverTolerance, whole.errorOverTolerance));
    }
}

TEST_CASE("regression: a best hypothesis that left almost every pixel unexplained was offered as the closest",
          "[diagnose][report][regression]")
{
    // A map of noise on the default scene: no hypothesis explains it, and none is named as if it
    // nearly did ("closest: field-of-view" pointed the user at a mistake the map does not show).
    const Checker checker(builtinScene("builtin:default"));
    const MapVerifier verifier(checker);
    const Camera camera(smallCamera(checker.scene()));
    DepthMap noise = DepthMap::exact(camera.width(), camera.height(), DepthQuantity::EyeZ, {});
    std::uint32_t state = 12345;
    for (int i = 0; i < camera.width() * camera.height(); ++i) {
        state = state * 1664525u + 1013904223u;
        noise.value.push_back(1.0 + 9.0 * (state >> 8) / double(1u << 24));
    }
    const VerifyResult run = verifier.verify(camera, noise);
    const ComparisonReport& c = run.comparison.report;
    const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, noise);
    REQUIRE_FALSE(diagnosis.front().consistent);
    const std::string text = formatDiagnosis(diagnosis, c.bothHit + c.rayOnly + c.rasterOnly);
    INFO(text);
    REQUIRE(text.find("none comes close") != std::string::npos);
    REQUIRE(text.find("closest") == std::string::npos);
    // A best that leaves under half the compared pixels unexplained is still offered.
    Hypothesis near;
    near.name = "pose", near.unexplained = 1204;
    REQUIRE(formatDiagnosis({near}, 41887).find("(closest: pose, 1204 of the 41887 compared pixels unexplained)") !=
            std::string::npos);
}

TEST_CASE("regression: 'about 0 unexplained pixels' stood beside 'none makes the map consistent'",
          "[diagnose][report][regression]")
{
    // A nearly empty comparison: too few pixels to tell hypotheses apart, and the report says so.
    Hypothesis best;
    best.name = "y-flip", best.unexplained = 0, best.estimated = true;
    const std::string few = formatDiagnosis({best}, 12);
    INFO(few);
    REQUIRE(few.find("only 12 pixels were compared") != std::string::npos);
    REQUIRE(few.find("about 0") == std::string::npos);
    // Enough compared, none unexplained, yet not consistent (a bias): said as such, not "about 0".
    const std::string biased = formatDiagnosis({best}, 5000);
    INFO(biased);
    REQUIRE(biased.find("explains every pixel but leaves a systematic bias or values out of range") != std::string::npos);
    REQUIRE(biased.find("about 0") == std::string::npos);
}

TEST_CASE("the BVH is built quickly for few rays per triangle, thoroughly for many", "[checker][bvh]")
{
    // bvhBuildFor: quick below kQuickBuildRaysPerTriangle rays per triangle.
    REQUIRE(kQuickBuildRaysPerTriangle == 10.0);
    REQUIRE(bvhBuildFor(0.0, 1) == BvhBuild::Quick);
    REQUIRE(bvhBuildFor(1920.0 * 1080, 1002528) == BvhBuild::Quick);      // one 1080p frame of a 1 M mesh
    REQUIRE(bvhBuildFor(3840.0 * 2160, 9999392) == BvhBuild::Quick);      // one 4K frame of a 10 M mesh
    REQUIRE(bvhBuildFor(9999999.0, 1000000) == BvhBuild::Quick);
    REQUIRE(bvhBuildFor(10000000.0, 1000000) == BvhBuild::Thorough);
    REQUIRE(bvhBuildFor(640.0 * 480, 3332) == BvhBuild::Thorough);          // the default scene's frame
    REQUIRE(bvhBuildFor(INFINITY, 1) == BvhBuild::Thorough);               // unknown: many
    REQUIRE(std::string(nameOf(BvhBuild::Quick)) == "quick");
    REQUIRE(std::string(nameOf(BvhBuild::Thorough)) == "thorough");
}

TEST_CASE("a check over a quick BVH reports what a check over a thorough one does", "[checker][bvh]")
{
    // The trace keeps the closest hit and recomputes its depth in double against the hit
    // triangle's plane, so the BVH's build cannot change a depth; it could change only which of
    // two triangles hit at exactly the same distance is kept. Meshes without such ties (a
    // terrain, the default scene, a scanned mesh) give the same renders bit for bit and the same
    // report; the soup's exact duplicates under other ids may differ in id, never in depth.
    int compared = 0;
    for (const std::string& name : {std::string("builtin:terrain?n=300"), std::string("builtin:default"),
                                   std::string(ZCHECK_MODELS_DIR) + "/stanford-bunny.obj", std::string("soup")}) {
        INFO(name);
        const bool soup = name == "soup";
        const Scene scene = soup ? testing::triangleSoup(true, 46) : loadScene(name);
        const Checker quick(scene, BvhBuild::Quick), thorough(scene, BvhBuild::Thorough);
        REQUIRE(quick.rayRenderer().bvhBuild() == BvhBuild::Quick);
        REQUIRE(thorough.rayRenderer().bvhBuild() == BvhBuild::Thorough);
        CameraSpec spec = soup ? testing::kernelCamera("opengl", DepthFormat::Unorm24, false, false) : scene.defaultCamera;
        spec.width = 331, spec.height = 197;
        for (const char* convention : {"opengl", "direct3d"}) {
            spec.convention = Convention::preset(convention);
            const Camera camera(spec);
            const RenderResult a = quick.renderRay(camera, {}, EyePoints::Keep), b = thorough.renderRay(camera, {}, EyePoints::Keep);
            REQUIRE(testing::sameBits(a.windowDepth.value, b.windowDepth.value));
            std::size_t hits = 0, otherId = 0;
            for (std::size_t i = 0; i < a.primitiveId.size(); ++i) {
                hits += b.hit(i);
                otherId += a.primitiveId[i] != b.primitiveId[i];
            }
            REQUIRE(hits > 1000);
            if (soup) {
                REQUIRE(otherId < hits / 100);
                continue;
            }
            REQUIRE(otherId == 0);
            REQUIRE(testing::sameBits(a.pEye, b.pEye));
            CheckOptions tileByTile;
            tileByTile.keepPixels = false;
            REQUIRE(reportWithoutTimings(quick.check(camera, tileByTile).report) ==
                    reportWithoutTimings(thorough.check(camera, tileByTile).report));
            ++compared;
        }
    }
    REQUIRE(compared == 6);
}
