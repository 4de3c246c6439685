#include "point_cloud.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <coal/collision.h>
#include <coal/distance.h>

#include "coal_requests.hpp"

namespace kcplan {

using coal::Vec3s;

namespace {

/// Unit directions of the faces, edges and corners of a cube: a hull's supports along
/// them bound it by 26 planes (a k-DOP), which a point's local coordinates meet in 26
/// dot products.
std::array<Vec3s, 26> dop_directions() {
  std::array<Vec3s, 26> out;
  std::size_t k = 0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x != 0 || y != 0 || z != 0) out[k++] = Vec3s(x, y, z).normalized();
  return out;
}

const std::array<Vec3s, 26> kDopDirections = dop_directions();

/// The 10 low bits of `v` spread to every third bit (bit i to bit 3 i): one axis of a
/// Morton code.
std::uint64_t spread_bits(std::uint32_t v) {
  std::uint64_t x = v & 0x3ffu;
  x = (x | (x << 16)) & 0x030000ffu;
  x = (x | (x << 8)) & 0x0300f00fu;
  x = (x | (x << 4)) & 0x030c30c3u;
  x = (x | (x << 2)) & 0x09249249u;
  return x;
}

/// The `kept` points of the n points `xyz` (n x 3) that `skip` (empty: none) does not
/// mark, sorted along a Morton curve: per point a key, its 30-bit code in bits 32-61
/// (cubic cells, 1024 to the longest side of the box lo-hi that holds them) and its index
/// in `xyz` below, the keys in the code's order (ties in the index's).
std::vector<std::uint64_t> morton_keys(const double* xyz, std::size_t n, std::size_t kept,
                                       const Vec3s& lo, const Vec3s& hi,
                                       const std::vector<bool>& skip) {
  const double side = (hi - lo).maxCoeff();
  const double scale = side > 0.0 ? 1023.0 / side : 0.0;
  auto cell = [scale](double v) {
    return static_cast<std::uint32_t>(std::clamp(v * scale, 0.0, 1023.0));
  };
  std::vector<std::uint64_t> keys(kept), sorted(kept);
  for (std::size_t i = 0, k = 0; i < n; ++i) {
    if (!skip.empty() && skip[i]) continue;
    const double* p = xyz + 3 * i;
    const std::uint64_t code = spread_bits(cell(p[0] - lo[0])) |
                               spread_bits(cell(p[1] - lo[1])) << 1 |
                               spread_bits(cell(p[2] - lo[2])) << 2;
    keys[k++] = code << 32 | i;
  }
  // least significant digit first, 10 bits a pass: 3 passes, each stable
  for (int shift = 32; shift < 62; shift += 10) {
    std::array<std::uint32_t, 1025> start{};
    for (const std::uint64_t k : keys) ++start[((k >> shift) & 1023u) + 1];
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    for (const std::uint64_t k : keys) sorted[start[(k >> shift) & 1023u]++] = k;
    keys.swap(sorted);
  }
  return keys;
}

}  // namespace

const PointCloud::Dop& PointCloud::dop_of(const coal::CollisionGeometry& hull,
                                          const VertexSupport& support) {
  auto [at, fresh] = dops_.try_emplace(&hull);
  if (fresh)
    for (std::size_t j = 0; j < kDopDirections.size(); ++j)
      at->second[j] = support(kDopDirections[j]) * (1.0 + 1e-12) + 1e-15;
  return at->second;
}

/// One query's shape and what the bounds need of it: its support, found once, and the
/// planes {x : n . x <= h} holding it that GJK's nearest points have shown so far.
struct PointCloud::Query {
  static constexpr int kPlanes = 4;
  const coal::CollisionObject* object;
  const coal::AABB* box;
  ShapeSupport support;
  bool supported;
  double scale;  // of the numbers in a bound, for its rounding allowance
  Vec3s normals[kPlanes];
  double offsets[kPlanes];
  int planes = 0, next = 0;

  bool ball;  // the shape is a ball: a point's bound along the centres' line is exact

  coal::Matrix3s rotation;  // the shape's frame
  Vec3s origin;
  const Dop* dop = nullptr;  // a hull's supports along kDopDirections (its frame), or null
  // those planes in the world, a coordinate to an array (26 products at once): the
  // normals n, their absolute values |n| (a box's half sides' reach) and the offsets
  using Planes = Eigen::Array<double, 26, 1>;
  Planes dop_x, dop_y, dop_z, dop_span_x, dop_span_y, dop_span_z, dop_offsets;

  CloudBounds use;

