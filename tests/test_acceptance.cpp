// No declaration accepts a wrong map: every way a map can be accepted — exact, a rounding grid,
// relative and absolute tolerances, a noise model, holes — goes through one rule that also
// judges the map's errors as a whole (judgeDeclaredAccuracy, diagnose/src/verify_estimators.h), and the diagnosis offers
// a declaration only as that rule judges it. An eye-z or distance map's tolerance is its own,
// whatever the camera's depth buffer; a sensor's noise is answered with a noise model.
#include "zcheck/declared_reading.h"
#include "zcheck/map_verifier.h"
#include "zcheck/verify.h"

#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"

#include "diagnosis_helpers.h"
#include "room.h"
#include "sweep.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>
#include <optional>
#include <cmath>
#include <random>

using namespace zcheck;
using testing::mapOf;
using testing::RoomVerifier;

namespace {

const ComparisonReport& verdictOf(const VerifyResult& run) { return run.comparison.report; }

bool accepted(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    return verifier.verify(camera, map).comparison.report.consistent();
}

// Values rounded to multiples of q (misses kept).
DepthMap rounded(DepthMap map, double q)
{
    for (double& v : map.value)
        if (std::isfinite(v)) v = double(float(std::round(v / q) * q));
    return map;
}

// Each value off by a uniform error in ±amplitude, or ±amplitude·|value| when `relative`.
DepthMap uniformlyOff(DepthMap map, double amplitude, bool relative, unsigned seed)
{
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
    for (double& v : map.value)
        if (std::isfinite(v)) v += uniform(random) * (relative ? std::abs(v) : 1.0);
    return map;
}

// σ(z) = 1.2 mm + 1.9 mm·(z − 0.4 m)², Gaussian, no rounding, no holes.
DepthMap kinectNoise(DepthMap map, unsigned seed)
{
    std::mt19937 random(seed);
    std::normal_distribution<double> normal;
    for (double& v : map.value)
        if (std::isfinite(v)) v += (0.0012 + 0.0019 * (v - 0.4) * (v - 0.4)) * normal(random);
    return map;
}

// Whether a hypothesis of the diagnosis only declares (declared_reading.h): every part of its
// name ("miss-value + quantum") a declaration, none a mistake or a fitted departure.
bool isDeclaration(const std::string& name)
{
    std::size_t from = 0;
    while (true) {
        const std::size_t to = name.find(" + ", from);
        const std::string part = name.substr(from, to == std::string::npos ? std::string::npos : to - from);
        if (part != "quantum" && part != "tolerance" && part != "noise" && part != "miss-value" && part != "holes") return false;
        if (to == std::string::npos) return true;
        from = to + 3;
    }
}

}  // namespace

TEST_CASE("regression: --quantum 5 accepted a float map in metres read with nerfstudio's scale 1000", "[acceptance]")
{
    const RoomVerifier room;
    const MapVerifier& verifier = room.verifier;
    const Camera& camera = room.camera;
    DepthMap map = room.truth(ExportQuantity::EyeZ);
    REQUIRE(accepted(verifier, camera, map));
    for (double& v : map.value) v /= 1000;  // metres read as millimetres
    REQUIRE_FALSE(accepted(verifier, camera, map));
    for (const double q : {5.0, 1.0, 0.5}) {
        DepthMap declared = map;
        declared.accuracy.quantum = q;
        const VerifyResult run = verifier.verify(camera, declared);
        INFO(q << ": " << verdictOf(run).declaredAccuracyRefused);
        REQUIRE_FALSE(verdictOf(run).consistent());
        REQUIRE_FALSE(verdictOf(run).declaredAccuracyRefused.empty());
    }
    // The diagnosis offers no declaration for it, consistent or closest.
    const std::vector<Hypothesis> hypotheses = verifier.diagnose(camera, map);
    for (const Hypothesis& h : hypotheses) {
        INFO(h.name << ": " << h.explanation);
        REQUIRE_FALSE((h.consistent && isDeclaration(h.name)));
    }
    REQUIRE_FALSE(isDeclaration(hypotheses.front().name));
}

