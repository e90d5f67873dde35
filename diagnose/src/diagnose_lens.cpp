// The mistakes of the lens family (lens.h), for maps judged through a lens model's camera — and,
// for a pinhole's map that no linear mistake explains, a lens the camera left out. Each
// hypothesis is the camera the renderer really used (or the map's other quantity), judged by a
// full verification (verifyLensMap, or the linear one for a pinhole):
//   distortion-ignored        the map made through the lens's K alone (a pinhole), declared with the lens
//   undistorted-new-k         the map undistorted to getOptimalNewCameraMatrix's K (alpha 0 or 1),
//                             declared with the lens (remap.h, undistortedCameraSpec)
//   coefficient-order         OpenCV's k1 k2 p1 p2 k3 read where k1 k2 k3 p1 p2 was meant, or the
//                             reverse; nerfstudio's k1 k2 k3 k4 p1 p2 against OpenCV's order
//   tangential-swapped        p1 and p2 exchanged (Metashape's P1 is OpenCV's p2)
//   distortion-signs-flipped  every distortion coefficient negated (undistortion's for distortion's)
//   fisheye-model             a fisheye read as another: equidistant, equisolid, stereographic
//   y-flip, x-flip, half-pixel, cx-cy-swapped   the catalogue's mistakes of the image and the
//                             principal point, as a lens map shows them
//   distance-as-eye-z, eye-z-as-distance   the map's values taken for the other quantity
//   fitted-radial-distortion  k1, k2 of a radial lens with the camera's K fitted to the map (rays
//                             traced per sample, Levenberg–Marquardt), then verified in full
#include "verify_estimators.h"

#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/map_verifier.h"
#include "zcheck/remap.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace zcheck {

