#include "arm_planner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace kcplan {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

double ArmRRTConnect::squared(const double* a, const double* b) const {
  double d = 0.0;
  for (int j = 0; j < n_; ++j) {
    const double e = chain_.difference(j, a[j], b[j]);
    d += e * e;
  }
  return d;
}

double ArmRRTConnect::distance(const double* a, const double* b) const {
  return std::sqrt(squared(a, b));
}

void ArmRRTConnect::between(const double* a, const double* b, double s, double* out) const {
  for (int j = 0; j < n_; ++j) out[j] = chain_.canonical(j, a[j] + s * chain_.difference(j, a[j], b[j]));
}

ArmRRTConnect::ArmRRTConnect(const Chain& chain, ArmMotionValidator& tree,
                             ArmMotionValidator* path)
    : chain_(chain), tree_(tree), path_(path), n_(chain.dof()), sample_(n_), step_(n_) {
  if (path != nullptr && !path->certified())
    throw std::invalid_argument("lazy planner: expected a certifying path validator");
}

void ArmRRTConnect::Tree::reset(const double* root, int n) {
  states.assign(root, root + n);
  parents = {-1}, below = {-1}, above = {-1}, depth = {0};
}

void ArmRRTConnect::Tree::add(const double* q, int parent, int n, bool kd_tree) {
  const int index = static_cast<int>(parents.size());
  states.insert(states.end(), q, q + n);
  parents.push_back(parent), below.push_back(-1), above.push_back(-1), depth.push_back(0);
  if (!kd_tree) return;
  for (int node = 0;;) {
    const int j = depth[node] % n;
    int& child = q[j] < states[static_cast<std::size_t>(node) * n + j] ? below[node] : above[node];
    if (child < 0) {
      child = index, depth[index] = depth[node] + 1;
      return;
    }
    node = child;
  }
}

void ArmRRTConnect::nearest_in(const Tree& tree, int node, const double* q, std::size_t& best,
                               double& least) const {
  while (node >= 0) {
    const double* s = tree.states.data() + static_cast<std::size_t>(node) * n_;
    const double d = squared(s, q);
    if (d < least) least = d, best = static_cast<std::size_t>(node);
    const int j = tree.depth[node] % n_;
    const double across = q[j] - s[j];
    const int near = across < 0.0 ? tree.below[node] : tree.above[node];
    const int far = across < 0.0 ? tree.above[node] : tree.below[node];
    nearest_in(tree, near, q, best, least);
    // the far side holds only states at least |across| away along joint j (a wrapping
    // angle's far side may be near the other way round: never pruned)
    if (far < 0 || (!chain_.wraps(j) && across * across >= least)) return;
    node = far;
  }
}

std::size_t ArmRRTConnect::nearest(const Tree& tree, const double* q) const {
  std::size_t best = 0;
  double least = std::numeric_limits<double>::infinity();
  if (kd_tree_) {
    nearest_in(tree, 0, q, best, least);
    return best;
  }
  const std::size_t count = tree.parents.size();
  for (std::size_t i = 0; i < count; ++i) {
    const double d = squared(tree.states.data() + i * n_, q);
    if (d < least) least = d, best = i;
  }
  return best;
}

ArmRRTConnect::Grown ArmRRTConnect::grow(Tree& tree, const double* target,
                                         ArmMotionValidator& edges, ArmPlan& plan) {
  const std::size_t near = nearest(tree, target);
  const double* from = tree.states.data() + near * n_;
  const double d = distance(from, target);
  if (d == 0.0) {  // the target is in the tree already
    last_ = near;
    return Grown::kReached;
  }
  const bool reach = d <= range_;
  const double t = reach ? 1.0 : range_ / d;
  if (reach)
    std::copy_n(target, n_, step_.data());
  else
    between(from, target, t, step_.data());
  ++plan.tree_edges;
  if (!edges.check(from, step_.data())) return Grown::kTrapped;
  tree.add(step_.data(), static_cast<int>(near), n_, kd_tree_);
  last_ = tree.parents.size() - 1;
  return reach ? Grown::kReached : Grown::kAdvanced;
}

std::vector<double> ArmRRTConnect::search(const double* start, const double* goal,
                                          ArmMotionValidator& edges, double deadline,
                                          ArmPlan& plan) {
  const auto t0 = Clock::now();
  Tree trees[2];
  trees[0].reset(start, n_);
  trees[1].reset(goal, n_);
  const std::vector<double>& lower = chain_.lower();
  const std::vector<double>& upper = chain_.upper();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> target(n_);
  int grown = 0;  // the tree that extends towards the sample
  std::vector<double> path;
  while (seconds_since(t0) < deadline) {
    ++plan.iterations;
    for (int j = 0; j < n_; ++j) sample_[j] = lower[j] + unit(rng_) * (upper[j] - lower[j]);
    Tree& a = trees[grown];
    Tree& b = trees[1 - grown];
    if (grow(a, sample_.data(), edges, plan) != Grown::kTrapped) {
      const std::size_t in_a = last_;
      std::copy_n(a.states.data() + in_a * n_, n_, target.data());
      Grown g = Grown::kAdvanced;
      while (g == Grown::kAdvanced && seconds_since(t0) < deadline)
        g = grow(b, target.data(), edges, plan);
      if (g == Grown::kReached) {  // the two branches meet at `target`
        const std::size_t in_b = last_;
        const std::size_t ends[2] = {grown == 0 ? in_a : in_b, grown == 0 ? in_b : in_a};
        for (int i = static_cast<int>(ends[0]); i >= 0; i = trees[0].parents[i])
          path.insert(path.begin(), trees[0].states.begin() + i * n_,
                      trees[0].states.begin() + (i + 1) * n_);
        for (int i = trees[1].parents[ends[1]]; i >= 0; i = trees[1].parents[i])
          path.insert(path.end(), trees[1].states.begin() + i * n_,
                      trees[1].states.begin() + (i + 1) * n_);
        break;
      }
    }
    grown = 1 - grown;
  }
  plan.tree_states += static_cast<std::int64_t>(trees[0].parents.size() + trees[1].parents.size());
  return path;
}

