#pragma once
// A room an RGB-D sensor sees, for the tests of maps as sensors and pipelines deliver them: the
// builtin scene shrunk ten times (0.36 .. 3.7 m from the eye), 200×150 pixels, and what verifying
// maps of it needs.
#include "zcheck/map_verifier.h"

#include "diagnosis_helpers.h"

#include <string>

namespace zcheck::testing {

struct Room {
    Scene scene = builtinScene("builtin:default");
    CameraSpec spec;
    explicit Room(const std::string& convention = "opengl")
    {
        for (glm::vec3& p : scene.positions) p *= 0.1f;
        spec = scene.defaultCamera;
        spec.view.eye *= 0.1, spec.view.target *= 0.1;
        spec.projection.near *= 0.1, spec.projection.far *= 0.1;
        spec.width = 200, spec.height = 150;
        spec.convention = Convention::preset(convention);
    }
};

// The room with its checker, verifier and camera, and its true maps.
struct RoomVerifier {
    explicit RoomVerifier(const std::string& convention = "opengl") : room(convention) {}
    Room room;
    Checker checker{room.scene};
    MapVerifier verifier{checker};
    Camera camera{room.spec};
    // The ray route's map of `quantity` as a float32 file holds it (misses: +inf).
    DepthMap truth(ExportQuantity quantity) const { return mapOf(checker.scene(), camera, checker.renderRay(camera), quantity); }
    bool accepts(const DepthMap& map) const { return verifier.verify(camera, map).comparison.report.consistent(); }
};

}  // namespace zcheck::testing
