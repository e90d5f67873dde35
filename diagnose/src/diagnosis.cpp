#include "zcheck/map_verifier.h"

#include "verify_estimators.h"
#include "zcheck/declared_reading.h"
#include "zcheck/error.h"
#include "zcheck/fit.h"
#include "zcheck/inverse_projection.h"
#include "zcheck/mistakes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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


// One reading of the catalogue (a mistake, one of its variants) as the diagnosis holds it. A
// reading that changes the camera or the sampling keeps its truth, for the pairs.
struct Candidate {
    const Mistake* mistake;
    Rereading reading;
    std::optional<Camera> camera;       // the reading's camera, once built
    std::optional<RenderResult> truth;  // when not the declared camera's
    std::optional<Hypothesis> judged;
    bool readsMapOnly() const { return !reading.camera && reading.truthFaults.none(); }
    bool changesCameraOnly() const { return camera && reading.camera && reading.truthFaults.none() && !reading.map; }
    const DepthMap& mapOr(const DepthMap& given) const { return reading.map ? *reading.map : given; }
};

// One diagnosis of one map through one camera: MapVerifier::diagnose's steps, taken in run()'s
// order, each adding hypotheses to the list that rank() orders last. The later steps run only
// while nothing explains the map yet; every hypothesis is judged by a full comparison (judge)
// or ruled out by an estimate.
class Diagnosis {
public:
    // Renders the declared camera's truth; `map` fits the camera (requireMapFits).
    Diagnosis(const MapVerifier& verifier, const Camera& camera, const DepthMap& map)
        : verifier_(verifier), checker_(verifier.checker()), scene_(checker_.scene()), camera_(camera), map_(map),
          truth_(checker_.renderRay(camera))
    {
    }

    std::vector<Hypothesis> run()
    {
        judgeCatalogue();
        nameEdgeFailures();
        judgeDeclaredReadings();
        if (std::none_of(out_.begin(), out_.end(), [](const Hypothesis& h) { return h.consistent; }))
            fitDepartures(map_, nullptr);
        // What the map's values say it should have declared (its miss value, say) and a departure
        // at once: Eevee's 65504 where nothing is hit and its Z pass 3.6·10⁻⁴ short.
        if (!anyExplains() && found_.any()) {
            const Declared alone{found_.missValue, found_.grid, false};
            if (alone.any()) {
                const ReadingLabel label{alone.name(), "", "consistent if read as declared: " + describeFindings(findings_, alone)};
                fitDepartures(declaredReading(map_, findings_, alone), &label);
            }
        }
        const bool explained = anyExplains();
        if (!explained) {
            judgeReadingPairs();
            judgeCameraPairs();
            if (!anyExplains()) fitAfterClosestReading();
            // Last: a lens the camera left out (a map made through a distorted camera).
            if (!anyExplains())
                if (std::optional<Hypothesis> lens = fitRadialDistortion(verifier_, camera_, map_)) out_.push_back(std::move(*lens));
        }
        suggestTolerance();
        if (!explained) flagEmptyMap();
        rank();
        return std::move(out_);
    }

private:
    // The catalogue's readings, judged side by side (each judgement is parallel inside too;
    // side by side they also overlap each other's serial parts).
    void judgeCatalogue();
    // The map as declared, when only edge pixels fail: anti-aliased depth if each of them holds
    // a blend of the surfaces either side.
    void nameEdgeFailures();
    // What the reading should have declared (declared_reading.h): each finding alone, and all
    // of them together, judged as any hypothesis.
    void judgeDeclaredReadings();
    // The continuous families (fit.h), fitted side by side, each confirmed by a full comparison;
    // not needed where a mistake of the catalogue explains the map whole. `reading` (a
    // catalogue reading of the map, or none) names the map fitted.
    // A re-reading's name, variant and explanation, for the hypotheses made on top of it.
    struct ReadingLabel {
        std::string name, variant, explanation;
    };
    void fitDepartures(const DepthMap& fittedMap, const ReadingLabel* reading);
    // Two mistakes at once (flipped and reversed, say), when no single one, no fit and no
    // edge-only reading explains the map: a reading of the map composed with a reading of the
    // map or of the camera, judged against the truth rendered for the latter.
    void judgeReadingPairs();
    // Two camera mistakes (a reversed-Z renderer with a left-handed view, say): the second
    // applied to the first's camera.
    void judgeCameraPairs();
    // A re-reading of the map and a fitted departure (a flipped map of one MSAA sample, say),
    // when no pair explains it either.
    void fitAfterClosestReading();
    // A stated accuracy, last, and only where no convention explains the map.
    void suggestTolerance();
    // A map with no surface at all, as read, is evidence for nothing: said first.
    void flagEmptyMap();
    // The consistent first, then those failing only at edges, then by unexplained pixels; ties
    // in the steps' order.
    void rank();

