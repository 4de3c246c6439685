// The collision world on coal: obstacles in one broad phase, the robot's bodies, and the
// four queries certificates are built from (collision, clearance, free region, core sweep).
// Python twin: kcplan/world/collision.py (CollisionWorld, on python-fcl).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <coal/broadphase/broadphase_dynamic_AABB_tree.h>
#include <coal/collision_data.h>
#include <coal/collision_object.h>
#include <coal/shape/geometric_shapes.h>

#include "mesh_planes.hpp"
#include "point_cloud.hpp"
#include "pose.hpp"
#include "primitive_bound.hpp"
#include "robot.hpp"

namespace kcplan {

/// A separating plane n . x <= offset of one obstacle piece near a body, and the body's
/// clearance to the piece (never an overestimate). offset = inf: no plane (a mesh, or a
/// degenerate direction); only the clearance can be used. n has nz = 0 in 2D.
struct Plane {
  double n[3];
  double offset;
  double clearance;
};

/// What a region query knows about one body: every piece within `horizon` of it, as a
/// plane; pieces not listed are at least `horizon` away. Python twin: world/region.py.
struct FreeRegion {
  std::vector<Plane> planes;
  double horizon = 0.0;
  /// Distance to every obstacle, never an overestimate (0: touching or too close to tell).
  double clearance() const {
    double d = horizon;
    for (const Plane& p : planes) d = std::min(d, p.clearance);
    return d;
  }
};

/// Query counts, with the meanings of CollisionWorld.counters in Python: one per robot pose
/// queried (`body_queries` one per body actually queried).
struct WorldCounters {
  std::int64_t collision_queries = 0, distance_queries = 0, region_queries = 0,
               region_pairs = 0, body_queries = 0;
};

/// Collision and clearance queries for one robot against fixed obstacles, on coal.
///
/// The plane (2D) is embedded as in the Python world: the robot's bodies are ellipsoids
/// (a1, a2, min(a)) at z = 0, obstacles are solids whose z = 0 slice and projection are
/// the planar obstacle (prisms over |z| <= half_height, spheres, ellipsoids
/// (e1, e2, min(e))), so every 3D answer equals the planar one.
///
/// Convex pieces are coal convex polytopes with vertex neighbours (GJK hill-climbs over
/// them); meshes are BVH surfaces (a body wholly inside a closed mesh is reported free, as
/// with FCL). Every convex piece keeps its exact support function for region queries.
/// A mesh also keeps its triangles' planes (MeshPlanes): a shape on the inner side of all
/// of them is proven clear without the BVH, and its distance is read off the planes when
/// the bound is exact (a robot inside a convex arena); otherwise coal's BVH answers.
///
/// Contract: obstacles are added, then `finalize()` registers them once; queries take a
/// robot pose and throw std::invalid_argument for a pose that is not finite. Distances of
/// `safe_*` queries are reduced by coal's error allowance, `d (1 - rtol) - atol`, and are
/// never overestimates (the allowance is justified in kcplan/_kernel/__init__.py).
/// Not thread-safe: the robot's coal objects, the solvers and GJK's warm starts are reused
/// between queries.
///
/// A box, ball or cylinder obstacle keeps its parameters (Primitive): a robot shape
/// whose separation from it along the line to its nearest point already decides a query
/// (clear of it, or farther than the cap or the nearest so far) is not given to GJK.
///
/// Every narrow-phase query of a (robot shape, obstacle) pair starts GJK where the pair's
/// last query ended (its last direction and support vertices): for nearby poses GJK then
/// starts next to the answer, and its hill-climbing over a polytope's vertices starts
/// next to the support point. The start changes only how fast GJK converges, never its
/// stopping test, so verdicts and the distance error bound are those of a cold start.
class World {
 public:
  World(const Robot& robot, double half_height, double rtol, double atol);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // -- obstacles (world frame; lengths in the scenario's unit) --
  /// 2D: the prism over a convex counter-clockwise polygon `xy` (k points, 2k numbers).
  void add_prism(const std::vector<double>& xy);
  /// A box of half sides `half` about `centre`, rotated by the row-major 3x3 `rotation`;
  /// an identity rotation gives coal's Box, any other a convex polytope of the corners.
  void add_box(const std::array<double, 3>& centre, const std::array<double, 9>& rotation,
               const std::array<double, 3>& half);
  /// A convex polytope: vertices (m x 3, row-major) and its hull's triangles (t x 3).
  void add_convex(const std::vector<double>& vertices, const std::vector<int>& triangles);
  /// A ball (2D: a disc, as a sphere at z = 0).
  void add_sphere(const std::array<double, 3>& centre, double radius);
  /// An ellipsoid {c + R diag(e) u}; in 2D pass (e1, e2, min(e)) and R embedding the yaw.
  void add_ellipsoid(const std::array<double, 3>& centre, const std::array<double, 9>& rotation,
                     const std::array<double, 3>& extents);
  /// A cylinder of `radius` about its local z axis, |z| <= half_height, centred at
  /// `centre` and rotated by `rotation` (arm scenes; like a mesh it has no support
  /// function: region queries keep only its clearance).
  void add_cylinder(const std::array<double, 3>& centre, const std::array<double, 9>& rotation,
                    double radius, double half_height);
  /// A triangle mesh surface (no support function: its pieces keep only clearances).
  void add_mesh(const std::vector<double>& vertices, const std::vector<int>& triangles);
  /// A point cloud (3D only): the balls of `radius` about n points (`xyz`, n x 3
  /// row-major), one obstacle whose narrow phase is its PointCloud (its k-d tree, then
  /// coal's GJK per point that the tree's bounds leave undecided). Like a mesh it has no
  /// support function: region queries keep only its clearance.
  void add_points(const double* xyz, std::size_t n, double radius,
                  CloudOrder order = CloudOrder::morton);
  /// Register every obstacle in the broad phase (once, after the last add_*).
  void finalize();