namespace {

struct LensCandidate {
    std::string name, variant, explanation;
    std::optional<CameraSpec> camera;   // the camera the renderer used; none: the declared one
    std::optional<DepthQuantity> quantity;  // the map's values read as this quantity; none: as declared
    int flip = 0;                       // the map's rows (1) or columns (2) read in the other order
};

// The map with its rows (flip 1) or columns (flip 2) in the other order.
DepthMap flipped(const DepthMap& map, int flip)
{
    DepthMap out = map;
    for (int row = 0; row < map.height; ++row)
        for (int col = 0; col < map.width; ++col) {
            const int fromRow = flip == 1 ? map.height - 1 - row : row, fromCol = flip == 2 ? map.width - 1 - col : col;
            out.value[std::size_t(row) * map.width + col] = map.value[std::size_t(fromRow) * map.width + fromCol];
            if (!map.valueStep.empty())
                out.valueStep[std::size_t(row) * map.width + col] = map.valueStep[std::size_t(fromRow) * map.width + fromCol];
        }
    return out;
}

std::string coefficientText(const LensSpec& lens, const std::vector<std::size_t>& which)
{
    const LensModelInfo& info = *lensModelNamed(lens.model);
    std::string out;
    for (std::size_t i : which) {
        char value[48];
        std::snprintf(value, sizeof value, "%.6g", lens.params[i]);
        out += (out.empty() ? "" : ", ") + std::string(info.params[i]) + " " + value;
    }
    return out;
}

// The index of a model's parameter, or npos.
std::size_t paramIndex(const LensSpec& lens, const char* name)
{
    const LensModelInfo& info = *lensModelNamed(lens.model);
    for (std::size_t i = 0; i < info.params.size(); ++i)
        if (std::string(info.params[i]) == name) return i;
    return std::string::npos;
}

CameraSpec withLens(const Camera& camera, LensSpec lens)
{
    CameraSpec spec = camera.spec();
    spec.projection.lens = std::move(lens);
    return spec;
}

// The hypotheses of the catalogue above for a lens camera.
std::vector<LensCandidate> lensCandidates(const Camera& camera, const DepthMap& map)
{
    std::vector<LensCandidate> out;
    const LensModel& lens = *camera.lens();
    const LensSpec& spec = lens.spec();
    const LensModelInfo& info = lens.info();
    const bool hasK = info.startsWithK();
    if (hasK) {
        CameraSpec pinhole = camera.spec();
        pinhole.projection = Projection{};
        pinhole.projection.type = ProjectionType::Pinhole;
        pinhole.projection.fx = spec.params[0], pinhole.projection.fy = spec.params[1];
        pinhole.projection.cx = spec.params[2], pinhole.projection.cy = spec.params[3];
        pinhole.projection.near = camera.nearDistance(), pinhole.projection.far = camera.farDistance();
        out.push_back({"distortion-ignored", "", "consistent if the map was made through the lens's K alone, its " +
                                                    spec.model + " distortion left out (the original K kept after undistorting)",
                       pinhole, std::nullopt});
    }
    for (const double alpha : {0.0, 1.0}) {
        try {
            const CameraSpec undistorted = undistortedCameraSpec(camera, alpha);
            char text[160];
            std::snprintf(text, sizeof text, "the new K of getOptimalNewCameraMatrix with alpha %g: fx %.6g, fy %.6g, cx %.6g, cy %.6g",
                          alpha, undistorted.projection.fx, undistorted.projection.fy, undistorted.projection.cx,
                          undistorted.projection.cy);
            out.push_back({"undistorted-new-k", alpha == 0 ? "alpha 0" : "alpha 1",
                           std::string("consistent if the map was undistorted to ") + text, undistorted, std::nullopt});
        } catch (const Error&) {  // a fisheye past 180°, a panorama: no pinhole holds it
        }
    }
    // Coefficient orders: the file's numbers read in another order.
    const auto reordered = [&](const std::vector<const char*>& asRead, const std::vector<const char*>& meant) {
        LensSpec other = spec;
        for (std::size_t k = 0; k < asRead.size(); ++k) other.params[paramIndex(spec, meant[k])] = spec.params[paramIndex(spec, asRead[k])];
        return other;
    };
    if (spec.model == "opencv") {
        const std::vector<const char*> opencvOrder = {"k1", "k2", "p1", "p2", "k3"};
        const std::vector<const char*> radialFirst = {"k1", "k2", "k3", "p1", "p2"};
        out.push_back({"coefficient-order", "k1 k2 k3 p1 p2 read as k1 k2 p1 p2 k3",
                       "consistent if the five coefficients were written k1 k2 k3 p1 p2 and read in OpenCV's order",
                       withLens(camera, reordered(opencvOrder, radialFirst)), std::nullopt});
        out.push_back({"coefficient-order", "k1 k2 p1 p2 k3 read as k1 k2 k3 p1 p2",
                       "consistent if OpenCV's k1 k2 p1 p2 k3 were read as k1 k2 k3 p1 p2",
                       withLens(camera, reordered(radialFirst, opencvOrder)), std::nullopt});
    }
    if (spec.model == "brown_conrady") {
        const std::vector<const char*> nerfstudioOrder = {"k1", "k2", "k3", "k4", "p1", "p2"};
        const std::vector<const char*> opencvLike = {"k1", "k2", "p1", "p2", "k3", "k4"};
        out.push_back({"coefficient-order", "k1 k2 p1 p2 k3 k4 read as k1 k2 k3 k4 p1 p2",
                       "consistent if OpenCV-ordered coefficients were read in nerfstudio's order",
                       withLens(camera, reordered(opencvLike, nerfstudioOrder)), std::nullopt});
    }
    // Tangential pair exchanged.
    for (const auto& [a, b] : {std::pair{"p1", "p2"}, std::pair{"p0", "p1"}}) {
        const std::size_t ia = paramIndex(spec, a), ib = paramIndex(spec, b);
        if (ia == std::string::npos || ib == std::string::npos || spec.params[ia] == spec.params[ib]) continue;
        LensSpec swapped = spec;
        std::swap(swapped.params[ia], swapped.params[ib]);
        out.push_back({"tangential-swapped", "", std::string("consistent if ") + a + " and " + b +
                                                     " were exchanged (Metashape's P1 is OpenCV's p2)",
                       withLens(camera, swapped), std::nullopt});
        break;
    }
    // Every distortion coefficient negated: those after the model's intrinsics that are not a
    // profile's own parameter (ξ, α, β, ω).
    {
        LensSpec negated = spec;
        std::vector<std::size_t> changed;
        for (std::size_t i = 0; i < info.params.size(); ++i) {
            const std::string name = info.params[i];
            const bool coefficient = (name[0] == 'k' || name[0] == 'p' || name[0] == 's') && name.size() <= 3;
            if (coefficient && spec.params[i] != 0) negated.params[i] = -spec.params[i], changed.push_back(i);
        }
        if (!changed.empty())
            out.push_back({"distortion-signs-flipped", "", "consistent if the distortion's signs were flipped (" +
                                                               coefficientText(negated, changed) + ")",
                           withLens(camera, negated), std::nullopt});
    }
    // A fisheye read as another fisheye with the same K.
    const bool fisheye = lens.seesBehind() || spec.model == "opencv_fisheye" || spec.model == "equisolid" ||
                         spec.model == "thin_prism_fisheye" || spec.model == "fisheye624";
    if (hasK && fisheye) {
        const std::vector<double> k(spec.params.begin(), spec.params.begin() + 4);
        const std::vector<std::pair<const char*, LensSpec>> others = {
            {"equidistant", {"opencv_fisheye", k}},
            {"equisolid", {"equisolid", k}},
            {"stereographic", {"unified", {k[0], k[1], k[2], k[3], 1.0}}},
        };
        for (const auto& [label, other] : others) {
            if (other.model == spec.model && other.params.size() == spec.params.size() && other.params == spec.params) continue;
            if (spec.model == "opencv_fisheye" && std::string(label) == "equidistant" &&
                std::all_of(spec.params.begin() + 4, spec.params.end(), [](double v) { return v == 0; }))
                continue;
            out.push_back({"fisheye-model", label, std::string("consistent if the fisheye was rendered ") + label +
                                                       " (same K) where " + spec.model + " was declared",
                           withLens(camera, other), std::nullopt});
        }
    }
    // The generic mistakes of the catalogue's names that a lens map shows alike: the image flipped,
    // the principal point half a pixel off (COLMAP's corner-based cx, cy taken as OpenCV's) or
    // its coordinates exchanged.
    out.push_back({"y-flip", "", "consistent if the map's rows are read bottom to top (a bottom-left image origin)",
                   std::nullopt, std::nullopt, 1});
    out.push_back({"x-flip", "", "consistent if the map is mirrored left to right", std::nullopt, std::nullopt, 2});
    if (hasK) {
        for (const double shift : {0.5, -0.5}) {
            LensSpec moved = spec;
            moved.params[2] += shift, moved.params[3] += shift;
            out.push_back({"half-pixel", shift > 0 ? "+0.5" : "-0.5",
                           std::string("consistent if the principal point is ") + (shift > 0 ? "half a pixel further" : "half a pixel nearer") +
                               " from the top-left corner (pixel centres counted from 0.5 or from 0)",
                           withLens(camera, moved), std::nullopt});
        }
        if (spec.params[2] != spec.params[3]) {
            LensSpec swapped = spec;
            std::swap(swapped.params[2], swapped.params[3]);
            out.push_back({"cx-cy-swapped", "", "consistent if cx and cy were exchanged", withLens(camera, swapped), std::nullopt});
        }
    }
    // The values taken for the other quantity.
    if (map.quantity == DepthQuantity::EyeZ)
        out.push_back({"distance-as-eye-z", "", "consistent if read as ray distance instead of eye-z", std::nullopt,
                       DepthQuantity::Distance});
    if (map.quantity == DepthQuantity::Distance)
        out.push_back({"eye-z-as-distance", "", "consistent if read as eye-z instead of ray distance", std::nullopt,
                       DepthQuantity::EyeZ});
    return out;
}

Hypothesis judged(const MapVerifier& verifier, const Camera& camera, const DepthMap& map, std::string name,
                  std::string variant, std::string explanation)
{
    Hypothesis h;
    h.name = std::move(name), h.variant = std::move(variant), h.explanation = std::move(explanation);
    const ComparisonReport r = verifier.verify(camera, map).comparison.report;
    h.consistent = r.consistent() && r.bothHit > 0;
    h.unexplained = r.unexplained();
    h.compared = r.bothHit + r.rayOnly + r.rasterOnly;
    return h;
}

}  // namespace