    bool anyExplains() const { return std::any_of(out_.begin(), out_.end(), [](const Hypothesis& h) { return h.explains(); }); }
    // One hypothesis judged against `truthUsed` (the truth through `hypothesisCamera`), the map
    // as re-read.
    Hypothesis judge(Hypothesis h, const Camera& hypothesisCamera, const DepthMap& hypothesisMap,
                     const RenderResult& truthUsed) const;
    // A hypothesis a probe ruled out, its count estimated from the probe.
    Hypothesis probedOut(Hypothesis h, const Probe& probe) const;
    // The map read with the findings `use` declares (`read`), judged; `extra` adds to its explanation.
    Hypothesis judgeReading(const Declared& use, const DepthMap& read, const std::string& extra) const;
    // The hypothesis that both readings were made, the first's explanation then the second's.
    static Hypothesis pairHypothesis(const Candidate& first, const Candidate& second);

    const MapVerifier& verifier_;
    const Checker& checker_;
    const Scene& scene_;
    const Camera& camera_;
    const DepthMap& map_;
    const RenderResult truth_;           // through the declared camera
    std::vector<Candidate> candidates_;  // the catalogue's readings (judgeCatalogue)
    ReadingFindings findings_;           // what the map's values say was not declared (judgeDeclaredReadings)
    Declared found_;                     // which of them it holds
    std::vector<Hypothesis> out_;
};

Hypothesis Diagnosis::judge(Hypothesis h, const Camera& hypothesisCamera, const DepthMap& hypothesisMap,
                            const RenderResult& truthUsed) const
{
    // Most hypotheses are plainly wrong: a sample of the pixels that need the surface
    // search proves it without searching them all (screenUnexplained).
    // A hypothesis failing at a few pixels only (at most a tenth of the truth's surface,
    // by the estimate) is compared in full all the same: it may fail only at edges.
    const std::optional<std::int64_t> estimate =
        screenUnexplained(scene_, hypothesisCamera, hypothesisMap, truthUsed, verifier_.neighbours());
    if (estimate && *estimate * 10 > std::count_if(truthUsed.primitiveId.begin(), truthUsed.primitiveId.end(),
                                                   [](std::uint32_t p) { return p != kNoPrimitive; })) {
        h.unexplained = *estimate, h.estimated = true;
    } else {
        const VerifyResult run = verifyAgainst(scene_, hypothesisCamera, hypothesisMap, truthUsed, verifier_.neighbours());
        // Consistent only where something is compared: a view that sees nothing does not
        // explain a map that holds nothing.
        const ComparisonReport& r = run.comparison.report;
        h.consistent = r.consistent() && r.bothHit > 0, h.unexplained = r.unexplained();
        h.compared = r.bothHit + r.rayOnly + r.rasterOnly;
        // A declaration the map's errors refuse as a whole (a bias it would absorb) explains none
        // of its pixels: such a reading is never offered, not even as the closest.
        if (!r.declaredAccuracyRefused.empty()) h.unexplained = std::max(h.unexplained, h.compared);
        if (!h.consistent && !r.depthBias) {
            const EdgeTally edges = tallyEdges(hypothesisCamera, run.truth, run.map, run.comparison);
            h.unexplainedAtEdges = edges.atEdges, h.blendsAtEdges = edges.blends;
        }
    }
    return h;
}

