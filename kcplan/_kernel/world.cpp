#include "world.hpp"

#include "coal_requests.hpp"
#include "convex_body.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <coal/BVH/BVH_model.h>
#include <coal/broadphase/default_broadphase_callbacks.h>
#include <coal/collision.h>
#include <coal/distance.h>
#include <coal/shape/convex.h>
#include <coal/shape/geometric_shapes.h>

namespace kcplan {
namespace {

using coal::Vec3s;

coal::Matrix3s matrix(const Quat& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
}

coal::Matrix3s matrix(const std::array<double, 9>& r) {
  coal::Matrix3s m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  return m;
}

void require_finite(const Pose& pose) {
  if (!pose.finite)
    throw std::invalid_argument("pose: expected finite numbers (and a non-zero quaternion)");
}

void require_finite(const double* v, std::size_t n, const char* what) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i]))
      throw std::invalid_argument(std::string(what) + ": expected finite numbers");
}

void require_positive(const double* v, std::size_t n, const char* message) {
  for (std::size_t i = 0; i < n; ++i)
    if (!(v[i] > 0.0) || !std::isfinite(v[i])) throw std::invalid_argument(message);
}

Vec3s vec(const std::array<double, 3>& v) { return Vec3s(v[0], v[1], v[2]); }

/// Finite points from m x 3 flat numbers.
std::vector<Vec3s> points_of(const std::vector<double>& flat, const char* what) {
  if (flat.size() % 3) throw std::invalid_argument(std::string(what) + ": expected m x 3 vertices");
  require_finite(flat.data(), flat.size(), what);
  std::vector<Vec3s> points;
  points.reserve(flat.size() / 3);
  for (std::size_t i = 0; i < flat.size(); i += 3)
    points.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  return points;
}

/// Triangles from t x 3 flat indices into m vertices.
std::vector<coal::Triangle> triangles_of(const std::vector<int>& flat, std::size_t m,
                                         const char* what) {
  if (flat.size() % 3)
    throw std::invalid_argument(std::string(what) + ": expected t x 3 triangle indices");
  std::vector<coal::Triangle> faces;
  faces.reserve(flat.size() / 3);
  for (std::size_t i = 0; i < flat.size(); i += 3) {
    for (std::size_t j = i; j < i + 3; ++j)
      if (flat[j] < 0 || static_cast<std::size_t>(flat[j]) >= m)
        throw std::invalid_argument(std::string(what) + ": triangle index out of range");
    faces.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  }
  return faces;
}

/// A convex polytope with its triangles (make_convex).
std::shared_ptr<coal::CollisionGeometry> convex(const std::vector<Vec3s>& points,
                                                const std::vector<int>& triangles) {
  std::vector<double> flat;
  flat.reserve(3 * points.size());
  for (const Vec3s& p : points) flat.insert(flat.end(), {p[0], p[1], p[2]});
  return make_convex(flat, triangles, "convex");
}

/// Collects the obstacles whose bounding boxes meet the query object's (no narrow phase).
struct Collect : coal::CollisionCallBackBase {
  coal::CollisionObject* query = nullptr;
  std::vector<coal::CollisionObject*>* found = nullptr;
  bool collide(coal::CollisionObject* o1, coal::CollisionObject* o2) override {
    found->push_back(o1 == query ? o2 : o1);
    return false;  // keep going: every piece in the box
  }
};

}  // namespace

/// The query shape's support function, found once per query and only if asked.
struct World::QuerySupport {
  explicit QuerySupport(const coal::CollisionObject* q) : query(q) {}
  const coal::CollisionObject* query;
  ShapeSupport support;
  int known = -1;  // -1 not looked at, 0 the shape has none, 1 `support` holds it
  /// Primitive::separation of `obstacle` from the query shape (-inf: nothing known).
  double gap(const World& world, const coal::CollisionObject& obstacle, bool& exact) {
    if (known < 0) known = ShapeSupport::of(*query, support) ? 1 : 0;
    exact = false;
    return known ? world.primitive_gap(support, obstacle, exact)
                 : -std::numeric_limits<double>::infinity();
  }
};

