// Maps as pipelines and sensors deliver them: what their reading declares (a rounding quantum,
// half floats' own steps, a stated accuracy, holes) accepts them; without it they are rejected
// and the diagnosis names the option; and declared accuracy does not hide a convention mistake.
#include "zcheck/declared_reading.h"
#include "zcheck/map_verifier.h"
#include "zcheck/verify.h"

#include "zcheck/inverse_projection.h"

#include "diagnosis_helpers.h"
#include "room.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

using namespace zcheck;
using testing::mapOf;
using testing::Room;

namespace {

// The truth's eye-z (or distance) map, exact to binary32 (misses: +inf).
DepthMap truthMap(const Checker& checker, const Camera& camera, ExportQuantity quantity)
{
    return mapOf(checker.scene(), camera, checker.renderRay(camera), quantity);
}

bool consistent(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    return verifier.verify(camera, map).comparison.report.consistent();
}

// The first consistent hypothesis's name, "" for none.
std::string bestConsistent(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    for (const Hypothesis& h : verifier.diagnose(camera, map))
        if (h.consistent) return h.name;
    return "";
}

// The map upside down (a y-flip).
DepthMap flippedRows(const DepthMap& map)
{
    DepthMap out = map;
    for (int row = 0; row < map.height; ++row)
        std::copy_n(map.value.begin() + std::ptrdiff_t(map.height - 1 - row) * map.width, map.width,
                    out.value.begin() + std::ptrdiff_t(row) * map.width);
    return out;
}

// A Kinect-like sensor's map (σ = 1.2 mm + 1.9 mm·(z − 0.4 m)², rounded to millimetres,
// silhouettes eroded by a pixel, `holeShare` of the pixels dropped), misses as 0.
DepthMap kinectLike(const DepthMap& exact, double holeShare, unsigned seed)
{
    std::mt19937 random(seed);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> uniform;
    DepthMap out = exact;
    const int W = exact.width, H = exact.height;
    auto hit = [&](int col, int row) {
        return col >= 0 && col < W && row >= 0 && row < H && std::isfinite(exact.value[std::size_t(row) * W + col]);
    };
    for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col) {
            double& v = out.value[std::size_t(row) * W + col];
            const bool inside = hit(col, row) && hit(col - 1, row) && hit(col + 1, row) && hit(col, row - 1) && hit(col, row + 1);
            if (!inside || uniform(random) < holeShare) {
                v = NAN;
                continue;
            }
            const double z = exact.value[std::size_t(row) * W + col];
            const double sigma = 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4);
            v = std::round((z + sigma * normal(random)) * 1000) / 1000;
        }
    return out;
}

}  // namespace

TEST_CASE("millimetre-rounded floats are accepted with --quantum 0.001, rejected and named without", "[declared]")
{
    for (const char* convention : {"opengl", "opencv", "direct3d"})
        for (ExportQuantity q : {ExportQuantity::EyeZ, ExportQuantity::Distance}) {
            const Room room(convention);
            const Checker checker(room.scene);
            const MapVerifier verifier(checker);
            const Camera camera(room.spec);
            DepthMap map = truthMap(checker, camera, q);
            for (double& v : map.value)
                if (std::isfinite(v)) v = double(float(std::round(v * 1000) / 1000));
            INFO(convention << " " << toString(q));
            REQUIRE_FALSE(consistent(verifier, camera, map));
            REQUIRE(bestConsistent(verifier, camera, map) == "quantum");
            DepthMap declared = map;
            declared.accuracy.quantum = 0.001;
            REQUIRE(consistent(verifier, camera, declared));
        }
}

TEST_CASE("half floats carry their own step: a float16 map verifies without options", "[declared]")
{
    const Room room;
    const Checker checker(room.scene);
    const MapVerifier verifier(checker);
    const Camera camera(room.spec);
    DepthMap map = truthMap(checker, camera, ExportQuantity::EyeZ);
    DepthMap asBinary32 = map;
    map.valueStep.assign(map.value.size(), 0.0f);
    for (std::size_t i = 0; i < map.value.size(); ++i) {
        // binary16 rounding of the value: to a multiple of its spacing.
        const double step = binary16Step(map.value[i]);
        if (std::isfinite(map.value[i])) map.value[i] = asBinary32.value[i] = std::round(map.value[i] / step) * step;
        map.valueStep[i] = float(step);
    }
    REQUIRE(binary16Step(1.0) == std::ldexp(1.0, -10));
    REQUIRE(binary16Step(3.0) == std::ldexp(1.0, -9));
    REQUIRE(binary16Step(1e-6) == std::ldexp(1.0, -24));
    REQUIRE(consistent(verifier, camera, map));
    REQUIRE_FALSE(consistent(verifier, camera, asBinary32));  // the same values read as binary32
}