  Query(const coal::CollisionObject& o, PointCloud& cloud)
      : object(&o), box(&o.getAABB()), supported(ShapeSupport::of(o, support)),
        use(cloud.bounds_used) {
    rotation = o.getTransform().getRotation();
    origin = o.getTransform().getTranslation();
    if (support.hull_support != nullptr && use.dop) {
      dop = &cloud.dop_of(*o.collisionGeometryPtr(), *support.hull_support);
      // the planes in the world: d . x <= h_d + d . t for the world's d = R d_local
      for (std::size_t j = 0; j < kDopDirections.size(); ++j) {
        const Vec3s n = rotation * kDopDirections[j];
        dop_x[j] = n[0], dop_y[j] = n[1], dop_z[j] = n[2];
        dop_span_x[j] = std::abs(n[0]), dop_span_y[j] = std::abs(n[1]);
        dop_span_z[j] = std::abs(n[2]);
        dop_offsets[j] = (*dop)[j] + n.dot(origin);
      }
    }
    scale = 1.0 + support.centre.norm() + std::abs(support.spread_high);
    ball = supported && support.hull == nullptr && !support.capsule &&
           support.spread_low == support.spread_high;
  }

  /// Keep the plane across unit `n` that touches the shape (its support there).
  void add_plane(const Vec3s& n) {
    if (!supported || !use.gjk_planes) return;
    normals[next] = n;
    offsets[next] = n.dot(support.centre) + support.spread(n);
    next = (next + 1) % kPlanes;
    planes = std::min(planes + 1, kPlanes);
  }

  /// A lower bound of the distance from the shape to any point of the box about `m` of
  /// half sides `half` (a point: `Point` true, half = 0), less rounding, or a number at
  /// least `best` as soon as one is known (the cheap bounds first: the boxes' gap, the
  /// shape's bounding ball, a hull's 26 fixed planes, the kept planes, and only then, for
  /// a shape other than a polytope, the support along the centres' line).
  template <bool Point>
  double bound(const Vec3s& m, const Vec3s& half, double best) const {
    const double rho = Point ? 0.0 : half.norm();
    const double slack = 1e-12 * (scale + m.norm() + rho);
    const coal::AABB& b = *box;  // the boxes' gap: the shape lies in its box
    const Vec3s out = Point ? Vec3s((b.min_ - m).cwiseMax(m - b.max_).cwiseMax(0.0))
                            : Vec3s((b.min_ - half - m).cwiseMax(m - half - b.max_).cwiseMax(0.0));
    double lower = out.norm();
    if (lower - slack >= best || !supported) return lower - slack;
    const Vec3s d = m - support.centre;
    const double length = d.norm();
    lower = std::max(lower, length - support.spread_high - rho);  // the shape's ball
    if (lower - slack >= best) return lower - slack;
    if (dop != nullptr) {  // the hull lies in {x : n . x <= h} for each of the 26 planes,
      // the box in {y : n . y >= n . m - |n| . half}
      Planes gap = dop_x * m[0] + dop_y * m[1] + dop_z * m[2] - dop_offsets;
      if (!Point) gap -= dop_span_x * half[0] + dop_span_y * half[1] + dop_span_z * half[2];
      lower = std::max(lower, gap.maxCoeff());
      if (lower - slack >= best) return lower - slack;
    }
    // each kept plane: the shape lies in {n . x <= h}, the box in {n . y >= n . m - |n| . half}
    for (int j = 0; j < planes; ++j)
      lower = std::max(lower, normals[j].dot(m) - (Point ? 0.0 : normals[j].cwiseAbs().dot(half)) -
                                  offsets[j]);
    if (lower - slack >= best) return lower - slack;
    // a polytope's support is a scan of its vertices: it cost more than it saved
    // (scripts/cloud_bounds.py), so hulls go to GJK here; an ellipsoid's is one product
    if (length > 0.0 && use.centre_line && support.hull == nullptr)
      lower = std::max(lower, length - support.spread(d / length) - rho);
    return lower - slack;
  }
};