/// The broad phase's candidates for one query shape, each tried with its pair's warm
/// start; stops at the first obstacle that touches the shape.
struct World::CollideNear : coal::CollisionCallBackBase {
  CollideNear(World* w, coal::CollisionObject* q, std::size_t s)
      : world(w), query(q), shape(s), support(q) {}
  World* world;
  coal::CollisionObject* query;
  std::size_t shape;
  QuerySupport support;
  bool hit = false;
  coal::CollisionRequest request = collision_request();
  coal::CollisionResult result;
  bool collide(coal::CollisionObject* o1, coal::CollisionObject* o2) override {
    coal::CollisionObject* obstacle = o1 == query ? o2 : o1;
    if (PointCloud* cloud = world->cloud_of(*obstacle)) return hit = cloud->collides(*query);
    bool exact;
    if (support.gap(*world, *obstacle, exact) > 0.0)
      return false;  // separated from the box, ball or cylinder along one line
    if (const auto bound = world->plane_bound(*query, *obstacle, false);
        bound && bound->value > 0.0)
      return false;  // clear of every triangle's plane: clear of the mesh
    WarmStart& w = world->warm(shape, *obstacle);
    w.start(request);
    result.clear();
    coal::collide(query, obstacle, request, result);
    w.keep(result);
    hit = confirmed_contact(result, [&] { return cold_collision(query, obstacle); });
    return hit;
  }
};

/// The smallest distance of one query shape to the broad phase's candidates, which the
/// broad phase uses to prune; stops at contact.
struct World::DistanceNear : coal::DistanceCallBackBase {
  DistanceNear(World* w, coal::CollisionObject* q, std::size_t s,
               double cap = std::numeric_limits<double>::infinity())
      : world(w), query(q), shape(s), support(q), best(cap) {}
  World* world;
  coal::CollisionObject* query;
  std::size_t shape;
  QuerySupport support;
  double best;  // starts at the cap: the broad phase then prunes every box beyond it
  coal::DistanceRequest request = distance_request(false);
  coal::DistanceResult result;
  bool distance(coal::CollisionObject* o1, coal::CollisionObject* o2,
                coal::CoalScalar& dist) override {
    coal::CollisionObject* obstacle = o1 == query ? o2 : o1;
    // the boxes' distance bounds the shapes' (each box holds its shape): past the cap,
    // or past the best so far, the obstacle cannot lower the answer
    if (query->getAABB().distance(obstacle->getAABB()) < best) {
      // a primitive's separation bounds the distance from below: at or past `best` the
      // obstacle cannot lower the answer; for a ball it is the distance
      bool exact;
      const double gap = support.gap(*world, *obstacle, exact);
      if (exact && gap > 0.0)
        best = std::min(best, gap);
      else if (gap < best)
        best = std::min(best,
                        world->pair_distance(*query, shape, *obstacle, request, result, best));
    }
    dist = best;
    return best <= 0.0;
  }
};

double World::Support::operator()(const double* n) const {
  switch (kind) {
    case kPoints: {
      // four running maxima: one alone makes the loop wait on each comparison's latency
      // (a polytope of the HRM maze has 3,008 vertices, and every region plane reads all)
      const double low = -std::numeric_limits<double>::infinity();
      double best[4] = {low, low, low, low};
      const double* p = points.data();
      const std::size_t m = points.size() / 3;
      std::size_t i = 0;
      for (; i + 4 <= m; i += 4)
        for (std::size_t j = 0; j < 4; ++j) {
          const double* x = p + 3 * (i + j);
          best[j] = std::max(best[j], x[0] * n[0] + x[1] * n[1] + x[2] * n[2]);
        }
      for (; i < m; ++i) {
        const double* x = p + 3 * i;
        best[0] = std::max(best[0], x[0] * n[0] + x[1] * n[1] + x[2] * n[2]);
      }
      return std::max(std::max(best[0], best[1]), std::max(best[2], best[3]));
    }
    case kBall:
      return centre[0] * n[0] + centre[1] * n[1] + centre[2] * n[2] +
             radius * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    case kEllipsoid: {
      double sq = 0.0;
      for (int r = 0; r < 3; ++r) {
        const double v = shape[3 * r] * n[0] + shape[3 * r + 1] * n[1] + shape[3 * r + 2] * n[2];
        sq += v * v;
      }
      return centre[0] * n[0] + centre[1] * n[1] + centre[2] * n[2] + std::sqrt(sq);
    }
    case kCylinder: {  // c . n + r |n across the axis| + h |n . a|
      const double along = shape[0] * n[0] + shape[1] * n[1] + shape[2] * n[2];
      const double across = std::max(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - along * along, 0.0);
      return centre[0] * n[0] + centre[1] * n[1] + centre[2] * n[2] +
             radius * std::sqrt(across) + shape[3] * std::abs(along);
    }
    case kNone:
      break;
  }
  return std::numeric_limits<double>::infinity();
}

