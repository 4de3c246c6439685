// Grid cells where the robot's origin cannot be, for every orientation.
// Python twin: kcplan/world/occupancy.py (CoreOccupancy; the proof is in its docstring).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "world.hpp"

namespace kcplan {

/// A regular grid over the bounds whose cells are learned blocked (the ball B(c, r - h)
/// of the cell's centre meets an obstacle, so every robot pose with its origin in the
/// cell collides) or open. It only ever proves collisions, never freedom; cells are
/// tested lazily, when a state in them was found colliding.
class CoreOccupancy {
 public:
  CoreOccupancy(World& world, const std::array<double, 3>& low, const std::array<double, 3>& high,
                double core_radius, double max_cells = 1e6)
      : world_(world), n_(world.robot().dimension()) {
    double volume = 1.0;
    for (int k = 0; k < n_; ++k) {
      low_[k] = low[k];
      extent_[k] = std::max(high[k] - low[k], 1e-12);
      volume *= extent_[k];
    }
    const double r = core_radius;
    side_ = std::max({std::pow(volume / max_cells, 1.0 / n_), r / std::sqrt(double(n_)), 1e-12});
    const double half_diagonal = 0.5 * side_ * std::sqrt(double(n_));
    for (int k = 0; k < n_; ++k) shape_[k] = static_cast<std::int64_t>(std::ceil(extent_[k] / side_));
    enabled_ = half_diagonal < 0.9 * r;
    radius_ = (r - half_diagonal) * (1.0 - 1e-6);
  }

  bool enabled() const { return enabled_; }
  /// True when the cell of `position` is known blocked (no query).
  bool blocked(const std::array<double, 3>& position) const {
    if (!enabled_) return false;
    std::int64_t cell;
    return index(position.data(), cell) && state(cell) == kBlocked;
  }
  /// Test the cell of `position` if it was never tested (one query); whether it is blocked.
  bool learn(const std::array<double, 3>& position) {
    if (!enabled_) return false;
    std::int64_t cell;
    if (!index(position.data(), cell)) return false;
    auto it = cells_.find(cell);
    if (it != cells_.end()) return it->second == kBlocked;
    std::array<double, 3> centre{0.0, 0.0, 0.0};
    std::int64_t rest = cell;
    for (int k = n_ - 1; k >= 0; --k) {
      centre[k] = low_[k] + (double(rest % shape_[k]) + 0.5) * side_;
      rest /= shape_[k];
    }
    ++queries;
    const bool hit = world_.ball_collides(centre, radius_);
    cells_[cell] = hit ? kBlocked : kOpen;
    return hit;
  }
  /// True when a point of the segment a -> b, taken one cell length apart from the end
  /// backwards, lies in a known-blocked cell (no query; a False proves nothing).
  bool segment_blocked(const std::array<double, 3>& a, const std::array<double, 3>& b) const {
    if (!enabled_) return false;
    double length = 0.0, d[3];
    for (int k = 0; k < n_; ++k) d[k] = b[k] - a[k], length += d[k] * d[k];
    // clamped before the cast: casting a length that overflowed (inf, NaN) is undefined
    const double cells = std::sqrt(length) / side_;
    const int steps = (cells < 255.0 ? static_cast<int>(cells) : 255) + 1;
    for (int j = steps; j >= 0; --j) {
      const double f = double(j) / steps;
      double p[3];
      for (int k = 0; k < n_; ++k) p[k] = a[k] + f * d[k];
      std::int64_t cell;
      if (index(p, cell) && state(cell) == kBlocked) return true;
    }
    return false;
  }

  std::int64_t queries = 0;  ///< queries spent testing cells

 private:
  enum : unsigned char { kUnknown, kBlocked, kOpen };
  bool index(const double* p, std::int64_t& cell) const {
    cell = 0;
    for (int k = 0; k < n_; ++k) {
      const double f = std::floor((p[k] - low_[k]) / side_);
      if (!(f >= 0.0) || f >= double(shape_[k])) return false;
      cell = cell * shape_[k] + static_cast<std::int64_t>(f);
    }
    return true;
  }
  unsigned char state(std::int64_t cell) const {
    auto it = cells_.find(cell);
    return it == cells_.end() ? kUnknown : it->second;
  }

  World& world_;
  int n_;
  std::array<double, 3> low_{}, extent_{};
  std::array<std::int64_t, 3> shape_{1, 1, 1};
  double side_ = 1.0, radius_ = 0.0;
  bool enabled_ = false;
  std::unordered_map<std::int64_t, unsigned char> cells_;
};

}  // namespace kcplan