TEST_CASE("regression: --quantum 0.1 accepted a distance map declared as eye-z", "[acceptance]")
{
    const RoomVerifier room;
    const MapVerifier& verifier = room.verifier;
    const Camera& camera = room.camera;
    DepthMap distance = room.truth(ExportQuantity::Distance);
    distance.quantity = DepthQuantity::EyeZ;  // declared eye-z, holds distance
    REQUIRE_FALSE(accepted(verifier, camera, distance));
    DepthMap declared = distance;
    declared.accuracy.quantum = 0.1;  // the values are not on that grid
    VerifyResult run = verifier.verify(camera, declared);
    REQUIRE_FALSE(verdictOf(run).consistent());
    REQUIRE_FALSE(verdictOf(run).declaredAccuracyRefused.empty());  // as coarse as the room's depths, and not its grid
    declared.accuracy.quantum = 0.01;
    run = verifier.verify(camera, declared);
    REQUIRE(verdictOf(run).declaredAccuracyRefused.find("is not the map's grid") != std::string::npos);
    // Rounded to the grid it declares, the same mistake is still refused: its errors are one-sided.
    for (const double q : {0.001, 0.01, 0.05}) {
        DepthMap onGrid = rounded(distance, q);
        onGrid.accuracy.quantum = q;
        INFO(q);
        REQUIRE_FALSE(accepted(verifier, camera, onGrid));
    }
}

TEST_CASE("regression: an eye-z map's tolerance depended on the camera's depth format and reversal", "[acceptance]")
{
    const RoomVerifier room;
    const MapVerifier& verifier = room.verifier;
    const Camera& camera = room.camera;
    const DepthMap exact = room.truth(ExportQuantity::EyeZ);
    const DepthMap off = uniformlyOff(exact, 0.007, false, 5);  // ±7 mm
    for (const ExportQuantity quantity : {ExportQuantity::EyeZ, ExportQuantity::Distance}) {
        const DepthMap right = room.truth(quantity);
        DepthMap wrong = right;
        for (std::size_t i = 0; i < wrong.value.size(); ++i)
            if (std::isfinite(wrong.value[i])) wrong.value[i] += off.value[i] - exact.value[i];
        std::optional<std::int64_t> unexplainedBefore;
        for (const DepthFormat format : {DepthFormat::Float32, DepthFormat::Unorm24, DepthFormat::Unorm16})
            for (const bool reversed : {false, true}) {
                CameraSpec spec = room.room.spec;
                spec.depth.format = format, spec.depth.reversed = reversed;
                const Camera variant(spec);
                INFO(toString(quantity) << " " << toString(format) << (reversed ? " reversed" : ""));
                REQUIRE(accepted(verifier, variant, right));
                const VerifyResult run = verifier.verify(variant, wrong);
                REQUIRE_FALSE(verdictOf(run).consistent());
                REQUIRE(run.report.tolerance.constantFor(variant.depth()) == 4.0);
                if (!unexplainedBefore) unexplainedBefore = verdictOf(run).unexplained();
                REQUIRE(verdictOf(run).unexplained() == *unexplainedBefore);
            }
        // Not "consistent if read as reversed-Z depth", nor as any other convention: uniform
        // errors of ±7 mm are noise, and only a declaration of it accepts the map.
        for (const Hypothesis& h : verifier.diagnose(camera, wrong)) {
            INFO(h.name);
            REQUIRE_FALSE((h.consistent && !isDeclaration(h.name)));
        }
    }
    // Integers carry their own step: C = 1 of it.
    DepthMap millimetres = rounded(exact, 0.001);
    millimetres.valueQuantum = 0.001;
    REQUIRE(mapTolerance(millimetres).storageConstant == 1.0);
    REQUIRE(accepted(verifier, camera, millimetres));
}