  // -- queries (each counted once per pose) --
  /// Whether some body touches or overlaps an obstacle (stops at the first that does).
  bool in_collision(const Pose& pose);
  /// Distance of each body to the nearest obstacle (0 on contact, inf with no obstacles),
  /// as coal computes it: may overestimate by coal's error (and, to a point cloud, lie
  /// below it within cloud_tolerance()). `out` has one slot per body.
  void body_distances(const Pose& pose, double* out);
  /// body_distances reduced by the error allowance: certain lower bounds.
  void safe_body_clearances(const Pose& pose, double* out);
  /// Per body, the planes and clearances of every piece whose bounding box meets the cube
  /// of half side max(a_k) + horizon about the body's centre (a piece outside is at least
  /// `horizon` away); a body with no such piece gets one distance query and its clearance
  /// as horizon. Returns false, with every region empty and of horizon 0, as soon as a
  /// piece touches a body.
  bool free_regions(const Pose& pose, double horizon, std::vector<FreeRegion>& out);
  /// One body's part of free_regions, for body k as placed: `out` gets the plane and
  /// clearance of every piece whose bounding box meets the cube of half side max(a_k) +
  /// horizon about the body's centre, and `horizon` (an empty region: nothing within
  /// it). Returns false, `out` emptied with horizon 0, when a piece touches the body.
  /// With `primitive_slabs`, a box, ball or cylinder piece that Primitive::separation
  /// already holds apart from the body gets that plane (along the line from its point
  /// nearest the body's centre, clearance the separation) with no GJK. Counted as a body
  /// query.
  bool body_region(std::size_t k, double horizon, FreeRegion& out, bool primitive_slabs = false);
  // -- the same queries for bodies placed one by one (an arm: each body by its own frame) --
  /// Make body k the convex `shape` instead of its ellipsoid (in the body's frame, inside
  /// the ellipsoid: a link's hull, ChainBody::hull). Such a body has no KC guard:
  /// grown_body_clear is false for it. Before the first query.
  void set_body_shape(std::size_t k, std::shared_ptr<coal::CollisionGeometry> shape);
  /// Place body k alone at `frame` (world frame, finite); the others stay where they are.
  void place_body(std::size_t k, const coal::Transform3s& frame);
  /// in_collision for the bodies as placed.
  bool bodies_collide();
  /// body_distances for the bodies as placed.
  void bodies_distances(double* out);
  /// safe_body_clearances for the bodies as placed. With `caps` (one per body), body k
  /// gets min(its clearance, caps[k]) (still never an overestimate), and obstacles whose
  /// bounding box lies farther than the cap are not measured at all.
  void bodies_safe_clearances(double* out, const double* caps = nullptr);
  /// min(cap, the certain clearance) of body k placed at `frame` (one distance query; the
  /// other bodies stay where they are).
  double body_safe_clearance(std::size_t k, const coal::Transform3s& frame, double cap);
  /// A distance reduced by the error allowance, d (1 - rtol) - atol, at least 0: what a
  /// coal distance certainly is (never an overestimate).
  double safe(double d) const { return std::max(d * (1.0 - rtol_) - atol_, 0.0); }
  /// The padding that shape `shape` keeps: body k's own (set_body_padding) for a body,
  /// the largest of every body's for a shape past them (a ball or a sweep standing for
  /// several bodies).
  double padding_of(std::size_t shape) const {
    if (body_padding_.empty()) return padding_;
    return shape < body_padding_.size() ? body_padding_[shape] : max_padding_;
  }
  /// What an obstacle's coal distance to shape `shape` certainly leaves beyond its
  /// padding: safe(d) less the padding, at least 0. Every clearance of a body to the
  /// obstacles is this.
  double clear(double d, std::size_t shape) const {
    return std::max(d * (1.0 - rtol_) - atol_ - padding_of(shape), 0.0);
  }
  /// The raw coal distance past which shape `shape` is certainly clear by `cap` beyond
  /// its padding: clear(d, shape) >= cap for every d at least this.
  double raw_cap(double cap, std::size_t shape) const {
    return (cap + atol_ + padding_of(shape)) / (1.0 - rtol_);
  }
  /// Keep every body at least `padding` (>= 0, finite; length units) from every obstacle:
  /// clearances are reduced by it and a body nearer than it is in collision (MoveIt's
  /// link padding; self pairs are not padded). 0 by default. Undoes set_body_padding.
  void set_padding(double padding);
  /// Keep body k at least `padding` (>= 0, finite) from every obstacle instead of
  /// padding() (MoveIt's per-link padding); balls and sweeps that stand for several
  /// bodies keep the largest padding of all.
  void set_body_padding(std::size_t k, double padding);
  double padding() const { return padding_; }

