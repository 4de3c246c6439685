// An arm's kinematic chain (the reduced model of its planning group), the ellipsoids that
// cover its links, and the chain's speed bounds.
// Python twins: kcplan/arm/kinematics.py (frames) and kcplan/arm/bounds.py (speeds).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <memory>

#include <coal/math/transform.h>

#include "convex_body.hpp"

namespace kcplan {

/// One joint of the reduced model: joint i's frame is
/// oMi[i] = oMi[parent] * placement * motion(q[state]), motion turning by q about `axis`
/// (revolute) or sliding q along it (prismatic); oMi[0] (the universe) is the identity.
struct ChainJoint {
  int parent = 0;
  coal::Transform3s placement;
  coal::Vec3s axis{0, 0, 1};  ///< unit, in the joint's frame
  bool prismatic = false;
  int state = 0;  ///< which number of the state moves it
};

/// One body of a link: an ellipsoid of semi-axes along its frame's axes, or (`hull` set)
/// a convex body inside that ellipsoid; its frame `placement` in the frame of the joint
/// that carries it (joint 0: fixed to the universe). Every speed bound holds for the
/// ellipsoid, hence for a hull inside it; collision queries use the hull.
struct ChainBody {
  int joint = 0;
  coal::Transform3s placement;
  std::array<double, 3> semi_axes{0, 0, 0};
  double a_max = 0.0;
  std::shared_ptr<const BodyHull> hull;  ///< null: the body is the ellipsoid
};

/// The immutable description of an arm: joints, limits and covering bodies, with the
/// chain's configuration-independent speed bounds (kcplan/arm/bounds.py, Schwarzer, Saha
/// and Latombe 2005, Sec. III).
///
/// Contract: states are the group's joint values (dof() numbers, radians or metres); the
/// constructor throws std::invalid_argument for an inconsistent description (a parent
/// after its child, a state index out of range, a zero axis, limits not lower <= upper,
/// semi-axes not positive). Every method is const: a Chain is shared by worlds and
/// certifiers.
class Chain {
 public:
  static constexpr int kMaxJoints = 24;  // a moving base and two arms: TIAGo dual has 20

  /// `parents`, `placements` (16 numbers per joint, a row-major homogeneous matrix),
  /// `axes` (3 per joint), `prismatic` and `states` describe joints 1..n of the reduced
  /// model (joint 0 is the universe); `lower`, `upper` the limits in state order;
  /// `body_joints`, `body_placements` (16 per body) and `semi_axes` (3 per body) the
  /// bodies; `hull_vertices` and `hull_triangles` (one list per body, or none at all)
  /// the hull of each body that is convex rather than its ellipsoid (empty lists for an
  /// ellipsoid; m x 3 vertices in the body's frame, t x 3 indices). A hull must lie in
  /// its body's ellipsoid (std::invalid_argument otherwise). `wraps` (dof() flags, or
  /// none) marks the revolute joints whose angle wraps (a moving base's yaw, a continuous
  /// joint; kcplan/arm/description.py): admits() takes any finite angle of theirs, and an
  /// edge turns them the shorter way (edge_end()).
  Chain(const std::vector<int>& parents, const std::vector<double>& placements,
        const std::vector<double>& axes, const std::vector<bool>& prismatic,
        const std::vector<int>& states, const std::vector<double>& lower,
        const std::vector<double>& upper, const std::vector<int>& body_joints,
        const std::vector<double>& body_placements, const std::vector<double>& semi_axes,
        const std::vector<std::vector<double>>& hull_vertices = {},
        const std::vector<std::vector<int>>& hull_triangles = {},
        const std::vector<bool>& wraps = {});

  int dof() const { return static_cast<int>(lower_.size()); }
  /// Joints of the reduced model, the universe included.
  std::size_t joint_count() const { return joints_.size() + 1; }
  const std::vector<ChainBody>& bodies() const { return bodies_; }
  const std::vector<double>& lower() const { return lower_; }
  const std::vector<double>& upper() const { return upper_; }

  /// Whether every number of q (dof() of them) is finite and within its limits (a
  /// wrapping angle: finite).
  bool admits(const double* q) const;
  /// Whether any joint's angle wraps.
  bool wraps() const { return !wraps_.empty(); }
  /// Whether joint j's (state order) angle wraps.
  bool wraps(int j) const { return !wraps_.empty() && wraps_[j]; }
  /// Where the straight edge from q1 towards q2 ends: q2 itself when no angle wraps,
  /// else `out` (dof() numbers) holding q2 with every wrapping angle at q1's plus the
  /// shorter turn, in [-pi, pi) (outside [-pi, pi] where the turn crosses it). Every
  /// state of the edge is q1 + s (end - q1), s in [0, 1] (kcplan/arm/description.py
  /// unwrapped).
  const double* edge_end(const double* q1, const double* q2, double* out) const;
  /// b - a for joint j: the shorter turn in [-pi, pi) for a wrapping angle.
  double difference(int j, double a, double b) const;
  /// An angle of joint j brought into [-pi, pi) if it wraps (unchanged otherwise).
  double canonical(int j, double v) const;
  /// World frames of every joint, the universe first (joint_count() of them).
  void joint_frames(const double* q, std::vector<coal::Transform3s>& out) const;
  /// World frames of every body (bodies().size() of them); `joints` is scratch.
  void body_frames(const double* q, std::vector<coal::Transform3s>& joints,
                   std::vector<coal::Transform3s>& out) const;

