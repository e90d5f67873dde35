// Checker::checkLens: a lens model's two directions against each other and against the trace
// (checker.h, LensCheck).
#include "zcheck/checker.h"

#include "zcheck/detail/clock.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace zcheck {

namespace {

// One worker's share: counts and the worst pixels (in scan order when tied, so any thread
// count gives the same report).
struct LensTally {
    LensCheck check;
    std::int64_t failing = 0;      // pixels beyond either bound
    std::int64_t hitsPassing = 0;  // hits within both
    void worse(double error, int col, int row, double& max, int& maxCol, int& maxRow)
    {
        if (error > max || (error == max && maxRow >= 0 && (row < maxRow || (row == maxRow && col < maxCol))))
            max = error, maxCol = col, maxRow = row;
    }
    void merge(const LensTally& other)
    {
        LensCheck& c = check;
        const LensCheck& o = other.check;
        failing += other.failing, hitsPassing += other.hitsPassing;
        c.inField += o.inField, c.outsideField += o.outsideField, c.hits += o.hits;
        c.roundTripFailures += o.roundTripFailures, c.forwardFailures += o.forwardFailures;
        c.forwardWidestBoundPx = std::max(c.forwardWidestBoundPx, o.forwardWidestBoundPx);
        if (o.roundTripRow >= 0) worse(o.roundTripMaxPx, o.roundTripCol, o.roundTripRow, c.roundTripMaxPx, c.roundTripCol, c.roundTripRow);
        if (o.forwardRow >= 0) worse(o.forwardMaxPx, o.forwardCol, o.forwardRow, c.forwardMaxPx, c.forwardCol, c.forwardRow);
    }
};

}  // namespace

double LensCheck::forwardBoundPx(double eyeFromOrigin, double t, double pixelsPerRadian)
{
    const double radians = 0x1p-52 * (eyeFromOrigin / t + 16);  // the rounding of the hit's direction
    return kForwardBoundPx + 2 * pixelsPerRadian * radians;
}

CheckResult Checker::checkLens(const Camera& camera, const CheckOptions& options) const
{
    const LensModel& lens = *camera.lens();
    const int W = camera.width(), H = camera.height();
    CheckResult run;
    run.ray = rays_.render(camera, options.faults.ray, EyePoints::Keep);
    const auto start = Clock::now();
    if (options.keepPixels) {
        run.comparison.pixelClass.resize(std::size_t(W) * H);
        run.comparison.errorOverTolerance.assign(std::size_t(W) * H, 0.0f);
    }
    const double eyeFromOrigin = glm::length(glm::dvec3(camera.worldFromEye[3]));
    tbb::enumerable_thread_specific<LensTally> tallies;
    tbb::parallel_for(0, H, [&](int row) {
        LensTally& tally = tallies.local();
        LensCheck& c = tally.check;
        for (int col = 0; col < W; ++col) {
            const std::size_t i = std::size_t(row) * W + col;
            const glm::dvec2 centre(col + 0.5, row + 0.5);
            PixelClass pixelClass = PixelClass::BothMiss;
            if (const std::optional<glm::dvec3> ray = lens.directionAtPixel(col, row)) {
                ++c.inField;
                const std::optional<glm::dvec2> back = lens.imageFromDirection(*ray);
                const double roundTrip = back ? glm::length(*back - centre) : INFINITY;
                tally.worse(roundTrip, col, row, c.roundTripMaxPx, c.roundTripCol, c.roundTripRow);
                const bool roundTripFails = !(roundTrip <= LensCheck::kRoundTripBoundPx);
                c.roundTripFailures += roundTripFails;
                double forward = 0, forwardBound = LensCheck::kForwardBoundPx;
                if (run.ray.hit(i)) {
                    ++c.hits;
                    const glm::dvec3 dLens = camera.lensFrameFromEye(run.ray.pEye[i]);
                    const std::optional<glm::dvec2> seen = lens.imageFromDirection(dLens);
                    forward = seen ? glm::length(*seen - centre) : INFINITY;
                    tally.worse(forward, col, row, c.forwardMaxPx, c.forwardCol, c.forwardRow);
                    if (seen && forward > forwardBound) {  // rare: what rounding allows this hit
                        forwardBound = LensCheck::forwardBoundPx(eyeFromOrigin, glm::length(dLens), lens.pixelsPerRadian(dLens));
                        c.forwardWidestBoundPx = std::max(c.forwardWidestBoundPx, forwardBound);
                    }
                    c.forwardFailures += !(forward <= forwardBound);
                }
                const bool fails = roundTripFails || !(forward <= forwardBound);
                tally.failing += fails;
                tally.hitsPassing += !fails && run.ray.hit(i);
                pixelClass = fails ? PixelClass::DepthError : run.ray.hit(i) ? PixelClass::Agree : PixelClass::BothMiss;
                if (options.keepPixels)
                    run.comparison.errorOverTolerance[i] =
                        float(std::max(roundTrip / LensCheck::kRoundTripBoundPx, forward / forwardBound));
            } else {
                ++c.outsideField;
            }
            if (options.keepPixels) run.comparison.pixelClass[i] = pixelClass;
        }
    });
    LensTally all;
    for (const LensTally& tally : tallies) all.merge(tally);
    LensCheck& lensCheck = all.check;
    lensCheck.model = lens.spec().model;
    lensCheck.fieldAngleDeg = glm::degrees(lens.fieldAngle());

    // The same report's form: a pixel whose two directions agree is "agree" (hit) or "both miss"
    // (no hit, or outside the field); one beyond a bound a depth error.
    ComparisonReport& report = run.comparison.report;
    report.width = W, report.height = H;
    // A failing pixel is a depth error whether or not its ray hit; hits that pass agree.
    report.depthErrors = all.failing;
    report.agree = all.hitsPassing;
    report.bothHit = report.agree + report.depthErrors;
    report.bothMiss = std::int64_t(W) * H - report.bothHit;
    run.report.timings.compareMs = millisecondsSince(start);
    run.report.timings.bvhBuildMs = rays_.buildMilliseconds();
    run.report.timings.traceMs = run.ray.renderMilliseconds;
    if (!options.keepPixels) run.ray = RenderResult{};
    run.report.describeInputs(scene_, camera, options.tolerance);
    run.report.comparison = report;
    run.report.secondRoute = "lens";
    run.report.lens = lensCheck;
    return run;
}

}  // namespace zcheck
