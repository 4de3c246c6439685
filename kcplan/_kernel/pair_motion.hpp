// How fast the bodies of self pairs approach each other near a guard: the relative first
// order. Python twin: kcplan/arm/bounds.py (relative_first_order, relative_accelerations).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <coal/math/transform.h>

#include "chain.hpp"

namespace kcplan {

/// The first-order terms of self pairs (k, l): within t of a guard at s = m the distance
/// between a point of k and a point of l changes by at most A1 t + M t^2 / 2, with A1 the
/// first-order speeds of both bodies (Chain::first_order_speeds) and M their largest
/// accelerations (Chain::point_accelerations), each taken with the steps of the joints
/// that carry both bodies set to 0: those joints move the pair as one rigid body, and in
/// the frame of the deepest of them each body moves by the other joints alone
/// (kcplan/arm/bounds.py has the proof).
///
/// Pairs share these terms by their set of common joints (a serial chain has one set per
/// joint): each set's joint twists and each (set, body) speed are computed once per
/// guard, each (set, body) acceleration once per edge, on first use. Contract: call edge() before a guard's
/// guard(), and guard() before speed(); the joint frames and centres given to guard()
/// must outlive its use. Not thread-safe.
class PairFirstOrder {
 public:
  PairFirstOrder(const Chain& chain, const std::vector<std::array<int, 2>>& pairs);

  /// A new edge of signed joint step `dq` (dof numbers, copied).
  void edge(const double* dq);
  /// A new guard: the joint frames (Chain::joint_frames) and the bodies' centres (3
  /// numbers per body) at its q.
  void guard(const std::vector<coal::Transform3s>& joints, const double* centres);
  /// A1 of pair m at the current guard for the current edge (metres per unit of s).
  double speed(std::size_t m);
  /// M of pair m for the current edge.
  double accel(std::size_t m);

 private:
  const Chain& chain_;
  std::vector<std::array<int, 2>> pairs_;
  std::vector<int> set_of_;             // per pair: its set of common joints
  std::vector<std::uint32_t> sets_;     // bit j: state j carries both bodies
  std::vector<double> step_, masked_;  // the edge's signed step; scratch
  std::vector<std::vector<coal::Vec3s>> w_, u_;  // per set: Chain::joint_twists at the guard
  std::vector<std::vector<double>> S_;           // per set: Chain::axis_turns of the edge
  std::vector<double> speeds_, accels_;          // sets x bodies
  std::vector<std::uint64_t> twist_at_, turn_at_, speed_at_, accel_at_;  // guard() / edge()
  std::uint64_t edge_ = 0, guard_ = 0;
  const std::vector<coal::Transform3s>* joints_ = nullptr;
  const double* centres_ = nullptr;
  /// masked_ = step_ with set s's joints at 0 (absolute values when `absolute`).
  void mask(int s, bool absolute);
  /// The first-order speed of body k in set s's frame (twists made on first use).
  double body_speed(int s, int k);
  /// The largest acceleration of body k in set s's frame (made on first use).
  double body_accel(int s, int k);
};

}  // namespace kcplan
