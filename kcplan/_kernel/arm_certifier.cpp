#include "arm_certifier.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "advancement.hpp"

namespace kcplan {

ArmCertifier::ArmCertifier(ArmWorld& world, const ArmCertifierOptions& options)
    : world_(world),
      chain_(world.chain()),
      n_(world.chain().dof()),
      max_guards_(options.max_guards),
      probes_(options.probes),
      part_balls_(options.part_balls),
      first_order_(options.first_order),
      planes_(options.planes && options.first_order),
      kc_(options.kc_inflation),
      cache_(options.cache_entries),
      rho_(world.chain().point_speeds()),
      rho_pairs_(world.chain().relative_speeds(world.pairs())),
      rho_groups_(world.parts().relative_speeds(world.groups())),
      pair_first_(world.chain(), world.pairs()) {
  if (max_guards_ < 1) throw std::invalid_argument("max_guards: expected at least 1");
  if (!(kc_ >= 0.0) || !std::isfinite(kc_))
    throw std::invalid_argument("kc_inflation: expected a finite number >= 0");
  speed_.resize(chain_.bodies().size());
  pair_speed_.resize(world.pairs().size());
  q_.resize(n_);
  end_.resize(n_);
  caps_.resize(speed_.size());
  dq_.resize(n_);
  growth_.resize(speed_.size() * n_);
  body_growth_.resize(speed_.size());
  pair_growth_.resize(pair_speed_.size());
  pair_edge_.assign(pair_speed_.size(), 0);
  pair_growth_edge_.assign(pair_speed_.size(), 0);
  const std::vector<bool>& C = chain_.carries();
  for (const auto& [k, l] : world.pairs())
    for (int j = 0; j < n_; ++j) {
      const bool ck = C[k * n_ + j], cl = C[l * n_ + j];
      only_first_.push_back(ck && !cl), only_second_.push_back(cl && !ck);
    }
  const std::vector<bool>& P = world.parts().carries();
  for (const auto& [p, q] : world.groups())
    for (int j = 0; j < n_; ++j) {
      const bool cp = P[p * n_ + j], cq = P[q * n_ + j];
      group_first_.push_back(cp && !cq), group_second_.push_back(cq && !cp);
    }
  group_speed_.resize(world.groups().size());
  group_growth_.resize(world.groups().size());
  group_t_.resize(world.groups().size());
  part_growth_.resize(world.parts().bodies().size() * n_);
  step_.resize(n_);
  accel_.resize(speed_.size());
  first_.resize(speed_.size());
  turn_.resize(speed_.size());
  body_t_.resize(speed_.size());
}

double ArmCertifier::root(double d, double A, double Q) {
  return 2.0 * d / (A + std::sqrt(A * A + 2.0 * Q * d));  // the stable form
}

double ArmCertifier::reach(double d, double v, double A, double Q) {
  if (!(v > 0.0)) return std::numeric_limits<double>::infinity();  // it does not move
  return std::max(d / v, root(d, A, Q));
}

double ArmCertifier::body_reach(const ArmGuard& guard, std::size_t k, double d) const {
  double A, Q;
  terms(guard, k, A, Q);
  const double t = reach(d, speed_[k], A, Q);
  return first_order_ ? std::max(t, root(d, first_[k], accel_[k])) : t;
}

void ArmCertifier::twist(const ArmGuard& guard) {
  chain_.twists(guard.joints, guard.centres.data(), step_.data(), w_, u_);
  for (std::size_t k = 0; k < first_.size(); ++k) first_[k] = chain_.first_order_speed(k, w_[k], u_[k]);
}

template <class Frames>
double ArmCertifier::kc_reach(const ArmGuard& guard, std::size_t k, Frames& frames) {
  const ChainBody& body = chain_.bodies()[k];
  if (body.hull) return 0.0;  // KC's guard is an ellipsoid's: a hull has the ball alone
  const std::array<double, 3>& a = body.semi_axes;
  if (guard.grown[k] == 0) {
    if (guard.scene[k] > kc_ * body.a_max) {
      guard.grown[k] = 1;  // the grown body lies within kc a_max of the body: clear
    } else {
      ++grown_queries;
      ++counters.collision_queries;
      guard.grown[k] = world_.grown_clear(k, frames(), 1.0 + kc_) ? 1 : 2;
    }
  }
  if (guard.grown[k] != 1) return 0.0;
  const double a_min = std::min({a[0], a[1], a[2]});
  const double turn = (body.a_max - a_min) * turn_[k];  // the support function's turn
  // the centre moves at most v t and A t + Q t^2 / 2 (any point does); scaled by a_min
  double A, Q;
  terms(guard, k, A, Q);
  const double budget = kc_ * a_min;
  double t = speed_[k] + turn > 0.0 ? budget / (speed_[k] + turn)
                                    : std::numeric_limits<double>::infinity();
  t = std::max(t, root(budget, A + turn, Q));
  if (first_order_) {  // |diag(a)^-1 R^T u|: the centre's velocity in the guard's axes
    const coal::Vec3s b = frames()[k].getRotation().transpose() * u_[k];
    const double nu = std::sqrt((b[0] / a[0]) * (b[0] / a[0]) + (b[1] / a[1]) * (b[1] / a[1]) +
                                (b[2] / a[2]) * (b[2] / a[2])) * (1.0 + 1e-12);
    t = std::max(t, root(kc_, nu + turn / a_min, accel_[k] / a_min));
  }
  return t;
}

template <class Frames>
double ArmCertifier::plane_reach(const ArmGuard& guard, std::size_t k, double want,
                                 Frames& frames) {
  // the horizon beyond which the ball alone gives `want` (the caps of measure_into)
  double A, Q;
  terms(guard, k, A, Q);
  const double need = std::min({want * speed_[k], want * (A + 0.5 * want * Q),
                                want * (first_[k] + 0.5 * want * accel_[k])});
  const double horizon = std::max(kCapSlack * need, kClearanceFloor);
  if (guard.separated[k] < horizon) {
    ++plane_queries;
    if (!world_.body_separations(k, frames(), horizon, guard.separations[k])) {
      guard.separated[k] = -1.0;
      return 0.0;  // in contact, though its clearance said not: the ball alone decides
    }
    guard.separated[k] = horizon;
  }
  const ChainBody& body = chain_.bodies()[k];
  // rounding of the speed across: relative, and absolute for a speed near 0
  const double rounding = 1e-12 * (u_[k].norm() + w_[k].norm() * body.a_max);
  double t = body_reach(guard, k, guard.separated[k]);  // every obstacle beyond the horizon
  for (const ArmWorld::Separation& s : guard.separations[k]) {
    double ts = body_reach(guard, k, s.clearance);
    if (ts >= t) continue;  // this obstacle cannot lower t
    if (s.gap > 0.0) {
      // the fastest any point x moves across: |n . u + (x - c) . (n x w)|, exactly over a
      // hull's vertices (the largest of a linear function on it), else |x - c| <= a_max
      const double along = s.n.dot(u_[k]);
      const coal::Vec3s z = s.n.cross(w_[k]);
      double across = std::abs(along) + z.norm() * body.a_max;
      if (body.hull) {
        const coal::Vec3s local = frames()[k].getRotation().transpose() * z;
        across = std::max(along + body.hull->support(local), -along + body.hull->support(-local));
      }
      across = across * (1.0 + 1e-12) + rounding;
      ts = std::max(ts, root(s.gap, across, accel_[k]));
    }
    t = std::min(t, ts);
  }
  return t;
}

template <class Frames>
void ArmCertifier::body_radius(const ArmGuard& guard, std::size_t k, double enough, double& r,
                               Frames& frames) {
  // the global speed alone may already give r (reach >= d / v): then nothing here can
  // lower r, nor is anything refined (that needs a reach below r)
  if (guard.scene[k] >= r * speed_[k]) return;
  double t = body_reach(guard, k, guard.scene[k]);
  if (kc_ > 0.0 && t < std::min(r, enough)) {
    const double kc = kc_reach(guard, k, frames);
    if (kc > t) ++kc_reaches, t = kc;
  }
  if (!guard.scene_exact[k] && t < std::min(r, enough)) {
    const double cap = std::numeric_limits<double>::infinity();
    guard.scene[k] = std::max(guard.scene[k], world_.body_clearance(k, frames(), cap));
    guard.scene_exact[k] = 1;
    ++refined_bodies;
    t = std::max(t, body_reach(guard, k, guard.scene[k]));
  }
  r = std::min(r, t);
}

void ArmCertifier::terms(const ArmGuard& guard, std::size_t k, double& A, double& Q) const {
  const std::size_t bodies = speed_.size();
  A = 0.0;
  if (k < bodies) {
    for (int j = 0; j < n_; ++j) A += dq_[j] * guard.levers[k * n_ + j];
    Q = body_growth_[k];
    return;
  }
  const std::size_t m = k - bodies;
  const auto [a, b] = world_.pairs()[m];
  for (int j = 0; j < n_; ++j)
    A += dq_[j] * (only_first_[m * n_ + j] * guard.levers[a * n_ + j] +
                   only_second_[m * n_ + j] * guard.levers[b * n_ + j]);
  Q = pair_growth(m);
}

double ArmCertifier::pair_reach(const ArmGuard& guard, std::size_t m, double d, double enough) {
  double A, Q;
  terms(guard, speed_.size() + m, A, Q);
  const double t = reach(d, pair_speed(m), A, Q);
  if (!first_order_ || t >= enough) return t;  // the first order could only add to it
  return std::max(t, root(d, pair_first_.speed(m), pair_first_.accel(m)));
}

double ArmCertifier::pair_speed(std::size_t m) const {
  if (pair_edge_[m] == edge_) return pair_speed_[m];
  pair_edge_[m] = edge_;
  double v = 0.0;
  for (int j = 0; j < n_; ++j) v += rho_pairs_[m * n_ + j] * dq_[j];
  return pair_speed_[m] = v;
}

double ArmCertifier::pair_growth(std::size_t m) const {
  if (pair_growth_edge_[m] == edge_) return pair_growth_[m];
  pair_growth_edge_[m] = edge_;
  const auto [a, b] = world_.pairs()[m];
  double Q = 0.0;
  for (int j = 0; j < n_; ++j)
    Q += only_first_[m * n_ + j] * growth_[a * n_ + j] +
         only_second_[m * n_ + j] * growth_[b * n_ + j];
  return pair_growth_[m] = Q;
}

template <class Frames>
double ArmCertifier::run_reach(const ArmGuard& guard, const ArmWorld::Run& run, Frames& frames,
                               double& speed) {
  const int g = run.group, k = run.body, q = world_.groups()[g][1];
  double v = 0.0, A = 0.0, Q = 0.0;
  for (int j = 0; j < n_; ++j) {
    const double first = group_first_[g * n_ + j], second = group_second_[g * n_ + j];
    v += dq_[j] * (first * rho_[k * n_ + j] + second * world_.parts().point_speeds()[q * n_ + j]);
    A += dq_[j] * (first * guard.levers[k * n_ + j] + second * guard.part_levers[q * n_ + j]);
    Q += first * growth_[k * n_ + j] + second * part_growth_[q * n_ + j];
  }
  speed = v;
  if (!(v > 0.0)) return std::numeric_limits<double>::infinity();
  const double gap = world_.body_part_gap(k, frames(), q, guard.part_centres.data());
  return reach(std::max(gap, 0.0), v, A, Q);
}

double ArmCertifier::group_reach(const ArmGuard& guard, std::size_t g) const {
  const double v = group_speed_[g];
  if (!(v > 0.0)) return std::numeric_limits<double>::infinity();
  const auto [p, q] = world_.groups()[g];
  double A = 0.0;
  for (int j = 0; j < n_; ++j)
    A += dq_[j] * (group_first_[g * n_ + j] * guard.part_levers[p * n_ + j] +
                   group_second_[g * n_ + j] * guard.part_levers[q * n_ + j]);
  const double gap = world_.group_gap(g, guard.part_centres.data());
  return reach(std::max(gap, 0.0), v, A, group_growth_[g]);
}

template <class Frames>
void ArmCertifier::pair_radius(const ArmGuard& guard, std::size_t m, double enough, double& r,
                               Frames& frames, double bound) {
  // as in body_radius: a lower bound of the distance that gives r at the global speed
  // (the bounding balls' gap before the pair's own gap, which costs more) decides it; at
  // `bound`, above the speed, before the speed is summed
  const double ball = guard.pair_known[m] ? 0.0 : world_.ball_gap(m, frames());
  if (!guard.pair_known[m] && ball >= r * bound) return;
  const double v = pair_speed(m);
  if (!(v > 0.0)) return;
  if (!guard.pair_known[m]) {
    if (ball >= r * v) return;
    guard.pairs[m] = std::max(world_.pair_gap(m, frames()), 0.0);
    guard.pair_known[m] = 1;
  }
  if (guard.pairs[m] >= r * v) return;
  double t = pair_reach(guard, m, guard.pairs[m], std::min(r, enough));
  if (guard.pair_known[m] == 1 && t < std::min(r, enough)) {
    guard.pairs[m] = std::max(guard.pairs[m], world_.pair_clearance(m, frames()));
    guard.pair_known[m] = 2;
    ++refined_pairs;
    if (!(guard.pairs[m] > 0.0)) guard.clearance = 0.0;  // in contact: the state is not free
    t = pair_reach(guard, m, guard.pairs[m], std::min(r, enough));
  }
  r = std::min(r, t);
}

bool ArmCertifier::reject(std::int64_t& reason) {
  ++counters.rejected;
  ++reason;
  return false;
}

bool ArmCertifier::certified_by_endpoints() {
  ++counters.certified_by_endpoints;
  covered_ball += 1.0;
  return true;
}

bool ArmCertifier::probe(const double* q1, const double* q2, double lo, double hi,
                         double length, double step) {
  const double wanted = (hi - lo) * length / step;
  const int count = wanted >= kMaxProbes ? kMaxProbes : static_cast<int>(wanted);
  if (count == 0) return true;
  ++counters.probed_edges;
  // the van der Corput points 1/2, 1/4, 3/4, 1/8, ...: each halves the largest stretch
  // left unprobed, as bisection would (kcplan/certification/certifier.py probe_points)
  for (int i = 1; i <= count; ++i) {
    double u = 0.0, bit = 0.5;
    for (int k = i; k > 0; k >>= 1, bit *= 0.5)
      if (k & 1) u += bit;
    const double s = lo + u * (hi - lo);
    for (int j = 0; j < n_; ++j) q_[j] = q1[j] + s * (q2[j] - q1[j]);
    ++counters.probes;
    ++counters.collision_queries;
    if (world_.in_collision(q_.data())) return false;
  }
  return true;
}

bool ArmCertifier::screen(const double* q1, const double* q2, double step) {
  if (!(step > 0.0)) throw std::invalid_argument("screen: expected a step > 0");
  ++counters.screened_edges;
  q2 = chain_.edge_end(q1, q2, end_.data());  // a wrapping angle turns the shorter way
  if (!chain_.admits(q1) || !chain_.admits(q2) || !state_valid(q2)) return false;
  double length = 0.0;
  for (int j = 0; j < n_; ++j) length += (q2[j] - q1[j]) * (q2[j] - q1[j]);
  return probe(q1, q2, 0.0, 1.0, std::sqrt(length), step);
}

bool ArmCertifier::state_valid(const double* q) {
  if (!chain_.admits(q)) return false;
  const ArmGuardCache::Key key = ArmGuardCache::key_of(q, n_);
  int known = cache_.validity(key);
  if (known < 0) {
    ++counters.collision_queries;
    known = !world_.in_collision(q);
    cache_.add_validity(key, known);
  }
  return known == 1;
}

ArmGuard ArmCertifier::measure(const double* q, double enough) {
  ArmGuard g;
  measure_into(q, enough, g);
  return g;
}

void ArmCertifier::measure_into(const double* q, double enough, ArmGuard& g) {
  ++counters.guards;
  std::copy(q, q + n_, g.q.begin());
  const std::size_t bodies = chain_.bodies().size(), pairs = world_.pairs().size();
  g.scene.resize(bodies);
  g.pairs.resize(pairs);
  g.levers.resize(bodies * n_);
  g.scene_exact.assign(bodies, !(enough > 0.0));
  g.pair_known.assign(pairs, 0);
  const std::vector<coal::Transform3s>& frames = world_.place(q);
  g.location = world_.location();
  chain_.levers(world_.joint_frames(), frames, g.levers.data());
  g.grown.assign(bodies, 0);
  g.separated.assign(bodies, -1.0);
  g.separations.resize(bodies);
  if (first_order_ || kc_ > 0.0) {
    g.joints = world_.joint_frames();
    g.centres.clear();
    for (const coal::Transform3s& f : frames)
      for (int i = 0; i < 3; ++i) g.centres.push_back(f.getTranslation()[i]);
    twist(g);
  }
  const Chain& parts = world_.parts();
  g.part_levers.resize(parts.bodies().size() * n_);
  parts.levers(world_.joint_frames(), world_.part_frames(), g.part_levers.data());
  g.part_centres.clear();
  for (const coal::Transform3s& f : world_.part_frames())
    for (int i = 0; i < 3; ++i) g.part_centres.push_back(f.getTranslation()[i]);
  if (enough > 0.0) {  // what a radius of `enough` needs: min(e v, e A + e^2 Q / 2, ...)
    double A, Q;
    for (std::size_t k = 0; k < bodies; ++k) {
      terms(g, k, A, Q);
      double need = std::min(enough * speed_[k], enough * (A + 0.5 * enough * Q));
      if (first_order_) need = std::min(need, enough * (first_[k] + 0.5 * enough * accel_[k]));
      caps_[k] = std::max(kCapSlack * need, kClearanceFloor);
    }
    world_.scene_clearances(g.scene.data(), caps_.data());
  } else {
    world_.scene_clearances(g.scene.data());
  }
  g.clearance = std::numeric_limits<double>::infinity();
  for (double d : g.scene) g.clearance = std::min(g.clearance, d);
  if (part_balls_ && enough > 0.0) return;  // the pairs when a radius asks (pair_radius)
  for (std::size_t m = 0; m < pairs; ++m) {
    g.pairs[m] = world_.pair_gap(m, frames);
    g.pair_known[m] = 1;
    if (g.pairs[m] <= 0.0) {  // the balls meet: only GJK can tell whether the bodies do
      g.pairs[m] = world_.pair_clearance(m, frames);
      g.pair_known[m] = 2;
    }
    g.clearance = std::min(g.clearance, g.pairs[m]);
  }
}

double ArmCertifier::radius(const ArmGuard& guard, double enough) {
  if (guard.clearance <= 0.0) return 0.0;
  const std::size_t bodies = speed_.size();
  double r = std::numeric_limits<double>::infinity();
  if (first_order_ || kc_ > 0.0) twist(guard);  // the bodies' twists here, for this edge
  if (first_order_) pair_first_.guard(guard.joints, guard.centres.data());
  // the bodies' frames at the guard: the world's if it is still where the guard was
  // measured (ArmGuard::location), else computed on first use
  const std::vector<coal::Transform3s>* at = nullptr;
  const auto frames = [&]() -> const std::vector<coal::Transform3s>& {
    if (at == nullptr) {
      if (guard.location != 0 && guard.location == world_.location()) {
        at = &world_.placed_frames();
      } else {
        chain_.body_frames(guard.q.data(), joints_, frames_);
        at = &frames_;
      }
    }
    return *at;
  };
  constexpr double kOpen = 1.0 - 1e-9;  // the open stretch, with a margin for rounding
  if (!(planes_ && first_order_)) {
    // the measured clearances first; then a capped one that would hold r below what is
    // needed is refined (after the KC guard): the radius is then that of exact distances
    // (and KC guards), or at least `enough`
    for (int exact = 1; exact >= 0; --exact)
      for (std::size_t k = 0; k < bodies; ++k)
        if (speed_[k] > 0.0 && guard.scene_exact[k] == exact)
          body_radius(guard, k, enough, r, frames);
    return pairs_radius(guard, enough, r, frames) * kOpen;
  }
  // With the planes, which cost a region query of the body, a body's planes are asked
  // only where they may raise the radius: the balls (and KC guards) of all bodies and the
  // pairs first (a pair below every body's ball decides it), then the planes of the body
  // that limits, in turn, until one whose planes were measured as far as needed limits
  // it, then the pairs again (a pair the balls' radius left out may limit the new one).
  // Every term is the one of exact distances where it is below `enough` (the class docs),
  // so is the radius.
  std::vector<double>& t = body_t_;
  for (std::size_t k = 0; k < bodies; ++k) {
    t[k] = std::numeric_limits<double>::infinity();
    if (!(speed_[k] > 0.0)) continue;
    t[k] = body_reach(guard, k, guard.scene[k]);
    if (kc_ > 0.0 && t[k] < enough) {
      const double kc = kc_reach(guard, k, frames);
      if (kc > t[k]) ++kc_reaches, t[k] = kc;
    }
  }
  double least = *std::min_element(t.begin(), t.end());
  const double balls = pairs_radius(guard, enough, least, frames);
  if (balls < least || !(least < enough)) return balls * kOpen;
  // each body's planes as far as `enough` needs, once: then it limits where it is least
  for (std::size_t round = 0; round < bodies; ++round) {
    const std::size_t arg = std::min_element(t.begin(), t.end()) - t.begin();
    least = t[arg];
    if (!(least < enough)) break;
    const double p = plane_reach(guard, arg, enough, frames);
    if (!(p > least)) break;  // its planes add nothing: it limits
    ++plane_reaches;
    t[arg] = p;
    if (p < enough) {  // it may still limit: the others are asked only while below it
      bool below = false;
      for (std::size_t k = 0; k < bodies; ++k) below = below || (k != arg && t[k] < p);
      if (!below) break;
    }
  }
  return pairs_radius(guard, enough, *std::min_element(t.begin(), t.end()), frames) * kOpen;
}

template <class Frames>
double ArmCertifier::pairs_radius(const ArmGuard& guard, double enough, double r,
                                  Frames& frames) {
  if (!part_balls_) {
    const double unknown = std::numeric_limits<double>::infinity();  // no bound but v
    for (std::size_t m = 0; m < pair_speed_.size(); ++m)
      pair_radius(guard, m, enough, r, frames, unknown);
    return r;
  }
  // a group whose gap gives its pairs at least r cannot lower r (the class docs)
  std::fill(group_t_.begin(), group_t_.end(), -1.0);
  for (const ArmWorld::Run& run : world_.runs()) {
    if (!(r > 0.0)) return 0.0;
    double& g = group_t_[run.group];
    if (g < 0.0) g = group_reach(guard, run.group);
    if (g >= r) {
      ++skipped_groups;
      continue;
    }
    double v;  // the run's speed: at least each of its pairs'
    if (run_reach(guard, run, frames, v) >= r) continue;  // the body against the other part
    for (std::size_t m = run.begin; m < run.end; ++m) pair_radius(guard, m, enough, r, frames, v);
  }
  return r;
}

std::shared_ptr<const ArmGuard> ArmCertifier::endpoint(const double* q,
                                                       const ArmGuardCache::Key& key) {
  if (auto g = cache_.guard(key)) {
    ++counters.cached_guards;
    return g;
  }
  ++counters.endpoint_guards;
  return cache_.add_guard(key, measure(q, 1.0));  // this edge's whole length from this end
}

void ArmCertifier::set_edge(const double* step) {
  const std::size_t dof = n_;
  for (std::size_t j = 0; j < dof; ++j) step_[j] = step[j], dq_[j] = std::abs(step[j]);
  for (std::size_t k = 0; k < speed_.size(); ++k) {
    double v = 0.0;
    for (std::size_t j = 0; j < dof; ++j) v += rho_[k * dof + j] * dq_[j];
    speed_[k] = v;
  }
  chain_.lever_growth(dq_.data(), growth_.data());
  for (std::size_t k = 0; k < speed_.size(); ++k) {
    double Q = 0.0;
    for (std::size_t j = 0; j < dof; ++j) Q += growth_[k * dof + j];
    body_growth_[k] = Q;
  }
  if (first_order_ || kc_ > 0.0) chain_.point_accelerations(dq_.data(), accel_.data());
  if (kc_ > 0.0) chain_.turn_speeds(dq_.data(), turn_.data());
  if (first_order_) pair_first_.edge(step_.data());
  ++edge_;  // the pairs' speeds and growth: on first use for this edge (pair_speed, ...)
  if (part_balls_) {
    const Chain& parts = world_.parts();
    for (std::size_t g = 0; g < group_speed_.size(); ++g) {
      double v = 0.0;
      for (std::size_t j = 0; j < dof; ++j) v += rho_groups_[g * dof + j] * dq_[j];
      group_speed_[g] = v;
    }
    parts.lever_growth(dq_.data(), part_growth_.data());
    for (std::size_t g = 0; g < group_growth_.size(); ++g) {
      const auto [p, q] = world_.groups()[g];
      double Q = 0.0;
      for (std::size_t j = 0; j < dof; ++j)
        Q += group_first_[g * dof + j] * part_growth_[p * dof + j] +
             group_second_[g * dof + j] * part_growth_[q * dof + j];
      group_growth_[g] = Q;
    }
  }
}

bool ArmCertifier::check_blend(const double* a, const double* c, const double* b,
                               int max_guards) {
  if (!chain_.admits(a) || !chain_.admits(c) || !chain_.admits(b)) return false;
  for (int j = 0; j < n_; ++j)
    q_[j] = 2.0 * std::max(std::abs(c[j] - a[j]), std::abs(b[j] - c[j]));
  // the bounds of a curve: the speed and lever terms only (the class docs)
  const bool first_order = first_order_;
  const double kc = kc_;
  first_order_ = false, kc_ = 0.0;
  set_edge(q_.data());
  std::vector<double> point(n_);
  int guards = 0;
  const Advanced outcome = advance(
      0.0, 1.0, max_guards, pending_,
      [&](double t, double s0, double s1, double& g_lo, double& g_hi) {
        const double u = 1.0 - t;
        for (int j = 0; j < n_; ++j) point[j] = u * u * a[j] + 2.0 * t * u * c[j] + t * t * b[j];
        const double enough = 0.5 * (s1 - s0);
        measure_into(point.data(), enough, scratch_);
        const double r = radius(scratch_, enough);
        if (r <= 0.0) return false;
        g_lo = t - r, g_hi = t + r;
        return true;
      },
      guards);
  first_order_ = first_order, kc_ = kc;
  return outcome == Advanced::kCovered;
}

bool ArmCertifier::check(const double* q1, const double* q2, bool with_probes) {
  CertifierCounters& c = counters;
  ++c.edges;
  q2 = chain_.edge_end(q1, q2, end_.data());  // a wrapping angle turns the shorter way
  if (!chain_.admits(q1) || !chain_.admits(q2)) return reject(c.rejected_end_state);
  if (!state_valid(q2)) return reject(c.rejected_end_state);
  for (int j = 0; j < n_; ++j) q_[j] = q2[j] - q1[j];
  set_edge(q_.data());
  const ArmGuardCache::Key k1 = ArmGuardCache::key_of(q1, n_), k2 = ArmGuardCache::key_of(q2, n_);
  std::shared_ptr<const ArmGuard> g1 = cache_.guard(k1), g2 = cache_.guard(k2);
  double lo = 0.0, hi = 1.0;
  if (g1) {
    ++c.cached_guards;
    lo = radius(*g1, 1.0);
  }
  if (g2 && lo < 1.0) {
    ++c.cached_guards;
    hi = 1.0 - radius(*g2, 1.0 - lo);
  }
  if (lo >= hi) return certified_by_endpoints();
  if (probes_ && with_probes) {
    double length = 0.0;
    for (int j = 0; j < n_; ++j) length += (q2[j] - q1[j]) * (q2[j] - q1[j]);
    if (!probe(q1, q2, lo, hi, std::sqrt(length))) return reject(c.rejected_probe);
  }
  if (!g1) {
    lo = radius(*endpoint(q1, k1), 1.0);
    if (lo <= 0.0) return reject(c.rejected_guard);
  }
  if (!g2 && lo < hi) {
    hi = 1.0 - radius(*endpoint(q2, k2), 1.0 - lo);
    if (hi >= 1.0) return reject(c.rejected_end_state);
  }
  if (lo >= hi) return certified_by_endpoints();
  int guards = 0;
  const Advanced outcome = advance(
      lo, hi, max_guards_, pending_,
      [&](double m, double s0, double s1, double& g_lo, double& g_hi) {
        for (int j = 0; j < n_; ++j) q_[j] = q1[j] + m * (q2[j] - q1[j]);
        const double enough = 0.5 * (s1 - s0);  // this guard covers [s0, s1] with that
        measure_into(q_.data(), enough, scratch_);  // a guard of this edge only: not kept
        const double r = radius(scratch_, enough);
        if (r <= 0.0) return false;
        g_lo = m - r, g_hi = m + r;
        return true;
      },
      guards);
  if (!c.settle(outcome, guards)) return false;
  covered_ball += 1.0;
  return true;
}

}  // namespace kcplan
