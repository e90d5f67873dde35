// The mistakes of the lens family (lens.h), for maps judged through a lens model's camera — and,
// for a pinhole's map that no linear mistake explains, a lens the camera left out. Each
// hypothesis is one of lens_mistakes.h's mistakes — the camera the renderer really used, the
// quantity it wrote, the image order it stored — under which the map is re-read and judged by a
// full verification (verifyLensMap, or the linear one for a pinhole); the suite injects the same
// definitions. When none explains the map:
//   miss-value, quantum, holes   what the map's values say its reading should have declared
//                             (declared_reading.h: Cycles' 1e10 outside a fisheye's circle, a
//                             millimetre grid, a sensor's holes), each alone and all together;
//   the catalogue's pose mistakes  mistakes.h's re-readings that change the view alone (inverted,
//                             OpenCV/OpenGL axes, a transposed rotation or 4×4, a quaternion's
//                             order, the translation's units, the mesh's up axis), through the lens;
//   fitted-radial-distortion  k1, k2 of a radial lens with the camera's K fitted to the map (rays
//                             traced per sample, Levenberg–Marquardt), then verified in full
#include "verify_estimators.h"

#include "zcheck/declared_reading.h"
#include "zcheck/error.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/lens_mistakes.h"
#include "zcheck/mistakes.h"
#include "zcheck/map_verifier.h"
#include "zcheck/remap.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace zcheck {

namespace {

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

// What the map's values say its reading should have declared, judged through the lens camera:
// each finding alone, then all of them (Diagnosis::judgeDeclaredReadings's rule for any camera).
std::vector<Hypothesis> declaredLensReadings(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    const RenderResult truth = verifier.checker().renderRay(camera);
    ReadingFindings findings = findReading(camera, map, truth);
    Declared found{findings.missValue.has_value(), findings.grid > 0, false};
    {  // holes: the pixels only the truth hits left unexplained once the miss value is read as one
        const VerifyResult run = verifier.verify(camera, declaredReading(map, findings, found));
        findings.holes = std::count(run.comparison.pixelClass.begin(), run.comparison.pixelClass.end(), PixelClass::RayOnly);
        found.holes = findings.holes > 0 && !map.accuracy.allowHoles;
    }
    const std::vector<Declared> readings = found.readingsToTry();
    std::vector<Hypothesis> out(readings.size());
    tbb::parallel_for(std::size_t(0), readings.size(), [&](std::size_t k) {
        out[k] = judged(verifier, camera, declaredReading(map, findings, readings[k]), readings[k].name(), "",
                        "consistent if read as declared: " + describeFindings(findings, readings[k]));
    });
    return out;
}

// The catalogue's re-readings (mistakes.h) that keep the lens, the convention, the map and the
// truth's sampling and change the view alone (the pose's mistakes) or the near and far distances
// alone (clip-planes), through the lens camera.
// Those the lens family has its own form of (the image's flips and shifts, the principal point,
// the quantity) are the lens family's; handedness, a mirrored eye x axis, is its x-flip.
std::vector<LensMistake> poseMistakes(const Camera& camera, const DepthMap& map)
{
    std::vector<LensMistake> out;
    for (const Mistake& mistake : mistakeCatalogue()) {
        if (!mistake.reread || mistake.name == "handedness") continue;
        std::vector<Rereading> readings;
        try {
            readings = mistake.reread(camera, map);
        } catch (const Error&) {
            continue;
        }
        for (const Rereading& r : readings) {
            if (!r.camera || r.map || !r.truthFaults.none()) continue;
            const Projection& p = r.camera->projection;
            const Projection& declared = camera.spec().projection;
            if (p.type != ProjectionType::NonLinear || !(p.lens == declared.lens) ||
                r.camera->convention.name != camera.convention().name || r.camera->width != camera.width() ||
                r.camera->height != camera.height())
                continue;
            if (p.near != declared.near || p.far != declared.far) {  // the planes: then the view kept
                try {
                    if (Camera(*r.camera).eyeFromWorld != camera.eyeFromWorld) continue;
                } catch (const Error&) {
                    continue;
                }
            }
            out.push_back({mistake.name, r.variant, r.explanation, *r.camera, std::nullopt, 0});
        }
    }
    return out;
}

// Each hypothesis ruled out on a 1-in-16 sample first where it is a lens camera's (see
// diagnoseLensMap), else judged in full; none where the variant is no valid camera.
std::vector<Hypothesis> judgedMistakes(const MapVerifier& verifier, const Camera& camera, const DepthMap& map,
                                       const std::vector<LensMistake>& candidates)
{
    std::vector<std::optional<Hypothesis>> judgedOnes(candidates.size());
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
        const LensMistake& c = candidates[k];
        try {
            DepthMap reread = flippedMap(map, c.flip);
            if (c.quantity) reread.quantity = *c.quantity;
            const Camera used(c.camera ? *c.camera : camera.spec());
            // A lens camera's hypothesis is ruled out on a 1-in-16 sample first (verifyLensMap's
            // rule): one leaving a fifth of the sampled pixels unexplained cannot explain the map
            // (explains() allows a tenth, at edges), and most of the catalogue's hypotheses leave
            // most pixels unexplained. A pinhole's (distortion-ignored, undistorted-new-k) is
            // judged by the linear verification, in full: its lens twin (opencv without
            // coefficients) has the same rays but clips at near and far distances where the pinhole
            // clips at planes, and screening through it ruled out true hypotheses where geometry
            // crosses the near plane (builtin:near-crossing).
            constexpr int kStride = 4;
            const LensSample sample = used.lens() ? judgeLensMapOnGrid(verifier.checker(), used, reread, kStride) : LensSample{};
            if (sample.unexplained >= 8 && sample.unexplained * 5 > sample.compared) {
                Hypothesis h;
                h.name = c.name, h.variant = c.variant, h.explanation = c.explanation;
                h.estimated = true;
                h.unexplained = sample.unexplained * kStride * kStride;
                judgedOnes[k] = std::move(h);
                return;
            }
            judgedOnes[k] = judged(verifier, used, reread, c.name, c.variant, c.explanation);
        } catch (const Error&) {  // a variant that is no valid camera is no hypothesis
        }
    });
    std::vector<Hypothesis> out;
    for (auto& h : judgedOnes)
        if (h) out.push_back(std::move(*h));
    return out;
}

}  // namespace

