#include "certifier.hpp"

#include <cmath>
#include <stdexcept>

namespace kcplan {

EdgeCertifier::EdgeCertifier(World& world, const CertifierOptions& options,
                             std::unique_ptr<KCPolytope> polytope)
    : world_(world), robot_(world.robot()), discrete_(options.discrete),
      max_guards_(options.max_guards), probes_(options.probes),
      learn_schedule_(options.learn_schedule), core_radius_(world.robot().core_radius()),
      domain_(world.robot().dimension(), options.low, options.high, world.robot().reach()),
      cache_(options.cache_entries) {
  if (options.certificates.empty())
    throw std::invalid_argument(
        "certificates: expected names from ball, rotation, polytope, region, region-lever");
  for (const std::string& name : options.certificates) {
    if (name == "ball" || name == "rotation") {
      certificates_.push_back(std::make_unique<ClearanceBall>(robot_, name == "rotation"));
    } else if (name == "region" || name == "region-lever") {
      certificates_.push_back(std::make_unique<FreeRegionPlanes>(robot_, name == "region"));
      use_region_ = true;
    } else if (name == "polytope") {
      if (!robot_.is_single())
        throw std::invalid_argument(
            "certificates: 'polytope' (the paper's bound) needs one body centred at the "
            "robot's origin");
      if (!polytope) throw std::invalid_argument("certificates: 'polytope' needs a ladder");
      certificates_.push_back(std::move(polytope));
    } else {
      throw std::invalid_argument("certificates: expected names from ball, rotation, polytope, "
                                  "region, region-lever, got '" + name + "'");
    }
  }
  if (max_guards_ < 0) throw std::invalid_argument("max_guards: expected a number >= 0");
  if (probes_ < 0) throw std::invalid_argument("probes: expected a number >= 0");
  covered_.assign(certificates_.size(), 0.0);
  horizon_ = options.horizon < 0.0 ? robot_.largest_semi_axis() : options.horizon;
  margin_ = world.atol() + 1e-12 * robot_.reach();
  const bool core = core_radius_ > 0.0;
  sweep_test_ = core && options.sweep_test;
  if (core && options.occupancy) grid_.emplace(world, options.low, options.high, core_radius_);
  clearances_.resize(robot_.size());
}

Guard EdgeCertifier::measure(const Pose& pose) {
  ++counters.guards;
  if (use_region_) {
    world_.free_regions(pose, horizon_, regions_);
    return Guard::from_regions(pose, regions_, robot_, margin_);
  }
  world_.safe_body_clearances(pose, clearances_.data());
  return Guard::of_clearances(clearances_.data(), clearances_.size());
}

bool EdgeCertifier::state_valid(const Pose& pose) {
  if (!domain_.admits(pose)) return false;
  const GuardCache::Key key = GuardCache::key(pose);
  const int known = cache_.validity(key);
  if (known >= 0) return known == 1;
  if (grid_ && grid_->blocked(pose.t)) {
    ++counters.occupancy_rejections;
    cache_.add_validity(key, false);
    return false;
  }
  return collision_free(pose, key);
}

bool EdgeCertifier::collision_free(const Pose& p, const GuardCache::Key& key) {
  ++counters.collision_queries;
  const bool valid = !world_.in_collision(p);
  if (!valid && grid_ && learning()) {  // learn the cell for the next state there
    const std::int64_t before = grid_->queries;
    grid_->learn(p.t);
    counters.occupancy_queries += grid_->queries - before;
  }
  cache_.add_validity(key, valid);
  return valid;
}

std::shared_ptr<const Guard> EdgeCertifier::endpoint(const Pose& pose,
                                                     const GuardCache::Key& key) {
  if (auto g = cache_.guard(key)) return g;
  ++counters.endpoint_guards;
  return cache_.add_guard(key, measure(pose));
}

void EdgeCertifier::reach(const Guard& guard, const Edge& edge, double m, double s0, double s1,
                          double& lo, double& hi) {
  double best_minus = 0.0, best_plus = 0.0;
  int win_minus = -1, win_plus = -1;
  const double need_minus = m - s0, need_plus = s1 - m;
  for (std::size_t i = 0; i < certificates_.size(); ++i) {
    double minus, plus;
    certificates_[i]->reach(guard, edge, m, minus, plus);
    if (minus > best_minus) best_minus = minus, win_minus = static_cast<int>(i);
    if (plus > best_plus) best_plus = plus, win_plus = static_cast<int>(i);
    if (best_minus >= need_minus && best_plus >= need_plus) break;  // later ones cannot add
  }
  lo = m - best_minus, hi = m + best_plus;
  if (win_minus >= 0 && m > s0) covered_[win_minus] += m - std::max(lo, s0);
  if (win_plus >= 0 && m < s1) covered_[win_plus] += std::min(hi, s1) - m;
}

bool EdgeCertifier::reject(std::int64_t& reason) {
  ++counters.rejected;
  ++reason;
  return false;
}

void EdgeCertifier::require_poses(const Pose& p1, const Pose& p2) const {
  if (p1.size != p2.size || p1.size != pose_size(robot_.dimension()))
    throw std::invalid_argument("pose: expected " + std::to_string(pose_size(robot_.dimension())) +
                                " numbers per pose");
}

bool EdgeCertifier::check(const Pose& p1, const Pose& p2, double resolution, bool with_probes) {
  CertifierCounters& c = counters;
  ++c.edges;
  require_poses(p1, p2);
  if (!domain_.admits(p1) || !domain_.admits(p2)) return reject(c.rejected_end_state);
  const GuardCache::Key k1 = GuardCache::key(p1), k2 = GuardCache::key(p2);
  CoreOccupancy* grid = grid_ ? &*grid_ : nullptr;
  if (grid && grid->blocked(p2.t)) return reject(c.rejected_occupancy);
  std::shared_ptr<const Guard> g1 = cache_.guard(k1), g2 = cache_.guard(k2);
  const bool had_g2 = g2 != nullptr;
  const int known = cache_.validity(k2);
  // a state never seen (RRT's new states): the free grid test before any query;
  // a known state (PRM's milestones): the cached guards first, they often suffice
  const bool tested = known < 0 && grid;
  if (tested && grid->segment_blocked(p1.t, p2.t)) return reject(c.rejected_occupancy);
  if (!(known == 1 || (known < 0 && collision_free(p2, k2)))) return reject(c.rejected_end_state);
  const Edge edge(p1, p2);
  double lo = 0.0, hi = 1.0, a, b;
  if (g1) {
    ++c.cached_guards;
    reach(*g1, edge, 0.0, 0.0, 1.0, a, lo);
  }
  if (g2 && lo < 1.0) {
    ++c.cached_guards;
    reach(*g2, edge, 1.0, lo, 1.0, hi, b);
  }
  if (lo >= hi) {
    ++c.certified_by_endpoints;
    return true;
  }
  if (!tested && grid && grid->segment_blocked(p1.t, p2.t)) return reject(c.rejected_occupancy);
  if (sweep_test_) {
    ++c.collision_queries;
    if (world_.sweep_core_collides(edge.pose(lo).t, edge.pose(hi).t, core_radius_))
      return reject(c.rejected_sweep);
  }
  if (with_probes && probing() && !probe(edge, lo, hi, probes_)) return reject(c.rejected_probe);
  if (!g1) {
    g1 = endpoint(p1, k1);
    if (g1->clearance <= 0.0) return reject(c.rejected_guard);
    reach(*g1, edge, 0.0, 0.0, hi, a, lo);
  }
  if (lo < hi && !had_g2) {
    g2 = endpoint(p2, k2);
    if (g2->clearance <= 0.0) return reject(c.rejected_end_state);
    reach(*g2, edge, 1.0, lo, 1.0, hi, b);
  }
  if (lo >= hi) {
    ++c.certified_by_endpoints;
    return true;
  }
  if (discrete_) return sample(edge, resolution, lo, hi);
  return advance(edge, lo, hi);
}

bool EdgeCertifier::probing() {
  // a probe costs a collision query on every edge it does not reject; it pays where
  // edges that reach the guards are often rejected (a guard costs several queries)
  return probes_ > 0 && probe_pace_.ask(counters.probed_edges, counters.rejected_probe);
}

bool EdgeCertifier::learning() {
  // a cell costs a ball query to test and saves a collision query each time it rejects
  // (a ball query costs about half of one): test cells while they pay
  const CertifierCounters& c = counters;
  return !learn_schedule_ ||
         learn_pace_.ask(c.occupancy_queries, c.occupancy_rejections + c.rejected_occupancy);
}

bool EdgeCertifier::screen(const Pose& p1, const Pose& p2, double step) {
  if (!(step > 0.0)) throw std::invalid_argument("screen: expected a step > 0");
  require_poses(p1, p2);
  ++counters.screened_edges;
  if (!domain_.admits(p1) || !domain_.admits(p2)) return false;
  if (grid_ && (grid_->blocked(p2.t) || grid_->segment_blocked(p1.t, p2.t))) return false;
  const GuardCache::Key k2 = GuardCache::key(p2);
  const int known = cache_.validity(k2);
  if (!(known == 1 || (known < 0 && collision_free(p2, k2)))) return false;
  const Edge edge(p1, p2);
  if (sweep_test_) {
    ++counters.collision_queries;
    if (world_.sweep_core_collides(p1.t, p2.t, core_radius_)) return false;
  }
  const double sweep = edge.translation_speed() + robot_.reach() * edge.rotation_speed();
  const double wanted = sweep / step;
  const int count = wanted >= kMaxScreenProbes ? kMaxScreenProbes : static_cast<int>(wanted);
  return count == 0 || probe(edge, 0.0, 1.0, count);
}

bool EdgeCertifier::probe(const Edge& edge, double lo, double hi, int count) {
  ++counters.probed_edges;
  // the van der Corput points 1/2, 1/4, 3/4, 1/8, 5/8, 3/8, ...: each probe halves the
  // largest stretch left unprobed, as bisection would
  for (int i = 1; i <= count; ++i) {
    double u = 0.0, bit = 0.5;
    for (int k = i; k > 0; k >>= 1, bit *= 0.5)
      if (k & 1) u += bit;
    ++counters.probes;
    ++counters.collision_queries;
    if (world_.in_collision(edge.pose(lo + u * (hi - lo)))) return false;
  }
  return true;
}

bool EdgeCertifier::advance(const Edge& edge, double lo, double hi) {
  CertifierCounters& c = counters;
  int guards = 0;
  const Advanced outcome = kcplan::advance(
      lo, hi, max_guards_, pending_,
      [&](double m, double s0, double s1, double& g_lo, double& g_hi) {
        const Guard guard = measure(edge.pose(m));
        if (guard.clearance <= 0.0) return false;
        reach(guard, edge, m, s0, s1, g_lo, g_hi);
        return true;
      },
      guards);
  return c.settle(outcome, guards);
}

bool EdgeCertifier::sample(const Edge& edge, double resolution, double lo, double hi) {
  if (!(resolution > 0.0)) throw std::invalid_argument("resolution: expected a positive number");
  const int steps = std::max(1, static_cast<int>(std::ceil(1.0 / resolution)));
  for (int i = 1; i < steps; ++i) {
    const double s = double(i) / steps;
    if (s <= lo || s >= hi) continue;  // covered by an endpoint guard
    ++counters.collision_queries;
    if (world_.in_collision(edge.pose(s))) return reject(counters.rejected_guard);
  }
  return true;
}

}  // namespace kcplan
