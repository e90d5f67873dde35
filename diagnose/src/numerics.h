#pragma once
// The numerics of the diagnosis, private to zcheck::diagnose: robust statistics, a robust
// Levenberg–Marquardt and a least-median-of-squares line. Plain numbers in, plain numbers out:
// nothing here knows a camera, a map or a sentence (the fits' model is fit.cpp's, their words
// fit_description.cpp's).
#include <functional>
#include <optional>
#include <vector>

namespace zcheck {

// The median of `values` (the upper one of an even count), 0 for none.
double medianOf(std::vector<double> values);
// The median of |r|, 0 for none.
double medianAbsolute(const std::vector<double>& r);
// The value at rank ⌈q·n⌉ − 1 of `values` (reordered), 0 for none.
double quantileOf(std::vector<double>& values, double q);
// The largest |r[k]| among those whose inliers[k] > 0 (0 for none).
double largestOf(const std::vector<double>& r, const std::vector<double>& inliers);

// Cauchy's robust cost at scale c: Σ log(1 + (r/c)²); +inf for no residuals.
double robustCost(const std::vector<double>& r, double c);
// The robust scale of residuals for Cauchy's cost: 2.4 × their MAD-estimated spread
// (1.4826 × median |r|), at least `floor` (a set that fits exactly would otherwise weigh its
// rounding).
double cauchyScale(const std::vector<double>& r, double floor);

// The residuals of a model at parameters p (any fixed count, one per sample); empty where p is
// outside the model's domain.
using ResidualsAt = std::function<std::vector<double>(const std::vector<double>& p)>;

struct LevenbergMarquardtOptions {
    int iterations = 30;        // at most this many steps
    double scaleFloor = 1e-7;   // cauchyScale's floor
    // Converged when no residual moved by more than this in a step; 0: when no parameter moved
    // by 1e-6 or more.
    double residualChange = 0;
    // Weighted least squares with these weights (one per residual) instead of Cauchy's cost.
    const std::vector<double>* weights = nullptr;
};

// Levenberg–Marquardt on the weighted normal equations from p = 0 (n ≤ 6 parameters), with a
// forward-difference Jacobian (step 1e-6). The cost is Cauchy's at cauchyScale of the current
// residuals, the weights 1/(1 + (r/c)²) refreshed every step; or, with options.weights, the
// weighted sum of squares. The damping starts at 1e-3, is divided by 4 after a step that lowers
// the cost and multiplied by 8 after one that does not; no step below 1e10 lowering it ends the
// search. Returns the parameters reached (those of the last step if a Jacobian's residuals come
// out empty); std::nullopt where residuals(0) is empty.
std::optional<std::vector<double>> levenbergMarquardt(int n, const ResidualsAt& residuals,
                                                      const LevenbergMarquardtOptions& options = {});

// A line y = a + b·x through points weighed by their scales (y's change for a unit change of
// what is fitted).
struct LinePoint {
    double x, y, sigma;
};
struct Line {
    double a, b;
};
// Least median of squares: of `line` and the lines through 256 pairs of points (none with
// fewer than 16 points), the one whose scaled residuals' median |r| is smallest. Global, and
// indifferent to up to half the points lying off it.
Line leastMedianLine(const std::vector<LinePoint>& points, Line line);

}  // namespace zcheck