bool ArmRRTConnect::certify(std::vector<double>& path, double budget, ArmPlan& plan) {
  const auto t0 = Clock::now();
  for (std::size_t i = 0; i + 1 < path.size() / n_; ++i) {
    const double* a = path.data() + i * n_;
    ++plan.path_edges;
    if (path_->check_screened(a, a + n_)) continue;
    const double left = budget - seconds_since(t0);
    if (left <= 0.0) return false;
    const std::vector<double> around = search(a, a + n_, *path_, left, plan);
    if (around.empty()) return false;
    ++plan.repaired_edges;
    // its ends are the edge's: splice its inner states in, and go on after them
    const std::size_t inner = around.size() / n_ - 2;
    path.insert(path.begin() + (i + 1) * n_, around.begin() + n_, around.end() - n_);
    i += inner;
  }
  return true;
}

void ArmRRTConnect::shortcut(std::vector<double>& path, ArmMotionValidator& edges,
                             double deadline, ArmPlan& plan) {
  const auto t0 = Clock::now();
  const auto state = [&](std::vector<double>& p, std::size_t i) { return p.data() + i * n_; };
  // greedily: from each state, the farthest later state it connects to
  std::vector<double> kept(path.begin(), path.begin() + n_);
  const std::size_t count = path.size() / n_;
  for (std::size_t i = 0; i + 1 < count;) {
    std::size_t j = count - 1;
    for (; j > i + 1 && seconds_since(t0) < deadline; --j) {
      ++plan.shortcut_edges;
      if (edges.check(state(path, i), state(path, j))) break;
    }
    if (seconds_since(t0) >= deadline) j = i + 1;
    kept.insert(kept.end(), state(path, j), state(path, j) + n_);
    i = j;
  }
  path.swap(kept);
  // random pairs of points along the path
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> at(2 * n_), lengths;
  for (std::size_t failed = 0, tries = 0;; ++tries) {
    const std::size_t states = path.size() / n_;
    if (states < 3 || failed >= states || tries >= 4 * states + 20) break;
    if (seconds_since(t0) >= deadline) break;
    lengths.assign(1, 0.0);
    for (std::size_t i = 0; i + 1 < states; ++i)
      lengths.push_back(lengths.back() + distance(state(path, i), state(path, i + 1)));
    double t[2] = {unit(rng_) * lengths.back(), unit(rng_) * lengths.back()};
    if (t[0] > t[1]) std::swap(t[0], t[1]);
    std::size_t seg[2];
    for (int e = 0; e < 2; ++e) {
      seg[e] = static_cast<std::size_t>(
          std::upper_bound(lengths.begin(), lengths.end(), t[e]) - lengths.begin() - 1);
      seg[e] = std::min(seg[e], states - 2);
      const double span = lengths[seg[e] + 1] - lengths[seg[e]];
      const double s = span > 0.0 ? (t[e] - lengths[seg[e]]) / span : 0.0;
      const double* a = state(path, seg[e]);
      between(a, a + n_, s, at.data() + e * n_);
    }
    ++failed;
    if (seg[0] == seg[1]) continue;  // on one edge already
    ++plan.shortcut_edges;
    if (!edges.check(at.data(), at.data() + n_)) continue;
    // path[..seg0], a, b, path[seg1 + 1..]
    std::vector<double> shorter(path.begin(), path.begin() + (seg[0] + 1) * n_);
    shorter.insert(shorter.end(), at.begin(), at.end());
    shorter.insert(shorter.end(), path.begin() + (seg[1] + 1) * n_, path.end());
    path.swap(shorter);
    failed = 0;
  }
}

ArmPlan ArmRRTConnect::solve(const double* start, const double* goal,
                             const ArmPlannerOptions& options) {
  if (!chain_.admits(start)) throw std::invalid_argument("start: outside the joint limits");
  if (!chain_.admits(goal)) throw std::invalid_argument("goal: outside the joint limits");
  if (!(options.range > 0.0) || !std::isfinite(options.range))
    throw std::invalid_argument("range: expected a finite number > 0");
  if (!(options.time_limit > 0.0))
    throw std::invalid_argument("time limit: expected a number > 0");
  range_ = options.range;
  kd_tree_ = options.kd_tree;
  rng_.seed(options.seed);
  ArmPlan plan;
  const auto t0 = Clock::now();
  if (tree_.state_valid(start) && tree_.state_valid(goal)) {
    for (;;) {
      const double left = options.time_limit - seconds_since(t0);
      if (left <= 0.0) break;
      ++plan.attempts;
      const auto attempt = Clock::now();
      std::vector<double> path = search(start, goal, tree_, left, plan);
      if (path.empty()) break;
      if (path_ == nullptr ||
          certify(path, options.repair_share * seconds_since(attempt), plan)) {
        plan.solved = true;
        plan.raw_path = path;
        break;
      }
      tree_.tighten();
    }
  }
  plan.solve_seconds = seconds_since(t0);
  plan.path = plan.raw_path;
  if (plan.solved && options.simplify) {
    const auto t1 = Clock::now();
    shortcut(plan.path, path_ != nullptr ? *path_ : tree_, options.time_limit, plan);
    plan.simplify_seconds = seconds_since(t1);
  }
  return plan;
}

}  // namespace kcplan