Hypothesis Diagnosis::probedOut(Hypothesis h, const Probe& probe) const
{
    h.unexplained = probe.unexplainedOf(double(camera_.width()) * camera_.height());
    h.estimated = true;
    return h;
}

Hypothesis Diagnosis::judgeReading(const Declared& use, const DepthMap& read, const std::string& extra) const
{
    std::string because = describeFindings(findings_, use);
    if (!extra.empty()) because += (because.empty() ? "" : "; ") + extra;
    return judge(hypothesis(use.name(), "", "consistent if read as declared: " + because), camera_, read, truth_);
}

Hypothesis Diagnosis::pairHypothesis(const Candidate& first, const Candidate& second)
{
    std::string also = second.reading.explanation;
    if (also.rfind("consistent if ", 0) == 0) also = also.substr(14);
    return hypothesis(first.mistake->name + " + " + second.mistake->name, second.reading.variant,
                      first.reading.explanation + ", and " + also);
}

void Diagnosis::judgeCatalogue()
{
    for (const Mistake& mistake : mistakeCatalogue())
        if (mistake.reread)
            for (Rereading& reading : mistake.reread(camera_, map_)) candidates_.push_back({&mistake, std::move(reading), {}, {}, {}});
    tbb::parallel_for(std::size_t(0), candidates_.size(), [&](std::size_t k) {
        Candidate& c = candidates_[k];
        // A variant that is not a valid camera (a near plane behind the eye) is no hypothesis.
        try {
            c.camera.emplace(c.reading.camera ? *c.reading.camera : camera_.spec());
            Hypothesis h = hypothesis(c.mistake->name, c.reading.variant, c.reading.explanation);
            // Another camera needs a truth of its own, unless a probe rules it out first: then
            // its count is estimated from the probe (a pair with it is probed in turn, judgeReadingPairs).
            if (c.changesCameraOnly()) {
                const Probe probe = probeAgreement(scene_, checker_.rayRenderer(), *c.camera, map_);
                if (probe.rulesOut()) {
                    c.judged = probedOut(std::move(h), probe);
                    return;
                }
            }
            if (!c.readsMapOnly()) c.truth = checker_.renderRay(*c.camera, c.reading.truthFaults);
            c.judged = judge(std::move(h), *c.camera, c.mapOr(map_), c.truth ? *c.truth : truth_);
        } catch (const Error&) {
            c.camera.reset(), c.truth.reset();
        }
    });
    for (const Candidate& c : candidates_)
        if (c.judged) out_.push_back(*c.judged);
}

void Diagnosis::nameEdgeFailures()
{
    Hypothesis asDeclared = judge(hypothesis("", "", ""), camera_, map_, truth_);
    if (!asDeclared.consistentExceptEdges()) return;
    const bool blends = asDeclared.blendsAtEdges == asDeclared.unexplainedAtEdges;
    asDeclared.name = blends ? "anti-aliased" : "edge-pixels";
    asDeclared.explanation =
        blends ? "consistent except at edges, whose depths lie between the surfaces either side: anti-aliased or "
                 "resolved multisample depth (keep one sample's depth, or resolve depth with min or max, not an "
                 "average)"
               : "consistent except at edges";
    out_.insert(out_.begin(), std::move(asDeclared));  // before readings that only rename the same values
}

void Diagnosis::judgeDeclaredReadings()
{
    findings_ = findReading(camera_, map_, truth_);
    found_.missValue = findings_.missValue.has_value(), found_.grid = findings_.grid > 0;
    {  // holes: the pixels left unexplained where only the truth hits, once the miss value is read as one
        const VerifyResult run =
            verifyAgainst(scene_, camera_, declaredReading(map_, findings_, found_), truth_, verifier_.neighbours());
        findings_.holes = std::count(run.comparison.pixelClass.begin(), run.comparison.pixelClass.end(), PixelClass::RayOnly);
        found_.holes = findings_.holes > 0 && !map_.accuracy.allowHoles;
    }
    const std::vector<Declared> readings = found_.readingsToTry();
    std::vector<Hypothesis> judged(readings.size());
    tbb::parallel_for(std::size_t(0), readings.size(), [&](std::size_t k) {
        judged[k] = judgeReading(readings[k], declaredReading(map_, findings_, readings[k]), "");
    });
    out_.insert(out_.end(), judged.begin(), judged.end());
}

