// A sensed point cloud as one obstacle: every point a ball of one radius, the points in a
// k-d tree whose boxes bound the distance from a robot-side shape from below.
// Python twin: kcplan/world/collision.py (each point an fcl.Sphere in the broad phase).
#pragma once

#include <cstddef>
#include <cstdint>
#include <array>
#include <limits>
#include <memory>
#include <unordered_map>
#include <vector>

#include <coal/BV/AABB.h>
#include <coal/collision_object.h>
#include <coal/data_types.h>
#include <coal/shape/geometric_shapes.h>

#include "mesh_planes.hpp"

namespace kcplan {

/// Counts of the work one cloud did, summed over its queries.
struct CloudCounters {
  std::int64_t queries = 0;  ///< collision and distance queries asked of the cloud
  std::int64_t nodes = 0;    ///< tree nodes whose bound was computed
  std::int64_t points = 0;   ///< points whose own bound was computed
  std::int64_t exact = 0;    ///< points measured by coal's GJK (their bound did not decide)
};

/// Which of a cloud's cheaper bounds are asked before GJK (all by default; switched off
/// only to measure what each buys: the answers are the same, the work is not).
struct CloudBounds {
  bool dop = true;          ///< a hull's 26 fixed planes
  bool gjk_planes = true;   ///< the planes GJK's nearest points have shown in this query
  bool centre_line = true;  ///< the support along the centres' line (not for hulls)
};

/// How far below the distance to a cloud its answer may lie: a search that stops early.
///
/// With g(x) = x for x <= floor and g(x) = floor + (1 + relative) (x - floor) beyond (g
/// increasing, g(x) >= x), the search skips every node and point whose bound b has
/// g(b) >= best, `best` the nearest ball met so far, and answers lower(best) = g^-1(best)
/// (the cap when no ball nearer than it was met). The answer a is a lower bound of the
/// true distance d: a point measured is at least best >= a away; a point skipped has
/// d >= b >= g^-1(best then) >= a, since `best` only falls. Where d <= floor nothing at
/// or below d is skipped (g(b) = b there), so a = d: a verdict at the floor (a clearance's
/// threshold: contact, or the padding) is the exact search's. Beyond it, d - floor <=
/// (1 + relative) (a - floor): a guard's clearance is at most that factor short.
/// relative = 0 is the exact search.
struct DistanceTolerance {
  double relative = 0.0;  ///< >= 0
  double floor = 0.0;     ///< metres, >= 0: exact at or below it
  /// g^-1(found): the least distance a nearest ball met at `found` stands for.
  double lower(double found) const {
    return found <= floor ? found : floor + (found - floor) / (1.0 + relative);
  }
};

/// A ball that holds the robot at every state (kcplan.arm.bounds.reach_ball): a point
/// whose ball lies beyond it is never met by a body, so a cloud keeps none of them. Every
/// answer of the cloud is then one about the points the robot can reach: a verdict is
/// unchanged at every state, and a distance is a lower bound of the distance to the balls
/// it keeps (a guard ball free of them is free of every ball where the robot can be).
/// The whole space by default.
struct CloudReach {
  coal::Vec3s centre = coal::Vec3s::Zero();
  double radius = std::numeric_limits<double>::infinity();  ///< metres, > 0
};

/// How a cloud's tree orders its points before splitting them in halves.
enum class CloudOrder {
  /// Sorted once along a Morton (Z-order) curve of 10 bits per axis (cubic cells, 1024 to
  /// the cloud's longest side), by a radix sort in O(n); a node's range is split where
  /// its cell splits (the highest bit in which its codes differ: an octree's cells, the
  /// empty ones skipped), and its box is the union of its children's (Karras's linear
  /// BVH, as a build on the CPU).
  morton,
  /// A k-d tree: median splits (std::nth_element) along the longest side of each node's
  /// box, O(n log n). The ablation of `morton`.
  median,
};

/// The union of the balls of radius `radius()` about the points, as an obstacle.
///
/// The points are kept in a balanced binary tree of leaves of at most `leaf_size` points
/// (ordered as CloudOrder says); each node keeps its points' bounding box. Which order
/// built the tree changes how much work a query does, never its answer. A query shape S
/// (an ellipsoid, ball, capsule or convex polytope placed by its coal object: what
/// ShapeSupport describes) is measured against a node by two lower bounds of the distance
/// from S to any point of the node's box B, and the larger is used:
///
///  - the gap between S's world bounding box and B (S lies in its box);
///  - for a shape other than a polytope (for a hull the scan of its vertices cost more
///    than it saved: scripts/cloud_bounds.py), S's separation along n = (m - c) / |m - c|,
///    c S's centre and m B's centre:
///    every x of S has n . x <= n . c + spread_S(n) and every y of B has
///    n . y >= n . m - rho (rho B's half diagonal), so |y - x| >= n . (y - x) >=
///    |m - c| - spread_S(n) - rho.
///
///  - for a convex polytope (a link's hull), the 26 planes across the faces, edges and
///    corners of its frame's cube that touch it (its support there, found once per hull):
///    the largest d . (m - c) - h(d) - rho, in the hull's frame;
///  - the planes {x : n . x <= h_S(n)} that hold S, one for each direction GJK's nearest
///    points have given so far in this query (a point of the cloud measured exactly):
///    every y of B has n . y >= n . m - |n| . half, so |y - x| >= n . m - |n| . half -
///    h_S(n) (beside a flat patch of points, such as a sensed table top, this is nearly
///    the distance, where the centres' line is not).
///
/// A point p is bounded the same way (rho = 0), and the bound along the centres' line is
/// the distance itself when S is a ball (then taken as it is, less its rounding
/// allowance: no GJK). A point whose bound cannot decide the query is measured by coal's
/// GJK (a sphere of the cloud's radius about p against S), exactly as any other obstacle
/// is: the distance the cloud returns is then coal's distance to the nearest ball, or a
/// lower bound proven to be at least the cap asked for. Its error is therefore coal's
/// alone, and the World's allowance (d (1 - rtol) - atol, kcplan/_kernel/__init__.py)
/// covers it as for every obstacle; the bounds themselves are exact up to rounding of
/// order 1e-16 of the numbers involved, of which 1e-12 is subtracted. A shape whose
/// support is not known is bounded by its box alone, and its candidate points all go to
/// GJK.
///
/// Contract: at least one point, every coordinate finite, radius > 0 and finite
/// (std::invalid_argument otherwise); at least one point within `reach` grown by the
/// radius (CloudReach; the World adds no cloud that has none). Immutable once built, except its counters and GJK
/// scratch: not thread-safe.
class PointCloud {
 public:
  /// `xyz`: n x 3 row-major coordinates (world frame).
  PointCloud(const double* xyz, std::size_t n, double radius,
             CloudOrder order = CloudOrder::morton, std::size_t leaf_size = 8,
             const CloudReach& reach = {});