World::World(const Robot& robot, double half_height, double rtol, double atol)
    : robot_(robot), dimension_(robot.dimension()), half_height_(half_height), rtol_(rtol),
      atol_(atol) {
  if (!(half_height > 0.0) || !(rtol >= 0.0 && rtol < 1.0) || !(atol >= 0.0) ||
      !std::isfinite(half_height) || !std::isfinite(atol))
    throw std::invalid_argument(
        "world: expected half_height > 0, 0 <= rtol < 1 and a finite atol >= 0");
  for (const Body& b : robot.bodies()) {
    const double c = dimension_ == 2 ? b.a_min : b.semi_axes[2];
    auto shape = std::make_shared<coal::Ellipsoid>(b.semi_axes[0], b.semi_axes[1], c);
    bodies_.push_back(std::make_unique<coal::CollisionObject>(shape));
    horizon_boxes_.emplace_back();
    horizon_sides_.push_back(-1.0);
  }
  body_query_counts.assign(robot.size(), 0);
  convex_.assign(robot.size(), 0);
  manager_ = std::make_unique<coal::DynamicAABBTreeCollisionManager>();
}

void World::add(const std::shared_ptr<coal::CollisionGeometry>& geometry,
                const coal::Transform3s& transform, Support support, Primitive primitive) {
  if (finalized_)
    throw std::invalid_argument("world: obstacles must be added before the first query");
  auto object = std::make_unique<coal::CollisionObject>(geometry, transform);
  object->computeAABB();
  object->setUserData(reinterpret_cast<void*>(supports_.size()));
  supports_.push_back(std::move(support));
  primitives_.push_back(primitive);
  planes_.emplace_back();
  clouds_.emplace_back();
  objects_.push_back(std::move(object));
}

void World::add_prism(const std::vector<double>& xy) {
  const std::size_t k = xy.size() / 2;
  if (k < 3 || xy.size() != 2 * k)
    throw std::invalid_argument("prism: expected a polygon of at least 3 points");
  require_finite(xy.data(), xy.size(), "prism");
  std::vector<Vec3s> points;
  Support support;
  support.kind = Support::kPoints;
  for (double z : {-half_height_, half_height_})
    for (std::size_t i = 0; i < k; ++i) points.emplace_back(xy[2 * i], xy[2 * i + 1], z);
  for (std::size_t i = 0; i < k; ++i) support.points.insert(support.points.end(), {xy[2 * i], xy[2 * i + 1], 0.0});
  std::vector<int> tri;
  const int n = static_cast<int>(k);
  // caps (bottom 0..k-1, top k..2k-1) as zigzag strips, not fans: coal stores at most
  // 255 neighbours per vertex, and a fan over a 256-gon gives its apex 255
  for (int i = 0, j = n - 1, step = 0; j - i >= 2; ++step) {
    const int a = i, b = step % 2 ? j - 1 : i + 1, c = j;
    tri.insert(tri.end(), {a, c, b});
    tri.insert(tri.end(), {n + a, n + b, n + c});
    (step % 2 ? j : i) += step % 2 ? -1 : 1;
  }
  for (int i = 0; i < n; ++i) {  // sides: two triangles per edge
    const int j = (i + 1) % n;
    tri.insert(tri.end(), {i, j, n + j});
    tri.insert(tri.end(), {i, n + j, n + i});
  }
  add(convex(points, tri), coal::Transform3s::Identity(), std::move(support));
}

void World::add_box(const std::array<double, 3>& centre, const std::array<double, 9>& rotation,
                    const std::array<double, 3>& half) {
  require_finite(centre.data(), 3, "box");
  require_finite(rotation.data(), 9, "box");
  require_positive(half.data(), 3, "box: expected positive finite half sides");
  const coal::Matrix3s R = matrix(rotation);
  Support support;
  support.kind = Support::kPoints;
  std::vector<Vec3s> corners;
  for (int c = 0; c < 8; ++c) {  // corner 4i + 2j + k has signs (i, j, k)
    const Vec3s local((c & 4 ? 1 : -1) * half[0], (c & 2 ? 1 : -1) * half[1],
                      (c & 1 ? 1 : -1) * half[2]);
    const Vec3s x = vec(centre) + R * local;
    corners.push_back(x);
    support.points.insert(support.points.end(), {x[0], x[1], x[2]});
  }
  const Primitive primitive = Primitive::box(vec(centre), R, vec(half));
  if (R.isIdentity(0.0)) {
    add(std::make_shared<coal::Box>(2 * half[0], 2 * half[1], 2 * half[2]),
        coal::Transform3s(coal::Matrix3s::Identity(), vec(centre)),
        std::move(support), primitive);
    return;
  }
  static const std::vector<int> faces = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                         2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
  add(convex(corners, faces), coal::Transform3s::Identity(), std::move(support), primitive);
}

