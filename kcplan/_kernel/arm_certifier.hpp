// The edge certifier of arms: joint-space edges proved free by the chain's clearance balls.
// Python twin: kcplan/certification/arm_certifier.py (ArmEdgeCertifier); both decide every edge
// by the same steps and count them under the rigid certifier's names.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "arm_world.hpp"
#include "certifier.hpp"
#include "guard.hpp"
#include "pair_motion.hpp"

namespace kcplan {

/// One guard of an arm: what one distance query at the state q proves.
///
/// `scene[k]` is a certain lower bound of body k's clearance to the obstacles: its
/// clearance, or (when `scene_exact[k]` is 0) a cap below it, as much as the edge it was
/// measured for needed; `pairs[m]` a certain lower bound of self pair m's distance once
/// known (`pair_known[m]`: 0 not yet, 1 the bounding balls' gap ArmWorld::pair_gap, 2 the
/// pair's GJK distance), each asked the first time a certificate needs it. Raising a lower
/// bound never makes it wrong, so a cached guard is refined in place when another edge
/// needs more of it. The parts' levers and centres decide far groups of pairs at once
/// (ArmWorld::parts).
struct ArmGuard {
  std::array<double, Chain::kMaxJoints> q{};
  std::vector<double> levers;        ///< Chain::levers at q: bodies x dof
  /// ArmWorld::location() right after its place(q): while the world is there, its frames
  /// are this guard's bodies' (radius() then computes none).
  std::uint64_t location = 0;
  std::vector<coal::Transform3s> joints;  ///< the joints' frames at q (first_order)
  std::vector<double> centres;            ///< the bodies' centres at q, 3 each (first_order)
  std::vector<double> part_levers;   ///< the same of ArmWorld::parts(): parts x dof
  std::vector<double> part_centres;  ///< the parts' centres at q: 3 per part
  mutable std::vector<double> scene, pairs;
  mutable std::vector<char> scene_exact, pair_known;
  /// Body k's KC guard (its body grown by 1 + the certifier's kc_inflation about its
  /// centre): 0 not asked yet, 1 certainly clear of the scene, 2 not known to be.
  mutable std::vector<char> grown;
  /// Body k's separations from the obstacles within `separated[k]` of it (the plane
  /// certificate), asked on first use; separated[k] < 0: not asked yet.
  mutable std::vector<std::vector<ArmWorld::Separation>> separations;
  mutable std::vector<double> separated;
  /// > 0: no body at q is known to touch anything (the scene's smallest bound, and of the
  /// pairs known); set to 0 when a pair is found in contact. A guard whose pairs are not
  /// all known is cached only at an end of an edge, whose radius() is asked at once: a
  /// pair in contact is then found (its group's gap is not positive).
  mutable double clearance = 0.0;
};

/// The guards of an arm, keyed by the joint vector.
using ArmGuardCache = StateCache<Chain::kMaxJoints, ArmGuard>;

/// Options of an ArmCertifier; the defaults are the Python certifier's.
struct ArmCertifierOptions {
  int max_guards = 256;  ///< guards per edge after the endpoints before "not proven"
  bool probes = true;    ///< collision probes of the open stretch before any guard
  /// Decide the self pairs of a far group of parts at once (ArmWorld::parts) and ask a
  /// pair's gap only when its group is near; false: every pair at every guard (the
  /// ablation; the radii are the same, kcplan/certification/arm_certifier.py decides so too).
  bool part_balls = true;
  /// Bound a body's motion near a guard by its exact twist there as well (Chain::
  /// first_order_speeds, Chain::point_accelerations); false: the levers alone (the
  /// ablation).
  bool first_order = true;
  /// The KC certificate's inflation eps > 0: a body also stays free while it stays inside
  /// its body grown by 1 + eps at a guard, proved clear by one query (the class docs); 0:
  /// the clearance ball alone (the `ca` ablation).
  double kc_inflation = 0.0;
  /// The plane certificate (needs first_order): a body also stays free of an obstacle
  /// while no point of it moves across the slab between them (the class docs); false:
  /// the others alone (the ablation).
  bool planes = true;
  std::size_t cache_entries = 200000;
};

/// Prove joint-space edges of an arm free, or reject them.
///
/// For the straight edge q(s) = q1 + s (q2 - q1), no point of body k moves faster than
/// v_k = sum_j rho[k, j] |dq_j| per unit of s and no two points of a self pair (k, l)
/// approach faster than v_kl (Chain::point_speeds, Chain::relative_speeds; Schwarzer, Saha
/// and Latombe 2005); nor, within t of a guard at s = m, farther than A t + Q t^2 / 2,
/// with A from the levers at q(m) and Q from how fast they can grow (Chain::levers,
/// Chain::lever_growth), nor, for a body (first_order), farther than A1 t + M t^2 / 2 with
/// A1 from its twist at q(m) and M its largest acceleration (Chain::first_order_speeds,
/// Chain::point_accelerations), and for a pair the same of both bodies in the frame of the
/// joints that carry both (PairFirstOrder). A guard with clearances d_k and d_kl therefore
/// proves the open stretch |s - m| < r free, r the smallest over bodies and pairs of
/// max(d / v, the root t of A t + Q t^2 / 2 = d, that of A1 t + M t^2 / 2 = d):
/// each body stays clear of the scene and of each body it may collide with, and the
/// covers hold the links.
/// kcplan/certification/arm_certifier.py has the proof in full.
///
/// The KC certificate (kc_inflation = eps > 0) is a second proof for each body's scene
/// clearance, tried where the ball leaves a body short: the body grown about its centre
/// by 1 + eps at the guard (its guard, in the paper's words) is proved clear by one query
/// (World::grown_body_clear), and the body stays inside it while, in the guard's frame,
/// its centre's displacement d and its turn theta keep |diag(a)^-1 d| + (a_max - a_min)
/// theta / a_min <= eps (the ellipsoid's support function turns at most a_max - a_min per
/// radian, kcplan/certification/certificates/ball.py). With d <= u t + M t^2 / 2 (the centre's
/// velocity u at the guard, Taylor's remainder), d <= min(v t, A t + Q t^2 / 2) and theta
/// <= w t (Chain::turn_speeds) this is a reach in t like the ball's; a body takes the
/// larger of the two. A body moving along its long axes may so go much farther than its
/// clearance. Self pairs keep the ball.
///
/// The plane certificate (planes, with first_order) is a third proof of a body's scene
/// clearance (ArmWorld::body_separations): the body and each obstacle within the horizon
/// the ball needs lie on either side of a slab of width g across a unit n at the guard.
/// Every point x of the body moves across it at |n . u + (x - c) . (n x w)| at the guard
/// (n . (w x (x - c)) = (x - c) . (n x w)): for a hull at most that of one of its
/// vertices (a linear function's largest value), else at most |n . u| + |n x w| a_max;
/// and its acceleration is at most M (Chain::point_accelerations), so within t of the
/// guard it crosses at most S t + M t^2 / 2 of the slab, S that speed: the body stays on
/// its side while that is below g. The body's radius is the smallest, over those
/// obstacles, of the larger of this root and the ball's reach of its distance to that
/// obstacle alone, and the ball's reach of the horizon for every obstacle beyond it. A
/// body sliding past a surface (the hand over a table) moves little across it. The planes
/// cost a region query of the body, so radius() asks them only of a body that limits the
/// radius, after the balls and the pairs (see there).
///
/// `check(q1, q2)` follows OMPL's MotionValidator contract (q1 assumed valid): (1) a state
/// outside the limits or not finite rejects the edge with no query; (2) q2's validity
/// (one collision query, cached); (3) the ends' cached guards, which may certify it; (4)
/// probes: collision queries at the van der Corput points of the stretch left open, one
/// per kProbeStep of joint-space distance (at most kMaxProbes), a colliding one rejects
/// at a collision query's price; (5) the missing end guards (cached per state); (6) a
/// guard in the middle of each stretch left open until none is (certified), one is in
/// contact (rejected) or max_guards were placed ("not proven", rejected). A self pair's exact
/// distance is asked only when its balls' gap would limit a radius: the radius is then
/// exactly the one of exact distances. With part_balls, a group of pairs whose parts'
/// balls (ArmWorld::parts) give every pair of it at least the radius the others allow is
/// not looked at, nor a run of it whose body's ball and other part's ball do: its pairs
/// could not lower that radius (each pair's distance is at least the balls' gap, each of
/// its speeds, levers and growth at most the balls' from the parts' speed bounds, and the
/// radius a clearance gives grows with the clearance and shrinks with the others), so
/// the radius is the same. For the same reason a body or pair whose clearance (for a
/// pair not yet known: its bounding balls' gap first) already gives the radius at its
/// global speed alone, d >= r v, is not looked at further; nor a pair whose balls' gap
/// gives it at its run's speed, which is at least its own.
/// Not thread-safe (the world's objects are reused).
class ArmCertifier {
 public:
  ArmCertifier(ArmWorld& world, const ArmCertifierOptions& options);
  ArmCertifier(const ArmCertifier&) = delete;
  ArmCertifier& operator=(const ArmCertifier&) = delete;

