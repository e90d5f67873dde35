#pragma once
// The mistake catalogue: the classic transform-chain mistakes, one list, one name each
// (library zcheck::diagnose).
//
// Every mistake can be used two ways:
//   inject — make one route of an otherwise correct chain commit it (the suite: a checker is
//            as good as the mistakes it catches);
//   reread — given a depth map that is inconsistent, ask "would a renderer that made this
//            mistake have produced it?" by re-reading the map, or re-rendering the truth,
//            under the mistake (the diagnosis, MapVerifier::diagnose in map_verifier.h).
// Some mistakes only have one use: a renderer's clipping or interpolation mistakes cannot be
// undone by re-reading a finished map (inject only), and a map's values taken for another
// quantity have no route to inject into (reread only); the other function is then empty.
//
//   for (const zcheck::Mistake& mistake : zcheck::mistakeCatalogue())
//       if (zcheck::RouteFaults faults; mistake.inject && mistake.inject(camera, faults))
//           zcheck::RenderResult wrong = checker.render(camera, mistake.route, faults);
#include "zcheck/checker.h"
#include "zcheck/depth_map.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace zcheck {

// One way a map might have been produced under a mistake: the truth is rendered by the ray
// route with `truthFaults` through `camera` (when set: the camera the renderer really used,
// else the given one), and the map is read as `map` (when set, else as given).
struct Rereading {
    std::string variant;                 // empty, or which variant ("x and y", "fovy 59.4°")
    std::string explanation;             // "consistent if ...", for people
    std::optional<CameraSpec> camera;
    RayFaults truthFaults;
    std::optional<DepthMap> map;
};

struct Mistake {
    std::string name;         // short, stable: in tables, --filter, JSON and hypotheses
    std::string description;  // what the mistake is, in a user's words
    Route route;              // the route `inject` puts it into
    // Fills `faults` for this camera; false where the mistake has no meaning here (a
    // field-of-view mistake on an orthographic camera, truncation of a float buffer).
    std::function<bool(const Camera&, RouteFaults&)> inject;
    // The ways to re-read `map` under the mistake; empty where it has no meaning.
    std::function<std::vector<Rereading>(const Camera&, const DepthMap&)> reread;
    // The diagnosis tries it alone, never paired with another: a mistake made with the files a
    // renderer was given (a pose's rotation, its units, the mesh's axes), not in its chain.
    bool alone = false;
};

const std::vector<Mistake>& mistakeCatalogue();
// The mistakes the suite injects (those with `inject`), in catalogue order.
std::vector<const Mistake*> injectableMistakes();

}  // namespace zcheck