void World::add_convex(const std::vector<double>& vertices, const std::vector<int>& triangles) {
  const std::vector<Vec3s> points = points_of(vertices, "convex");
  Support support;
  support.kind = Support::kPoints;
  support.points = vertices;
  add(convex(points, triangles), coal::Transform3s::Identity(), std::move(support));
}

void World::add_sphere(const std::array<double, 3>& centre, double radius) {
  require_finite(centre.data(), 3, "sphere");
  require_positive(&radius, 1, "sphere: expected a positive finite radius");
  Support support;
  support.kind = Support::kBall;
  support.centre = centre;
  support.radius = radius;
  add(std::make_shared<coal::Sphere>(radius),
      coal::Transform3s(coal::Matrix3s::Identity(), vec(centre)),
      std::move(support), Primitive::ball(vec(centre), radius));
}

void World::add_ellipsoid(const std::array<double, 3>& centre,
                          const std::array<double, 9>& rotation,
                          const std::array<double, 3>& extents) {
  require_finite(centre.data(), 3, "ellipsoid");
  require_finite(rotation.data(), 9, "ellipsoid");
  require_positive(extents.data(), 3, "ellipsoid: expected positive finite semi-axes");
  Support support;
  support.kind = Support::kEllipsoid;
  support.centre = centre;
  // shape = diag(e) R^T: row r is e_r times column r of R; in 2D the third row is 0 so
  // that only the planar ellipse counts (its support in the plane is the 2D one)
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      support.shape[3 * r + c] =
          (dimension_ == 2 && r == 2) ? 0.0 : extents[r] * rotation[3 * c + r];
  add(std::make_shared<coal::Ellipsoid>(extents[0], extents[1], extents[2]),
      coal::Transform3s(matrix(rotation), vec(centre)),
      std::move(support));
}

void World::add_cylinder(const std::array<double, 3>& centre,
                         const std::array<double, 9>& rotation, double radius,
                         double half_height) {
  require_finite(centre.data(), 3, "cylinder");
  require_finite(rotation.data(), 9, "cylinder");
  const double sizes[2] = {radius, half_height};
  require_positive(sizes, 2, "cylinder: expected a positive finite radius and height");
  Support support;
  support.kind = Support::kCylinder;
  support.centre = centre;
  support.radius = radius;
  const coal::Matrix3s R = matrix(rotation);
  for (int i = 0; i < 3; ++i) support.shape[i] = R(i, 2);  // the local z axis
  support.shape[3] = half_height;
  add(std::make_shared<coal::Cylinder>(radius, 2.0 * half_height),
      coal::Transform3s(R, vec(centre)), support,
      Primitive::cylinder(vec(centre), R, radius, half_height));
}

void World::add_mesh(const std::vector<double>& vertices, const std::vector<int>& triangles) {
  std::vector<Vec3s> points = points_of(vertices, "mesh");
  std::vector<coal::Triangle> faces = triangles_of(triangles, points.size(), "mesh");
  if (points.size() < 3 || faces.empty())
    throw std::invalid_argument("mesh: expected m x 3 vertices and t x 3 triangles");
  auto model = std::make_shared<coal::BVHModel<coal::OBBRSS>>();
  model->beginModel(static_cast<unsigned int>(faces.size()),
                    static_cast<unsigned int>(points.size()));
  model->addSubModel(points, faces);
  model->endModel();
  model->computeLocalAABB();
  add(model, coal::Transform3s::Identity(), Support{});
  auto planes = std::make_unique<const MeshPlanes>(points, faces);
  if (planes->usable()) planes_.back() = std::move(planes);
}

void World::add_points(const double* xyz, std::size_t n, double radius, CloudOrder order) {
  if (dimension_ != 3) throw std::invalid_argument("point cloud: a 3D obstacle");
  if (n > 0 && std::isfinite(reach_.radius)) {  // no obstacle when nothing is within reach
    bool any = false;  // a point within reach, or one the cloud refuses (not finite)
    for (std::size_t i = 0; i < n && !any; ++i) {
      const Eigen::Map<const Vec3s> p(xyz + 3 * i);
      any = !p.allFinite() || PointCloud::reachable(p, radius, reach_);
    }
    if (!any && std::isfinite(radius) && radius > 0.0) return;
  }
  auto cloud = std::make_unique<PointCloud>(xyz, n, radius, order, 8, reach_);
  // the broad phase sees the cloud's box; its narrow phase is the cloud's own
  const coal::AABB& box = cloud->bounds();
  const Vec3s side = box.max_ - box.min_;
  add(std::make_shared<coal::Box>(side[0], side[1], side[2]),
      coal::Transform3s(coal::Matrix3s::Identity(), box.center()), Support{});
  clouds_.back() = std::move(cloud);
}

