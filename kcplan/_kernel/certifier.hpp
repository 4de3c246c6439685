// The edge certifier: where certificates, guards, the guard cache and rejection meet.
// Python twin: kcplan/certification/certifier.py (EdgeCertifier); both decide every edge by the
// same steps and count them under the same names (COUNTER_NAMES).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "advancement.hpp"
#include "certificates.hpp"
#include "domain.hpp"
#include "guard.hpp"
#include "occupancy.hpp"
#include "pose.hpp"
#include "world.hpp"

namespace kcplan {

/// The probes' schedule (kcplan/certification/certifier.py: PROBE_WARMUP, PROBE_ODDS,
/// PROBE_EVERY): every edge is probed while fewer than kProbeWarmup were, or while at
/// least one probed edge in kProbeOdds was rejected by a probe; otherwise every
/// kProbeEvery-th edge, so that the rate stays measured.
constexpr std::int64_t kProbeWarmup = 64, kProbeOdds = 5, kProbeEvery = 16;

/// The occupancy grid's learning schedule (kcplan/certification/certifier.py: LEARN_WARMUP,
/// LEARN_ODDS, LEARN_EVERY): the cell of every colliding state is tested while fewer than
/// kLearnWarmup cells were, or while the grid rejects at least one state or edge per
/// kLearnOdds tested cells; otherwise at every kLearnEvery-th colliding state.
constexpr std::int64_t kLearnWarmup = 256, kLearnOdds = 2, kLearnEvery = 8;

/// A piece of work asked while it pays: on each of the first `warmup` tries, and while at
/// least one try in `odds` paid off; otherwise on every `every`-th, so that the rate
/// stays measured. Python twin: kcplan/certification/certifier.py, PayingSchedule.
class PayingSchedule {
 public:
  PayingSchedule(std::int64_t warmup, std::int64_t odds, std::int64_t every)
      : warmup_(warmup), odds_(odds), every_(every) {}
  /// Whether to do the work now, after `tried` tries of which `paid` paid off.
  bool ask(std::int64_t tried, std::int64_t paid) {
    if (tried < warmup_ || paid * odds_ >= tried) return true;
    return ++skips_ % every_ == 0;
  }

 private:
  std::int64_t warmup_, odds_, every_, skips_ = 0;
};

/// kcplan's counters, with the meanings documented in kcplan/certification/certifier.py.
struct CertifierCounters {
  std::int64_t edges = 0, rejected = 0, rejected_end_state = 0, rejected_sweep = 0,
               rejected_occupancy = 0, rejected_probe = 0, rejected_guard = 0, not_proven = 0,
               certified_by_endpoints = 0, certified_one_guard = 0, guards = 0,
               endpoint_guards = 0, cached_guards = 0, bisection_nodes = 0,
               collision_queries = 0, occupancy_rejections = 0, occupancy_queries = 0,
               probes = 0, probed_edges = 0, screened_edges = 0;

  /// Count how an advancement of `guards` guards ended; whether the edge is certified.
  bool settle(Advanced outcome, int guards) {
    bisection_nodes += guards;
    if (outcome == Advanced::kCovered) {
      certified_one_guard += guards == 1;
      return true;
    }
    ++rejected;
    ++(outcome == Advanced::kRejected ? rejected_guard : not_proven);
    return false;
  }
};

/// Options of an EdgeCertifier; the defaults are the Python certifier's.
struct CertifierOptions {
  std::vector<std::string> certificates{"region"};  ///< ball, rotation, polytope, region(-lever)
  bool discrete = false;     ///< fallback: OMPL-style sampling instead of advancement
  int max_guards = 64;       ///< guards per edge after the endpoints before "not proven"
  double horizon = -1.0;     ///< region horizon; < 0: the largest semi-axis
  bool sweep_test = true;    ///< the core-capsule rejection (needs a core)
  bool occupancy = true;     ///< the occupancy grid (needs a core)
  int probes = 3;            ///< collision queries at bisection points before any guard
  bool learn_schedule = true;  ///< the grid learns cells on its schedule (false: always)
  /// Bounds of the robot's origin: the occupancy grid's box, and the domain of poses
  /// decided (PoseDomain pads them by their diagonal and the robot's reach).
  std::array<double, 3> low{0, 0, 0}, high{0, 0, 0};
  std::size_t cache_entries = 200000;
};

/// Prove OMPL edges collision-free with guards and certificates, or reject them.
///
/// `check(p1, p2)` follows OMPL's MotionValidator contract: p1 is assumed valid, p2 is
/// not. It returns true only when the whole edge, interpolated as OMPL does, is proven
/// free: (1) p2 is rejected by the occupancy grid or one collision query unless the cache
/// knows it; (2) cached endpoint guards may certify it with no query; (3) a centre path
/// through a blocked cell or a colliding core capsule rejects it, and so does a colliding
/// probe, one of `probes` collision queries at the bisection points 1/2, 1/4, 3/4, 1/8, ...
/// of what is left open (a colliding pose proves the edge not free at a collision query's
/// price, before any guard is paid for), asked while probes reject at least one edge in
/// kProbeOdds (see probing()); (4) missing endpoint
/// guards are measured and cached; (5) advancement places guards in the middle of what is
/// left open until nothing is (certified), one touches an obstacle or makes no progress
/// (rejected), or max_guards were placed ("not proven": rejected). A pose outside the
/// domain (not finite, far outside the bounds, see PoseDomain) is never free and costs no
/// query. Not thread-safe (the world's coal objects are reused).
class EdgeCertifier {
 public:
  EdgeCertifier(World& world, const CertifierOptions& options,
                std::unique_ptr<KCPolytope> polytope = nullptr);
  EdgeCertifier(const EdgeCertifier&) = delete;
  EdgeCertifier& operator=(const EdgeCertifier&) = delete;

