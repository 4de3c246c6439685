// A convex body given by its hull: the exact geometry of a convex link (or the hull of a
// non-convex one), for coal's GJK and for support functions.
// Python twin: kcplan/arm/hulls.py (BodyHull).
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <coal/math/transform.h>
#include <coal/shape/convex.h>

namespace kcplan {

/// The support function of a finite point set, h(n) = max_i n . v_i, exactly (every
/// vertex is looked at) in one vectorised pass over the coordinates stored as three
/// arrays: the arm's collision and clearance queries ask it for every obstacle near a
/// hull and every self pair whose balls meet (Primitive::separation, the pairs' gaps).
class VertexSupport {
 public:
  /// `points`: at least one (make_convex asks for four).
  explicit VertexSupport(const std::vector<coal::Vec3s>& points);
  /// h(n), for n of any length.
  double operator()(const coal::Vec3s& n) const {
    return (x_ * n[0] + y_ * n[1] + z_ * n[2]).maxCoeff();
  }

 private:
  Eigen::ArrayXd x_, y_, z_;
};

/// The planes of a convex polytope's faces, n . x <= offset for every point x of it: one
/// per distinct triangle normal (unit n, turned outwards), its offset the support over
/// every vertex rounded up, so that each plane holds the polytope whatever a triangle's
/// orientation or rounding. For a point p, max over the planes of n . p - offset is a
/// lower bound of p's distance to the polytope (every x of it has |p - x| >= n . (p - x)),
/// and is that distance when p's nearest point lies inside a face.
class FacePlanes {
 public:
  FacePlanes(const std::vector<coal::Vec3s>& points,
             const std::vector<coal::Triangle>& triangles, const VertexSupport& support);
  /// The largest n . p - offset over the planes (< 0: p inside; -inf for no plane).
  double lower_bound(const coal::Vec3s& p) const {
    if (offset_.size() == 0) return -std::numeric_limits<double>::infinity();
    return (x_ * p[0] + y_ * p[1] + z_ * p[2] - offset_).maxCoeff();
  }
  std::size_t size() const { return static_cast<std::size_t>(offset_.size()); }
  /// p's distance to the polytope when a face's plane gives it, and that face's normal:
  /// 0 when p lies inside; else the largest n . p - offset, b, when p - b n (p's foot on
  /// that plane) lies within every plane, to a rounding allowance. The answer is a lower
  /// bound of the distance either way, and within the allowance (1e-12 of the numbers)
  /// of it. false when the foot lies outside (p is nearest an edge or a corner: GJK's).
  bool face_distance(const coal::Vec3s& p, double& distance, coal::Vec3s& normal) const;

 private:
  Eigen::ArrayXd x_, y_, z_, offset_;
};

/// coal's Convex with its vertices' VertexSupport: what make_convex builds. It marks
/// itself in CollisionGeometry::user_data (pointing to itself), so that a support query
/// given only the coal geometry can tell it from any other ConvexBase (a copy made by
/// coal's clone() is a plain Convex whose mark points elsewhere): `of(geometry)`.
class SupportedConvex : public coal::Convex<coal::Triangle> {
 public:
  SupportedConvex(std::shared_ptr<std::vector<coal::Vec3s>> points, unsigned int num_points,
                  std::shared_ptr<std::vector<coal::Triangle>> faces, unsigned int num_faces);
  /// The VertexSupport of `geometry` if it is a SupportedConvex, else null.
  static const VertexSupport* of(const coal::CollisionGeometry& geometry) {
    return geometry.user_data == &geometry
               ? &static_cast<const SupportedConvex&>(geometry).support_
               : nullptr;
  }
  /// The FacePlanes of `geometry` if it is a SupportedConvex, else null.
  static const FacePlanes* faces_of(const coal::CollisionGeometry& geometry) {
    return geometry.user_data == &geometry
               ? &static_cast<const SupportedConvex&>(geometry).faces_
               : nullptr;
  }

 private:
  VertexSupport support_;
  FacePlanes faces_;
};

/// A convex polytope from m x 3 vertices and t x 3 triangle indices (flat): a
/// SupportedConvex, whose vertex neighbours (filled from the triangles) let GJK hill-climb.
/// Throws std::invalid_argument for fewer than 4 vertices or triangles, an index out of
/// range or a coordinate that is not finite; `what` names the input in the message.
std::shared_ptr<coal::ConvexBase> make_convex(const std::vector<double>& vertices,
                                              const std::vector<int>& triangles,
                                              const char* what);

/// A convex body in its own frame (its centre at the origin), as a ChainBody holds it.
///
/// Contract: the body is the convex hull of `vertices()`; `radius()` is at least the
/// largest |v|, so the ball of that radius about the origin holds the body (what every
/// speed bound of the chain assumes). Immutable once built; shared by worlds.
class BodyHull {
 public:
  /// Throws std::invalid_argument as make_convex does.
  BodyHull(const std::vector<double>& vertices, const std::vector<int>& triangles);

  /// h(n) = max over the vertices of n . v: how far the body reaches along n (in its
  /// own frame, n of any length) from its centre.
  double support(const coal::Vec3s& n) const;
  double radius() const { return radius_; }
  const std::shared_ptr<coal::ConvexBase>& shape() const { return shape_; }
  std::size_t size() const { return shape_->num_points; }

 private:
  std::shared_ptr<coal::ConvexBase> shape_;
  const VertexSupport* support_;  // shape_'s
  double radius_ = 0.0;
};

}  // namespace kcplan
