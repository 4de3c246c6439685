// Self pairs of an arm proven apart over its whole joint box, once per robot.
// Python twin: kcplan/arm/pairs.py (PairProofs, which calls this and keeps the result).
#pragma once

#include <cstdint>
#include <vector>

#include "arm_world.hpp"

namespace kcplan {

/// What the branch and bound of prove_pairs_apart found for one self pair.
struct PairProof {
  enum Verdict { kApart, kTouches, kUnknown };
  Verdict verdict = kUnknown;
  std::int64_t boxes = 0;      ///< sub-boxes whose centre was measured
  /// kApart: the least certain clearance measured at a box centre (metres); kTouches: 0.
  double least = 0.0;
  /// kTouches: a configuration within the limits where the pair's certain clearance is 0
  /// (in contact, or too close for coal to tell); empty otherwise.
  std::vector<double> witness;
};

/// For each self pair m of `world`, whether its two bodies can ever touch while every
/// joint stays within its limits.
///
/// Proof (Schwarzer, Saha and Latombe's chain bound, Chain::relative_speeds): on the
/// straight joint-space segment from a box's centre c to any q in the box, the distance
/// between a point of body k and a point of body l changes by at most sum_j rho_kl[j]
/// |q_j - c_j| <= sum_j rho_kl[j] w_j / 2 (w_j the box's width along joint j; only the
/// joints that carry exactly one of the two bodies count), so a certain clearance d(c)
/// above that sum proves the pair apart in the whole box. Best first: the box of least
/// slack d(c) - reach is cut in two across the joint of the largest rho_kl[j] w_j; when
/// even the least slack is positive, every box is apart, hence the whole joint box
/// (kApart). A centre where the certain clearance is 0 ends the search (kTouches, with
/// that centre as the witness); after `max_boxes` centres the pair is kUnknown (and stays
/// checked).
///
/// Before the boxes, kWitnessSamples random configurations (seeded by the pair's index,
/// counted from `first`: the same verdicts on every run, and when a list of pairs is
/// proven in parts, each part's world given its first pair's index) look for a
/// contact; they count as boxes.
///
/// Contract: the world's obstacles play no part (only self pairs are measured); the
/// world's frames are moved (as by place()). max_boxes >= 1 (std::invalid_argument).
/// Reads the world's chain only: two worlds may be proven in two threads.
std::vector<PairProof> prove_pairs_apart(ArmWorld& world, std::int64_t max_boxes,
                                         std::size_t first = 0);

/// Random configurations tried per pair before the branch and bound.
constexpr int kWitnessSamples = 64;

}  // namespace kcplan