TEST_CASE("a miss value where nothing is hit is named with the --miss rule that reads it", "[declared]")
{
    const Room room;
    const Checker checker(room.scene);
    const MapVerifier verifier(checker);
    const Camera camera(room.spec);
    const DepthMap exact = truthMap(checker, camera, ExportQuantity::EyeZ);
    for (const double sentinel : {1e10, 65504.0}) {
        DepthMap map = exact;
        std::int64_t misses = 0;
        for (double& v : map.value)
            if (!std::isfinite(v)) v = sentinel, ++misses;
        REQUIRE(misses > 1000);
        REQUIRE_FALSE(consistent(verifier, camera, map));
        const RenderResult truth = checker.renderRay(camera);
        const ReadingFindings found = findReading(camera, map, truth);
        REQUIRE(found.missValue == sentinel);
        REQUIRE(found.missPixels == misses);
        REQUIRE(found.missRule == (sentinel >= 1e9 ? ">=1e9" : "65504"));
        REQUIRE(bestConsistent(verifier, camera, map) == "miss-value");
        const std::vector<Hypothesis> diagnosis = verifier.diagnose(camera, map);
        REQUIRE(diagnosis.front().explanation.find("pass --miss") != std::string::npos);
    }
}

TEST_CASE("holes are failures unless allowed, allowed, they are counted and a flipped map still fails", "[declared]")
{
    const Room room;
    const Checker checker(room.scene);
    const MapVerifier verifier(checker);
    const Camera camera(room.spec);
    const DepthMap exact = truthMap(checker, camera, ExportQuantity::EyeZ);
    DepthMap map = exact;
    std::mt19937 random(3);
    std::int64_t holes = 0;
    for (double& v : map.value)
        if (std::isfinite(v) && random() % 20 == 0) v = NAN, ++holes;
    REQUIRE_FALSE(consistent(verifier, camera, map));
    REQUIRE(bestConsistent(verifier, camera, map) == "holes");
    map.accuracy.allowHoles = true;
    const VerifyResult run = verifier.verify(camera, map);
    const ComparisonReport& r = run.comparison.report;
    REQUIRE(r.consistent());
    // Every hole is a pixel only the truth sees; those at an edge are explained there already.
    REQUIRE(r.rayOnly == holes);
    REQUIRE(r.holes <= holes);
    REQUIRE(r.holes >= holes * 98 / 100);
    // Holes allowed do not make a y-flipped map pass.
    const DepthMap flipped = flippedRows(map);
    REQUIRE_FALSE(consistent(verifier, camera, flipped));
    REQUIRE(bestConsistent(verifier, camera, flipped) == "y-flip");
}

TEST_CASE("a noisy, quantized, holed RGB-D map: accepted with its options, flipped, distance or moved: rejected and named",
          "[declared]")
{
    for (const char* convention : {"opencv", "opengl"}) {
        const Room room(convention);
        const Checker checker(room.scene);
        const MapVerifier verifier(checker);
        const Camera camera(room.spec);
        const DepthMap exact = truthMap(checker, camera, ExportQuantity::EyeZ);
        MapAccuracy sensor;  // what its user knows of it: millimetres, holes, and 6σ of its noise, relative
        sensor.quantum = 0.001, sensor.allowHoles = true;
        for (double z : exact.value)
            if (std::isfinite(z)) sensor.relative = std::max(sensor.relative, 6 * (0.0012 + 0.0019 * (z - 0.4) * (z - 0.4)) / z);
        REQUIRE(sensor.relative < 0.05);
        DepthMap map = kinectLike(exact, 0.03, 11);
        INFO(convention);
        REQUIRE_FALSE(consistent(verifier, camera, map));
        map.accuracy = sensor;
        REQUIRE(consistent(verifier, camera, map));
        // Flipped rows.
        const DepthMap flipped = flippedRows(map);
        REQUIRE_FALSE(consistent(verifier, camera, flipped));
        REQUIRE(bestConsistent(verifier, camera, flipped) == "y-flip");
        // Distance stored where eye-z was declared.
        DepthMap distance = kinectLike(truthMap(checker, camera, ExportQuantity::Distance), 0.03, 12);
        distance.accuracy = sensor;
        distance.quantity = DepthQuantity::EyeZ;  // declared eye-z, holds distance
        REQUIRE_FALSE(consistent(verifier, camera, distance));
        REQUIRE(bestConsistent(verifier, camera, distance) == "distance-as-eye-z");
        // Seen from an eye 5 cm to the side.
        CameraSpec moved = room.spec;
        moved.view.eye.x += 0.05, moved.view.target.x += 0.05;
        const Camera movedCamera(moved);
        DepthMap fromElsewhere = kinectLike(truthMap(checker, movedCamera, ExportQuantity::EyeZ), 0.03, 13);
        fromElsewhere.accuracy = sensor;
        REQUIRE_FALSE(consistent(verifier, camera, fromElsewhere));
    }
}

