// The scene of an arm: its covering bodies, placed by the chain, against the obstacles
// (a World) and against each other (the self pairs that may collide).
// Python twin: kcplan/arm/world.py (ArmWorld, on python-fcl).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <coal/collision_data.h>
#include <coal/collision_object.h>

#include "chain.hpp"
#include "world.hpp"

namespace kcplan {

/// Collision and clearance queries of an arm at a joint configuration.
///
/// The obstacles live in `scene()`, a World whose bodies are the chain's (added with its
/// add_* methods, before the first query); the self pairs are (k, l) body indices that may
/// collide. A pair is first tested by the bodies' bounding balls (centre, largest
/// semi-axis): balls apart, bodies apart; only pairs whose balls meet go to coal's GJK.
///
/// Parts: the bodies on one joint of the chain move as one rigid body; `parts()` is the
/// chain with one ball per such joint that encloses its bodies (part_of(k) says which), and
/// the self pairs fall into groups of one part pair each (`groups()`; `runs()` are the
/// stretches of consecutive pairs of one group and one first body). A group's ball gap
/// bounds the distance of each of its pairs from below, a run's (its body's ball against
/// the other part's) each of its pairs', and the parts' speed bounds bound the bodies':
/// queries and the certifier decide whole groups and runs that are far apart without
/// looking at their pairs, and a part's bodies only when the part's ball is near the
/// scene (a part of one body, such as a link's hull, is asked as that body at once: its
/// ball would be the body's own).
///
/// Contract: a configuration has chain().dof() finite numbers (std::invalid_argument
/// otherwise; limits are the certifier's business). Distances of safe_* queries are
/// reduced by the scene's error allowance (World::safe) and never overestimate.
/// Not thread-safe: the bodies' coal objects and the frames are reused.
class ArmWorld {
 public:
  ArmWorld(const Chain& chain, const std::vector<std::array<int, 2>>& pairs, double rtol,
           double atol);
  ArmWorld(const ArmWorld&) = delete;
  ArmWorld& operator=(const ArmWorld&) = delete;

  /// Consecutive self pairs [begin, end) of one group with one first body, `body`: that
  /// body against bodies of the group's second part.
  struct Run {
    std::size_t begin, end;
    int group, body;
  };

  const Chain& chain() const { return chain_; }
  const Chain& parts() const { return parts_; }
  int part_of(std::size_t k) const { return part_of_[k]; }
  /// The part pairs (p, q) of the self pairs, each once; pairs()[m] is in group_of(m).
  const std::vector<std::array<int, 2>>& groups() const { return groups_; }
  int group_of(std::size_t m) const { return group_of_[m]; }
  const std::vector<Run>& runs() const { return runs_; }
  /// A certain lower bound of the distance between any body of part p and any body of
  /// part q, (p, q) = groups()[g], from the parts' centres (3 numbers per part, world
  /// frame): the balls' gap less rounding (<= 0: nothing known).
  double group_gap(std::size_t g, const double* centres) const;
  /// The same between body k, at `frames[k]`, and part q: its ball's gap to the part's.
  double body_part_gap(std::size_t k, const std::vector<coal::Transform3s>& frames, int q,
                       const double* centres) const;
  World& scene() { return *scene_; }
  const std::vector<std::array<int, 2>>& pairs() const { return pairs_; }

  /// Whether a body at q touches an obstacle or a body it may collide with (one
  /// collision query).
  bool in_collision(const double* q);
  /// Certain clearances at q: of each body to the obstacles (`scene`, one per body, inf
  /// with no obstacles) and of each self pair (`pairs`, one per pair), 0 on contact (one
  /// distance query).
  void safe_clearances(const double* q, double* scene, double* pairs);