  /// Whether the whole edge q1 -> q2 (dof() numbers each) is proven free. `with_probes`
  /// false skips step (4), which only rejects early and proves nothing: for an edge a
  /// lazy planner has screened already (screen()), whose probes would be asked again.
  /// A wrapping angle (Chain::wraps) turns the shorter way: the edge proven, as screen()'s,
  /// is q1 -> Chain::edge_end(q1, q2), the one OMPL's SO2StateSpace interpolates.
  bool check(const double* q1, const double* q2, bool with_probes = true);
  /// Whether the edge q1 -> q2 passes the collision queries check() begins with (both
  /// ends within the limits, q2 valid, no probe over the whole edge in contact: one per
  /// `step` of joint-space distance, radians L2, at most kMaxProbes), and nothing more.
  /// Not a proof: the edge may still touch between its probes. A lazy planner screens
  /// its tree's edges so and certifies only the path it returns with check()
  /// (kcplan/planning/lazy.py); counted as screened_edges, its queries as probes.
  bool screen(const double* q1, const double* q2, double step = kProbeStep);
  /// Whether the quadratic Bezier blend B(t) = (1 - t)^2 a + 2 t (1 - t) c + t^2 b,
  /// t in [0, 1] (a, c, b: dof() numbers each, within the limits), is proven free.
  /// B'(t) = 2 ((1 - t) (c - a) + t (b - c)), so |B'_j(t)| <= bound_j = 2 max(|c_j - a_j|,
  /// |b_j - c_j|) all along it; the chain's speed and lever bounds integrate |dq_j/dt|
  /// along any curve in the joint box, so the radius (in t) a guard at B(t_m) gives the
  /// straight edge of |dq| = bound holds for the curve, and guards placed by conservative
  /// advancement in t (advance(), at most `max_guards`, not cached) prove it. The first
  /// order and the KC guard are not used here: they need a straight edge's signed step.
  /// kcplan/trajectory/smoothing.py has the proof and the Python twin.
  bool check_blend(const double* a, const double* c, const double* b, int max_guards);
  /// State validity with the cache: one collision query for a state not seen before.
  bool state_valid(const double* q);
  /// One guard at q, not cached. With `enough` > 0 (during check()), each body's
  /// clearance is measured only as far as a radius of `enough` needs for the current
  /// edge, and never below kClearanceFloor, so that clearance > 0 still means free;
  /// otherwise wholly.
  ArmGuard measure(const double* q, double enough = -1.0);
  /// measure() into `g`, reusing its storage.
  void measure_into(const double* q, double enough, ArmGuard& g);
  /// The half width, in s, of a stretch `guard` proves free for the current edge (the
  /// class docs), or a radius of at least `enough` (the guard's bounds are refined where
  /// they would limit it below that).
  double radius(const ArmGuard& guard, double enough);

