#include "arm_world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <coal/collision.h>
#include <coal/distance.h>
#include <coal/shape/geometric_shapes.h>

#include "coal_requests.hpp"

namespace kcplan {
namespace {

/// The chain's bodies as a Robot of ellipsoids at the robot frame's origin (each is placed
/// by its own frame, World::place_body).
Robot bodies_of(const Chain& chain) {
  std::vector<double> semi_axes, poses;
  for (const ChainBody& b : chain.bodies()) {
    semi_axes.insert(semi_axes.end(), b.semi_axes.begin(), b.semi_axes.end());
    poses.insert(poses.end(), {0, 0, 0, 0, 0, 0, 1});
  }
  return Robot(3, semi_axes, poses, Robot::kMaxArmBodies);
}

/// Which part each body belongs to: parts are numbered by the first body of their joint.
std::vector<int> parts_of(const Chain& chain) {
  std::vector<int> part_of_joint(chain.joint_count(), -1), out;
  int parts = 0;
  for (const ChainBody& b : chain.bodies()) {
    if (part_of_joint[b.joint] < 0) part_of_joint[b.joint] = parts++;
    out.push_back(part_of_joint[b.joint]);
  }
  return out;
}

/// The parts' balls, in their joints' frames: centred on the box of the bodies' bounding
/// balls, with a radius enclosing each of them (a_max of a ball is its radius).
Chain part_chain(const Chain& chain, const std::vector<int>& part_of) {
  const int parts = part_of.empty() ? 0 : *std::max_element(part_of.begin(), part_of.end()) + 1;
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<coal::Vec3s> lo(parts, coal::Vec3s::Constant(inf)), hi(parts, coal::Vec3s::Constant(-inf));
  std::vector<ChainBody> balls(parts);
  for (std::size_t k = 0; k < part_of.size(); ++k) {
    const ChainBody& b = chain.bodies()[k];
    const coal::Vec3s& c = b.placement.getTranslation();
    lo[part_of[k]] = lo[part_of[k]].cwiseMin(c - coal::Vec3s::Constant(b.a_max));
    hi[part_of[k]] = hi[part_of[k]].cwiseMax(c + coal::Vec3s::Constant(b.a_max));
    balls[part_of[k]].joint = b.joint;
  }
  for (int p = 0; p < parts; ++p)
    balls[p].placement = coal::Transform3s(coal::Matrix3s::Identity(), 0.5 * (lo[p] + hi[p]));
  for (std::size_t k = 0; k < part_of.size(); ++k) {
    const ChainBody& b = chain.bodies()[k];
    ChainBody& ball = balls[part_of[k]];
    const double r = (b.placement.getTranslation() - ball.placement.getTranslation()).norm() + b.a_max;
    ball.a_max = std::max(ball.a_max, r * (1.0 + 1e-12));  // rounding: the ball must hold
  }
  for (ChainBody& ball : balls) ball.semi_axes = {ball.a_max, ball.a_max, ball.a_max};
  return chain.with_bodies(std::move(balls));
}

}  // namespace

ArmWorld::ArmWorld(const Chain& chain, const std::vector<std::array<int, 2>>& pairs, double rtol,
                   double atol)
    : chain_(chain),
      part_of_(parts_of(chain)),
      parts_(part_chain(chain, part_of_)),
      pairs_(pairs) {
  const int count = static_cast<int>(chain.bodies().size());
  for (const auto& [k, l] : pairs)
    if (k < 0 || l < 0 || k >= count || l >= count || k == l)
      throw std::invalid_argument("pairs: expected two different body indices below " +
                                  std::to_string(count));
  for (std::size_t m = 0; m < pairs.size(); ++m) {
    const std::array<int, 2> group{part_of_[pairs[m][0]], part_of_[pairs[m][1]]};
    const auto it = std::find(groups_.begin(), groups_.end(), group);
    group_of_.push_back(static_cast<int>(it - groups_.begin()));
    if (it == groups_.end()) groups_.push_back(group);
    if (runs_.empty() || runs_.back().group != group_of_.back() ||
        pairs[runs_.back().begin][0] != pairs[m][0])  // one first body per run
      runs_.push_back({m, m + 1, group_of_.back(), pairs[m][0]});
    else
      runs_.back().end = m + 1;
  }
  scene_ = std::make_unique<World>(bodies_of(chain), 1.0, rtol, atol);
  part_sizes_.assign(parts_.bodies().size(), 0);
  for (int p : part_of_) ++part_sizes_[p];
  frames_.resize(chain.bodies().size());
  framed_.assign(chain.bodies().size(), 0);
  placed_.assign(chain.bodies().size(), 0);
  for (std::size_t k = 0; k < chain.bodies().size(); ++k) {
    const ChainBody& b = chain.bodies()[k];
    if (b.hull) {
      shapes_.push_back(b.hull->shape());
      scene_->set_body_shape(k, b.hull->shape());
    } else {
      shapes_.push_back(
          std::make_shared<coal::Ellipsoid>(b.semi_axes[0], b.semi_axes[1], b.semi_axes[2]));
    }
  }
  guesses_.assign(pairs.size(), coal::Vec3s(1.0, 0.0, 0.0));
  hints_.assign(pairs.size(), coal::support_func_guess_t::Zero());
}

void ArmWorld::locate(const double* q) {
  for (int j = 0; j < chain_.dof(); ++j)
    if (!std::isfinite(q[j]))
      throw std::invalid_argument("state: expected " + std::to_string(chain_.dof()) +
                                  " finite joint values");
  chain_.joint_frames(q, joints_);
  parts_.place_bodies(joints_, part_frames_);
  ++located_;
}

const coal::Transform3s& ArmWorld::frame(std::size_t k) {
  if (framed_[k] != located_) {
    const ChainBody& b = chain_.bodies()[k];
    frames_[k] = joints_[b.joint] * b.placement;
    framed_[k] = located_;
  }
  return frames_[k];
}

void ArmWorld::put(std::size_t k) {
  if (placed_[k] == located_) return;
  scene_->place_body(k, frame(k));
  placed_[k] = located_;
}

const std::vector<coal::Transform3s>& ArmWorld::place(const double* q) {
  locate(q);
  chain_.place_bodies(joints_, frames_);
  std::fill(framed_.begin(), framed_.end(), located_);
  return frames_;
}

void ArmWorld::scene_clearances(double* out, const double* caps) {
  if (caps == nullptr) {
    for (std::size_t k = 0; k < part_of_.size(); ++k) put(k);
    return scene_->bodies_safe_clearances(out);
  }
  ++scene_->counters.distance_queries;
  part_caps_.assign(parts_.bodies().size(), 0.0);
  for (std::size_t k = 0; k < part_of_.size(); ++k)
    part_caps_[part_of_[k]] = std::max(part_caps_[part_of_[k]], caps[k]);
  for (std::size_t p = 0; p < part_caps_.size(); ++p) {
    if (part_sizes_[p] == 1) {  // the part's ball is its body's: ask the body alone
      part_caps_[p] = 0.0;
      continue;
    }
    const coal::Vec3s& c = part_frames_[p].getTranslation();
    ++part_queries;
    const double d = scene_->ball_safe_clearance({c[0], c[1], c[2]}, parts_.bodies()[p].a_max,
                                                 part_caps_[p]);
    part_caps_[p] = d >= part_caps_[p] ? 1.0 : 0.0;  // now: whether the part is far
  }
  for (std::size_t k = 0; k < part_of_.size(); ++k) {
    if (part_caps_[part_of_[k]] > 0.0) {
      out[k] = caps[k];
      continue;
    }
    put(k);
    out[k] = scene_->capped_clearance(k, caps[k]);
  }
}

namespace {

/// How far the body at `frame` reaches from its centre along the unit n (its support
/// function about its centre): a hull's largest n . v, an ellipsoid's |diag(a) R^T n|.
double half_width(const ChainBody& body, const coal::Transform3s& frame, const coal::Vec3s& n) {
  const coal::Vec3s local = frame.getRotation().transpose() * n;
  if (body.hull) return body.hull->support(local);
  const std::array<double, 3>& a = body.semi_axes;
  return std::sqrt(a[0] * a[0] * local[0] * local[0] + a[1] * a[1] * local[1] * local[1] +
                   a[2] * a[2] * local[2] * local[2]);
}

/// What the rounding of a gap between two balls of radii ra and rb whose centres are
/// `between` apart may take off it: below 1e-12 of the numbers involved.
double gap_rounding(double between, double ra, double rb) {
  return 1e-12 * (1.0 + between + ra + rb);
}

/// A certain lower bound of the distance between anything inside those two balls.
double balls_gap(double between, double ra, double rb) {
  return between - ra - rb - gap_rounding(between, ra, rb);
}

/// |c - centres[3 q .. 3 q + 2]|, for centres stored three to a part.
double distance_to(const coal::Vec3s& c, const double* centres, int q) {
  const double dx = c[0] - centres[3 * q], dy = c[1] - centres[3 * q + 1],
               dz = c[2] - centres[3 * q + 2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

bool ArmWorld::body_separations(std::size_t k, const std::vector<coal::Transform3s>& frames,
                                 double horizon, std::vector<Separation>& out) {
  out.clear();
  placed_[k] = 0;  // it leaves the place of the last place()
  scene_->place_body(k, frames[k]);
  if (!scene_->body_region(k, horizon, region_, /*primitive_slabs=*/true)) return false;
  const ChainBody& body = chain_.bodies()[k];
  const coal::Vec3s& c = frames[k].getTranslation();
  for (const Plane& p : region_.planes) {
    Separation s;
    s.clearance = p.clearance;
    s.n = coal::Vec3s(-p.n[0], -p.n[1], -p.n[2]);  // the plane's normal points at the body
    s.gap = -std::numeric_limits<double>::infinity();
    if (std::isfinite(p.offset)) {
      // the obstacle lies in {n . x >= -offset}, the body in {n . x <= n . c + h(n)}
      const double reach = s.n.dot(c) + half_width(body, frames[k], s.n);
      const double rounding = 1e-12 * (1.0 + std::abs(p.offset) + c.norm() + body.a_max);
      s.gap = -p.offset - reach - rounding;
    }
    out.push_back(s);
  }
  return true;
}

double ArmWorld::ball_gap(std::size_t m, const std::vector<coal::Transform3s>& frames) const {
  const auto [k, l] = pairs_[m];
  const double a = chain_.bodies()[k].a_max, b = chain_.bodies()[l].a_max;
  return balls_gap((frames[l].getTranslation() - frames[k].getTranslation()).norm(), a, b);
}

double ArmWorld::pair_gap(std::size_t m, const std::vector<coal::Transform3s>& frames) const {
  const auto [k, l] = pairs_[m];
  const ChainBody &a = chain_.bodies()[k], &b = chain_.bodies()[l];
  const coal::Vec3s between = frames[l].getTranslation() - frames[k].getTranslation();
  const double centres = between.norm();
  // Along any unit n the two bodies are n . (c_l - c_k) - w_k(n) - w_l(-n) apart at least
  // (their support functions, half_width); along the centres' line this is never below the
  // bounding balls' gap (w <= a_max), and it depends on the configuration alone (not on
  // the pair's last GJK direction: the same radii whatever was asked before)
  double gap = centres - a.a_max - b.a_max;
  if (centres > 0.0) {
    const coal::Vec3s n = between / centres;
    gap = std::max(gap, centres - half_width(a, frames[k], n) - half_width(b, frames[l], -n));
  }
  return gap - gap_rounding(centres, a.a_max, b.a_max);
}

double ArmWorld::group_gap(std::size_t g, const double* centres) const {
  const auto [p, q] = groups_[g];
  const coal::Vec3s c(centres[3 * p], centres[3 * p + 1], centres[3 * p + 2]);
  return balls_gap(distance_to(c, centres, q), parts_.bodies()[p].a_max,
                   parts_.bodies()[q].a_max);
}

double ArmWorld::body_part_gap(std::size_t k, const std::vector<coal::Transform3s>& frames, int q,
                               const double* centres) const {
  return balls_gap(distance_to(frames[k].getTranslation(), centres, q), chain_.bodies()[k].a_max,
                   parts_.bodies()[q].a_max);
}

bool ArmWorld::pair_collides(std::size_t m, const std::vector<coal::Transform3s>& frames) {
  // the balls' gap first: it costs less, and pair_gap is never below it
  if (ball_gap(m, frames) > 0.0 || pair_gap(m, frames) > 0.0) return false;
  ++pair_queries;
  const auto [k, l] = pairs_[m];
  coal::CollisionRequest request = collision_request();
  request.cached_gjk_guess = guesses_[m];
  request.cached_support_func_guess = hints_[m];
  coal::CollisionResult result;
  coal::collide(shapes_[k].get(), frames[k], shapes_[l].get(), frames[l], request, result);
  guesses_[m] = result.cached_gjk_guess;
  hints_[m] = result.cached_support_func_guess;
  return confirmed_contact(result, [&] {
    return cold_collision(shapes_[k].get(), frames[k], shapes_[l].get(), frames[l]);
  });
}

double ArmWorld::pair_clearance(std::size_t m, const std::vector<coal::Transform3s>& frames) {
  ++pair_queries;
  const auto [k, l] = pairs_[m];
  coal::DistanceRequest request = distance_request(false);
  request.cached_gjk_guess = guesses_[m];
  request.cached_support_func_guess = hints_[m];
  coal::DistanceResult result;
  const double d =
      coal::distance(shapes_[k].get(), frames[k], shapes_[l].get(), frames[l], request, result);
  guesses_[m] = result.cached_gjk_guess;
  hints_[m] = result.cached_support_func_guess;
  return d > 0.0 ? scene_->safe(d) : 0.0;  // an overlap or what coal cannot tell (NaN)
}

bool ArmWorld::in_collision(const double* q) {
  locate(q);  // a body's frame only when a part's ball is near (frame(), put())
  // the scene: only the bodies of parts whose ball touches it
  ++scene_->counters.collision_queries;
  part_caps_.assign(parts_.bodies().size(), -1.0);  // per part: -1 not asked, 0 apart, 1 touches
  for (std::size_t k = 0; k < part_of_.size(); ++k) {
    double& touches = part_caps_[part_of_[k]];
    if (touches < 0.0 && part_sizes_[part_of_[k]] == 1) {
      touches = 1.0;  // the part's ball is its body's: ask the body alone
    } else if (touches < 0.0) {
      const coal::Vec3s& c = part_frames_[part_of_[k]].getTranslation();
      ++part_queries;
      touches = scene_->ball_touches({c[0], c[1], c[2]}, parts_.bodies()[part_of_[k]].a_max);
    }
    if (touches > 0.0) {
      put(k);
      if (scene_->body_collides(k)) return true;
    }
  }
  centres_.clear();
  for (const coal::Transform3s& f : part_frames_)
    for (int i = 0; i < 3; ++i) centres_.push_back(f.getTranslation()[i]);
  near_.resize(groups_.size());
  for (std::size_t g = 0; g < groups_.size(); ++g) near_[g] = !(group_gap(g, centres_.data()) > 0.0);
  for (const Run& run : runs_) {
    if (!near_[run.group]) continue;  // the parts' balls are apart
    frame(run.body);
    if (body_part_gap(run.body, frames_, groups_[run.group][1], centres_.data()) > 0.0)
      continue;  // the body's ball and the other part's are apart
    for (std::size_t m = run.begin; m < run.end; ++m) {
      frame(pairs_[m][1]);
      if (pair_collides(m, frames_)) return true;
    }
  }
  return false;
}

void ArmWorld::safe_clearances(const double* q, double* scene, double* pairs) {
  const std::vector<coal::Transform3s>& frames = place(q);
  scene_clearances(scene);
  for (std::size_t m = 0; m < pairs_.size(); ++m) pairs[m] = pair_clearance(m, frames);
}

}  // namespace kcplan