  /// Whether body k grown about its centre by `scale` (its semi-axes times scale >= 1)
  /// and placed at `frame` is certainly clear of every obstacle: its clearance, reduced by
  /// the error allowance, is positive (one body query; the KC guard of arms). The body
  /// itself stays where it is. False, with no query, for a body of set_body_shape.
  bool grown_body_clear(std::size_t k, const coal::Transform3s& frame, double scale);
  /// Whether body k as placed touches an obstacle (one body's part of bodies_collide;
  /// counted as a body query, not as a collision query).
  bool body_collides(std::size_t k);
  /// min(cap, the certain clearance) of body k as placed (one body's part of
  /// bodies_safe_clearances; counted as a body query, not as a distance query).
  double capped_clearance(std::size_t k, double cap);

  /// Whether the ball of `radius` about `centre` (z = 0 in 2D) meets an obstacle.
  bool ball_collides(const std::array<double, 3>& centre, double radius);
  /// ball_collides, not counted: whether anything inside the ball may touch an obstacle.
  bool ball_touches(const std::array<double, 3>& centre, double radius);
  /// min(cap, the certain clearance) of the ball of `radius` about `centre` (not
  /// counted): a lower bound of the clearance of anything inside the ball.
  double ball_safe_clearance(const std::array<double, 3>& centre, double radius, double cap);
  /// Whether the capsule of `radius` about the segment a -> b meets an obstacle.
  bool sweep_core_collides(const std::array<double, 3>& a, const std::array<double, 3>& b,
                           double radius);