  /// Place the bodies at q (no query) and return their frames; valid until the next
  /// place(). A body is put into the scene (its coal object moved, its box computed)
  /// only when a query of this world first needs it there, so bodies of parts far from
  /// the obstacles cost nothing more.
  const std::vector<coal::Transform3s>& place(const double* q);
  /// Which place() (or other query) this world is at: changes at each. While it stays
  /// what it was right after place(q), that call's frames are still the bodies' at q.
  std::uint64_t location() const { return located_; }
  /// The frames the last place() returned: the bodies' there while location() is still
  /// what it was right after it (later queries may recompute some of them otherwise).
  const std::vector<coal::Transform3s>& placed_frames() const { return frames_; }
  /// The joints' frames of the last place().
  const std::vector<coal::Transform3s>& joint_frames() const { return joints_; }
  /// The parts' frames of the last place() (their balls' centres).
  const std::vector<coal::Transform3s>& part_frames() const { return part_frames_; }
  /// Certain clearance of each body to the obstacles, as placed (one distance query);
  /// with `caps`, min(clearance, caps[k]) (World::bodies_safe_clearances), each part's
  /// ball asked first: a ball clear by the largest cap of its bodies holds each of them
  /// clear by its cap, and only the bodies of the parts nearer than that are asked.
  void scene_clearances(double* out, const double* caps = nullptr);
  /// min(cap, body k's certain clearance to the obstacles) with the bodies at `frames`.
  double body_clearance(std::size_t k, const std::vector<coal::Transform3s>& frames, double cap) {
    placed_[k] = 0;  // it leaves the place of the last place()
    return scene_->body_safe_clearance(k, frames[k], cap);
  }
  /// How body k is kept apart from one obstacle near it (body_separations): the body lies
  /// in {x : n . x <= b} and the obstacle in {x : n . x >= b + gap} for some b, both
  /// exactly (support functions; `gap` less rounding, <= 0: no slab known), and
  /// `clearance` is the body's certain distance to the obstacle.
  struct Separation {
    coal::Vec3s n;  ///< unit, from the body towards the obstacle
    double gap;
    double clearance;
  };
  /// The separations of body k at `frames[k]` from every obstacle whose bounding box
  /// meets the cube of half side a_max,k + horizon about its centre (World::body_region;
  /// every other obstacle is at least `horizon` away). A box, ball or cylinder is taken
  /// along the line from its point nearest the body's centre when that holds them apart
  /// (Primitive::separation, no GJK), any other obstacle along coal's nearest points; the
  /// slab is measured by the exact support functions of the body and the obstacle, so a
  /// wrong direction only narrows it. An obstacle with no support function (a mesh) has
  /// its clearance only (gap -inf). False, `out` emptied, on contact.
  bool body_separations(std::size_t k, const std::vector<coal::Transform3s>& frames,
                        double horizon, std::vector<Separation>& out);
  /// Whether body k at `frames[k]`, grown about its centre by `scale` (semi-axes times
  /// scale >= 1), is certainly clear of the obstacles (World::grown_body_clear; the KC
  /// guard of a body; self pairs are not looked at).
  bool grown_clear(std::size_t k, const std::vector<coal::Transform3s>& frames, double scale) {
    return scene_->grown_body_clear(k, frames[k], scale);
  }
  /// A certain lower bound of self pair m's distance with the bodies at `frames`: the
  /// larger of the gap between their bounding balls and their separation along the
  /// centres' line (support functions), less rounding (<= 0: nothing known).
  double pair_gap(std::size_t m, const std::vector<coal::Transform3s>& frames) const;
  /// The gap between self pair m's bounding balls (centre, largest semi-axis) less
  /// rounding: never above pair_gap, and cheaper.
  double ball_gap(std::size_t m, const std::vector<coal::Transform3s>& frames) const;
  /// Self pair m's certain distance with the bodies at `frames` (coal's GJK, warm-started
  /// where the pair's last query ended, reduced by the allowance; 0 on contact).
  double pair_clearance(std::size_t m, const std::vector<coal::Transform3s>& frames);

  WorldCounters& counters() { return scene_->counters; }
  std::int64_t pair_queries = 0;  ///< self pairs that went to GJK
  std::int64_t part_queries = 0;  ///< parts' balls asked for their scene clearance

 private:
  bool pair_collides(std::size_t m, const std::vector<coal::Transform3s>& frames);
  /// The joints' and parts' frames at q; the bodies' frames and places become stale.
  void locate(const double* q);
  /// Body k's frame at the last locate(), computed on first use.
  const coal::Transform3s& frame(std::size_t k);
  /// Body k put into the scene at frame(k), if it is not there yet.
  void put(std::size_t k);

  Chain chain_;
  std::vector<int> part_of_;  // before parts_: parts_ is built from it
  std::vector<int> part_sizes_;  // bodies per part: a part of one body needs no ball query
  Chain parts_;
  std::vector<std::array<int, 2>> pairs_, groups_;
  std::vector<int> group_of_;
  std::vector<Run> runs_;
  std::unique_ptr<World> scene_;
  std::vector<std::shared_ptr<coal::CollisionGeometry>> shapes_;
  std::vector<coal::Transform3s> joints_, frames_, part_frames_;
  FreeRegion region_;  // body_separations' scratch
  std::vector<double> part_caps_, centres_;
  // per body: the locate() whose frame it has, and whose frame it has in the scene (0:
  // none; body_clearance moves it elsewhere)
  std::vector<std::uint64_t> framed_, placed_;
  std::uint64_t located_ = 0;
  std::vector<char> near_;  // per group, in_collision: whether the parts' balls meet
  std::vector<coal::Vec3s> guesses_;  // per pair: where its last GJK ended
  std::vector<coal::support_func_guess_t> hints_;
};

}  // namespace kcplan