void World::set_reach(const std::array<double, 3>& centre, double radius) {
  if (!(radius > 0.0) || !std::isfinite(centre[0]) || !std::isfinite(centre[1]) ||
      !std::isfinite(centre[2]))
    throw std::invalid_argument("reach: expected a finite centre and a radius > 0");
  if (!clouds_.empty()) throw std::invalid_argument("reach: expected before the first obstacle");
  reach_ = CloudReach{Vec3s(centre[0], centre[1], centre[2]), radius};
}

void World::set_cloud_order(CloudOrder order) {
  for (auto& cloud : clouds_) {
    if (!cloud) continue;
    const std::vector<Vec3s>& points = cloud->points();
    std::vector<double> xyz;
    xyz.reserve(3 * points.size());
    for (const Vec3s& p : points) xyz.insert(xyz.end(), {p[0], p[1], p[2]});
    auto rebuilt = std::make_unique<PointCloud>(xyz.data(), points.size(), cloud->radius(), order);
    rebuilt->bounds_used = cloud->bounds_used;
    cloud = std::move(rebuilt);
  }
}

CloudCounters World::cloud_counters() const {
  CloudCounters sum;
  for (const auto& cloud : clouds_)
    if (cloud) {
      sum.queries += cloud->counters.queries;
      sum.nodes += cloud->counters.nodes;
      sum.points += cloud->counters.points;
      sum.exact += cloud->counters.exact;
    }
  return sum;
}

void World::set_padding(double padding) {
  if (!(padding >= 0.0) || !std::isfinite(padding))
    throw std::invalid_argument("padding: expected a finite number >= 0");
  padding_ = padding;
  body_padding_.clear();
  max_padding_ = padding;
}

void World::set_body_padding(std::size_t k, double padding) {
  if (k >= bodies_.size())
    throw std::invalid_argument("body padding: expected a body index below " +
                                std::to_string(bodies_.size()));
  if (!(padding >= 0.0) || !std::isfinite(padding))
    throw std::invalid_argument("body padding: expected a finite number >= 0");
  if (body_padding_.empty()) body_padding_.assign(bodies_.size(), padding_);
  body_padding_[k] = padding;
  max_padding_ = *std::max_element(body_padding_.begin(), body_padding_.end());
}

void World::finalize() {
  if (finalized_) return;
  std::vector<coal::CollisionObject*> raw;
  raw.reserve(objects_.size());
  for (auto& o : objects_) raw.push_back(o.get());
  if (!raw.empty()) {
    manager_->registerObjects(raw);
    manager_->setup();
  }
  warm_.assign((bodies_.size() + 1) * objects_.size(), WarmStart{});
  finalized_ = true;
}

void World::place(const Pose& pose) {
  require_finite(pose);
  if (pose.size != pose_size(dimension_))
    throw std::invalid_argument("pose: expected " + std::to_string(pose_size(dimension_)) +
                                " numbers in " + std::to_string(dimension_) + "D, got " +
                                std::to_string(pose.size));
  if (!finalized_) finalize();
  std::array<double, 3> c;
  Quat q;
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    robot_.body_pose(pose, k, c, q);
    bodies_[k]->setTransform(matrix(q), Vec3s(c[0], c[1], c[2]));
    bodies_[k]->computeAABB();
  }
}

void World::count_body(std::size_t k) {
  ++counters.body_queries;
  ++body_query_counts[k];
}

std::optional<MeshPlanes::Bound> World::plane_bound(const coal::CollisionObject& query,
                                                    const coal::CollisionObject& obstacle,
                                                    bool measure) const {
  const MeshPlanes* planes = planes_[reinterpret_cast<std::size_t>(obstacle.getUserData())].get();
  ShapeSupport support;
  if (planes == nullptr || !ShapeSupport::of(query, support)) return std::nullopt;
  return planes->bound(support, measure);
}

World::WarmStart& World::warm(std::size_t shape, const coal::CollisionObject& obstacle) {
  return warm_[shape * objects_.size() + reinterpret_cast<std::size_t>(obstacle.getUserData())];
}

bool World::collides(coal::CollisionObject& object, std::size_t shape) {
  if (padding_of(shape) > 0.0) {  // nearer than the padding (beyond the allowance): a contact
    const double cap = 2.0 * raw_cap(0.0, shape);
    DistanceNear near(this, &object, shape, cap);
    manager_->distance(&object, &near);
    return near.best < cap && !(clear(near.best, shape) > 0.0);
  }
  CollideNear near(this, &object, shape);
  manager_->collide(&object, &near);
  return near.hit;
}

