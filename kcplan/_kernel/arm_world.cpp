#include "arm_world.hpp"

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
/// by its own frame, World::place_bodies).
Robot bodies_of(const Chain& chain) {
  std::vector<double> semi_axes, poses;
  for (const ChainBody& b : chain.bodies()) {
    semi_axes.insert(semi_axes.end(), b.semi_axes.begin(), b.semi_axes.end());
    poses.insert(poses.end(), {0, 0, 0, 0, 0, 0, 1});
  }
  return Robot(3, semi_axes, poses, Robot::kMaxArmBodies);
}

}  // namespace

ArmWorld::ArmWorld(const Chain& chain, const std::vector<std::array<int, 2>>& pairs, double rtol,
                   double atol)
    : chain_(chain), pairs_(pairs) {
  const int count = static_cast<int>(chain.bodies().size());
  for (const auto& [k, l] : pairs)
    if (k < 0 || l < 0 || k >= count || l >= count || k == l)
      throw std::invalid_argument("pairs: expected two different body indices below " +
                                  std::to_string(count));
  scene_ = std::make_unique<World>(bodies_of(chain), 1.0, rtol, atol);
  for (const ChainBody& b : chain.bodies())
    shapes_.push_back(
        std::make_shared<coal::Ellipsoid>(b.semi_axes[0], b.semi_axes[1], b.semi_axes[2]));
  guesses_.assign(pairs.size(), coal::Vec3s(1.0, 0.0, 0.0));
  hints_.assign(pairs.size(), coal::support_func_guess_t::Zero());
}

const std::vector<coal::Transform3s>& ArmWorld::place(const double* q) {
  for (int j = 0; j < chain_.dof(); ++j)
    if (!std::isfinite(q[j]))
      throw std::invalid_argument("state: expected " + std::to_string(chain_.dof()) +
                                  " finite joint values");
  chain_.body_frames(q, joints_, frames_);
  scene_->place_bodies(frames_.data());
  return frames_;
}

double ArmWorld::pair_gap(std::size_t m, const std::vector<coal::Transform3s>& frames) const {
  const auto [k, l] = pairs_[m];
  const ChainBody &a = chain_.bodies()[k], &b = chain_.bodies()[l];
  const double centres = (frames[k].getTranslation() - frames[l].getTranslation()).norm();
  // the gap's rounding is below 1e-12 of the numbers involved
  return centres - a.a_max - b.a_max - 1e-12 * (1.0 + centres + a.a_max + b.a_max);
}

bool ArmWorld::pair_collides(std::size_t m, const std::vector<coal::Transform3s>& frames) {
  if (pair_gap(m, frames) > 0.0) return false;
  ++pair_queries;
  const auto [k, l] = pairs_[m];
  coal::CollisionRequest request = collision_request();
  request.cached_gjk_guess = guesses_[m];
  request.cached_support_func_guess = hints_[m];
  coal::CollisionResult result;
  coal::collide(shapes_[k].get(), frames[k], shapes_[l].get(), frames[l], request, result);
  guesses_[m] = result.cached_gjk_guess;
  hints_[m] = result.cached_support_func_guess;
  return result.isCollision();
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
  const std::vector<coal::Transform3s>& frames = place(q);
  if (scene_->bodies_collide()) return true;
  for (std::size_t m = 0; m < pairs_.size(); ++m)
    if (pair_collides(m, frames)) return true;
  return false;
}

void ArmWorld::safe_clearances(const double* q, double* scene, double* pairs) {
  const std::vector<coal::Transform3s>& frames = place(q);
  scene_clearances(scene);
  for (std::size_t m = 0; m < pairs_.size(); ++m) pairs[m] = pair_clearance(m, frames);
}

}  // namespace kcplan