  /// Whether the whole edge p1 -> p2 is proven free; `resolution` (in units of s) is the
  /// step of the discrete fallback. `with_probes` false skips the probes (3), which only
  /// reject early and prove nothing: for an edge a lazy planner has screened already
  /// (screen()).
  bool check(const Pose& p1, const Pose& p2, double resolution = 0.01,
             bool with_probes = true);
  /// Whether the edge p1 -> p2 passes the cheap tests check() begins with, and nothing
  /// more: both poses in the domain, p2 and the centre path clear of blocked cells, p2
  /// valid, the core capsule clear (sweep_test), and no probe in contact, at most `step`
  /// (length units) of motion of the robot's farthest point apart (|t2 - t1| + reach
  /// |w12| over the edge; at most kMaxScreenProbes). Not a proof: the edge may touch
  /// between its probes. A lazy planner screens its trees' edges so and certifies only
  /// the path it returns with check() (kcplan/planning/lazy.py); counted as
  /// screened_edges, its probes as probes.
  bool screen(const Pose& p1, const Pose& p2, double step);
  static constexpr int kMaxScreenProbes = 64;
  /// State validity with the cache: one collision query for a pose not seen before.
  bool state_valid(const Pose& pose);
  /// One guard query at `pose`, not cached.
  Guard measure(const Pose& pose);

  const std::vector<std::unique_ptr<Certificate>>& certificates() const { return certificates_; }
  const std::vector<double>& covered() const { return covered_; }
  const GuardCache& cache() const { return cache_; }
  const PoseDomain& domain() const { return domain_; }
  double horizon() const { return horizon_; }
  double margin() const { return margin_; }
  bool sweep_test() const { return sweep_test_; }
  bool occupancy() const { return grid_.has_value(); }
  bool learn_schedule() const { return learn_schedule_; }
  int probes() const { return probes_; }
  bool discrete() const { return discrete_; }
  World& world() { return world_; }
  CertifierCounters counters;

 private:
  /// std::invalid_argument unless both poses have the robot's pose size.
  void require_poses(const Pose& p1, const Pose& p2) const;
  bool collision_free(const Pose& p, const GuardCache::Key& key);
  std::shared_ptr<const Guard> endpoint(const Pose& pose, const GuardCache::Key& key);
  void reach(const Guard& guard, const Edge& edge, double m, double s0, double s1, double& lo,
             double& hi);
  bool reject(std::int64_t& reason);
  bool probing();
  bool learning();
  /// False when one of `count` probes of [lo, hi] collides.
  bool probe(const Edge& edge, double lo, double hi, int count);
  bool advance(const Edge& edge, double lo, double hi);
  bool sample(const Edge& edge, double resolution, double lo, double hi);

  World& world_;
  const Robot& robot_;
  std::vector<std::unique_ptr<Certificate>> certificates_;
  std::vector<double> covered_;
  bool use_region_ = false, discrete_ = false, sweep_test_ = false;
  int max_guards_, probes_;
  bool learn_schedule_;
  PayingSchedule probe_pace_{kProbeWarmup, kProbeOdds, kProbeEvery};
  PayingSchedule learn_pace_{kLearnWarmup, kLearnOdds, kLearnEvery};
  double horizon_, margin_, core_radius_;
  PoseDomain domain_;
  GuardCache cache_;
  std::optional<CoreOccupancy> grid_;
  std::vector<FreeRegion> regions_;  // scratch of region queries
  std::vector<double> clearances_;   // scratch of clearance queries
  std::vector<std::pair<double, double>> pending_;
};

}  // namespace kcplan