TEST_CASE("regression: a uniform scale 4e-4 short was accepted as --rel-tolerance 5e-4", "[acceptance]")
{
    const RoomVerifier room;
    const MapVerifier& verifier = room.verifier;
    const Camera& camera = room.camera;
    const DepthMap exact = room.truth(ExportQuantity::EyeZ);
    DepthMap scaled = exact;
    for (double& v : scaled.value) v *= 1 - 4e-4;
    for (const double relative : {5e-4, 1e-3, 0.05}) {
        DepthMap declared = scaled;
        declared.accuracy.relative = relative;
        const VerifyResult run = verifier.verify(camera, declared);
        INFO(relative);
        REQUIRE_FALSE(verdictOf(run).consistent());
        REQUIRE(verdictOf(run).declaredAccuracyRefused.find("systematic") != std::string::npos);
    }
    // The diagnosis names the scale, and offers no tolerance for it.
    bool scale = false;
    for (const Hypothesis& h : verifier.diagnose(camera, scaled)) {
        INFO(h.name << ": " << h.explanation);
        REQUIRE_FALSE((h.consistent && isDeclaration(h.name)));
        scale |= h.consistent && h.name == "depth-scale";
    }
    REQUIRE(scale);
    // Unbiased errors of the same size are an accuracy: accepted with it, and the option is named.
    const DepthMap jittered = uniformlyOff(exact, 4e-4, true, 3);
    REQUIRE_FALSE(accepted(verifier, camera, jittered));
    DepthMap declared = jittered;
    declared.accuracy.relative = 5e-4;
    REQUIRE(accepted(verifier, camera, declared));
    bool named = false;
    for (const Hypothesis& h : verifier.diagnose(camera, jittered))
        named |= h.consistent && (h.name == "tolerance" || h.name == "noise");
    REQUIRE(named);
}

TEST_CASE("regression: Kinect-like noise was blamed on a convention, it is answered with a noise model", "[acceptance]")
{
    const RoomVerifier room;
    const MapVerifier& verifier = room.verifier;
    const Camera& camera = room.camera;
    const DepthMap exact = room.truth(ExportQuantity::EyeZ);
    const DepthMap noisy = kinectNoise(exact, 17);
    REQUIRE_FALSE(accepted(verifier, camera, noisy));
    // The diagnosis: noise, first, with a model that accepts it.
    const std::vector<Hypothesis> hypotheses = verifier.diagnose(camera, noisy);
    REQUIRE(hypotheses.front().consistent);
    REQUIRE(hypotheses.front().name == "noise");
    INFO(hypotheses.front().explanation);
    const std::string& said = hypotheses.front().explanation;
    const std::size_t at = said.find("--noise-model '");
    REQUIRE(at != std::string::npos);
    const std::string model = said.substr(at + 15, said.find('\'', at + 15) - at - 15);
    DepthMap declared = noisy;
    declared.accuracy.noise = NoiseModel::parse(model);
    REQUIRE(accepted(verifier, camera, declared));
    // The sensor's own model, declared by name, accepts it too.
    declared.accuracy.noise = NoiseModel::parse("kinect");
    REQUIRE(accepted(verifier, camera, declared));
    // ... and does not accept the same sensor's map flipped, holding distance, or 1 % far.
    DepthMap flipped = declared;
    for (int row = 0; row < flipped.height; ++row)
        std::copy_n(declared.value.begin() + std::ptrdiff_t(declared.height - 1 - row) * declared.width, declared.width,
                    flipped.value.begin() + std::ptrdiff_t(row) * declared.width);
    REQUIRE_FALSE(accepted(verifier, camera, flipped));
    DepthMap distance = kinectNoise(room.truth(ExportQuantity::Distance), 18);
    distance.quantity = DepthQuantity::EyeZ, distance.accuracy.noise = NoiseModel::parse("kinect");
    REQUIRE_FALSE(accepted(verifier, camera, distance));
    DepthMap far = declared;
    for (double& v : far.value) v *= 1.01;
    REQUIRE_FALSE(accepted(verifier, camera, far));
}