  /// The smallest cap of a body's clearance (metres): a body closer than this to an
  /// obstacle is always measured.
  static constexpr double kClearanceFloor = 1e-6;
  /// Caps are this much above what a stretch needs, so that the radius they give, less
  /// its rounding margin, still covers the stretch.
  static constexpr double kCapSlack = 1.0 + 1e-6;
  /// Joint-space distance (radians, L2) per probe, and probes per edge at most
  /// (kcplan/certification/arm_certifier.py: PROBE_STEP, MAX_PROBES).
  static constexpr double kProbeStep = 0.1;
  static constexpr int kMaxProbes = 64;

  ArmWorld& world() { return world_; }
  const ArmGuardCache& cache() const { return cache_; }
  int max_guards() const { return max_guards_; }
  bool probes() const { return probes_; }
  bool part_balls() const { return part_balls_; }
  bool first_order() const { return first_order_; }
  double kc_inflation() const { return kc_; }
  bool planes() const { return planes_; }
  std::int64_t plane_queries = 0;  ///< bodies whose separations were asked
  std::int64_t plane_reaches = 0;  ///< bodies whose plane reach beat the others' where asked
  double covered_ball = 0.0;  ///< edges certified (each covers its whole [0, 1])
  std::int64_t grown_queries = 0;  ///< KC guards asked (one body query each)
  std::int64_t kc_reaches = 0;     ///< bodies whose KC reach beat their ball's where asked
  CertifierCounters counters;
  std::int64_t refined_pairs = 0;   ///< pair bounds raised to their GJK distance
  std::int64_t skipped_groups = 0;  ///< groups of pairs a radius decided by their parts
  std::int64_t refined_bodies = 0;  ///< capped scene clearances measured again, uncapped

 private:
  std::shared_ptr<const ArmGuard> endpoint(const double* q, const ArmGuardCache::Key& key);
  /// The current edge's terms from its signed joint step (step_, dq_, the speeds, growth,
  /// accelerations, turns and the groups' terms): what radius() needs of an edge.
  void set_edge(const double* step);
  bool reject(std::int64_t& reason);
  bool certified_by_endpoints();
  bool probe(const double* q1, const double* q2, double lo, double hi, double length,
             double step = kProbeStep);

