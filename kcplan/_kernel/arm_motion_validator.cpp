#include "arm_motion_validator.hpp"

#include <cmath>
#include <deque>
#include <stdexcept>
#include <utility>

namespace kcplan {

ScreenedArmMotions::ScreenedArmMotions(ArmCertifier& certifier, double step)
    : certifier_(certifier), step_(step) {
  if (!(step > 0.0) || !std::isfinite(step))
    throw std::invalid_argument("screen step: expected a finite number > 0");
}

DiscreteArmMotions::DiscreteArmMotions(ArmWorld& world, double step)
    : world_(world), step_(step), q_(world.chain().dof()), end_(world.chain().dof()) {
  if (!(step > 0.0) || !std::isfinite(step))
    throw std::invalid_argument("joint step: expected a finite number > 0");
}

bool DiscreteArmMotions::state_valid(const double* q) {
  ++states;
  return world_.chain().admits(q) && !world_.in_collision(q);
}

bool DiscreteArmMotions::check(const double* q1, const double* q2) {
  ++edges;
  q2 = world_.chain().edge_end(q1, q2, end_.data());  // the shorter turn, as OMPL's SO(2)
  if (!state_valid(q2)) return false;
  const int n = world_.chain().dof();
  double length = 0.0;
  for (int j = 0; j < n; ++j) length += (q2[j] - q1[j]) * (q2[j] - q1[j]);
  // OMPL's validSegmentCount: the states i / segments, 0 < i < segments
  const int segments = static_cast<int>(std::ceil(std::sqrt(length) / step_));
  if (segments < 2) return true;
  std::deque<std::pair<int, int>> open{{1, segments - 1}};
  while (!open.empty()) {
    const auto [lo, hi] = open.front();
    open.pop_front();
    const int mid = (lo + hi) / 2;
    const double s = static_cast<double>(mid) / segments;
    for (int j = 0; j < n; ++j) q_[j] = q1[j] + s * (q2[j] - q1[j]);
    if (!state_valid(q_.data())) return false;
    if (lo < mid) open.emplace_back(lo, mid - 1);
    if (mid < hi) open.emplace_back(mid + 1, hi);
  }
  return true;
}

}  // namespace kcplan