TEST_CASE("noise models: kinect, A+B*z^2 and A+B*(z-C)^2, each read back from its text, others refused by name",
          "[acceptance]")
{
    const NoiseModel kinect = NoiseModel::parse("kinect");
    REQUIRE(kinect.sigma(0.4) == Approx(0.0012));
    REQUIRE(kinect.sigma(2.4) == Approx(0.0012 + 0.0019 * 4));  // Nguyen et al. 2012 at 2.4 m: 8.8 mm
    REQUIRE(kinect.allowance(2.4) == Approx(6 * 0.0088));
    REQUIRE(NoiseModel::parse(kinect.text()) == kinect);
    const NoiseModel quadratic = NoiseModel::parse(" 0.001 + 0.002*z^2");
    REQUIRE(quadratic.sigma(2) == Approx(0.009));
    REQUIRE(NoiseModel::parse(quadratic.text()) == quadratic);
    REQUIRE(NoiseModel::parse("1e-3+2e-3*(z-0.5)^2").sigma(1.5) == Approx(0.003));
    for (const char* bad : {"", "kinect2", "0.001", "0.001+z^2", "-1+0.002*z^2", "0+0*z^2", "nan+1*z^2", "0.001+0.002*z^3",
                            "0.001+0.002*(z-0.4)^2x"}) {
        INFO(bad);
        REQUIRE_THROWS_WITH(NoiseModel::parse(bad), Catch::Contains("--noise-model must be kinect"));
    }
}

