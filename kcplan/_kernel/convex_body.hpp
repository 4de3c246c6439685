// A convex body given by its hull: the exact geometry of a convex link (or the hull of a
// non-convex one), for coal's GJK and for support functions.
// Python twin: kcplan/arm/hulls.py (BodyHull).
#pragma once

#include <memory>
#include <vector>

#include <coal/math/transform.h>
#include <coal/shape/convex.h>

namespace kcplan {

/// A convex polytope from m x 3 vertices and t x 3 triangle indices (flat): coal's
/// Convex, whose vertex neighbours (filled from the triangles) let GJK hill-climb.
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
  double radius_ = 0.0;
};

}  // namespace kcplan