std::optional<Hypothesis> fitRadialDistortion(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    // The lens to fit: the declared one's own k1, k2 (a radial lens keeps its model), else OpenCV's
    // radial terms around the pinhole's K.
    LensSpec start;
    if (const LensModel* lens = camera.lens()) {
        start = lens->spec();
    } else if (camera.spec().projection.type == ProjectionType::Pinhole) {
        const Projection& p = camera.spec().projection;
        start = {"opencv", {p.fx, p.fy, p.cx, p.cy, 0, 0}};
    } else {
        return std::nullopt;
    }
    const std::size_t i1 = paramIndex(start, "k1"), i2 = paramIndex(start, "k2");
    if (i1 == std::string::npos || i2 == std::string::npos) return std::nullopt;
    if (map.quantity != DepthQuantity::EyeZ && map.quantity != DepthQuantity::Distance) return std::nullopt;
    const int W = camera.width(), H = camera.height();
    const Scene& scene = verifier.checker().scene();
    const RayRenderer& rays = verifier.checker().rayRenderer();
    // Samples: a 48×36 grid of pixels where the map holds a depth.
    std::vector<glm::ivec2> samples;
    for (int j = 0; j < 36; ++j)
        for (int i = 0; i < 48; ++i) {
            const int col = int((i + 0.5) * W / 48), row = int((j + 0.5) * H / 36);
            if (kindOfDepthValue(camera, map.quantity, map.value[std::size_t(row) * W + col]) == DepthValueKind::Depth)
                samples.push_back({col, row});
        }
    if (samples.size() < 50) return std::nullopt;
    CameraSpec spec = camera.spec();
    spec.projection.type = ProjectionType::NonLinear;
    spec.projection.near = camera.nearDistance(), spec.projection.far = camera.farDistance();
    // Relative residuals of the map against one traced ray per sample, through k = (k1, k2); a
    // sample whose ray misses or cannot be made counts 0.05, as does any larger residual (edges).
    const auto residuals = [&](const glm::dvec2& k, std::vector<double>& out) -> bool {
        LensSpec lens = start;
        lens.params[i1] = k.x, lens.params[i2] = k.y;
        spec.projection.lens = lens;
        std::optional<Camera> trial;
        try {
            trial.emplace(spec);
        } catch (const Error&) {
            return false;
        }
        out.assign(samples.size(), 0.05);
        tbb::parallel_for(std::size_t(0), samples.size(), [&](std::size_t s) {
            const glm::dvec2 pWindow = windowFromPixelCentre(*trial, samples[s].x, samples[s].y);
            const std::optional<glm::dvec3> dEye = eyeDirectionThroughWindow(*trial, pWindow);
            if (!dEye) return;
            const std::uint32_t hit = rays.primitiveAt(*trial, pWindow);
            if (hit == kNoPrimitive) return;
            const glm::dvec3 eye(trial->worldFromEye[3]), d(trial->worldFromEye * glm::dvec4(*dEye, 0.0));
            const glm::uvec3 t = scene.triangles[hit];
            const glm::dvec3 a(scene.positions[t[0]]), b(scene.positions[t[1]]), c(scene.positions[t[2]]);
            const glm::dvec3 n = glm::cross(b - a, c - a);
            const double distance = glm::dot(n, a - eye) / glm::dot(n, d);
            const double predicted = map.quantity == DepthQuantity::Distance ? distance : distance * trial->eyeZOf(*dEye);
            const double value = map.value[std::size_t(samples[s].y) * W + samples[s].x];
            const double r = (predicted - value) / value;
            out[s] = std::isfinite(r) ? std::clamp(r, -0.05, 0.05) : 0.05;
        });
        return true;
    };
    const auto cost = [](const std::vector<double>& r) {
        double sum = 0;
        for (double v : r) sum += v * v;
        return sum;
    };
    glm::dvec2 k(start.params[i1], start.params[i2]);
    std::vector<double> r;
    if (!residuals(k, r)) return std::nullopt;
    double current = cost(r), lambda = 1e-3;
    const double initial = current;
    for (int iteration = 0; iteration < 40; ++iteration) {
        // The Jacobian by central differences, then a damped Gauss–Newton step.
        std::vector<double> rPlus, rMinus;
        glm::dvec2 columns[2];
        std::vector<double> jacobian[2];
        for (int p = 0; p < 2; ++p) {
            const double h = 1e-5;
            glm::dvec2 kp = k, km = k;
            kp[p] += h, km[p] -= h;
            if (!residuals(kp, rPlus) || !residuals(km, rMinus)) return std::nullopt;
            jacobian[p].resize(r.size());
            for (std::size_t s = 0; s < r.size(); ++s) jacobian[p][s] = (rPlus[s] - rMinus[s]) / (2 * h);
            (void)columns;
        }
        double a00 = 0, a01 = 0, a11 = 0, g0 = 0, g1 = 0;
        for (std::size_t s = 0; s < r.size(); ++s) {
            a00 += jacobian[0][s] * jacobian[0][s], a01 += jacobian[0][s] * jacobian[1][s], a11 += jacobian[1][s] * jacobian[1][s];
            g0 += jacobian[0][s] * r[s], g1 += jacobian[1][s] * r[s];
        }
        bool improved = false;
        for (int tries = 0; tries < 12 && !improved; ++tries) {
            const double d00 = a00 * (1 + lambda), d11 = a11 * (1 + lambda), det = d00 * d11 - a01 * a01;
            if (!(std::abs(det) > 0)) break;
            const glm::dvec2 step((d11 * g0 - a01 * g1) / det, (d00 * g1 - a01 * g0) / det);
            std::vector<double> rNew;
            if (residuals(k - step, rNew) && cost(rNew) < current) {
                k -= step, r = std::move(rNew), current = cost(r), lambda = std::max(lambda / 10, 1e-9), improved = true;
                if (glm::length(step) <= 1e-12 * (1 + glm::length(k))) iteration = 40;
            } else {
                lambda *= 10;
            }
        }
        if (!improved) break;
    }
    if (!(current < 0.5 * initial)) return std::nullopt;  // the fit found nothing the declared lens lacks
    LensSpec fitted = start;
    fitted.params[i1] = k.x, fitted.params[i2] = k.y;
    spec.projection.lens = fitted;
    try {
        const Camera fittedCamera(spec);
        char text[200];
        std::snprintf(text, sizeof text, "consistent with the radial distortion k1 %.6g, k2 %.6g (%s lens with the camera's K)",
                      k.x, k.y, fitted.model.c_str());
        Hypothesis h = judged(verifier, fittedCamera, map, "fitted-radial-distortion", "", text);
        h.fitted = {{"k1", k.x, start.params[i1]}, {"k2", k.y, start.params[i2]}};
        return h;
    } catch (const Error&) {
        return std::nullopt;
    }
}

std::vector<Hypothesis> diagnoseLensMap(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    const std::vector<LensCandidate> candidates = lensCandidates(camera, map);
    std::vector<std::optional<Hypothesis>> judgedOnes(candidates.size());
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
        const LensCandidate& c = candidates[k];
        try {
            DepthMap reread = c.flip ? flipped(map, c.flip) : map;
            if (c.quantity) reread.quantity = *c.quantity;
            const Camera used(c.camera ? *c.camera : camera.spec());
            judgedOnes[k] = judged(verifier, used, reread, c.name, c.variant, c.explanation);
        } catch (const Error&) {  // a variant that is no valid camera is no hypothesis
        }
    });
    std::vector<Hypothesis> out;
    for (auto& h : judgedOnes)
        if (h) out.push_back(std::move(*h));
    if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) { return h.explains(); }))
        if (std::optional<Hypothesis> fit = fitRadialDistortion(verifier, camera, map)) out.push_back(std::move(*fit));
    std::stable_sort(out.begin(), out.end(), [](const Hypothesis& a, const Hypothesis& b) {
        if (a.explains() != b.explains()) return a.explains();
        return a.unexplained < b.unexplained;
    });
    return out;
}

}  // namespace zcheck