TEST_CASE("property: no mistake of the catalogue is accepted under any declaration or any suggestion of the diagnosis",
          "[acceptance]")
{
    const RoomVerifier room;
    const MapVerifier& verifier = room.verifier;
    const Camera& camera = room.camera;
    // Each declaration a user might give, applied to the mistaken map as that user would hold it.
    struct Declaration {
        std::string name;
        std::function<DepthMap(DepthMap)> apply;
    };
    const std::vector<Declaration> declarations = {
        {"nothing", [](DepthMap m) { return m; }},
        {"holes", [](DepthMap m) { m.accuracy.allowHoles = true; return m; }},
        {"quantum 0.001 (rounded)", [](DepthMap m) { m = rounded(m, 0.001); m.accuracy.quantum = 0.001; return m; }},
        {"quantum 0.01 (rounded)", [](DepthMap m) { m = rounded(m, 0.01); m.accuracy.quantum = 0.01; return m; }},
        {"quantum 0.05 (rounded) + holes",
         [](DepthMap m) { m = rounded(m, 0.05); m.accuracy.quantum = 0.05, m.accuracy.allowHoles = true; return m; }},
        {"rel-tolerance 0.001", [](DepthMap m) { m.accuracy.relative = 0.001; return m; }},
        {"rel-tolerance 0.02", [](DepthMap m) { m.accuracy.relative = 0.02; return m; }},
        {"rel-tolerance 0.09 + holes", [](DepthMap m) { m.accuracy.relative = 0.09, m.accuracy.allowHoles = true; return m; }},
        {"abs-tolerance 0.001", [](DepthMap m) { m.accuracy.absolute = 0.001; return m; }},
        {"abs-tolerance 0.02", [](DepthMap m) { m.accuracy.absolute = 0.02; return m; }},
        {"abs-tolerance 0.1 + holes", [](DepthMap m) { m.accuracy.absolute = 0.1, m.accuracy.allowHoles = true; return m; }},
        {"noise-model kinect", [](DepthMap m) { m.accuracy.noise = NoiseModel::parse("kinect"); return m; }},
        {"noise-model kinect + quantum 0.001 + holes", [](DepthMap m) {
             m = rounded(m, 0.001);
             m.accuracy.noise = NoiseModel::parse("kinect"), m.accuracy.quantum = 0.001, m.accuracy.allowHoles = true;
             return m;
         }},
    };
    int mistakes = 0, visible = 0;
    // A wrong map: rejected as it is, and under every declaration and every suggestion (each
    // wrong map a case of the sweep, sweep.h).
    auto neverAccepted = [&](const DepthMap& wrong) {
        if (!testing::sweepTakes(0, std::size_t(visible++))) return;
        for (const Declaration& d : declarations) {
            INFO("declared: " << d.name);
            REQUIRE_FALSE(accepted(verifier, camera, d.apply(wrong)));
        }
        for (const Hypothesis& h : verifier.diagnose(camera, wrong)) {
            INFO("suggested: " << h.name << ": " << h.explanation);
            REQUIRE_FALSE((h.consistent && isDeclaration(h.name)));
        }
    };
    for (const Mistake* mistake : injectableMistakes()) {
        RouteFaults faults;
        if (!mistake->inject(camera, faults)) continue;
        ++mistakes;
        const RenderResult render = room.checker.render(camera, mistake->route, faults);
        for (const ExportQuantity quantity : {ExportQuantity::EyeZ, ExportQuantity::Distance}) {
            const DepthMap wrong = mapOf(room.checker.scene(), camera, render, quantity);
            INFO(mistake->name << ", " << toString(quantity));
            // A mistake that leaves this quantity as it is (reversed-Z in an eye-z map) makes no wrong map.
            if (accepted(verifier, camera, wrong)) continue;
            neverAccepted(wrong);
        }
    }
    // The catalogue's mistakes made with the files (a pose's rotation, its units, the mesh's axes):
    // the map a renderer that made one draws, through the camera it really used (the first
    // variant of each that sees the scene), in eye-z.
    const DepthMap anyMap = room.truth(ExportQuantity::EyeZ);
    int fileMistakes = 0;
    for (const Mistake& mistake : mistakeCatalogue()) {
        if (mistake.inject || !mistake.reread) continue;
        for (const Rereading& reading : mistake.reread(camera, anyMap)) {
            if (!reading.camera || !reading.truthFaults.none() || reading.map) continue;
            const Camera used(*reading.camera);
            const RenderResult render = room.checker.renderRay(used);
            if (!testing::anyHit(render)) continue;
            const DepthMap wrong = mapOf(room.checker.scene(), used, render, ExportQuantity::EyeZ);
            INFO(mistake.name << " [" << reading.variant << "]");
            if (accepted(verifier, camera, wrong)) continue;
            ++fileMistakes;
            neverAccepted(wrong);
            break;
        }
    }
    REQUIRE(fileMistakes >= 5);
    // Mistakes made with the files rather than the chain: another quantity, other units.
    const RenderResult truth = room.checker.renderRay(camera);
    for (const auto& [name, make] : std::vector<std::pair<std::string, std::function<DepthMap()>>>{
             {"distance-as-eye-z",
              [&] { DepthMap m = mapOf(room.checker.scene(), camera, truth, ExportQuantity::Distance); m.quantity = DepthQuantity::EyeZ; return m; }},
             {"eye-z-as-distance",
              [&] { DepthMap m = mapOf(room.checker.scene(), camera, truth, ExportQuantity::EyeZ); m.quantity = DepthQuantity::Distance; return m; }},
             {"metres read as millimetres",
              [&] { DepthMap m = mapOf(room.checker.scene(), camera, truth, ExportQuantity::EyeZ); for (double& v : m.value) v /= 1000; return m; }},
             {"inches read as metres",
              [&] { DepthMap m = mapOf(room.checker.scene(), camera, truth, ExportQuantity::EyeZ); for (double& v : m.value) v *= 39.37; return m; }},
             {"a centimetre too far",
              [&] { DepthMap m = mapOf(room.checker.scene(), camera, truth, ExportQuantity::EyeZ); for (double& v : m.value) v += 0.01; return m; }},
         }) {
        const DepthMap wrong = make();
        INFO(name);
        REQUIRE_FALSE(accepted(verifier, camera, wrong));
        neverAccepted(wrong);
    }
    REQUIRE(mistakes >= 15);  // 18 of the catalogue apply to this camera
    REQUIRE(visible >= 30);
}
