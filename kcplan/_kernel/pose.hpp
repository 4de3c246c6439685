// Robot poses and OMPL's straight edges between them.
// Python twin: kcplan/geometry/pose.py (same layout, same interpolation, same numbers).
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kcplan {

constexpr double kPi = 3.14159265358979323846;

/// A unit quaternion [x, y, z, w] (scalar last, as OMPL's SO3State and scipy).
struct Quat {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;

  static Quat yaw(double angle) { return {0.0, 0.0, std::sin(0.5 * angle), std::cos(0.5 * angle)}; }
  Quat conjugate() const { return {-x, -y, -z, w}; }
  /// Hamilton product this * q.
  Quat operator*(const Quat& q) const {
    return {w * q.x + x * q.w + y * q.z - z * q.y, w * q.y - x * q.z + y * q.w + z * q.x,
            w * q.z + x * q.y - y * q.x + z * q.w, w * q.w - x * q.x - y * q.y - z * q.z};
  }
  /// v rotated by this (unit) quaternion: v + w t + u x t with t = 2 u x v.
  std::array<double, 3> rotate(const std::array<double, 3>& v) const {
    const double tx = 2.0 * (y * v[2] - z * v[1]), ty = 2.0 * (z * v[0] - x * v[2]),
                 tz = 2.0 * (x * v[1] - y * v[0]);
    return {v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz,
            v[2] + w * tz + x * ty - y * tx};
  }
};

/// A robot pose: translation t (z = 0 in 2D) and orientation q (a yaw about z in 2D).
///
/// Flat layout, as OMPL's states hold it: [x, y, yaw] (2D) or [x, y, z, qx, qy, qz, qw]
/// (3D). `raw` keeps those numbers bit for bit: the guard cache is keyed by them.
struct Pose {
  std::array<double, 3> t{0.0, 0.0, 0.0};
  Quat q;
  std::array<double, 7> raw{0, 0, 0, 0, 0, 0, 0};
  int size = 3;  ///< 3 (2D) or 7 (3D)

  /// Every number finite and, in 3D, a quaternion that can be normalised.
  bool finite = true;

  /// From `size` flat numbers; the quaternion is normalised (a pose that is not finite or
  /// has a zero quaternion gets finite == false and must never be called free).
  static Pose from_flat(const double* p, int size) {
    Pose pose;
    pose.size = size;
    for (int i = 0; i < size; ++i) {
      pose.raw[i] = p[i];
      pose.finite = pose.finite && std::isfinite(p[i]);
    }
    if (size == 3) {
      pose.t = {p[0], p[1], 0.0};
      pose.q = Quat::yaw(p[2]);
      return pose;
    }
    pose.t = {p[0], p[1], p[2]};
    const double norm = std::sqrt(p[3] * p[3] + p[4] * p[4] + p[5] * p[5] + p[6] * p[6]);
    if (!(norm > 0.0) || !std::isfinite(norm)) {
      pose.finite = false;
      return pose;
    }
    pose.q = {p[3] / norm, p[4] / norm, p[5] / norm, p[6] / norm};
    return pose;
  }
};

/// The number of flat pose numbers in `dimension` (2 or 3); throws otherwise.
inline int pose_size(int dimension) {
  if (dimension != 2 && dimension != 3)
    throw std::invalid_argument("dimension: expected 2 or 3, got " + std::to_string(dimension));
  return dimension == 2 ? 3 : 7;
}

/// A straight edge between two poses under OMPL's interpolation:
/// q(s) = (R1 exp(s hat(w12)), t1 + s (t2 - t1)), s in [0, 1], with the shorter yaw arc
/// (SE(2), exactly pi going the direct way) or slerp (SE(3), q2 flipped when q1.q2 < 0).
/// Seen from q(m) the KC coordinates of q(s) are (s - m) direction(m) (design notes, Sec. 4).
class Edge {
 public:
  Edge(const Pose& p1, const Pose& p2) : two_d_(p1.size == 3) {
    for (int k = 0; k < 3; ++k) {
      t1_[k] = p1.t[k];
      dt_[k] = p2.t[k] - p1.t[k];
    }
    translation_speed_ = std::sqrt(dt_[0] * dt_[0] + dt_[1] * dt_[1] + dt_[2] * dt_[2]);
    if (two_d_) {
      yaw1_ = p1.raw[2];
      double diff = p2.raw[2] - p1.raw[2];
      if (std::fabs(diff) > kPi) diff -= std::copysign(2.0 * kPi, diff);
      turn_ = diff;
      rotation_speed_ = std::fabs(diff);
      return;
    }
    Quat q2 = p2.q;
    q1_ = p1.q;
    if (q1_.x * q2.x + q1_.y * q2.y + q1_.z * q2.z + q1_.w * q2.w < 0.0)
      q2 = {-q2.x, -q2.y, -q2.z, -q2.w};
    const Quat r = q1_.conjugate() * q2;
    const double norm = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
    angle_ = 2.0 * std::atan2(norm, r.w);
    axis_ = norm > 0.0 ? std::array<double, 3>{r.x / norm, r.y / norm, r.z / norm}
                       : std::array<double, 3>{1.0, 0.0, 0.0};
    rotation_speed_ = std::fabs(angle_);
  }

  /// |t2 - t1|: length units per unit s.
  double translation_speed() const { return translation_speed_; }
  /// |w12|: radians per unit s.
  double rotation_speed() const { return rotation_speed_; }
  const std::array<double, 3>& dt() const { return dt_; }
  /// The angular velocity w in the world frame, radians per unit s, constant along the
  /// edge (R(s) = exp((s - m) [w]) R(m)); (0, 0, turn) in 2D.
  std::array<double, 3> spin() const {
    if (two_d_) return {0.0, 0.0, turn_};
    const std::array<double, 3> a = q1_.rotate(axis_);
    return {a[0] * angle_, a[1] * angle_, a[2] * angle_};
  }

  /// The pose q(s), with the flat numbers OMPL's interpolation would give (yaw wrapped to
  /// [-pi, pi) as Python's modulo does).
  Pose pose(double s) const {
    double flat[7];
    for (int k = 0; k < 3; ++k) flat[k] = t1_[k] + s * dt_[k];
    if (two_d_) {
      const double a = yaw1_ + s * turn_ + kPi, period = 2.0 * kPi;
      flat[2] = a - period * std::floor(a / period) - kPi;
      return Pose::from_flat(flat, 3);
    }
    const Quat q = rotation(s);
    flat[3] = q.x, flat[4] = q.y, flat[5] = q.z, flat[6] = q.w;
    return Pose::from_flat(flat, 7);
  }

  /// KC coordinates per unit s seen from q(s): [w12, R(s)^T (t2 - t1)], 3 or 6 numbers.
  int direction(double s, double* out) const {
    if (two_d_) {
      const double yaw = yaw1_ + s * turn_, c = std::cos(yaw), si = std::sin(yaw);
      out[0] = turn_;
      out[1] = c * dt_[0] + si * dt_[1];
      out[2] = -si * dt_[0] + c * dt_[1];
      return 3;
    }
    const std::array<double, 3> local = rotation(s).conjugate().rotate(dt_);
    for (int k = 0; k < 3; ++k) {
      out[k] = axis_[k] * angle_;
      out[3 + k] = local[k];
    }
    return 6;
  }

 private:
  Quat rotation(double s) const {
    const double half = 0.5 * s * angle_, sh = std::sin(half);
    return q1_ * Quat{sh * axis_[0], sh * axis_[1], sh * axis_[2], std::cos(half)};
  }

  bool two_d_;
  std::array<double, 3> t1_{}, dt_{};
  double translation_speed_ = 0.0, rotation_speed_ = 0.0;
  double yaw1_ = 0.0, turn_ = 0.0;                    // SE(2)
  Quat q1_;                                           // SE(3)
  std::array<double, 3> axis_{1.0, 0.0, 0.0};
  double angle_ = 0.0;
};

}  // namespace kcplan