void Diagnosis::fitDepartures(const DepthMap& fittedMap, const ReadingLabel* reading)
{
    const TruthRender render = [&](const Camera& c, const RayFaults& faults) { return checker_.renderRay(c, faults); };
    const std::vector<FitFamily> families = fitFamilies(camera_, fittedMap);
    std::vector<std::optional<Hypothesis>> fitted(families.size());
    tbb::parallel_for(std::size_t(0), families.size(), [&](std::size_t k) {
        try {
            const FitResult fit = fitDeparture(scene_, camera_, fittedMap, truth_, families[k], render);
            if (fit.samples == 0) return;  // too few pixels on one plane to fit anything
            // After a re-reading, only a fit that explains much of the map is worth its
            // confirmation (a render and a comparison): a consistent one leaves residuals at
            // the map's rounding, far under half those under the declared camera.
            if (reading && !(fit.residual <= 0.5 * fit.initialResidual)) return;
            const Camera fittedCamera(departedCameraSpec(camera_, fit.departure));
            Hypothesis h = reading ? hypothesis(reading->name + " + " + toString(families[k]), reading->variant,
                                                reading->explanation + ", and with " + describeFit(camera_, fittedMap, fit))
                                   : hypothesis(toString(families[k]), "", "consistent with " + describeFit(camera_, fittedMap, fit));
            h.fitted = fittedValues(camera_, fittedMap, fit);
            fitted[k] = judge(std::move(h), fittedCamera, departedReading(camera_, fittedMap, fit.departure),
                              checker_.renderRay(fittedCamera));
        } catch (const Error&) {
        }
    });
    for (auto& h : fitted)
        if (h) out_.push_back(std::move(*h));
}