  /// rho[k * dof + j]: how far a point of body k moves per unit of joint j's motion, for
  /// every configuration in the limits (kcplan/arm/bounds.py point_speeds: the farthest
  /// point from joint j's axis, bounded through the chain's joint origins by the triangle
  /// inequality; 1 for a prismatic joint; 0 where j does not carry k).
  const std::vector<double>& point_speeds() const { return rho_; }
  /// Whether joint j (state order) carries body k: carries()[k * dof + j].
  const std::vector<bool>& carries() const { return carries_; }
  /// The levers at a configuration: out[k * dof + j] = |c_k - o_j| + a_max,k, the
  /// farthest any point of body k lies from joint j's origin (c_k its centre, o_j the
  /// joint's origin, both at the frames given: joint_frames and body_frames of one q),
  /// 1 for a prismatic joint, 0 where j does not carry k. Never above point_speeds().
  void levers(const std::vector<coal::Transform3s>& joints,
              const std::vector<coal::Transform3s>& bodies, double* out) const;
  /// How fast the levers can grow along an edge with joint steps |dq| = `dq`:
  /// out[k * dof + j] = |dq_j| sum_i |dq_i| rho[k, i] over the joints i below j that
  /// carry k (they alone change |x - o_j|), 0 for a prismatic j or one not carrying k
  /// (kcplan/arm/bounds.py lever_growth).
  void lever_growth(const double* dq, double* out) const;
  /// First order at a configuration (kcplan/arm/bounds.py first_order_speeds): out[k] =
  /// |u_k| + |w_k| a_max,k, the fastest any point of body k moves along the signed joint
  /// step `dq`, from the body's twist (w_k, u_k) at one q: its joint_frames and the
  /// bodies' centres there (3 numbers per body).
  void first_order_speeds(const std::vector<coal::Transform3s>& joints, const double* centres,
                          const double* dq, double* out) const;
  /// The fastest any point of body k moves with angular velocity w and centre velocity u:
  /// |u| + |w| a_max,k, rounded up (one number of first_order_speeds).
  double first_order_speed(std::size_t k, const coal::Vec3s& w, const coal::Vec3s& u) const {
    return (u.norm() + w.norm() * bodies_[k].a_max) * (1.0 + 1e-12);  // and rounding
  }
  /// The bodies' twists at one q along the signed joint step `dq` (kcplan/arm/bounds.py
  /// twists): w[k] the angular velocity of body k, u[k] the velocity of its centre, per
  /// unit of the edge parameter (world frame), from joint_frames and the bodies' centres
  /// (3 numbers per body) there. first_order_speeds is |u| + |w| a_max of these.
  void twists(const std::vector<coal::Transform3s>& joints, const double* centres,
              const double* dq, std::vector<coal::Vec3s>& w, std::vector<coal::Vec3s>& u) const;
  /// The twist of every joint's frame at one q along the signed step `dq`: w[i] its
  /// angular velocity and u[i] such that a point x fixed to it moves at w[i] x x + u[i]
  /// (joint_count() of each, the universe's 0); twists() reads the bodies' off these.
  void joint_twists(const std::vector<coal::Transform3s>& joints, const double* dq,
                    std::vector<coal::Vec3s>& w, std::vector<coal::Vec3s>& u) const;
  /// S[i]: the sum of |dq| over the revolute joints above joint i, how fast its axis
  /// turns at most (joint_count() numbers; point_accelerations' S_j).
  void axis_turns(const double* dq, std::vector<double>& S) const;
  /// point_accelerations of body k alone, given axis_turns(dq) = S.
  double point_acceleration(std::size_t k, const double* dq, const std::vector<double>& S) const;
  /// out[k] = the sum of |dq_j| over the revolute joints j that carry body k: how far body
  /// k turns at most per unit of the edge parameter, anywhere along the edge (radians;
  /// kcplan/arm/bounds.py turn_speeds).
  void turn_speeds(const double* dq, double* out) const;
  /// The largest acceleration of any point of body k along an edge of joint steps |dq| =
  /// `dq` in the limits (kcplan/arm/bounds.py point_accelerations): out[k] = sum over the
  /// revolute joints j carrying k of |dq_j| (2 S_j rho[k, j] + sum_{i = j or below} |dq_i|
  /// rho[k, i]), plus |dq_j| S_j per prismatic j, S_j the revolute steps above j.
  void point_accelerations(const double* dq, double* out) const;
  /// The bound on how fast the distance between a point of body k and a point of body l
  /// changes per unit of joint j's motion: only the joints that carry exactly one of
  /// them count (kcplan/arm/bounds.py relative_speeds). Row m for pairs[m], dof per row.
  std::vector<double> relative_speeds(const std::vector<std::array<int, 2>>& pairs) const;

  /// The same joints and limits with other bodies (each `placement` in its joint's
  /// frame), and their speed bounds: what ArmWorld::parts() is made of.
  Chain with_bodies(std::vector<ChainBody> bodies) const;
  /// Frames of the bodies, given the joint frames of one configuration (joint_frames).
  void place_bodies(const std::vector<coal::Transform3s>& joints,
                    std::vector<coal::Transform3s>& out) const;

 private:
  Chain() = default;
  /// rho_ and carries_ of bodies_ (the constructor's speed bounds).
  void bound_speeds();

  std::vector<ChainJoint> joints_;  // joints 1..n; joints_[i - 1] is joint i
  std::vector<ChainBody> bodies_;
  std::vector<double> lower_, upper_, rho_;
  std::vector<bool> carries_;
  std::vector<bool> wraps_;  // dof() flags, or empty: no angle wraps
};

}  // namespace kcplan
