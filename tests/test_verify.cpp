// zcheck verify: a correct map verifies; each classic mutation is rejected and diagnosed.
#include "faults.h"
#include "verify.h"

#include "zcheck/export.h"
#include "zcheck/inverse_projection.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace zcheck;

namespace {

ExternalDepthMap mapOf(const Scene& scene, const Camera& camera, const RenderResult& route, ExportQuantity quantity)
{
    const QuantityImage image = quantityImage(scene, camera, route, quantity);
    ExternalDepthMap map;
    map.width = image.width, map.height = image.height;
    map.quantity = quantity == ExportQuantity::Window ? DepthQuantity::Window
                   : quantity == ExportQuantity::EyeZ ? DepthQuantity::EyeZ
                                                       : DepthQuantity::Distance;
    map.value = image.value;
    for (double& v : map.value) v = double(float(v));  // as stored in a float32 file
    return map;
}

// The first hypothesis that makes the map consistent, or "".
std::string diagnosis(const Scene& scene, const Camera& camera, const ExternalDepthMap& map, RayRenderer& rays)
{
    for (const Hypothesis& h : diagnoseDepthMap(scene, camera, map, rays))
        if (h.consistent) return h.name;
    return "";
}

struct Setup {
    Scene scene = builtinScene("builtin:default");
    CameraSpec spec;
    Setup()
    {
        spec = scene.defaultCamera;
        spec.width = 200, spec.height = 150;
    }
};

}  // namespace

TEST_CASE("a depth map from the raster route verifies, in every quantity and convention", "[verify]")
{
    Setup s;
    RayRenderer rays(s.scene);
    RasterRenderer raster(s.scene);
    for (const auto& convention : Convention::presetNames())
        for (bool reversed : {false, true}) {
            CameraSpec spec = s.spec;
            spec.convention = Convention::preset(convention);
            spec.depth.reversed = reversed;
            const Camera camera(spec);
            const RenderResult drawn = raster.render(camera);
            for (ExportQuantity q : {ExportQuantity::Window, ExportQuantity::EyeZ, ExportQuantity::Distance}) {
                const VerifyRun run = verifyDepthMap(s.scene, camera, mapOf(s.scene, camera, drawn, q), rays);
                INFO(convention << (reversed ? " reversed " : " ") << toString(q) << ": unexplained "
                                << run.comparison.report.unexplained());
                REQUIRE(run.comparison.report.bothHit > 10000);
                REQUIRE(run.comparison.report.consistent());
            }
        }
}

TEST_CASE("mutated depth maps are rejected and the diagnosis names the mutation", "[verify][diagnose]")
{
    Setup s;
    RayRenderer rays(s.scene);
    RasterRenderer raster(s.scene);
    for (const auto& convention : {std::string("opengl"), std::string("direct3d"), std::string("vulkan")}) {
        CameraSpec spec = s.spec;
        spec.convention = Convention::preset(convention);
        const Camera camera(spec);
        const RenderResult drawn = raster.render(camera);
        auto requireDiagnosed = [&](const std::string& mutation, const ExternalDepthMap& map, const std::string& expected) {
            INFO(convention << ": " << mutation);
            REQUIRE_FALSE(verifyDepthMap(s.scene, camera, map, rays).comparison.report.consistent());
            REQUIRE(diagnosis(s.scene, camera, map, rays) == expected);
        };
        // Flipped vertically.
        ExternalDepthMap flipped = mapOf(s.scene, camera, drawn, ExportQuantity::Window);
        for (int row = 0; row < 75; ++row)
            for (int col = 0; col < 200; ++col)
                std::swap(flipped.value[std::size_t(row) * 200 + col], flipped.value[std::size_t(149 - row) * 200 + col]);
        requireDiagnosed("flipped", flipped, "vertical-flip");
        // Rendered with pixel centres at integer coordinates (the +0.5 forgotten).
        rays.sampling.shiftPixels = {-0.5, -0.5};
        const RenderResult shifted = rays.render(camera);
        rays.sampling = RayFaults{};
        requireDiagnosed("shifted half a pixel", mapOf(s.scene, camera, shifted, ExportQuantity::Window),
                         "half-pixel-shift x and y");
        // The other NDC depth range: an OpenGL-style matrix in a [0,1] pipeline, or the reverse.
        FaultInjection ndc;
        for (const Fault& fault : faultCatalogue())
            if (fault.name == "ndc-range") fault.inject(camera, ndc);
        raster.faults = ndc.raster;
        const RenderResult otherRange = raster.render(camera);
        raster.faults = RasterFaults{};
        requireDiagnosed("other depth range", mapOf(s.scene, camera, otherRange, ExportQuantity::Window), "other-ndc-range");
        // A correct reversed-Z renderer, verified as if standard.
        CameraSpec reversedSpec = spec;
        reversedSpec.depth.reversed = true;
        const Camera reversedCamera(reversedSpec);
        requireDiagnosed("reversed", mapOf(s.scene, reversedCamera, raster.render(reversedCamera), ExportQuantity::Window),
                         "reversed");
        // eye-z passed as window depth; distance passed as eye-z.
        ExternalDepthMap eyeZ = mapOf(s.scene, camera, drawn, ExportQuantity::EyeZ);
        eyeZ.quantity = DepthQuantity::Window;
        requireDiagnosed("eye-z as window depth", eyeZ, "eye-z-as-window");
        ExternalDepthMap distance = mapOf(s.scene, camera, drawn, ExportQuantity::Distance);
        distance.quantity = DepthQuantity::EyeZ;
        requireDiagnosed("distance as eye-z", distance, "distance-as-eye-z");
    }
}

TEST_CASE("a map that no hypothesis explains is diagnosed as such", "[verify][diagnose]")
{
    Setup s;
    RayRenderer rays(s.scene);
    const Camera camera(s.spec);
    ExternalDepthMap noise = mapOf(s.scene, camera, RasterRenderer(s.scene).render(camera), ExportQuantity::EyeZ);
    for (std::size_t i = 0; i < noise.value.size(); ++i)
        if (std::isfinite(noise.value[i])) noise.value[i] *= 1.0 + 0.05 * std::sin(double(i));
    REQUIRE_FALSE(verifyDepthMap(s.scene, camera, noise, rays).comparison.report.consistent());
    REQUIRE(diagnosis(s.scene, camera, noise, rays).empty());
}