double World::pair_distance(coal::CollisionObject& object, std::size_t shape,
                            coal::CollisionObject& obstacle, coal::DistanceRequest& request,
                            coal::DistanceResult& result, double cap) {
  if (PointCloud* cloud = cloud_of(obstacle))
    return cloud->distance(object, cap, nullptr, cloud_search(shape));
  if (const auto bound = plane_bound(object, obstacle, true);
      bound && bound->value > 0.0 && bound->exact)
    return bound->value;
  WarmStart& w = warm(shape, obstacle);
  w.start(request);
  result.clear();
  const double d = coal::distance(&object, &obstacle, request, result);
  w.keep(result);
  return d > 0.0 ? d : 0.0;  // an overlap, or anything coal cannot tell (NaN): no clearance
}

double World::distance(coal::CollisionObject& object, std::size_t shape) {
  DistanceNear near(this, &object, shape);
  manager_->distance(&object, &near);
  return near.best;
}

void World::set_body_shape(std::size_t k, std::shared_ptr<coal::CollisionGeometry> shape) {
  if (k >= bodies_.size() || !shape) throw std::invalid_argument("body shape: expected a body index and a shape");
  if (finalized_) throw std::invalid_argument("body shape: expected before the first query");
  bodies_[k] = std::make_unique<coal::CollisionObject>(std::move(shape));
  convex_[k] = 1;
}

void World::place_body(std::size_t k, const coal::Transform3s& frame) {
  if (!finalized_) finalize();
  bodies_[k]->setTransform(frame);
  bodies_[k]->computeAABB();
}

bool World::in_collision(const Pose& pose) {
  place(pose);
  return bodies_collide();
}

bool World::bodies_collide() {
  ++counters.collision_queries;
  if (objects_.empty()) return false;
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    count_body(k);
    if (collides(*bodies_[k], k)) return true;
  }
  return false;
}

void World::body_distances(const Pose& pose, double* out) {
  place(pose);
  bodies_distances(out);
}

void World::bodies_distances(double* out) {
  ++counters.distance_queries;
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    if (objects_.empty()) {
      out[k] = std::numeric_limits<double>::infinity();
      continue;
    }
    count_body(k);
    out[k] = distance(*bodies_[k], k);
  }
}

void World::safe_body_clearances(const Pose& pose, double* out) {
  place(pose);
  bodies_safe_clearances(out);
}

void World::bodies_safe_clearances(double* out, const double* caps) {
  if (caps == nullptr) {
    bodies_distances(out);
    for (std::size_t k = 0; k < bodies_.size(); ++k) out[k] = clear(out[k], k);
    return;
  }
  ++counters.distance_queries;
  for (std::size_t k = 0; k < bodies_.size(); ++k) out[k] = capped_clearance(k, caps[k]);
}

double World::body_safe_clearance(std::size_t k, const coal::Transform3s& frame, double cap) {
  bodies_[k]->setTransform(frame);
  bodies_[k]->computeAABB();
  ++counters.distance_queries;
  return capped_clearance(k, cap);
}

bool World::grown_body_clear(std::size_t k, const coal::Transform3s& frame, double scale) {
  if (!(scale >= 1.0) || !std::isfinite(scale))
    throw std::invalid_argument("grown body: expected a finite scale >= 1");
  if (convex_[k]) return false;  // KC's guard is an ellipsoid's
  if (objects_.empty()) return true;
  if (!finalized_) finalize();
  if (grown_.empty()) grown_.resize(bodies_.size());
  const std::array<double, 3>& a = robot_.bodies()[k].semi_axes;
  if (!grown_[k])
    grown_[k] = std::make_unique<coal::CollisionObject>(
        std::make_shared<coal::Ellipsoid>(a[0], a[1], a[2]));
  coal::CollisionObject& grown = *grown_[k];
  auto* shape = static_cast<coal::Ellipsoid*>(grown.collisionGeometry().get());
  const coal::Vec3s radii(scale * a[0], scale * a[1], scale * a[2]);
  if (shape->radii != radii) {
    shape->radii = radii;
    shape->computeLocalAABB();
  }
  grown.setTransform(frame);
  grown.computeAABB();
  count_body(k);
  // clear when its distance is certainly positive: past the smallest cap that says so
  const double cap = std::numeric_limits<double>::min();
  const double raw = raw_cap(cap, k);
  DistanceNear near(this, &grown, k, raw);  // body k's warm starts: a shape like it
  manager_->distance(&grown, &near);
  return near.best >= raw || clear(near.best, k) > 0.0;
}