PointCloud::PointCloud(const double* xyz, std::size_t n, double radius, CloudOrder order,
                       std::size_t leaf_size, const CloudReach& reach)
    : radius_(radius) {
  if (n == 0) throw std::invalid_argument("point cloud: expected at least one point");
  if (n >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("point cloud: too many points");
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("point cloud: expected a finite radius > 0");
  if (!(reach.radius > 0.0) || !reach.centre.allFinite())
    throw std::invalid_argument("point cloud: expected a reach of radius > 0");
  if (leaf_size == 0) leaf_size = 1;
  Vec3s lo = Vec3s::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  std::vector<bool> skip;  // the points beyond reach (none: empty)
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Map<const Vec3s> p(xyz + 3 * i);
    if (!p.allFinite()) throw std::invalid_argument("point cloud: expected finite coordinates");
    if (std::isfinite(reach.radius) && !reachable(p, radius, reach)) {
      if (skip.empty()) skip.assign(n, false);
      skip[i] = true;
      continue;
    }
    ++kept;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (kept == 0) throw std::invalid_argument("point cloud: expected a point within reach");
  // a split leaves at least one point on each side: at most 2 n - 1 nodes
  nodes_.reserve(order == CloudOrder::median ? 4 * (kept / leaf_size + 1) : 2 * kept);
  nodes_.resize(1);
  points_.resize(kept);
  if (order == CloudOrder::median) {
    for (std::size_t i = 0, k = 0; i < n; ++i)
      if (skip.empty() || !skip[i]) points_[k++] = Eigen::Map<const Vec3s>(xyz + 3 * i);
    build_median(0, 0, static_cast<std::uint32_t>(kept), leaf_size);
  } else {  // the points copied once, in the curve's order
    const std::vector<std::uint64_t> keys = morton_keys(xyz, n, kept, lo, hi, skip);
    for (std::size_t i = 0; i < kept; ++i)
      points_[i] = Eigen::Map<const Vec3s>(xyz + 3 * (keys[i] & 0xffffffffu));
    Vec3s node_lo, node_hi;
    build_cells(0, 0, static_cast<std::uint32_t>(kept), keys, leaf_size, node_lo, node_hi);
  }
  const Node& root = nodes_[0];
  const Vec3s grow = root.half + Vec3s::Constant(radius_);
  bounds_ = coal::AABB(root.centre - grow, root.centre + grow);
  ball_ = std::make_shared<coal::Sphere>(radius_);
}

void PointCloud::build_median(std::size_t index, std::uint32_t begin, std::uint32_t end,
                              std::size_t leaf_size) {
  Vec3s lo = points_[begin], hi = points_[begin];
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    lo = lo.cwiseMin(points_[i]);
    hi = hi.cwiseMax(points_[i]);
  }
  nodes_[index] = Node{0.5 * (lo + hi), 0.5 * (hi - lo), begin, end, -1};
  if (end - begin <= leaf_size) return;
  int axis;
  (hi - lo).maxCoeff(&axis);
  const std::uint32_t middle = begin + (end - begin) / 2;
  std::nth_element(points_.begin() + begin, points_.begin() + middle, points_.begin() + end,
                   [axis](const Vec3s& a, const Vec3s& b) { return a[axis] < b[axis]; });
  // the children side by side: left at `left`, right at `left + 1`
  const std::size_t left = nodes_.size();
  nodes_.resize(left + 2);
  nodes_[index].left = static_cast<std::int32_t>(left);
  build_median(left, begin, middle, leaf_size);
  build_median(left + 1, middle, end, leaf_size);
}

void PointCloud::build_cells(std::size_t index, std::uint32_t begin, std::uint32_t end,
                             const std::vector<std::uint64_t>& keys, std::size_t leaf_size,
                             Vec3s& lo, Vec3s& hi) {
  std::int32_t left = -1;
  if (end - begin <= leaf_size) {
    lo = hi = points_[begin];
    for (std::uint32_t i = begin + 1; i < end; ++i) {
      lo = lo.cwiseMin(points_[i]);
      hi = hi.cwiseMax(points_[i]);
    }
  } else {  // the children side by side: left at `left`, right at `left + 1`
    // split where the highest bit in which the range's codes differ turns to 1 (the
    // codes are sorted: every code before has it 0); one cell: at the middle
    std::uint32_t middle = begin + (end - begin) / 2;
    const std::uint64_t differ = (keys[begin] ^ keys[end - 1]) >> 32;
    if (differ != 0) {
      std::uint64_t bit = std::uint64_t{1} << 31;
      while ((differ & bit) == 0) bit >>= 1;
      bit <<= 32;  // the code's bit, in the key
      middle = static_cast<std::uint32_t>(
          std::partition_point(keys.begin() + begin, keys.begin() + end,
                               [bit](std::uint64_t k) { return (k & bit) == 0; }) -
          keys.begin());
    }
    left = static_cast<std::int32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + 2);
    Vec3s right_lo, right_hi;
    build_cells(left, begin, middle, keys, leaf_size, lo, hi);
    build_cells(left + 1, middle, end, keys, leaf_size, right_lo, right_hi);
    lo = lo.cwiseMin(right_lo);
    hi = hi.cwiseMax(right_hi);
  }
  nodes_[index] = Node{0.5 * (lo + hi), 0.5 * (hi - lo), begin, end, left};
}

