#include "numerics.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace zcheck {

double medianOf(std::vector<double> values)
{
    if (values.empty()) return 0;
    const auto middle = values.begin() + std::ptrdiff_t(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

double medianAbsolute(const std::vector<double>& r)
{
    std::vector<double> a(r.size());
    std::transform(r.begin(), r.end(), a.begin(), [](double x) { return std::abs(x); });
    return medianOf(std::move(a));
}

double quantileOf(std::vector<double>& values, double q)
{
    if (values.empty()) return 0;
    const std::size_t rank = std::size_t(std::max(0.0, std::ceil(q * double(values.size())) - 1));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(rank), values.end());
    return values[rank];
}

double largestOf(const std::vector<double>& r, const std::vector<double>& inliers)
{
    double most = 0;
    for (std::size_t k = 0; k < r.size(); ++k)
        if (inliers[k] > 0) most = std::max(most, std::abs(r[k]));
    return most;
}

double robustCost(const std::vector<double>& r, double c)
{
    if (r.empty()) return INFINITY;
    double sum = 0;
    for (double x : r) sum += std::log1p((x / c) * (x / c));
    return sum;
}

double cauchyScale(const std::vector<double>& r, double floor)
{
    return std::max(2.4 * 1.4826 * medianAbsolute(r), floor);
}

namespace {

// Solves A·x = b (n ≤ 6) by Gaussian elimination with partial pivoting; false if singular.
bool solve(std::vector<double> A, std::vector<double> b, int n, std::vector<double>& x)
{
    for (int col = 0; col < n; ++col) {
        int pivot = col;
        for (int row = col + 1; row < n; ++row)
            if (std::abs(A[row * n + col]) > std::abs(A[pivot * n + col])) pivot = row;
        if (!(std::abs(A[pivot * n + col]) > 0)) return false;
        for (int k = 0; k < n; ++k) std::swap(A[col * n + k], A[pivot * n + k]);
        std::swap(b[col], b[pivot]);
        for (int row = col + 1; row < n; ++row) {
            const double f = A[row * n + col] / A[col * n + col];
            for (int k = col; k < n; ++k) A[row * n + k] -= f * A[col * n + k];
            b[row] -= f * b[col];
        }
    }
    x.assign(n, 0);
    for (int row = n - 1; row >= 0; --row) {
        double sum = b[row];
        for (int k = row + 1; k < n; ++k) sum -= A[row * n + k] * x[k];
        x[row] = sum / A[row * n + row];
    }
    return std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace

std::optional<std::vector<double>> levenbergMarquardt(int n, const ResidualsAt& residuals,
                                                      const LevenbergMarquardtOptions& options)
{
    const std::vector<double>* weights = options.weights;
    std::vector<double> p(static_cast<std::size_t>(n), 0.0);
    std::vector<double> r = residuals(p);
    if (r.empty()) return std::nullopt;
    double lambda = 1e-3;
    constexpr double h = 1e-6;
    auto costOf = [&](const std::vector<double>& res, double c) {
        if (!weights) return robustCost(res, c);
        if (res.empty()) return double(INFINITY);
        double sum = 0;
        for (std::size_t k = 0; k < res.size(); ++k) sum += (*weights)[k] * res[k] * res[k];
        return sum;
    };
    for (int iteration = 0; iteration < options.iterations; ++iteration) {
        const double c = cauchyScale(r, options.scaleFloor);
        const double cost = costOf(r, c);
        // Weighted normal equations with a forward-difference Jacobian.
        std::vector<std::vector<double>> J(static_cast<std::size_t>(n));
        for (int j = 0; j < n; ++j) {
            std::vector<double> q = p;
            q[std::size_t(j)] += h;
            J[std::size_t(j)] = residuals(q);
            if (J[std::size_t(j)].empty()) return p;
            for (std::size_t k = 0; k < r.size(); ++k) J[std::size_t(j)][k] = (J[std::size_t(j)][k] - r[k]) / h;
        }
        std::vector<double> A(std::size_t(n * n), 0.0), g(std::size_t(n), 0.0);
        for (std::size_t k = 0; k < r.size(); ++k) {
            const double w = weights ? (*weights)[k] : 1 / (1 + (r[k] / c) * (r[k] / c));
            if (w == 0) continue;
            for (int a = 0; a < n; ++a) {
                g[std::size_t(a)] -= w * J[std::size_t(a)][k] * r[k];
                for (int b = 0; b < n; ++b) A[std::size_t(a * n + b)] += w * J[std::size_t(a)][k] * J[std::size_t(b)][k];
            }
        }
        bool improved = false;
        std::vector<double> step;
        double change = 0;  // the step's largest change of a residual
        while (lambda < 1e10) {
            std::vector<double> damped = A;
            for (int a = 0; a < n; ++a) damped[std::size_t(a * n + a)] *= 1 + lambda;
            if (solve(damped, g, n, step)) {
                std::vector<double> q = p;
                for (int a = 0; a < n; ++a) q[std::size_t(a)] += step[std::size_t(a)];
                std::vector<double> rq = residuals(q);
                if (costOf(rq, c) < cost) {
                    for (std::size_t k = 0; k < r.size(); ++k) change = std::max(change, std::abs(rq[k] - r[k]));
                    p = std::move(q), r = std::move(rq), lambda = std::max(lambda / 4, 1e-9), improved = true;
                    break;
                }
            }
            lambda *= 8;
        }
        double size = 0;
        for (double s : step) size = std::max(size, std::abs(s));
        if (!improved) break;
        if (options.residualChange > 0 ? change < options.residualChange : size < 1e-6) break;
    }
    return p;
}

Line leastMedianLine(const std::vector<LinePoint>& points, Line line)
{
    const std::size_t n = points.size();
    auto medianOfLine = [&](const Line& l) {
        std::vector<double> r(n);
        for (std::size_t k = 0; k < n; ++k) r[k] = (l.a + l.b * points[k].x - points[k].y) / points[k].sigma;
        return medianAbsolute(r);
    };
    double bestMedian = medianOfLine(line);
    constexpr std::size_t kPairs = 256;
    for (std::size_t k = 0; n >= 16 && k < kPairs; ++k) {
        const LinePoint& p = points[k * n / kPairs];
        const LinePoint& q = points[(k * n / kPairs + n / 2 + 37 * k) % n];
        if (!(std::abs(p.x - q.x) > 1e-9 * std::max(std::abs(p.x), std::abs(q.x)))) continue;
        Line trial;
        trial.b = (p.y - q.y) / (p.x - q.x);
        trial.a = p.y - trial.b * p.x;
        const double median = medianOfLine(trial);
        if (median < bestMedian) line = trial, bestMedian = median;
    }
    return line;
}

}  // namespace zcheck