void Diagnosis::judgeReadingPairs()
{
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    auto changesQuantity = [&](const Candidate& c) { return c.reading.map && c.reading.map->quantity != map_.quantity; };
    for (std::size_t a = 0; a < candidates_.size(); ++a)
        for (std::size_t b = 0; b < candidates_.size(); ++b) {
            const Candidate &first = candidates_[a], &second = candidates_[b];
            if (!first.camera || !second.camera || first.mistake == second.mistake || !first.readsMapOnly() ||
                first.mistake->alone || second.mistake->alone)
                continue;
            if (second.readsMapOnly() && (b <= a || (changesQuantity(first) && changesQuantity(second)))) continue;
            pairs.emplace_back(a, b);
        }
    // The first re-reads the map; the second then re-reads that, or changes the camera.
    auto mapOfPair = [&](const Candidate& first, const Candidate& second) -> std::optional<DepthMap> {
        const DepthMap& firstMap = first.mapOr(map_);
        std::vector<Rereading> again = second.mistake->reread(camera_, firstMap);
        const auto same = std::find_if(again.begin(), again.end(), [&](const Rereading& r) { return r.variant == second.reading.variant; });
        if (same == again.end()) return std::nullopt;
        return same->map ? *same->map : firstMap;
    };
    // A pair whose camera the catalogue's probe ruled out (it has no truth yet) is probed
    // itself; only those it keeps get the truth rendered, once per camera.
    std::vector<std::optional<Hypothesis>> paired(pairs.size());
    std::vector<char> kept(pairs.size(), 1);
    tbb::parallel_for(std::size_t(0), pairs.size(), [&](std::size_t k) {
        const Candidate &first = candidates_[pairs[k].first], &second = candidates_[pairs[k].second];
        if (second.readsMapOnly() || second.truth) return;
        try {
            const std::optional<DepthMap> both = mapOfPair(first, second);
            if (!both) return;
            const Probe probe = probeAgreement(scene_, checker_.rayRenderer(), *second.camera, *both);
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
        if (kept[k] && !candidates_[b].readsMapOnly() && !candidates_[b].truth &&
            std::find(untraced.begin(), untraced.end(), b) == untraced.end())
            untraced.push_back(b);
    }
    tbb::parallel_for(std::size_t(0), untraced.size(), [&](std::size_t k) {
        Candidate& c = candidates_[untraced[k]];
        try {
            c.truth = checker_.renderRay(*c.camera, c.reading.truthFaults);
        } catch (const Error&) {
        }
    });
    tbb::parallel_for(std::size_t(0), pairs.size(), [&](std::size_t k) {
        const Candidate &first = candidates_[pairs[k].first], &second = candidates_[pairs[k].second];
        if (!kept[k] || (!second.readsMapOnly() && !second.truth)) return;  // probed out, or no truth
        try {
            if (const std::optional<DepthMap> both = mapOfPair(first, second))
                paired[k] = judge(pairHypothesis(first, second), *second.camera, *both, second.truth ? *second.truth : truth_);
        } catch (const Error&) {
        }
    });
    for (auto& h : paired)
        if (h) out_.push_back(std::move(*h));
}

void Diagnosis::judgeCameraPairs()
{
    // A truth for each of a few hundred cameras would cost seconds; a grid of single rays
    // (probeAgreement) rules out almost all of them first, and a camera that two orders of the
    // same pair both make is judged once.
    struct CameraPair {
        std::size_t first, second;
        std::optional<Camera> camera;
    };
    std::vector<CameraPair> cameraPairs;
    for (std::size_t a = 0; a < candidates_.size(); ++a)
        for (std::size_t b = 0; b < candidates_.size(); ++b)
            if (candidates_[a].mistake != candidates_[b].mistake && candidates_[a].changesCameraOnly() &&
                candidates_[b].changesCameraOnly())
                cameraPairs.push_back({a, b, {}});
    tbb::parallel_for(std::size_t(0), cameraPairs.size(), [&](std::size_t k) {
        CameraPair& pair = cameraPairs[k];
        const Candidate& second = candidates_[pair.second];
        try {
            for (const Rereading& r : second.mistake->reread(*candidates_[pair.first].camera, map_))
                if (r.variant == second.reading.variant && r.camera) {
                    Camera composed(*r.camera);
                    if (!probeAgreement(scene_, checker_.rayRenderer(), composed, map_).rulesOut())
                        pair.camera.emplace(std::move(composed));
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
            pairedCameras[k] = judge(pairHypothesis(candidates_[pair.first], candidates_[pair.second]), *pair.camera, map_,
                                     checker_.renderRay(*pair.camera));
        } catch (const Error&) {
        }
    });
    for (auto& h : pairedCameras)
        if (h) out_.push_back(std::move(*h));
}

void Diagnosis::fitAfterClosestReading()
{
    // The fits run again on the map as the re-reading reads it that comes closest to the truth
    // where the truth is one plane (medianResidual), if that is under half of how close the map
    // as declared comes — a re-reading that is half the answer leaves only the departure's own
    // small residuals.
    std::vector<double> residual(candidates_.size(), INFINITY);
    tbb::parallel_for(std::size_t(0), candidates_.size(), [&](std::size_t k) {
        const Candidate& c = candidates_[k];
        if (c.camera && c.readsMapOnly() && c.reading.map) residual[k] = medianResidual(scene_, camera_, *c.reading.map, truth_);
    });
    const auto closest = std::min_element(residual.begin(), residual.end());
    if (closest != residual.end() && *closest < 0.5 * medianResidual(scene_, camera_, map_, truth_)) {
        const Candidate& reading = candidates_[std::size_t(closest - residual.begin())];
        const ReadingLabel label{reading.mistake->name, reading.reading.variant, reading.reading.explanation};
        fitDepartures(*reading.reading.map, &label);
    }
}

void Diagnosis::suggestTolerance()
{
    // Only where no convention explains the map (a uniform offset, which the depth-scale fit
    // measures, may be the map's stated accuracy): the tolerance that would accept the map as
    // read with the findings of judgeDeclaredReadings.
    if (std::any_of(out_.begin(), out_.end(), [](const Hypothesis& h) { return h.explains() && h.name != "depth-scale"; }))
        return;
    const DepthMap read = declaredReading(map_, findings_, found_);
    if (const std::optional<NoiseFinding> noise = noiseFinding(camera_, read, truth_)) {
        DepthMap declared = read;
        declared.accuracy.noise = noise->model;
        auto sigma = [&](double z) {
            char text[64];
            std::snprintf(text, sizeof text, "%.3g at %.3g", noise->model.sigma(z), z);
            return std::string(text);
        };
        Hypothesis h = judgeReading(
            found_, declared,
            "its errors are noise (unbiased, uncorrelated from pixel to pixel) with σ from " + sigma(noise->zNear) +
                " to " + sigma(noise->zFar) + " (map units, z the map's value): pass --noise-model '" +
                noise->model.text() + "' if that is your sensor's noise (each pixel may be off by 6σ(z); a noise model is "
                "for noise, never for a convention mistake)");
        h.name = h.name.empty() ? "noise" : h.name + " + noise";
        h.fitted.push_back({"noise_a", noise->model.a, map_.accuracy.noise.a});
        h.fitted.push_back({"noise_b", noise->model.b, map_.accuracy.noise.b});
        const bool accepted = h.consistent;
        out_.push_back(std::move(h));
        if (accepted) return;
    }
    const std::optional<MapAccuracy> accuracy = toleranceFinding(camera_, read, truth_);
    if (!accuracy) return;
    DepthMap declared = read;
    declared.accuracy = *accuracy;
    const bool relative = accuracy->relative > map_.accuracy.relative;  // else absolute (toleranceFinding)
    const double value = relative ? accuracy->relative : accuracy->absolute;
    const std::string option = std::string(relative ? "--rel-tolerance " : "--abs-tolerance ") + formatNumber(value);
    const std::string within = "±" + formatNumber(value) + " of the truth" + (relative ? " (relative)" : "");
    Hypothesis h = judgeReading(found_, declared,
                                "its values lie within " + within + " everywhere: pass " + option +
                                    " if your renderer or sensor is good only to that (a tolerance is for "
                                    "accuracy, never for a convention mistake)");
    h.name = h.name.empty() ? "tolerance" : h.name + " + tolerance";
    h.fitted.push_back({relative ? "rel_tolerance" : "abs_tolerance", value,
                        relative ? map_.accuracy.relative : map_.accuracy.absolute});
    out_.push_back(std::move(h));
}

void Diagnosis::flagEmptyMap()
{
    for (int row = 0; row < map_.height; ++row)
        for (int col = 0; col < map_.width; ++col)
            if (kindOfDepthValue(camera_, map_.quantity, map_.value[std::size_t(row) * map_.width + col]) != DepthValueKind::Miss)
                return;
    out_.insert(out_.begin(), hypothesis("empty-map", "",
                                         "the map holds no surface as read: every value is a miss (check --quantity, "
                                         "--channel, --miss and --scale)"));
}

void Diagnosis::rank()
{
    std::stable_sort(out_.begin(), out_.end(), [](const Hypothesis& a, const Hypothesis& b) {
        if (a.consistent != b.consistent) return a.consistent;
        if (a.consistentExceptEdges() != b.consistentExceptEdges()) return a.consistentExceptEdges();
        return a.unexplained < b.unexplained;
    });
}

}  // namespace

std::vector<Hypothesis> MapVerifier::diagnose(const Camera& camera, const DepthMap& map) const
{
    requireMapFits(camera, map);
    if (camera.lens()) return diagnoseLensMap(*this, camera, map);
    return Diagnosis(*this, camera, map).run();
}

}  // namespace zcheck