  const Robot& robot() const { return robot_; }
  /// The point clouds' work, summed over every cloud.
  CloudCounters cloud_counters() const;
  /// Which cheaper bounds every cloud asks before GJK (PointCloud::bounds_used; for
  /// ablations: the answers stay the same).
  void set_cloud_bounds(const CloudBounds& bounds) {
    for (auto& cloud : clouds_)
      if (cloud) cloud->bounds_used = bounds;
  }
  /// Rebuild every cloud's tree in `order` (for ablations: the answers stay the same).
  void set_cloud_order(CloudOrder order);
  /// A ball (metres) that holds every body at every state, padding included: the clouds
  /// added after it keep only the points whose balls meet it, and a cloud with none is
  /// not added (CloudReach: the verdicts at every state stay those of every point).
  /// Before the first obstacle (std::invalid_argument otherwise); none by default.
  void set_reach(const std::array<double, 3>& centre, double radius);
  const CloudReach& reach() const { return reach_; }
  /// Points kept by every cloud.
  std::size_t cloud_points() const {
    std::size_t n = 0;
    for (const auto& cloud : clouds_)
      if (cloud) n += cloud->size();
    return n;
  }
  /// How far below its distance a cloud's answer may lie beyond a shape's threshold
  /// (DistanceTolerance::relative, its floor raw_cap(0, shape): the verdict "clear beyond
  /// the padding" stays exact, and a clearance c past it is at least c / (1 + tolerance)).
  /// A looser answer lets the tree's search stop sooner (RESULTS 35.1: planning on a cloud
  /// 0.6-0.7x the time at 0.25); guards shrink by at most that factor. 0: exact.
  double cloud_tolerance() const { return cloud_tolerance_; }
  void set_cloud_tolerance(double relative) {
    if (!(relative >= 0.0) || !std::isfinite(relative))
      throw std::invalid_argument("cloud tolerance: expected a finite number >= 0");
    cloud_tolerance_ = relative;
  }
  void reset_cloud_counters() {
    for (auto& cloud : clouds_)
      if (cloud) cloud->counters = CloudCounters{};
  }
  std::size_t n_objects() const { return objects_.size(); }
  double atol() const { return atol_; }
  double rtol() const { return rtol_; }
  WorldCounters counters;
  std::vector<std::int64_t> body_query_counts;

 private:
  /// The exact support function h(n) = max over the piece of n . x, for region planes.
  struct Support {
    enum Kind { kPoints, kBall, kEllipsoid, kCylinder, kNone } kind = kNone;
    std::vector<double> points;  // kPoints: m x 3
    std::array<double, 3> centre{};
    double radius = 0.0;
    /// kEllipsoid: diag(e) R^T, row-major; kCylinder: its unit axis, then its half height
    std::array<double, 9> shape{};
    double operator()(const double* n) const;
  };

  /// Where GJK ended for one (robot shape, obstacle) pair: its last direction and the
  /// support vertices of both shapes (indices into that pair's polytopes only).
  struct WarmStart {
    coal::Vec3s guess = coal::Vec3s(1.0, 0.0, 0.0);
    coal::support_func_guess_t hint = coal::support_func_guess_t::Zero();
    /// Start the next query of the pair here (with GJKInitialGuess::CachedGuess).
    void start(coal::QueryRequest& request) const {
      request.cached_gjk_guess = guess;
      request.cached_support_func_guess = hint;
    }
    /// Keep where the query ended.
    void keep(const coal::QueryResult& result) {
      guess = result.cached_gjk_guess;
      hint = result.cached_support_func_guess;
    }
  };
  struct QuerySupport;
  struct CollideNear;
  struct DistanceNear;

