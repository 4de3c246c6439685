#include "pair_motion.hpp"

#include <cmath>
#include <stdexcept>

namespace kcplan {

PairFirstOrder::PairFirstOrder(const Chain& chain, const std::vector<std::array<int, 2>>& pairs)
    : chain_(chain), pairs_(pairs) {
  const int dof = chain.dof();
  const std::size_t bodies = chain.bodies().size();
  const std::vector<bool>& C = chain.carries();
  for (const auto& [k, l] : pairs_) {
    if (k < 0 || l < 0 || static_cast<std::size_t>(k) >= bodies ||
        static_cast<std::size_t>(l) >= bodies)
      throw std::invalid_argument("pairs: expected body indices");
    std::uint32_t set = 0;
    for (int j = 0; j < dof; ++j)
      if (C[k * dof + j] && C[l * dof + j]) set |= std::uint32_t{1} << j;
    int s = 0;
    while (s < static_cast<int>(sets_.size()) && sets_[s] != set) ++s;
    if (s == static_cast<int>(sets_.size())) sets_.push_back(set);
    set_of_.push_back(s);
  }
  step_.resize(dof), masked_.resize(dof);
  w_.resize(sets_.size()), u_.resize(sets_.size()), S_.resize(sets_.size());
  speeds_.resize(sets_.size() * bodies), accels_.resize(sets_.size() * bodies);
  twist_at_.assign(sets_.size(), 0), turn_at_.assign(sets_.size(), 0);
  speed_at_.assign(sets_.size() * bodies, 0), accel_at_.assign(sets_.size() * bodies, 0);
}

void PairFirstOrder::edge(const double* dq) {
  step_.assign(dq, dq + chain_.dof());
  ++edge_, ++guard_;  // a guard's speeds are of one edge's step
}

void PairFirstOrder::guard(const std::vector<coal::Transform3s>& joints, const double* centres) {
  joints_ = &joints, centres_ = centres;
  ++guard_;
}

void PairFirstOrder::mask(int s, bool absolute) {
  for (std::size_t j = 0; j < step_.size(); ++j)
    masked_[j] = (sets_[s] >> j) & 1u ? 0.0 : (absolute ? std::abs(step_[j]) : step_[j]);
}

double PairFirstOrder::body_speed(int s, int k) {
  const std::size_t at = s * chain_.bodies().size() + k;
  if (speed_at_[at] == guard_) return speeds_[at];
  if (twist_at_[s] != guard_) {
    mask(s, false);
    chain_.joint_twists(*joints_, masked_.data(), w_[s], u_[s]);
    twist_at_[s] = guard_;
  }
  const int i = chain_.bodies()[k].joint;
  const coal::Vec3s c(centres_[3 * k], centres_[3 * k + 1], centres_[3 * k + 2]);
  // body k's first order with set s's joints still
  speeds_[at] = chain_.first_order_speed(k, w_[s][i], w_[s][i].cross(c) + u_[s][i]);
  speed_at_[at] = guard_;
  return speeds_[at];
}

double PairFirstOrder::body_accel(int s, int k) {
  const std::size_t at = s * chain_.bodies().size() + k;
  if (accel_at_[at] != edge_) {
    mask(s, true);
    if (turn_at_[s] != edge_) chain_.axis_turns(masked_.data(), S_[s]), turn_at_[s] = edge_;
    accels_[at] = chain_.point_acceleration(k, masked_.data(), S_[s]);
    accel_at_[at] = edge_;
  }
  return accels_[at];
}

double PairFirstOrder::speed(std::size_t m) {
  return body_speed(set_of_[m], pairs_[m][0]) + body_speed(set_of_[m], pairs_[m][1]);
}

double PairFirstOrder::accel(std::size_t m) {
  return body_accel(set_of_[m], pairs_[m][0]) + body_accel(set_of_[m], pairs_[m][1]);
}

}  // namespace kcplan
