// A rigid robot of ellipses (2D) or ellipsoids (3D).
// Python twin: kcplan/geometry/robot.py (Body, Robot; same levers, reach and core radius).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "pose.hpp"

namespace kcplan {

/// One body E_k = {p_k + R_k A_k u : |u| <= 1} in the robot frame.
struct Body {
  std::array<double, 3> semi_axes{0.0, 0.0, 0.0};  ///< a_k, third 0 in 2D
  std::array<double, 3> position{0.0, 0.0, 0.0};   ///< p_k, third 0 in 2D
  Quat turn;                                       ///< R_k
  double yaw = 0.0;                                ///< R_k's yaw in 2D
  double a_max = 0.0, a_min = 0.0;

  /// |p_k|: distance of the centre from the robot's origin.
  double offset() const {
    return std::sqrt(position[0] * position[0] + position[1] * position[1] +
                     position[2] * position[2]);
  }
  /// |p_k| + a_max - a_min: bound on the rate of change of the body's support function
  /// per radian of robot rotation (proof in kcplan/certification/certificates/ball.py).
  double lever() const { return offset() + a_max - a_min; }
  /// |p_k| + a_max: every point of the body lies this close to the robot's origin.
  double reach() const { return offset() + a_max; }
};

/// The robot: at most 32 bodies of one dimension (an arm's bodies, each placed by its own
/// frame, up to kMaxArmBodies). Body k at the robot pose (R, t) has the world pose
/// (R R_k, t + R p_k).
class Robot {
 public:
  static constexpr int kMaxBodies = 32, kMaxArmBodies = 1024;

  /// `semi_axes` and `poses` hold one row per body: `dimension` semi-axes, and the body's
  /// flat pose in the robot frame ([x, y, yaw] or [x, y, z, qx, qy, qz, qw]).
  Robot(int dimension, const std::vector<double>& semi_axes, const std::vector<double>& poses,
        int max_bodies = kMaxBodies)
      : dimension_(dimension) {
    const int size = pose_size(dimension);
    const std::size_t count = semi_axes.size() / dimension;
    if (count == 0 || semi_axes.size() != count * dimension || poses.size() != count * size)
      throw std::invalid_argument("robot: expected " + std::to_string(dimension) +
                                  " semi-axes and " + std::to_string(size) +
                                  " pose numbers per body");
    if (count > static_cast<std::size_t>(max_bodies))
      throw std::invalid_argument("robot: expected at most " + std::to_string(max_bodies) +
                                  " bodies, got " + std::to_string(count));
    for (std::size_t k = 0; k < count; ++k) {
      Body b;
      b.a_max = 0.0, b.a_min = INFINITY;
      for (int i = 0; i < dimension; ++i) {
        const double a = semi_axes[k * dimension + i];
        if (!(a > 0.0) || !std::isfinite(a))
          throw std::invalid_argument("robot: semi-axes must be positive finite numbers, got " +
                                      std::to_string(a));
        b.semi_axes[i] = a;
        b.a_max = std::max(b.a_max, a), b.a_min = std::min(b.a_min, a);
      }
      const Pose p = Pose::from_flat(&poses[k * size], size);
      if (!p.finite) throw std::invalid_argument("robot: body poses must be finite");
      b.position = p.t;
      b.turn = p.q;
      b.yaw = dimension == 2 ? p.raw[2] : 0.0;
      bool at_origin = true;
      for (int i = 0; i < size; ++i)
        at_origin = at_origin && p.raw[i] == (size == 7 && i == 6 ? 1.0 : 0.0);
      single_ = count == 1 && at_origin;
      bodies_.push_back(b);
    }
  }

  int dimension() const { return dimension_; }
  const std::vector<Body>& bodies() const { return bodies_; }
  std::size_t size() const { return bodies_.size(); }
  /// One body centred at the origin: the paper's E_a.
  bool is_single() const { return single_; }

  double largest_semi_axis() const {
    double m = 0.0;
    for (const Body& b : bodies_) m = std::max(m, b.a_max);
    return m;
  }
  double reach() const {
    double m = 0.0;
    for (const Body& b : bodies_) m = std::max(m, b.reach());
    return m;
  }
  /// Radius of a ball about the origin the robot contains in every orientation (0: none).
  double core_radius() const {
    double m = 0.0;
    for (const Body& b : bodies_) m = std::max(m, b.a_min - b.offset());
    return m;
  }

  /// World centre and orientation of body k at the robot pose `pose`.
  void body_pose(const Pose& pose, std::size_t k, std::array<double, 3>& centre,
                 Quat& orientation) const {
    const Body& b = bodies_[k];
    if (single_) {
      centre = pose.t, orientation = pose.q;
      return;
    }
    const std::array<double, 3> o = pose.q.rotate(b.position);
    centre = {pose.t[0] + o[0], pose.t[1] + o[1], pose.t[2] + o[2]};
    orientation = pose.q * b.turn;
  }

 private:
  int dimension_;
  bool single_ = false;
  std::vector<Body> bodies_;
};

}  // namespace kcplan
