// RRT-Connect for arms, compiled: sampling, nearest neighbours, extension, connection and
// shortcutting in C++, each edge decided by an ArmMotionValidator with no Python call.
// Python side: kcplan/planning/native.py (the kc-rrtconnect-native planners).
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "arm_motion_validator.hpp"
#include "chain.hpp"

namespace kcplan {

/// Options of ArmRRTConnect::solve.
struct ArmPlannerOptions {
  double range = 0.5;       ///< longest tree edge, radians of joint-space distance (L2)
  double time_limit = 10.0; ///< seconds for the search (the shortcuts have as many again)
  std::uint64_t seed = 0;   ///< the sampler's seed: the same seed, the same path
  bool simplify = true;     ///< shortcut the path (ArmRRTConnect::shortcut)
  /// Nearest neighbours by a k-d tree grown with the tree (true), or by a linear scan
  /// (false, the ablation); the same neighbour either way, up to ties.
  bool kd_tree = true;
  /// Lazy (with a path validator): seconds the repairs of one path may take, as a
  /// multiple of what the attempt that found it took.
  double repair_share = 1.0;
};

/// What ArmRRTConnect::solve did.
struct ArmPlan {
  bool solved = false;
  std::vector<double> path;      ///< the states, dof() numbers each (shortcut if asked)
  std::vector<double> raw_path;  ///< the same before the shortcuts
  double solve_seconds = 0.0, simplify_seconds = 0.0;
  std::int64_t iterations = 0;     ///< samples drawn
  std::int64_t tree_states = 0;    ///< states the searches' trees held, summed
  std::int64_t tree_edges = 0;     ///< edges the tree validator was asked
  std::int64_t path_edges = 0;     ///< lazy: path edges the path validator was asked
  std::int64_t repaired_edges = 0; ///< lazy: rejected path edges replaced by a sub-plan
  std::int64_t attempts = 0;       ///< lazy: searches started (1 + restarts)
  std::int64_t shortcut_edges = 0; ///< edges the shortcuts asked
};

/// RRT-Connect (Kuffner and LaValle 2000, as OMPL's geometric::RRTConnect) in an arm's
/// joint box, edges decided by validators.
///
/// Two trees grow from the start and the goal: a uniform sample in the box, the nearest
/// state of one tree (L2 in joint space: a k-d tree that splits on the joints in turn,
/// grown as the tree is, searched exactly with the usual pruning; or a linear scan), a
/// step of at most `range` towards the sample, kept when `tree.check(nearest, new)` holds; then the other tree extends towards the new state
/// until it reaches it (a path) or is stopped; the trees swap. As OMPL's, every tree edge
/// is checked from the tree's state to the new one (check()'s q1 is always a valid state).
///
/// Eager (no path validator): the tree validator's answers are final, so the path is
/// proven free when tree.certified(). Lazy (a path validator, certified): the trees'
/// edges are only screened; each edge of a found path is then checked by `path`, and an
/// edge it rejects is replaced by an eager RRT-Connect sub-plan between its ends on
/// `path` (time: repair_share times the attempt's), or, if that fails, the search
/// starts again with tree.tighten() (kcplan/planning/lazy.py's scheme, compiled). A
/// returned path so holds exactly what the final validator proves, edge by edge.
///
/// Shortcuts (simplify) are asked of the final validator: first greedily, from each
/// state the farthest later state it connects to, then random pairs of points along
/// the path (OMPL's PathSimplifier::shortcutPath), until as many tries in a row fail as
/// the path has states (at most 4 states + 20 tries), all within time_limit seconds. A
/// point between two states lies on a checked edge, so it is valid, and a shortcut from
/// it is checked as any edge; the path never gets longer (triangle inequality).
///
/// A wrapping angle (Chain::wraps: a moving base's yaw, a continuous joint) is sampled in
/// [-pi, pi], measured and stepped the shorter way round (as OMPL's SO2StateSpace), and
/// every state kept in [-pi, pi); an edge is the validators' (Chain::edge_end).
///
/// Contract: start and goal have dof() finite numbers within the limits (else
/// std::invalid_argument); the trees' states are within the limits. Not thread-safe.
class ArmRRTConnect {
 public:
  /// `path`: the lazy planner's certifier of the found path, or nullptr (eager).
  ArmRRTConnect(const Chain& chain, ArmMotionValidator& tree, ArmMotionValidator* path);

  ArmPlan solve(const double* start, const double* goal, const ArmPlannerOptions& options);
  const Chain& chain() const { return chain_; }

 private:
  struct Tree {
    std::vector<double> states;  // dof() each
    std::vector<int> parents;    // -1 at the root
    // the k-d tree over the states: state i's children (-1: none); it splits on joint
    // depth % dof() at its own value
    std::vector<int> below, above;
    std::vector<int> depth;
    void reset(const double* root, int n);
    void add(const double* q, int parent, int n, bool kd_tree);
  };
  enum class Grown { kTrapped, kAdvanced, kReached };

  /// One search until a path of edges `edges` accepts or `deadline` (seconds); empty
  /// when none.
  std::vector<double> search(const double* start, const double* goal,
                             ArmMotionValidator& edges, double deadline, ArmPlan& plan);
  Grown grow(Tree& tree, const double* target, ArmMotionValidator& edges, ArmPlan& plan);
  std::size_t nearest(const Tree& tree, const double* q) const;
  void nearest_in(const Tree& tree, int node, const double* q, std::size_t& best,
                  double& least) const;
  /// The lazy planner's path checked edge by edge by `path_`, rejected edges repaired;
  /// false when a repair failed.
  bool certify(std::vector<double>& path, double budget, ArmPlan& plan);
  void shortcut(std::vector<double>& path, ArmMotionValidator& edges, double deadline,
                ArmPlan& plan);
  /// Joint-space distance (L2) and its square, a wrapping angle's the shorter turn.
  double distance(const double* a, const double* b) const;
  double squared(const double* a, const double* b) const;
  /// a + s (b - a) along the edge from a to b (a wrapping angle the shorter way round,
  /// brought into [-pi, pi)), into `out`.
  void between(const double* a, const double* b, double s, double* out) const;

  const Chain& chain_;
  ArmMotionValidator& tree_;
  ArmMotionValidator* path_;
  int n_;
  double range_ = 0.5;
  bool kd_tree_ = true;
  std::mt19937_64 rng_;
  std::vector<double> sample_, step_;
  std::size_t last_ = 0;  // grow(): the index of the state that reached or advanced
};

}  // namespace kcplan
