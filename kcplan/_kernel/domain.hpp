// The poses a certifier decides: the others are rejected before any arithmetic on them.
// Python twin: kcplan/certification/domain.py (PoseDomain; same box, same limits).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "pose.hpp"

namespace kcplan {

/// The box of robot origins, yaw range and quaternion norms inside which every number a
/// certificate computes (squared norms, speeds, distances, grid indices, AABBs of a sweep)
/// is finite and exact to the margins the certificates assume.
///
/// A pose is admitted when it is finite and
/// - its translation lies in the space's bounds [low, high] padded on every side by
///   pad = |high - low| + reach (the bounds' diagonal plus the robot's reach): a robot
///   farther out is outside the scene by more than the scene's size, and OMPL's planners
///   never produce it;
/// - in 2D, |yaw| <= 2 pi: OMPL's SO(2) states lie in [-pi, pi], and a larger angle loses
///   digits (its rounding error times the robot's reach would exceed the guards' margin);
/// - in 3D, the quaternion's squared norm lies in [1e-200, 1e200], so that its
///   normalisation neither overflows nor divides by a number that underflowed.
///
/// The padded box must lie within |x| <= 1e100 (so that squared distances between any two
/// admitted points are finite); the constructor throws std::invalid_argument otherwise.
/// Rejecting a pose is always sound: `admits` only ever narrows what is certified.
class PoseDomain {
 public:
  static constexpr double kLimit = 1e100;        ///< largest admitted coordinate magnitude
  static constexpr double kQuatLow = 1e-200, kQuatHigh = 1e200;  ///< squared-norm range

  /// `low`, `high`: bounds of the robot's origin (z ignored in 2D); `reach`: the robot's
  /// reach (the farthest point of a body from its origin).
  PoseDomain(int dimension, const std::array<double, 3>& low, const std::array<double, 3>& high,
             double reach)
      : n_(dimension == 2 ? 2 : 3) {
    double diagonal = 0.0;
    for (int k = 0; k < n_; ++k) {
      if (!std::isfinite(low[k]) || !std::isfinite(high[k]) || !(low[k] <= high[k]))
        throw std::invalid_argument("bounds: expected finite numbers with low <= high");
      diagonal = std::hypot(diagonal, high[k] - low[k]);
    }
    if (!std::isfinite(reach) || !(reach >= 0.0))
      throw std::invalid_argument("reach: expected a finite number >= 0");
    const double pad = diagonal + reach;
    for (int k = 0; k < n_; ++k) {
      low_[k] = low[k] - pad, high_[k] = high[k] + pad;
      if (!(std::max(std::fabs(low_[k]), std::fabs(high_[k])) <= kLimit))
        throw std::invalid_argument("bounds: expected |low|, |high| and the scene's size <= 1e100");
    }
  }

  /// Whether `pose` is decided (true) or rejected unseen (false).
  bool admits(const Pose& pose) const {
    if (!pose.finite) return false;
    for (int k = 0; k < n_; ++k)
      if (!(pose.t[k] >= low_[k] && pose.t[k] <= high_[k])) return false;
    if (pose.size == 3) return std::fabs(pose.raw[2]) <= 2.0 * kPi;
    double sq = 0.0;
    for (int i = 3; i < 7; ++i) {
      if (!(std::fabs(pose.raw[i]) <= kLimit)) return false;
      sq += pose.raw[i] * pose.raw[i];
    }
    return sq >= kQuatLow && sq <= kQuatHigh;
  }

  /// The padded box (z = 0 in 2D).
  const std::array<double, 3>& low() const { return low_; }
  const std::array<double, 3>& high() const { return high_; }

 private:
  int n_;
  std::array<double, 3> low_{0.0, 0.0, 0.0}, high_{0.0, 0.0, 0.0};
};

}  // namespace kcplan
