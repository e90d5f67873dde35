// A renderer's test would do this: verify the depth map its renderer wrote against zcheck's
// ground truth, and when it is wrong, say which mistake explains it. Here zcheck's raster route
// stands in for the renderer, and its rows are flipped (a bottom-left origin read as top-left).
//   verify_map [MESH]      (default: zcheck's built-in scene)
#include <zcheck/checker.h>
#include <zcheck/error.h>
#include <zcheck/map_verifier.h>
#include <zcheck/mesh_loader.h>
#include <zcheck/verify_map.h>

#include <cstdio>
#include <vector>

int main(int argc, char** argv)
{
    try {
        const zcheck::Checker checker(zcheck::loadScene(argc > 1 ? argv[1] : "builtin:default"));
        const zcheck::MapVerifier verifier(checker);  // keep it beside the checker for every map
        zcheck::CameraSpec spec = checker.scene().defaultCamera;
        spec.width = 320, spec.height = 240;
        const zcheck::Camera camera(spec);

        // "Your renderer's" eye-z, row 0 at the top, then flipped upside down.
        const zcheck::QuantityImage rendered =
            checker.render(camera, zcheck::ExportQuantity::EyeZ, zcheck::Route::Raster);
        std::vector<double> flipped(rendered.value.size());
        for (int row = 0; row < spec.height; ++row)
            for (int col = 0; col < spec.width; ++col)
                flipped[std::size_t(row) * spec.width + col] = rendered.value[std::size_t(spec.height - 1 - row) * spec.width + col];
        const zcheck::DepthMap map =
            zcheck::DepthMap::exact(spec.width, spec.height, zcheck::DepthQuantity::EyeZ, std::move(flipped));

        const zcheck::VerifiedMap verified = zcheck::verifyMap(verifier, camera, map, /*diagnose=*/true);
        std::printf("map %s\n", verified.run.comparison.report.consistent() ? "CONSISTENT" : "INCONSISTENT");
        for (const zcheck::Hypothesis& h : verified.diagnosis)
            if (h.consistent) std::printf("consistent if %s: %s\n", h.name.c_str(), h.explanation.c_str());
        return verified.run.comparison.report.consistent() ? 0 : 1;
    } catch (const zcheck::Error& e) {
        std::fprintf(stderr, "verify_map: %s\n", e.what());
        return 2;
    }
}