  ArmWorld& world_;
  const Chain& chain_;
  int n_, max_guards_;
  bool probes_, part_balls_, first_order_, planes_;
  double kc_;
  ArmGuardCache cache_;
  /// The radius a clearance d gives to a body or pair of global speed v, lever term A
  /// and growth Q (the class docs).
  static double reach(double d, double v, double A, double Q);
  /// The root t of A t + Q t^2 / 2 = d (inf when neither moves).
  static double root(double d, double A, double Q);
  /// Body k's radius from the clearance d at `guard`: reach, and the first order's root.
  double body_reach(const ArmGuard& guard, std::size_t k, double d) const;
  /// Body k's radius from its KC guard (the class docs), 0 if that is not clear; asks the
  /// guard's query on first use. Needs twist() of `guard` and the bodies' frames there.
  template <class Frames>
  double kc_reach(const ArmGuard& guard, std::size_t k, Frames& frames);
  /// Body k's radius by the plane certificate (the class docs), asking its separations
  /// out to the horizon the ball needs for a radius of `want` if not known that far.
  /// Needs twist() of `guard` and the bodies' frames there.
  template <class Frames>
  double plane_reach(const ArmGuard& guard, std::size_t k, double want, Frames& frames);
  /// Body k's part of radius(): the ball, then (kc) its KC guard, then (a capped
  /// clearance) the clearance measured again, each only while r stays below min(r, enough).
  template <class Frames>
  void body_radius(const ArmGuard& guard, std::size_t k, double enough, double& r,
                   Frames& frames);
  /// The bodies' twists at `guard` for the current edge (w_, u_) and first_.
  void twist(const ArmGuard& guard);
  /// Pair m's radius from the distance d at the guard of the current radius(): reach,
  /// and (first_order, where reach is below `enough`) the root of its relative first
  /// order (PairFirstOrder).
  double pair_reach(const ArmGuard& guard, std::size_t m, double d, double enough);
  /// A and Q of body k (k < bodies) or of pair k - bodies, for the current edge.
  void terms(const ArmGuard& guard, std::size_t k, double& A, double& Q) const;
  /// The radius group g's gap gives all its pairs, for the current edge.
  double group_reach(const ArmGuard& guard, std::size_t g) const;
  /// The same of one run's pairs: its body's ball against the other part's; `speed` is
  /// set to the run's global speed, at least each of its pairs' (pair_speed).
  template <class Frames>
  double run_reach(const ArmGuard& guard, const ArmWorld::Run& run, Frames& frames,
                   double& speed);
  /// Self pair m's part of radius(): its bound asked if not known, refined if it would
  /// hold r below min(r, enough), then r lowered to what it gives. `bound` is at least
  /// pair_speed(m) (its run's, or infinity). `frames()` gives the bodies' frames at the
  /// guard (computed on first use).
  template <class Frames>
  void pair_radius(const ArmGuard& guard, std::size_t m, double enough, double& r,
                   Frames& frames, double bound);
  /// The self pairs' part of radius(): r lowered to what every pair allows (pair_radius,
  /// whole groups and runs decided at once with part_balls).
  template <class Frames>
  double pairs_radius(const ArmGuard& guard, double enough, double r, Frames& frames);

  std::vector<double> rho_, rho_pairs_;
  std::vector<double> only_first_, only_second_;  // pairs x dof: joint carries one body only
  std::vector<double> speed_, q_, caps_, dq_, growth_, step_, accel_;
  std::vector<double> end_;  // an edge's end, its wrapping angles unwrapped (Chain::edge_end)
  std::vector<double> body_growth_;  // per body: Q of the current edge (the sum of growth_)
  mutable std::vector<double> first_;  // A1 of the bodies at the guard of the radius asked
  std::vector<coal::Vec3s> w_, u_;     // their twists there (twist())
  PairFirstOrder pair_first_;          // the pairs' first order (first_order)
  std::vector<double> turn_;           // per body: Chain::turn_speeds of the edge
  /// Self pair m's speed v_kl and growth Q for the current edge, each computed when
  /// first needed (a pair its speed decides never needs its growth).
  double pair_speed(std::size_t m) const;
  double pair_growth(std::size_t m) const;
  mutable std::vector<double> pair_speed_, pair_growth_;
  mutable std::vector<std::uint64_t> pair_edge_, pair_growth_edge_;  // the edge they are of
  std::uint64_t edge_ = 0;
  std::vector<double> rho_groups_, group_speed_, group_growth_, part_growth_, group_t_;
  std::vector<double> group_first_, group_second_;  // groups x dof: joint carries one part only
  std::vector<coal::Transform3s> joints_, frames_;  // scratch of refinements
  std::vector<std::pair<double, double>> pending_;
  ArmGuard scratch_;  // the advancement's guards, measured in place
  std::vector<double> body_t_;  // radius() with the planes: each body's reach so far
};

}  // namespace kcplan