std::optional<Hypothesis> fitRadialDistortion(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
{
    // The lens to fit: the declared one's own k1, k2 (a radial lens keeps its model), else OpenCV's
    // radial terms around the pinhole's K.
    LensSpec start;
    if (const LensModel* lens = camera.lens()) {
        start = lens->spec();  // every parameter, the trailing ones a file may leave out 0 (lens.h)
        start.params.resize(std::max(start.params.size(), lens->info().params.size()), 0.0);
    } else if (camera.spec().projection.type == ProjectionType::Pinhole) {
        const Projection& p = camera.spec().projection;
        start = {"opencv", {p.fx, p.fy, p.cx, p.cy, 0, 0}};
    } else {
        return std::nullopt;
    }
    const std::size_t i1 = lensParamIndex(start, "k1"), i2 = lensParamIndex(start, "k2");
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
            const Scene::Plane plane = scene.worldPlane(hit);
            const double distance = glm::dot(plane.normal, plane.point - eye) / glm::dot(plane.normal, d);
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
    std::vector<Hypothesis> out = judgedMistakes(verifier, camera, map, lensMistakes(camera, map.quantity));
    const auto explained = [&] { return std::any_of(out.begin(), out.end(), [](const Hypothesis& h) { return h.explains(); }); };
    if (!explained()) {
        for (Hypothesis& h : declaredLensReadings(verifier, camera, map)) out.push_back(std::move(h));
        for (Hypothesis& h : judgedMistakes(verifier, camera, map, poseMistakes(camera, map))) out.push_back(std::move(h));
    }
    if (!explained())
        if (std::optional<Hypothesis> fit = fitRadialDistortion(verifier, camera, map)) out.push_back(std::move(*fit));
    std::stable_sort(out.begin(), out.end(), [](const Hypothesis& a, const Hypothesis& b) {
        if (a.explains() != b.explains()) return a.explains();
        return a.unexplained < b.unexplained;
    });
    return out;
}

}  // namespace zcheck