  /// Whether point `p`'s ball of `radius` meets the ball `reach`.
  static bool reachable(const coal::Vec3s& p, double radius, const CloudReach& reach) {
    const double r = reach.radius + radius;
    return (p - reach.centre).squaredNorm() <= r * r;
  }

  std::size_t size() const { return points_.size(); }
  double radius() const { return radius_; }
  /// The box of every ball (the points' box grown by the radius).
  const coal::AABB& bounds() const { return bounds_; }
  /// The points in the tree's order (n x 3).
  const std::vector<coal::Vec3s>& points() const { return points_; }
  std::size_t nodes() const { return nodes_.size(); }

  /// Whether some ball touches `shape` (at its transform, its AABB computed).
  bool collides(const coal::CollisionObject& shape);
  /// min(cap, the distance from `shape` to the nearest ball), 0 on contact; as coal
  /// measures it (see the class notes), and as far below it as `tolerance` allows (exact
  /// by default; std::invalid_argument for a negative one). `cap` = inf for the distance
  /// itself. With `towards`, the unit direction from that ball's nearest point towards
  /// the shape's (zero when no ball is nearer than the cap, or on contact).
  double distance(const coal::CollisionObject& shape, double cap,
                  coal::Vec3s* towards = nullptr, const DistanceTolerance& tolerance = {});
  /// The support of the balls that meet `region` along `n`: the largest n . y over every
  /// point y of those balls (-inf if none). Every ball meeting the region lies in
  /// {x : n . x <= support}: a plane of the points near a body, for region certificates
  /// (balls beyond the region are farther than it reaches).
  double support(const coal::AABB& region, const coal::Vec3s& n) const;

  CloudCounters counters;
  CloudBounds bounds_used;

 private:
  struct Node {
    coal::Vec3s centre, half;   // the node's box
    std::uint32_t begin, end;   // its points: points_[begin, end)
    std::int32_t left = -1;     // children (right = left + 1); -1: a leaf
  };
  struct Query;
  /// A hull's supports along 26 fixed directions of its frame (conservatively rounded up).
  using Dop = std::array<double, 26>;
  /// The Dop of a link's hull (an immutable SupportedConvex), made on its first query.
  const Dop& dop_of(const coal::CollisionGeometry& hull, const VertexSupport& support);

  /// Fill node `index` (already allocated) with points_[begin, end) and its subtree, the
  /// points split at the median of the box's longest side (CloudOrder::median).
  void build_median(std::size_t index, std::uint32_t begin, std::uint32_t end,
                    std::size_t leaf_size);
  /// Fill node `index` (already allocated) with points_[begin, end) and its subtree, the
  /// range split between the two halves of its Morton cell (`keys`: the points' sorted
  /// Morton keys, the code in bits 32-61); the box from the children's; `lo`, `hi` get
  /// its corners.
  void build_cells(std::size_t index, std::uint32_t begin, std::uint32_t end,
                   const std::vector<std::uint64_t>& keys, std::size_t leaf_size,
                   coal::Vec3s& lo, coal::Vec3s& hi);
  /// GJK's distance from the query shape to the ball about point i (<= 0: contact).
  /// `towards` gets GJK's unit direction from the ball to the shape (zero if none).
  double exact(Query& q, std::size_t i, coal::Vec3s& towards);
  /// min(cap, the distance to the nearest ball) within `tolerance` (DistanceTolerance),
  /// depth first, the nearer child first; returns that ball's distance as soon as it is
  /// below `stop_below`.
  double search(Query& q, double cap, double stop_below, const DistanceTolerance& tolerance,
                coal::Vec3s* towards);

  std::vector<coal::Vec3s> points_;
  std::vector<Node> nodes_;
  double radius_;
  coal::AABB bounds_;
  std::shared_ptr<coal::Sphere> ball_;
  std::vector<std::int32_t> stack_;
  std::unordered_map<const coal::CollisionGeometry*, Dop> dops_;
};

}  // namespace kcplan