  void add(const std::shared_ptr<coal::CollisionGeometry>& geometry,
           const coal::Transform3s& transform, Support support, Primitive primitive = {});
  void place(const Pose& pose);
  /// `shape` is the row of warm starts: a body's index, or core_shape() for a ball or capsule.
  bool collides(coal::CollisionObject& object, std::size_t shape);
  double distance(coal::CollisionObject& object, std::size_t shape);
  /// The distance of one pair (0 for an overlap or what coal cannot tell), warm-started;
  /// `result` keeps coal's nearest points.
  /// A point cloud is measured up to `cap` only (past it: `cap`, or more), and within
  /// cloud_tolerance() of the distance.
  double pair_distance(coal::CollisionObject& object, std::size_t shape,
                       coal::CollisionObject& obstacle, coal::DistanceRequest& request,
                       coal::DistanceResult& result,
                       double cap = std::numeric_limits<double>::infinity());
  /// The tolerance of a cloud's distance to shape `shape`: exact up to its threshold.
  DistanceTolerance cloud_search(std::size_t shape) const {
    return DistanceTolerance{cloud_tolerance_, raw_cap(0.0, shape)};
  }
  /// The obstacle's point cloud, or null when it is not one.
  PointCloud* cloud_of(const coal::CollisionObject& obstacle) const {
    return clouds_[reinterpret_cast<std::size_t>(obstacle.getUserData())].get();
  }
  WarmStart& warm(std::size_t shape, const coal::CollisionObject& obstacle);
  /// The planes' bound of a mesh obstacle for `query` (MeshPlanes::bound); no value when
  /// the obstacle is not a mesh (or its planes are unusable) or the query shape has no
  /// support here.
  std::optional<MeshPlanes::Bound> plane_bound(const coal::CollisionObject& query,
                                               const coal::CollisionObject& obstacle,
                                               bool measure) const;
  /// Primitive::separation of `obstacle` from the query shape `shape` (<= 0 or -inf:
  /// nothing known; `exact`: the bound is the distance).
  double primitive_gap(const ShapeSupport& shape, const coal::CollisionObject& obstacle,
                       bool& exact) const {
    return primitives_[reinterpret_cast<std::size_t>(obstacle.getUserData())].separation(
        shape, exact);
  }
  std::size_t core_shape() const { return bodies_.size(); }
  /// The one ball of ball queries, resized and moved to `centre` (not allocated anew).
  coal::CollisionObject& place_ball(const std::array<double, 3>& centre, double radius);
  void count_body(std::size_t k);

  Robot robot_;
  int dimension_;
  double half_height_, rtol_, atol_;
  double padding_ = 0.0;
  double cloud_tolerance_ = 0.25;
  CloudReach reach_;
  std::vector<double> body_padding_;  // per body; empty: padding_ for every one
  double max_padding_ = 0.0;          // the largest of body_padding_
  std::vector<std::unique_ptr<coal::CollisionObject>> objects_;
  std::vector<Support> supports_;
  std::vector<Primitive> primitives_;  // per obstacle; kNone: not a box, ball or cylinder
  std::vector<std::unique_ptr<const MeshPlanes>> planes_;  // per obstacle; null: not a mesh
  std::vector<std::unique_ptr<PointCloud>> clouds_;  // per obstacle; null: not a cloud
  std::vector<std::unique_ptr<coal::CollisionObject>> bodies_;
  std::vector<std::unique_ptr<coal::CollisionObject>> grown_;  // per body, made on first use
  std::vector<char> convex_;  // per body: its shape is set_body_shape's, not the ellipsoid
  std::vector<std::unique_ptr<coal::CollisionObject>> horizon_boxes_;
  std::shared_ptr<coal::Sphere> ball_shape_;  // ball queries' shape and object (place_ball)
  std::unique_ptr<coal::CollisionObject> ball_;
  std::vector<double> horizon_sides_;
  std::unique_ptr<coal::DynamicAABBTreeCollisionManager> manager_;
  std::vector<coal::CollisionObject*> near_;
  std::vector<WarmStart> warm_;  // (bodies + 1) x obstacles; the last row: ball and capsule
  bool finalized_ = false;
};

}  // namespace kcplan
