// Khachiyan's iteration for the minimum-volume enclosing ellipsoid, step for step.
// Python twin: kcplan/geometry/enclosing.py (minimum_volume_ellipsoid's loop).
#pragma once

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace kcplan {

/// The weights u (m, summing to 1) of Khachiyan's iteration for the minimum-volume
/// ellipsoid around the m points `x` (row-major m x n, n = 2 or 3, full-dimensional: the
/// hull's vertices, centred), in the form of Todd and Yildirim (Discrete Appl. Math. 155,
/// 2007: away steps, Kumar and Yildirim's start), each step a rank-one update of V(u)^-1
/// and of every g_l = q_l^T V(u)^-1 q_l (Sherman and Morrison), computed afresh every
/// `refresh` steps and before stopping (0: at every step, the textbook iteration).
///
/// The same steps as the Python loop: the same start, the first of near ties within
/// `tie` of the extreme, the same formulas in the same order; only the rounding of sums
/// may differ, which `tie` keeps from choosing a step. Stops when every g_l / (n + 1) - 1
/// <= `tol` on fresh values, or after `max_iterations` steps. The ellipsoid is
/// c = sum u_l x_l, M = (sum u_l x_l x_l^T - c c^T)^-1 / n (the caller's part). Throws
/// std::invalid_argument for a dimension other than 2 or 3, fewer than n + 1 points or a
/// coordinate that is not finite.
inline std::vector<double> khachiyan_weights(const double* x, std::int64_t m, int n,
                                             double tol, std::int64_t max_iterations,
                                             std::int64_t refresh, double tie) {
  if (n != 2 && n != 3) throw std::invalid_argument("points: expected 2 or 3 columns");
  if (m <= n) throw std::invalid_argument("points: expected more points than dimensions");
  for (std::int64_t l = 0; l < m * n; ++l)
    if (!std::isfinite(x[l])) throw std::invalid_argument("points: expected finite coordinates");
  using Matrix = Eigen::MatrixXd;
  using Vector = Eigen::VectorXd;
  const int d = n + 1;
  const double dd = static_cast<double>(d);
  Matrix rows(m, d);  // the lifted points q_l = (x_l, 1) as rows
  for (std::int64_t l = 0; l < m; ++l) {
    for (int i = 0; i < n; ++i) rows(l, i) = x[l * n + i];
    rows(l, n) = 1.0;
  }
  // Kumar and Yildirim's start: the extreme points along each axis (the first of ties)
  Vector u = Vector::Zero(m);
  for (int i = 0; i < n; ++i) {
    Eigen::Index lo, hi;
    rows.col(i).minCoeff(&lo);
    rows.col(i).maxCoeff(&hi);
    u[lo] = 1.0, u[hi] = 1.0;
  }
  u = (0.9 * u.array()) / u.sum() + 0.1 / static_cast<double>(m);  // V starts regular

  Matrix V_inv(d, d);
  Vector g(m), h(m), w(d);
  auto fresh_values = [&] {
    const Matrix V = rows.transpose() * u.asDiagonal() * rows;
    V_inv = V.inverse();
    g = ((rows * V_inv).array() * rows.array()).rowwise().sum();
  };
  fresh_values();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> barred(m, 0.0);  // +inf where u_l = 0: no away step from those
  std::int64_t fresh = 0;              // rank-one updates since g was computed afresh
  // the first index where `holds` (numpy's argmax of a mask: 0 where none does)
  auto first = [m](auto&& holds) {
    for (std::int64_t l = 0; l < m; ++l)
      if (holds(l)) return l;
    return std::int64_t{0};
  };
  for (std::int64_t it = 0; it < max_iterations; ++it) {
    const double top = g.maxCoeff();
    const std::int64_t j = first([&](std::int64_t l) { return g[l] >= top - tie * std::abs(top); });
    double low = inf;
    for (std::int64_t l = 0; l < m; ++l) low = std::min(low, g[l] + barred[l]);
    const std::int64_t k =
        first([&](std::int64_t l) { return g[l] + barred[l] <= low + tie * std::abs(low); });
    const double grow = g[j] / dd - 1.0, shrink = 1.0 - g[k] / dd;
    std::int64_t i = -1;
    double step = 0.0;
    if (grow <= tol) {
      if (fresh == 0) break;
      fresh = refresh;  // the test on updated g: confirm it on g computed afresh
    } else if (grow >= shrink) {  // Khachiyan's step towards the worst point
      i = j, step = (g[j] - dd) / (dd * (g[j] - 1.0));
      u *= 1.0 - step;
      u[j] += step;
      barred[j] = 0.0;  // back in the support, if it had been dropped
    } else {  // Todd and Yildirim's away step from the weakest support point
      i = k;
      step = -std::min((dd - g[k]) / (dd * (g[k] - 1.0)), u[k] / (1.0 - u[k]));
      u *= 1.0 - step;
      u[k] += step;
      if (u[k] <= 0.0) u[k] = 0.0, barred[k] = inf;  // dropped from the support
    }
    if (fresh >= refresh) {  // bound the updates' rounding drift
      fresh_values();
      fresh = 0;
      continue;
    }
    // V(u) became (1 - step) V + step q_i q_i^T: Sherman and Morrison, O(m n)
    w.noalias() = V_inv * rows.row(i).transpose();
    h.noalias() = rows * w;  // q_l^T V^-1 q_i for every l
    const double scale = step / (1.0 - step + step * g[i]);
    const double keep = 1.0 / (1.0 - step);
    V_inv = (V_inv - (scale * w) * w.transpose()) * keep;
    g = (g.array() - scale * h.array().square()) * keep;
    ++fresh;
  }
  return std::vector<double>(u.data(), u.data() + m);
}

}  // namespace kcplan
