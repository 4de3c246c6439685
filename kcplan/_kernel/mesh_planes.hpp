// The planes of a triangle mesh's triangles: a certain lower bound on the distance from a
// convex shape to the mesh, found without the BVH when the shape lies on the inner side
// of every plane (a robot inside a convex arena, as in HRM's maps).
// Python twin: none; the python-fcl world measures meshes with FCL's BVH, and the tests
// compare the kernel's verdicts and distances inside a convex arena with python-fcl's
// (tests/test_kernel.py).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <coal/collision_object.h>
#include <coal/data_types.h>
#include <coal/shape/convex.h>
#include <coal/shape/geometric_shapes.h>

#include "convex_body.hpp"

namespace kcplan {

/// The support function h(n) = max over a robot-side shape of n . x: an ellipsoid
/// {c + R diag(r) u : |u| <= 1} (a ball: r = (rho, rho, rho)), a capsule (the points
/// within rho of the segment c +- R e_z l) or a convex polytope (the hull of c + R v over
/// its vertices v: an arm link's hull, ConvexBody). `spread_low <= h(n) - n . c <=
/// spread_high` for every unit n.
struct ShapeSupport {
  coal::Vec3s centre = coal::Vec3s::Zero();
  coal::Matrix3s M = coal::Matrix3s::Zero();  // ellipsoid: diag(r) R^T, so h = n.c + |M n|
  coal::Vec3s half_segment = coal::Vec3s::Zero();  // capsule: R e_z l
  double radius = 0.0;                             // capsule: rho
  bool capsule = false;
  const std::vector<coal::Vec3s>* hull = nullptr;  // polytope: its vertices v
  const VertexSupport* hull_support = nullptr;       // and their support, if it has one
  coal::Matrix3s rotation = coal::Matrix3s::Identity();  // polytope: R
  double spread_low = 0.0, spread_high = 0.0;

  /// The support of `object`'s shape at its transform; false for any other shape.
  static bool of(const coal::CollisionObject& object, ShapeSupport& out) {
    const coal::Transform3s& tf = object.getTransform();
    const coal::CollisionGeometry* g = object.collisionGeometryPtr();
    out.centre = tf.getTranslation();
    out.capsule = false;
    out.hull = nullptr;
    out.hull_support = nullptr;
    // by coal's node type, not dynamic_cast: this runs for every broad-phase candidate,
    // and a failed cross-library dynamic_cast compares type names
    switch (g == nullptr ? coal::BV_UNKNOWN : g->getNodeType()) {
      case coal::GEOM_ELLIPSOID: {
        const auto* e = static_cast<const coal::Ellipsoid*>(g);
        out.M = e->radii.asDiagonal() * tf.getRotation().transpose();
        out.spread_low = e->radii.minCoeff(), out.spread_high = e->radii.maxCoeff();
        return true;
      }
      case coal::GEOM_SPHERE: {
        const auto* s = static_cast<const coal::Sphere*>(g);
        out.M = s->radius * tf.getRotation().transpose();
        out.spread_low = out.spread_high = s->radius;
        return true;
      }
      case coal::GEOM_CAPSULE: {
        const auto* c = static_cast<const coal::Capsule*>(g);
        out.capsule = true;
        out.half_segment = tf.getRotation().col(2) * c->halfLength;
        out.radius = c->radius;
        out.spread_low = c->radius, out.spread_high = c->radius + c->halfLength;
        return true;
      }
      case coal::GEOM_CONVEX: {  // every coal::ConvexBase, and nothing else
        const auto* h = static_cast<const coal::ConvexBase*>(g);
        // |v| <= |aabb centre| + the local box's half diagonal (coal's aabb_radius), so
        // |h(n) - n . c| <= that bound whatever the frame's origin is
        out.hull = h->points.get();
        out.hull_support = SupportedConvex::of(*h);
        out.rotation = tf.getRotation();
        out.spread_high = (h->aabb_center.norm() + h->aabb_radius) * (1.0 + 1e-12);
        out.spread_low = -out.spread_high;
        return true;
      }
      default:
        break;
    }
    return false;
  }

  /// h(n) - n . c.
  double spread(const coal::Vec3s& n) const {
    if (hull_support != nullptr) return (*hull_support)(rotation.transpose() * n);
    if (hull != nullptr) return (*hull)[extreme_vertex(n)].dot(rotation.transpose() * n);
    return capsule ? std::abs(n.dot(half_segment)) + radius : (M * n).norm();
  }
  /// A polytope's vertex where (R v) . n is largest.
  std::size_t extreme_vertex(const coal::Vec3s& n) const {
    const coal::Vec3s local = rotation.transpose() * n;
    std::size_t best = 0;
    double most = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hull->size(); ++i) {
      const double h = (*hull)[i].dot(local);
      if (h > most) most = h, best = i;
    }
    return best;
  }
  /// A point of the shape where n . x = h(n).
  coal::Vec3s extreme_point(const coal::Vec3s& n) const {
    if (hull != nullptr) return centre + rotation * (*hull)[extreme_vertex(n)];
    if (capsule)
      return centre + (n.dot(half_segment) >= 0.0 ? half_segment : coal::Vec3s(-half_segment)) +
             radius * n;
    const coal::Vec3s m = M * n;
    const double length = m.norm();
    return length > 0.0 ? coal::Vec3s(centre + M.transpose() * m / length) : centre;
  }
};