double World::capped_clearance(std::size_t k, double cap) {
  if (objects_.empty()) return std::numeric_limits<double>::infinity();
  count_body(k);
  // a raw distance of at least (cap + atol) / (1 - rtol) is certainly at least cap
  const double raw =
      cap < std::numeric_limits<double>::infinity() ? raw_cap(cap, k) : std::numeric_limits<double>::infinity();
  DistanceNear near(this, bodies_[k].get(), k, raw);
  manager_->distance(bodies_[k].get(), &near);
  return near.best >= raw ? cap : clear(near.best, k);
}

bool World::free_regions(const Pose& pose, double horizon, std::vector<FreeRegion>& out) {
  place(pose);
  ++counters.region_queries;
  out.resize(bodies_.size());
  for (FreeRegion& r : out) r.planes.clear(), r.horizon = horizon;
  if (objects_.empty()) {
    for (FreeRegion& r : out) r.horizon = std::numeric_limits<double>::infinity();
    return true;
  }
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    FreeRegion& region = out[k];
    if (!body_region(k, horizon, region)) {
      for (FreeRegion& r : out) r.planes.clear(), r.horizon = 0.0;
      return false;
    }
    if (region.planes.empty()) {  // open space: the clearance to everything is the better horizon
      ++counters.distance_queries;
      region.horizon = std::max(horizon, clear(distance(*bodies_[k], k), k));
    }
  }
  return true;
}

bool World::body_region(std::size_t k, double horizon, FreeRegion& region, bool primitive_slabs) {
  region.planes.clear();
  region.horizon = objects_.empty() ? std::numeric_limits<double>::infinity() : horizon;
  if (objects_.empty()) return true;
  if (!finalized_) finalize();
  count_body(k);
  coal::CollisionObject& body = *bodies_[k];
  // the broad-phase box of body k: contains every point within `horizon` of the body
  // beyond its padding (an obstacle outside it is farther than horizon + padding, so its
  // padded clearance exceeds the horizon)
  const double pad = padding_of(k);
  const double side = 2.0 * (robot_.bodies()[k].a_max + horizon + pad);
  const double height = dimension_ == 3 ? side : 4.0 * half_height_;  // every prism
  if (!horizon_boxes_[k]) {
    horizon_boxes_[k] =
        std::make_unique<coal::CollisionObject>(std::make_shared<coal::Box>(side, side, height));
    horizon_sides_[k] = side;
  } else if (horizon_sides_[k] != side) {  // resized in place: no allocation per query
    auto* shape = static_cast<coal::Box*>(horizon_boxes_[k]->collisionGeometry().get());
    shape->halfSide = 0.5 * Vec3s(side, side, height);
    shape->computeLocalAABB();
    horizon_sides_[k] = side;
  }
  coal::CollisionObject& box = *horizon_boxes_[k];
  box.setTranslation(body.getTranslation());
  box.computeAABB();
  near_.clear();
  Collect collect;
  collect.query = &box;
  collect.found = &near_;
  manager_->collide(&box, &collect);
  counters.region_pairs += static_cast<std::int64_t>(near_.size());
  coal::DistanceRequest request = distance_request(/*nearest_points=*/true);
  coal::DistanceResult result;
  ShapeSupport shape;
  primitive_slabs = primitive_slabs && ShapeSupport::of(body, shape);
  for (coal::CollisionObject* obstacle : near_) {
    const std::size_t index = reinterpret_cast<std::size_t>(obstacle->getUserData());
    if (primitive_slabs && primitives_[index].kind != Primitive::kNone) {
      bool exact;
      Vec3s n;
      const double gap = primitives_[index].separation(shape, exact, n) - pad;
      if (gap > 0.0) {  // the (padded) obstacle lies in {n . x <= support(n) + padding}
        Plane plane;
        for (int i = 0; i < 3; ++i) plane.n[i] = n[i];
        plane.offset = primitives_[index].support(n) + pad;
        plane.clearance = gap;
        region.planes.push_back(plane);
        continue;
      }
    }
    if (PointCloud* cloud = cloud_of(*obstacle)) {
      // measured up to the horizon only; its plane holds the balls that meet the
      // horizon's box (every other ball is farther than the horizon)
      Vec3s towards;
      const double d = cloud->distance(body, raw_cap(horizon, k), &towards, cloud_search(k));
      if (!(d > 0.0) || (pad > 0.0 && !(clear(d, k) > 0.0))) {
        region.planes.clear(), region.horizon = 0.0;
        return false;
      }
      Plane plane;
      plane.clearance = clear(d, k);
      plane.n[0] = plane.n[1] = plane.n[2] = 0.0;
      plane.offset = std::numeric_limits<double>::infinity();
      if (dimension_ == 3 && towards.squaredNorm() > 0.0) {
        for (int i = 0; i < 3; ++i) plane.n[i] = towards[i];
        // the padded balls lie in {n . x <= support + padding}
        plane.offset = cloud->support(box.getAABB(), towards) + pad;
      }
      region.planes.push_back(plane);
      continue;
    }
    const double d = pair_distance(body, k, *obstacle, request, result);
    if (!(d > 0.0) || (pad > 0.0 && !(clear(d, k) > 0.0))) {
      region.planes.clear(), region.horizon = 0.0;
      return false;
    }
    Plane plane;
    plane.clearance = clear(d, k);
    const Support& support = supports_[index];
    double v[3] = {0.0, 0.0, 0.0};
    if (support.kind != Support::kNone) {  // a mesh's distance may come without points
      const Vec3s dir = result.nearest_points[0] - result.nearest_points[1];
      v[0] = dir[0], v[1] = dir[1], v[2] = dimension_ == 3 ? dir[2] : 0.0;
    }
    const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (support.kind == Support::kNone || !(length > 0.0) || !std::isfinite(length)) {
      plane.n[0] = plane.n[1] = plane.n[2] = 0.0;
      plane.offset = std::numeric_limits<double>::infinity();
    } else {
      for (int i = 0; i < 3; ++i) plane.n[i] = v[i] / length;
      // exact: a wrong direction only weakens the plane; the padding lies beyond it
      plane.offset = support(plane.n) + pad;
    }
    region.planes.push_back(plane);
  }
  return true;
}

