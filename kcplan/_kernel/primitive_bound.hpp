// A primitive obstacle (box, ball, cylinder) and a certain lower bound of its distance to
// a convex robot-side shape found without GJK: the two shapes' separation along the line
// from the obstacle's point nearest the shape's centre to that centre.
// Python twin: none (a shortcut of the kernel's broad phase, like mesh_planes.hpp); the
// bound's soundness is tested against coal's distances in tests/test_kernel.py.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <coal/data_types.h>

#include "mesh_planes.hpp"

namespace kcplan {

/// A box, ball or cylinder obstacle, by its centre, its rotation (columns: the local
/// axes) and its sizes: a box's half sides; a ball's radius (all three); a cylinder's
/// (radius, radius, half height) about its local z axis.
///
/// Proof of the bound (`separation`): for any unit n, every point x of a convex shape S
/// has n . x >= -h_S(-n) = n . c - spread_S(-n) (ShapeSupport; spread_S(-n) = spread_S(n)
/// for a centrally symmetric S, not for a polytope) and every point y of the obstacle B
/// has n . y <= h_B(n), so |x - y| >= n . (x - y) >= n . c - spread_S(-n) - h_B(n): the
/// separation along n is a lower bound of dist(S, B), whichever n is taken. n from the
/// point of B nearest S's centre c towards c makes it tight where S is a ball (it is
/// then the distance itself) and close for a thin ellipsoid beside a bar. Rounding is of
/// order 1e-16 of the numbers involved; 1e-12 of them is subtracted.
struct Primitive {
  enum Kind { kNone, kBox, kBall, kCylinder } kind = kNone;
  coal::Vec3s centre = coal::Vec3s::Zero();
  coal::Matrix3s rotation = coal::Matrix3s::Identity();
  coal::Vec3s size = coal::Vec3s::Zero();

  static Primitive box(const coal::Vec3s& c, const coal::Matrix3s& R, const coal::Vec3s& half) {
    return {kBox, c, R, half};
  }
  static Primitive ball(const coal::Vec3s& c, double radius) {
    return {kBall, c, coal::Matrix3s::Identity(), coal::Vec3s::Constant(radius)};
  }
  static Primitive cylinder(const coal::Vec3s& c, const coal::Matrix3s& R, double radius,
                            double half_height) {
    return {kCylinder, c, R, coal::Vec3s(radius, radius, half_height)};
  }

  /// The point of the obstacle nearest x (x itself when x is inside).
  coal::Vec3s nearest(const coal::Vec3s& x) const {
    coal::Vec3s local = rotation.transpose() * (x - centre);
    switch (kind) {
      case kBox:
        local = local.cwiseMax(-size).cwiseMin(size);
        break;
      case kBall: {
        const double r = local.norm();
        if (r > size[0]) local *= size[0] / r;
        break;
      }
      case kCylinder: {
        const double r = std::hypot(local[0], local[1]);
        if (r > size[0]) local[0] *= size[0] / r, local[1] *= size[0] / r;
        local[2] = std::clamp(local[2], -size[2], size[2]);
        break;
      }
      case kNone:
        break;
    }
    return centre + rotation * local;
  }

  /// h(n) = max over the obstacle of n . y.
  double support(const coal::Vec3s& n) const {
    const coal::Vec3s local = rotation.transpose() * n;
    switch (kind) {
      case kBox:
        return n.dot(centre) + size.dot(local.cwiseAbs());
      case kBall:
        return n.dot(centre) + size[0] * n.norm();
      case kCylinder:
        return n.dot(centre) + size[0] * std::hypot(local[0], local[1]) +
               size[2] * std::abs(local[2]);
      case kNone:
        break;
    }
    return std::numeric_limits<double>::infinity();
  }

  /// A certain lower bound of the distance from `shape` to the obstacle (the struct's
  /// docs; <= 0: nothing known, e.g. the shape's centre inside the obstacle, or no
  /// primitive). `exact` is set when the bound is the distance itself (a ball outside).
  double separation(const ShapeSupport& shape, bool& exact) const {
    coal::Vec3s n;
    return separation(shape, exact, n);
  }
  /// separation(), and `n` the unit direction it is measured along (from the obstacle
  /// towards the shape's centre; the shape lies in {x : n . x >= support(n) + the bound}).
  double separation(const ShapeSupport& shape, bool& exact, coal::Vec3s& n) const {
    exact = false;
    constexpr double kUnknown = -std::numeric_limits<double>::infinity();
    if (kind == kNone) return kUnknown;
    const coal::Vec3s& c = shape.centre;
    const coal::Vec3s d = c - nearest(c);
    const double length = d.norm();
    if (!(length > 0.0) || !std::isfinite(length)) return kUnknown;
    n = d / length;
    const double gap = n.dot(c) - shape.spread(-n) - support(n);
    const double scale = 1.0 + c.norm() + centre.norm() + size.norm() + shape.spread_high;
    exact = !shape.capsule && shape.spread_low == shape.spread_high;
    return gap - 1e-12 * scale;
  }
};

}  // namespace kcplan