/// One plane per triangle of a mesh, n_t . y >= h_t on every point y of triangle t, with
/// n_t of unit length pointing away from the mesh's vertex centroid and h_t the least of
/// n_t . v over the triangle's corners.
///
/// Proof of the bound: let s_t = h_t - h_S(n_t) for a convex shape S. For x in S and y in
/// triangle t, |y - x| >= n_t . (y - x) >= h_t - h_S(n_t) = s_t, so if every s_t > 0 the
/// shape is clear of the mesh and dist(S, mesh) >= min_t s_t. The bound is the distance
/// when the foot of S's extreme point on the plane of the minimising triangle lies in the
/// triangle (`exact`). Rounding in n_t, h_t and h_S is of order 1e-15 relative, far
/// inside the allowance the kernel subtracts from every clearance.
///
/// Search: g_t = h_t - n_t . c (c the shape's centre) for every triangle in one
/// vectorised pass; since spread_low <= h_S(n_t) - n_t . c <= spread_high, only triangles
/// with small g_t can decide, and only those get the exact support.
///
/// Contract: built once per mesh; `bound` allocates nothing and reuses a scratch array
/// (not thread-safe, like the World that owns it). A mesh with a degenerate triangle has
/// no planes (`usable()` false): its bound would not cover that triangle.
class MeshPlanes {
 public:
  MeshPlanes(const std::vector<coal::Vec3s>& points, const std::vector<coal::Triangle>& faces) {
    coal::Vec3s centroid = coal::Vec3s::Zero();
    for (const coal::Vec3s& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
    const Eigen::Index m = static_cast<Eigen::Index>(faces.size());
    nx_.resize(m), ny_.resize(m), nz_.resize(m), h_.resize(m), gap_.resize(m);
    corners_.resize(faces.size());
    for (Eigen::Index t = 0; t < m; ++t) {
      const coal::Triangle& f = faces[static_cast<std::size_t>(t)];
      const coal::Vec3s& a = points[f[0]];
      const coal::Vec3s& b = points[f[1]];
      const coal::Vec3s& c = points[f[2]];
      coal::Vec3s n = (b - a).cross(c - a);
      const double area2 = n.norm();
      const double scale = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
      if (!(area2 > 1e-12 * scale * scale)) {  // a sliver: no reliable plane, so none
        h_.resize(0);
        return;
      }
      n /= area2;
      const bool flip = n.dot(a - centroid) < 0.0;  // n_t points away from the centroid
      if (flip) n = -n;
      nx_[t] = n[0], ny_[t] = n[1], nz_[t] = n[2];
      h_[t] = std::min({n.dot(a), n.dot(b), n.dot(c)});
      corners_[static_cast<std::size_t>(t)] = flip ? Corners{a, c, b} : Corners{a, b, c};
    }
  }

  bool usable() const { return h_.size() > 0; }

  struct Bound {
    double value;  // measured: min_t s_t, a certain lower bound on the distance when > 0;
                   // not measured: a number with the sign of min_t s_t (<= 0: no proof)
    bool exact;    // value is the distance itself
  };

  /// Whether `shape` is clear of every triangle's plane (value > 0), and with `measure`
  /// the bound min_t s_t itself and whether it is the distance.
  Bound bound(const ShapeSupport& shape, bool measure) const {
    const coal::Vec3s& c = shape.centre;
    gap_ = h_ - (nx_ * c[0] + ny_ * c[1] + nz_ * c[2]);
    const double least = gap_.minCoeff();
    // s_t >= g_t - spread_high: with every g_t above spread_high the shape is clear
    if (!measure && least > shape.spread_high) return {least - shape.spread_high, false};
    // only a triangle with g_t <= cut can have s_t <= 0 (not measured) or be the minimiser
    const double cut = measure ? least + (shape.spread_high - shape.spread_low)
                               : shape.spread_high;
    double best = kInf;
    Eigen::Index arg = 0;
    for (Eigen::Index t = 0; t < gap_.size(); ++t) {
      if (gap_[t] > cut) continue;
      const double s = gap_[t] - shape.spread(coal::Vec3s(nx_[t], ny_[t], nz_[t]));
      if (s < best) best = s, arg = t;
    }
    if (!measure) return {best, false};  // the others have s_t > 0: best has min s_t's sign
    if (!(best > 0.0)) return {best, false};
    const coal::Vec3s n(nx_[arg], ny_[arg], nz_[arg]);
    return {best, contains(static_cast<std::size_t>(arg), shape.extreme_point(n) + best * n)};
  }

 private:
  struct Corners {
    coal::Vec3s a, b, c;
  };
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  /// Whether the point f of triangle t's plane lies in the triangle (to rounding; the
  /// corners run counter-clockwise about n_t).
  bool contains(std::size_t t, const coal::Vec3s& f) const {
    const Corners& k = corners_[t];
    const coal::Vec3s n(nx_[t], ny_[t], nz_[t]);
    const double slack = -1e-12 * ((k.b - k.a).squaredNorm() + (k.c - k.a).squaredNorm());
    return n.dot((k.b - k.a).cross(f - k.a)) >= slack &&
           n.dot((k.c - k.b).cross(f - k.b)) >= slack &&
           n.dot((k.a - k.c).cross(f - k.c)) >= slack;
  }

  Eigen::ArrayXd nx_, ny_, nz_, h_;
  mutable Eigen::ArrayXd gap_;  // scratch: g_t of the last query
  std::vector<Corners> corners_;
};

}  // namespace kcplan