bool World::body_collides(std::size_t k) {
  if (objects_.empty()) return false;
  count_body(k);
  return collides(*bodies_[k], k);
}

coal::CollisionObject& World::place_ball(const std::array<double, 3>& centre, double radius) {
  if (!ball_) {
    ball_shape_ = std::make_shared<coal::Sphere>(radius);
    ball_ = std::make_unique<coal::CollisionObject>(ball_shape_);
  }
  if (ball_shape_->radius != radius) {
    ball_shape_->radius = radius;
    ball_shape_->computeLocalAABB();
  }
  ball_->setTransform(coal::Matrix3s::Identity(), Vec3s(centre[0], centre[1], centre[2]));
  ball_->computeAABB();
  return *ball_;
}

bool World::ball_collides(const std::array<double, 3>& centre, double radius) {
  ++counters.collision_queries;
  return ball_touches(centre, radius);
}

bool World::ball_touches(const std::array<double, 3>& centre, double radius) {
  require_finite(centre.data(), 3, "centre");
  if (!(radius > 0.0)) throw std::invalid_argument("radius: expected a positive number");
  if (!finalized_) finalize();
  if (objects_.empty()) return false;
  return collides(place_ball(centre, radius), core_shape());
}

double World::ball_safe_clearance(const std::array<double, 3>& centre, double radius,
                                  double cap) {
  require_finite(centre.data(), 3, "centre");
  if (!(radius > 0.0)) throw std::invalid_argument("radius: expected a positive number");
  if (!finalized_) finalize();
  if (objects_.empty()) return std::numeric_limits<double>::infinity();
  coal::CollisionObject& ball = place_ball(centre, radius);
  // as capped_clearance: a raw distance of at least (cap + atol) / (1 - rtol) is certainly
  // at least cap
  const double raw =
      cap < std::numeric_limits<double>::infinity() ? raw_cap(cap, core_shape())
                                                    : std::numeric_limits<double>::infinity();
  DistanceNear near(this, &ball, core_shape(), raw);
  manager_->distance(&ball, &near);
  return near.best >= raw ? cap : clear(near.best, core_shape());
}

bool World::sweep_core_collides(const std::array<double, 3>& a, const std::array<double, 3>& b,
                                double radius) {
  require_finite(a.data(), 3, "sweep");
  require_finite(b.data(), 3, "sweep");
  if (!(radius > 0.0)) throw std::invalid_argument("radius: expected a positive number");
  if (!finalized_) finalize();
  ++counters.collision_queries;
  if (objects_.empty()) return false;
  const Vec3s p(a[0], a[1], a[2]), q(b[0], b[1], b[2]);
  const Vec3s d = q - p;
  const double length = d.norm();
  // the rotation taking the capsule's z axis onto the segment
  const Vec3s u = length > 0.0 ? Vec3s(d / length) : Vec3s(0.0, 0.0, 1.0);
  const coal::Matrix3s R =
      Eigen::Quaterniond::FromTwoVectors(Vec3s(0.0, 0.0, 1.0), u).toRotationMatrix();
  coal::CollisionObject capsule(std::make_shared<coal::Capsule>(radius, length),
                                coal::Transform3s(R, 0.5 * (p + q)));
  capsule.computeAABB();
  return collides(capsule, core_shape());
}

}  // namespace kcplan
