#include "zcheck/map_verifier.h"

#include "zcheck/declared_reading.h"
#include "zcheck/error.h"
#include "zcheck/fit.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/mistakes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace zcheck {

namespace {

// A hypothesis not judged yet.
Hypothesis hypothesis(std::string name, std::string variant, std::string explanation)
{
    Hypothesis h;
    h.name = std::move(name), h.variant = std::move(variant), h.explanation = std::move(explanation);
    return h;
}

}  // namespace

std::vector<Hypothesis> MapVerifier::diagnose(const Camera& camera, const DepthMap& map) const
{
    requireMapFits(camera, map);
    const Scene& scene = checker_.scene();
    const RayRenderer& rays = checker_.rayRenderer();
    const RenderResult truth = checker_.renderRay(camera);
    // One hypothesis judged against `truthUsed` (the truth through `hypothesisCamera`), the map
    // as re-read.
    auto judgeAgainst = [&](Hypothesis h, const Camera& hypothesisCamera, const DepthMap& hypothesisMap,
                            const RenderResult& truthUsed) {
        // Most hypotheses are plainly wrong: a sample of the pixels that need the surface
        // search proves it without searching them all (screenUnexplained).
        // A hypothesis failing at a few pixels only (at most a tenth of the truth's surface,
        // by the estimate) is compared in full all the same: it may fail only at edges.
        const std::optional<std::int64_t> estimate = screenUnexplained(scene, hypothesisCamera, hypothesisMap, truthUsed, neighbours());
        if (estimate && *estimate * 10 > std::count_if(truthUsed.primitiveId.begin(), truthUsed.primitiveId.end(),
                                                       [](std::uint32_t p) { return p != kNoPrimitive; })) {
            h.unexplained = *estimate, h.estimated = true;
        } else {
            const VerifyResult run = verifyAgainst(scene, hypothesisCamera, hypothesisMap, truthUsed, neighbours());
            // Consistent only where something is compared: a view that sees nothing does not
            // explain a map that holds nothing.
            const ComparisonReport& r = run.comparison.report;
            h.consistent = r.consistent() && r.bothHit > 0, h.unexplained = r.unexplained();
            h.compared = r.bothHit + r.rayOnly + r.rasterOnly;
            if (!h.consistent && !r.depthBias) {
                const EdgeTally edges = tallyEdges(hypothesisCamera, run.truth, run.map, run.comparison);
                h.unexplainedAtEdges = edges.atEdges, h.blendsAtEdges = edges.blends;
            }
        }
        return h;
    };
    // The catalogue's readings, judged side by side (each judgement is parallel inside too;
    // side by side they also overlap each other's serial parts). A reading that changes the
    // camera or the sampling keeps its truth, for the pairs below.
    struct Candidate {
        const Mistake* mistake;
        Rereading reading;
        std::optional<Camera> camera;       // the reading's camera, once built
        std::optional<RenderResult> truth;  // when not the declared camera's
        std::optional<Hypothesis> judged;
        bool readsMapOnly() const { return !reading.camera && reading.truthFaults.none(); }
        const DepthMap& mapOr(const DepthMap& given) const { return reading.map ? *reading.map : given; }
    };
    std::vector<Candidate> candidates;
    for (const Mistake& mistake : mistakeCatalogue())
        if (mistake.reread)
            for (Rereading& reading : mistake.reread(camera, map)) candidates.push_back({&mistake, std::move(reading), {}, {}, {}});
    // A hypothesis a probe ruled out, its count estimated from the probe.
    auto probedOut = [&](Hypothesis h, const Probe& probe) {
        h.unexplained = probe.unexplainedOf(double(camera.width()) * camera.height());
        h.estimated = true;
        return h;
    };
    auto changesCameraOnly = [](const Candidate& c) { return c.camera && c.reading.camera && c.reading.truthFaults.none() && !c.reading.map; };
    tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
        Candidate& c = candidates[k];
        // A variant that is not a valid camera (a near plane behind the eye) is no hypothesis.
        try {
            c.camera.emplace(c.reading.camera ? *c.reading.camera : camera.spec());
            Hypothesis h = hypothesis(c.mistake->name, c.reading.variant, c.reading.explanation);
            // Another camera needs a truth of its own, unless a probe rules it out first: then
            // its count is estimated from the probe (a pair with it is probed in turn below).
            if (changesCameraOnly(c)) {
                const Probe probe = probeAgreement(scene, rays, *c.camera, map);
                if (probe.rulesOut()) {
                    c.judged = probedOut(std::move(h), probe);
                    return;
                }
            }
            if (!c.readsMapOnly()) c.truth = checker_.renderRay(*c.camera, c.reading.truthFaults);
            c.judged = judgeAgainst(std::move(h), *c.camera, c.mapOr(map), c.truth ? *c.truth : truth);
        } catch (const Error&) {
            c.camera.reset(), c.truth.reset();
        }
    });
    std::vector<Hypothesis> out;
    for (const Candidate& c : candidates)
        if (c.judged) out.push_back(*c.judged);
    // The map as declared, when only edge pixels fail: anti-aliased depth if each of them holds
    // a blend of the surfaces either side.
    if (Hypothesis asDeclared = judgeAgainst(hypothesis("", "", ""), camera, map, truth);
        asDeclared.consistentExceptEdges()) {
        const bool blends = asDeclared.blendsAtEdges == asDeclared.unexplainedAtEdges;
        asDeclared.name = blends ? "anti-aliased" : "edge-pixels";
        asDeclared.explanation =
            blends ? "consistent except at edges, whose depths lie between the surfaces either side: anti-aliased or "
                     "resolved multisample depth (keep one sample's depth, or resolve depth with min or max, not an "
                     "average)"
                   : "consistent except at edges";
        out.insert(out.begin(), std::move(asDeclared));  // before readings that only rename the same values
    }
    // What the reading should have declared (declared_reading.h): each finding alone, and all
    // of them together, judged as any hypothesis.
    ReadingFindings findings = findReading(camera, map, truth);
    Declared found;
    found.missValue = findings.missValue.has_value(), found.grid = findings.grid > 0;
    {  // holes: the pixels left unexplained where only the truth hits, once the miss value is read as one
        const VerifyResult run = verifyAgainst(scene, camera, declaredReading(map, findings, found), truth, neighbours());
        findings.holes = std::count(run.comparison.pixelClass.begin(), run.comparison.pixelClass.end(), PixelClass::RayOnly);
        found.holes = findings.holes > 0 && !map.accuracy.allowHoles;
    }
    auto judgeReading = [&](const Declared& use, const DepthMap& read, const std::string& extra) {
        std::string because = describeFindings(findings, use);
        if (!extra.empty()) because += (because.empty() ? "" : "; ") + extra;
        return judgeAgainst(hypothesis(use.name(), "", "consistent if read as declared: " + because), camera, read, truth);
    };
    {
        std::vector<Declared> readings;  // each finding alone, then all of them
        for (const auto member : {&Declared::missValue, &Declared::grid, &Declared::holes})
            if (found.*member) {
                Declared alone;
                alone.*member = true;
                readings.push_back(alone);
            }
        if (readings.size() > 1) readings.push_back(found);
        std::vector<Hypothesis> judged(readings.size());
        tbb::parallel_for(std::size_t(0), readings.size(), [&](std::size_t k) {
            judged[k] = judgeReading(readings[k], declaredReading(map, findings, readings[k]), "");
        });
        out.insert(out.end(), judged.begin(), judged.end());
    }
    // The continuous families, fitted side by side, each confirmed by a full comparison; not
    // needed where a mistake of the catalogue explains the map whole.
    // `reading` (a catalogue mistake that re-reads the map, or none) names the map fitted.
    const TruthRender render = [&](const Camera& c, const RayFaults& faults) { return checker_.renderRay(c, faults); };
    auto fitEach = [&](const DepthMap& fittedMap, const Candidate* reading) {
        const std::vector<FitFamily> families = fitFamilies(camera, fittedMap);
        std::vector<std::optional<Hypothesis>> fitted(families.size());
        tbb::parallel_for(std::size_t(0), families.size(), [&](std::size_t k) {
            try {
                const FitResult fit = fitDeparture(scene, camera, fittedMap, truth, families[k], render);
                if (fit.samples == 0) return;  // too few pixels on one plane to fit anything
                // After a re-reading, only a fit that explains much of the map is worth its
                // confirmation (a render and a comparison): a consistent one leaves residuals at
                // the map's rounding, far under half those under the declared camera.
                if (reading && !(fit.residual <= 0.5 * fit.initialResidual)) return;
                const Camera fittedCamera(departedCameraSpec(camera, fit.departure));
                Hypothesis h = reading ? hypothesis(reading->mistake->name + " + " + toString(families[k]), reading->reading.variant,
                                                    reading->reading.explanation + ", and with " + describeFit(camera, fittedMap, fit))
                                       : hypothesis(toString(families[k]), "", "consistent with " + describeFit(camera, fittedMap, fit));
                h.fitted = fittedValues(camera, fittedMap, fit);
                fitted[k] = judgeAgainst(std::move(h), fittedCamera, departedReading(camera, fittedMap, fit.departure),
                                         checker_.renderRay(fittedCamera));
            } catch (const Error&) {
            }
        });
        for (auto& h : fitted)
            if (h) out.push_back(std::move(*h));
    };
    if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) { return h.consistent; })) fitEach(map, nullptr);
    const bool explained = std::any_of(out.begin(), out.end(), [](const Hypothesis& h) {
        return h.consistent || h.consistentExceptEdges();
    });
    // Two mistakes at once (flipped and reversed, say), when no single one, no fit and no
    // edge-only reading explains the map: a reading of the map composed with a reading of the
    // map or of the camera, judged against the truth already rendered for the latter; and two
    // camera mistakes, below.
    auto pairHypothesis = [&](const Candidate& first, const Candidate& second) {
        std::string also = second.reading.explanation;
        if (also.rfind("consistent if ", 0) == 0) also = also.substr(14);
        return hypothesis(first.mistake->name + " + " + second.mistake->name, second.reading.variant,
                          first.reading.explanation + ", and " + also);
    };
    if (!explained) {
        std::vector<std::pair<std::size_t, std::size_t>> pairs;
        auto changesQuantity = [&](const Candidate& c) { return c.reading.map && c.reading.map->quantity != map.quantity; };
        for (std::size_t a = 0; a < candidates.size(); ++a)
            for (std::size_t b = 0; b < candidates.size(); ++b) {
                const Candidate &first = candidates[a], &second = candidates[b];
                if (!first.camera || !second.camera || first.mistake == second.mistake || !first.readsMapOnly() ||
                    first.mistake->alone || second.mistake->alone)
                    continue;
                if (second.readsMapOnly() && (b <= a || (changesQuantity(first) && changesQuantity(second)))) continue;
                pairs.emplace_back(a, b);
            }
        // The first re-reads the map; the second then re-reads that, or changes the camera.
        auto mapOfPair = [&](const Candidate& first, const Candidate& second) -> std::optional<DepthMap> {
            const DepthMap& firstMap = first.mapOr(map);
            std::vector<Rereading> again = second.mistake->reread(camera, firstMap);
            const auto same = std::find_if(again.begin(), again.end(), [&](const Rereading& r) { return r.variant == second.reading.variant; });
            if (same == again.end()) return std::nullopt;
            return same->map ? *same->map : firstMap;
        };
        // A pair whose camera the catalogue's probe ruled out (it has no truth yet) is probed
        // itself; only those it keeps get the truth rendered, once per camera.
        std::vector<std::optional<Hypothesis>> paired(pairs.size());
        std::vector<char> kept(pairs.size(), 1);
        tbb::parallel_for(std::size_t(0), pairs.size(), [&](std::size_t k) {
            const Candidate &first = candidates[pairs[k].first], &second = candidates[pairs[k].second];
            if (second.readsMapOnly() || second.truth) return;
            try {
                const std::optional<DepthMap> both = mapOfPair(first, second);
                if (!both) return;
                const Probe probe = probeAgreement(scene, rays, *second.camera, *both);
                if (!probe.rulesOut()) return;
                kept[k] = 0;
                paired[k] = probedOut(pairHypothesis(first, second), probe);
            } catch (const Error&) {
                kept[k] = 0;
            }
        });
        std::vector<std::size_t> untraced;
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            const std::size_t b = pairs[k].second;
            if (kept[k] && !candidates[b].readsMapOnly() && !candidates[b].truth &&
                std::find(untraced.begin(), untraced.end(), b) == untraced.end())
                untraced.push_back(b);
        }
        tbb::parallel_for(std::size_t(0), untraced.size(), [&](std::size_t k) {
            Candidate& c = candidates[untraced[k]];
            try {
                c.truth = checker_.renderRay(*c.camera, c.reading.truthFaults);
            } catch (const Error&) {
            }
        });
        tbb::parallel_for(std::size_t(0), pairs.size(), [&](std::size_t k) {
            const Candidate &first = candidates[pairs[k].first], &second = candidates[pairs[k].second];
            if (!kept[k] || (!second.readsMapOnly() && !second.truth)) return;  // probed out, or no truth
            try {
                if (const std::optional<DepthMap> both = mapOfPair(first, second))
                    paired[k] = judgeAgainst(pairHypothesis(first, second), *second.camera, *both, second.truth ? *second.truth : truth);
            } catch (const Error&) {
            }
        });
        for (auto& h : paired)
            if (h) out.push_back(std::move(*h));
        // Two camera mistakes (a reversed-Z renderer with a left-handed view, say): the second
        // applied to the first's camera. A truth for each of a few hundred cameras would cost
        // seconds; a grid of single rays (probeAgreement) rules out almost all of them first,
        // and a camera that two orders of the same pair both make is judged once.
        struct CameraPair {
            std::size_t first, second;
            std::optional<Camera> camera;
        };
        std::vector<CameraPair> cameraPairs;
        for (std::size_t a = 0; a < candidates.size(); ++a)
            for (std::size_t b = 0; b < candidates.size(); ++b)
                if (candidates[a].mistake != candidates[b].mistake && changesCameraOnly(candidates[a]) && changesCameraOnly(candidates[b]))
                    cameraPairs.push_back({a, b, {}});
        tbb::parallel_for(std::size_t(0), cameraPairs.size(), [&](std::size_t k) {
            CameraPair& pair = cameraPairs[k];
            const Candidate& second = candidates[pair.second];
            try {
                for (const Rereading& r : second.mistake->reread(*candidates[pair.first].camera, map))
                    if (r.variant == second.reading.variant && r.camera) {
                        Camera composed(*r.camera);
                        if (!probeAgreement(scene, rays, composed, map).rulesOut()) pair.camera.emplace(std::move(composed));
                    }
            } catch (const Error&) {
            }
        });
        std::vector<std::size_t> survivors;
        for (std::size_t k = 0; k < cameraPairs.size(); ++k) {
            const Camera* c = cameraPairs[k].camera ? &*cameraPairs[k].camera : nullptr;
            if (c && std::none_of(survivors.begin(), survivors.end(), [&](std::size_t j) {
                    const Camera& other = *cameraPairs[j].camera;
                    return other.worldFromClip == c->worldFromClip && other.windowFromNdc == c->windowFromNdc &&
                           other.depth().reversed == c->depth().reversed;
                }))
                survivors.push_back(k);
        }
        std::vector<std::optional<Hypothesis>> pairedCameras(survivors.size());
        tbb::parallel_for(std::size_t(0), survivors.size(), [&](std::size_t k) {
            const CameraPair& pair = cameraPairs[survivors[k]];
            try {
                pairedCameras[k] = judgeAgainst(pairHypothesis(candidates[pair.first], candidates[pair.second]), *pair.camera, map,
                                                checker_.renderRay(*pair.camera));
            } catch (const Error&) {
            }
        });
        for (auto& h : pairedCameras)
            if (h) out.push_back(std::move(*h));
        // A re-reading of the map and a fitted departure (a flipped map of one MSAA sample, say),
        // when no pair explains it either: the fits run again on the map as the re-reading
        // reads it that comes closest to the truth where the truth is one plane (medianResidual),
        // if that is under half of how close the map as declared comes — a re-reading that is
        // half the answer leaves only the departure's own small residuals.
        if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) { return h.consistent || h.consistentExceptEdges(); })) {
            std::vector<double> residual(candidates.size(), INFINITY);
            tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
                const Candidate& c = candidates[k];
                if (c.camera && c.readsMapOnly() && c.reading.map) residual[k] = medianResidual(scene, camera, *c.reading.map, truth);
            });
            const auto closest = std::min_element(residual.begin(), residual.end());
            if (closest != residual.end() && *closest < 0.5 * medianResidual(scene, camera, map, truth)) {
                const Candidate& reading = candidates[std::size_t(closest - residual.begin())];
                fitEach(*reading.reading.map, &reading);
            }
        }
    }
    // A stated accuracy, last, and only where no convention explains the map (a uniform offset,
    // which the depth-scale fit measures, may be the map's stated accuracy): the tolerance that
    // would accept the map as read with the findings above.
    if (std::none_of(out.begin(), out.end(), [](const Hypothesis& h) {
            return (h.consistent || h.consistentExceptEdges()) && h.name != "depth-scale";
        })) {
        const DepthMap read = declaredReading(map, findings, found);
        if (const std::optional<MapAccuracy> accuracy = toleranceFinding(camera, read, truth)) {
            DepthMap declared = read;
            declared.accuracy = *accuracy;
            const bool relative = accuracy->relative > map.accuracy.relative;  // else absolute (toleranceFinding)
            const double value = relative ? accuracy->relative : accuracy->absolute;
            const std::string option = std::string(relative ? "--rel-tolerance " : "--abs-tolerance ") + formatNumber(value);
            const std::string within = "±" + formatNumber(value) + " of the truth" + (relative ? " (relative)" : "");
            Hypothesis h = judgeReading(found, declared,
                                        "its values lie within " + within + " everywhere: pass " + option +
                                            " if your renderer or sensor is good only to that (a tolerance is for "
                                            "accuracy, never for a convention mistake)");
            h.name = h.name.empty() ? "tolerance" : h.name + " + tolerance";
            h.fitted.push_back({relative ? "rel_tolerance" : "abs_tolerance", value,
                                relative ? map.accuracy.relative : map.accuracy.absolute});
            out.push_back(std::move(h));
        }
    }
    // A map with no surface at all, as read, is evidence for nothing: say so first.
    const bool anySurface = !explained && [&] {
        for (int row = 0; row < map.height; ++row)
            for (int col = 0; col < map.width; ++col)
                if (kindOfDepthValue(camera, map.quantity, map.value[std::size_t(row) * map.width + col]) != DepthValueKind::Miss)
                    return true;
        return false;
    }();
    if (!explained && !anySurface)
        out.insert(out.begin(), hypothesis("empty-map", "",
                                           "the map holds no surface as read: every value is a miss (check --quantity, "
                                           "--channel, --miss and --scale)"));
    std::stable_sort(out.begin(), out.end(), [](const Hypothesis& a, const Hypothesis& b) {
        if (a.consistent != b.consistent) return a.consistent;
        if (a.consistentExceptEdges() != b.consistentExceptEdges()) return a.consistentExceptEdges();
        return a.unexplained < b.unexplained;
    });
    return out;
}

}  // namespace zcheck