TEST_CASE("regression: a declared accuracy hid an offset on maps under 256 pixels and a tenth of the depth passed",
          "[declared][regression]")
{
    // A wall at eye-z 5 across an orthographic view (OpenGL): every pixel's truth is exactly 5.
    Scene wall;
    wall.name = "wall";
    wall.positions = {{-10, -10, -5}, {10, -10, -5}, {10, 10, -5}, {-10, 10, -5}};
    wall.triangles = {{0, 1, 2}, {0, 2, 3}};
    wall = frameScene(wall, "wall");
    const Checker checker(wall);
    const MapVerifier verifier(checker);
    auto orthographic = [](int width, int height) {
        CameraSpec spec;
        spec.convention = Convention::preset("opengl");
        spec.width = width, spec.height = height;
        spec.projection.type = ProjectionType::Orthographic;
        spec.projection.left = -1, spec.projection.right = 1, spec.projection.bottom = -0.75, spec.projection.top = 0.75;
        spec.projection.near = 1, spec.projection.far = 10;
        spec.view = View::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
        return Camera(spec);
    };
    auto refusal = [&](const Camera& camera, const DepthMap& map) {
        const auto report = verifier.verify(camera, map).comparison.report;
        REQUIRE(report.consistent() == report.declaredAccuracyRefused.empty());
        return report.declaredAccuracyRefused;
    };
    auto filled = [](const Camera& camera, auto value) {
        std::vector<double> values(std::size_t(camera.width()) * std::size_t(camera.height()));
        for (double& v : values) v = double(float(value()));
        return DepthMap::exact(camera.width(), camera.height(), DepthQuantity::EyeZ, std::move(values));
    };
    const Camera small = orthographic(16, 12);  // 192 pixels: the bias rule used to skip such maps

    // One centimetre far everywhere, under a declared ±2 cm: an offset, never noise.
    DepthMap offset = filled(small, [] { return 5.01; });
    REQUIRE_FALSE(verifier.verify(small, offset).comparison.report.consistent());
    offset.accuracy.absolute = 0.02;
    REQUIRE_THAT(refusal(small, offset), Catch::Contains("the map's errors are systematic"));
    // Unbiased noise of σ 5 mm under ±3 cm stands.
    std::mt19937 random(7);
    std::normal_distribution<double> noise(0, 0.005);
    DepthMap noisy = filled(small, [&] { return 5 + noise(random); });
    noisy.accuracy.absolute = 0.03;
    REQUIRE(refusal(small, noisy).empty());

    // Exactly a tenth of the depth is "a tenth or more": refused; just under it stands.
    DepthMap exact = filled(small, [] { return 5.0; });
    exact.accuracy.absolute = 0.5;
    REQUIRE_THAT(refusal(small, exact), Catch::Contains("as coarse as the depths"));
    exact.accuracy.absolute = 0.4999;
    REQUIRE(refusal(small, exact).empty());

    // Sixteen pixels cannot tell noise from an offset: any declared accuracy is refused, the map
    // declaring none is judged pixel by pixel as ever.
    const Camera tiny = orthographic(4, 4);
    DepthMap few = filled(tiny, [] { return 5.0; });
    REQUIRE(verifier.verify(tiny, few).comparison.report.consistent());
    few.accuracy.absolute = 0.02;
    REQUIRE_THAT(refusal(tiny, few), Catch::Contains("only 16 pixels are compared, too few"));
}