double PointCloud::exact(Query& q, std::size_t i, Vec3s& towards) {
  ++counters.exact;
  coal::DistanceRequest request = distance_request(true);
  request.gjk_initial_guess = coal::GJKInitialGuess::DefaultGuess;
  coal::DistanceResult result;
  const coal::Transform3s at(coal::Matrix3s::Identity(), points_[i]);
  const double d = coal::distance(q.object->collisionGeometryPtr(), q.object->getTransform(),
                                  ball_.get(), at, request, result);
  if (!(d > 0.0)) {  // an overlap, or anything coal cannot tell (NaN): contact
    towards.setZero();
    return 0.0;
  }
  // the direction from the shape's nearest point towards the ball's: a plane that will
  // bound the points beside this one (its offset is the shape's exact support)
  const Vec3s dir = result.nearest_points[1] - result.nearest_points[0];
  const double length = dir.norm();
  if (length > 0.0 && std::isfinite(length)) {
    q.add_plane(dir / length);
    towards = -dir / length;
  } else {
    towards.setZero();
  }
  return d;
}

double PointCloud::search(Query& q, double cap, double stop_below, const DistanceTolerance& tol,
                          Vec3s* towards) {
  ++counters.queries;
  // `best`: the nearest ball met (cap: none yet); `limit`: what a bound must stay under
  // for its node or point to be looked at, tol.lower(best) (every bound at or past it
  // leaves the answer, tol.lower(best), a lower bound; DistanceTolerance)
  double best = cap, limit = cap;
  auto node_bound = [&](const Node& node) {
    ++counters.nodes;
    return q.bound<false>(node.centre, node.half, limit + radius_) - radius_;
  };
  stack_.clear();
  if (node_bound(nodes_[0]) < limit) stack_.push_back(0);
  while (!stack_.empty()) {
    const Node& node = nodes_[stack_.back()];
    stack_.pop_back();
    if (node.left < 0) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        ++counters.points;
        const double bound = q.bound<true>(points_[i], Vec3s::Zero(), limit + radius_) - radius_;
        if (bound >= limit) continue;
        Vec3s dir;
        double d;
        if (q.ball) {  // the bound is the distance, along the centres' line
          d = std::max(bound, 0.0);
          dir = q.support.centre - points_[i];
          const double length = dir.norm();
          dir = length > 0.0 ? Vec3s(dir / length) : Vec3s(Vec3s::Zero());
        } else {
          d = exact(q, i, dir);
        }
        if (d < best) {
          best = d;
          limit = tol.lower(d);
          if (towards != nullptr) *towards = dir;
        }
        if (best < stop_below) return best;
      }
      continue;
    }
    const double a = node_bound(nodes_[node.left]), b = node_bound(nodes_[node.left + 1]);
    // the nearer child is popped first: pushed last
    const std::int32_t near = a <= b ? node.left : node.left + 1;
    const double far_bound = a <= b ? b : a, near_bound = a <= b ? a : b;
    if (far_bound < limit) stack_.push_back(near == node.left ? node.left + 1 : node.left);
    if (near_bound < limit) stack_.push_back(near);
  }
  return best < cap ? limit : cap;
}

bool PointCloud::collides(const coal::CollisionObject& shape) {
  Query q(shape, *this);
  // a contact within GJK's tolerance counts (as collision_request() counts it)
  const double within = distance_request(false).gjk_tolerance;
  return search(q, within, within, DistanceTolerance{}, nullptr) < within;
}

double PointCloud::distance(const coal::CollisionObject& shape, double cap, Vec3s* towards,
                            const DistanceTolerance& tolerance) {
  if (!(tolerance.relative >= 0.0) || !(tolerance.floor >= 0.0))
    throw std::invalid_argument("cloud distance: expected a tolerance and a floor >= 0");
  Query q(shape, *this);
  if (towards != nullptr) towards->setZero();
  return std::max(search(q, cap, std::numeric_limits<double>::min(), tolerance, towards), 0.0);
}

double PointCloud::support(const coal::AABB& region, const Vec3s& n) const {
  // a ball meets the region only if its centre lies in the region grown by the radius
  const coal::AABB grown(region.min_ - Vec3s::Constant(radius_),
                         region.max_ + Vec3s::Constant(radius_));
  const Vec3s m = n.cwiseAbs();
  double best = -std::numeric_limits<double>::infinity();
  std::vector<std::int32_t> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    const coal::AABB box(node.centre - node.half, node.centre + node.half);
    // nothing of the node in the region, or nothing of it above what is known
    if (!grown.overlap(box) || n.dot(node.centre) + m.dot(node.half) <= best) continue;
    if (node.left >= 0) {
      stack.push_back(node.left);
      stack.push_back(node.left + 1);
      continue;
    }
    for (std::uint32_t i = node.begin; i < node.end; ++i)
      if (grown.contain(points_[i])) best = std::max(best, n.dot(points_[i]));
  }
  return best + radius_ * n.norm();
}

}  // namespace kcplan
