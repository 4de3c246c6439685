// A convex body given by its hull: the exact geometry of a convex link (or the hull of a
// non-convex one), for coal's GJK and for support functions.
// Python twin: kcplan/arm/hulls.py (BodyHull).
#pragma once

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

 private:
  VertexSupport support_;
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
