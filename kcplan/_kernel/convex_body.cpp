#include "convex_body.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kcplan {

std::shared_ptr<coal::ConvexBase> make_convex(const std::vector<double>& vertices,
                                              const std::vector<int>& triangles,
                                              const char* what) {
  const std::string name(what);
  if (vertices.size() % 3 || triangles.size() % 3)
    throw std::invalid_argument(name + ": expected m x 3 vertices and t x 3 triangle indices");
  const std::size_t m = vertices.size() / 3;
  if (m < 4 || triangles.size() < 12)
    throw std::invalid_argument(name + ": expected at least 4 vertices and 4 triangles");
  auto points = std::make_shared<std::vector<coal::Vec3s>>();
  points->reserve(m);
  for (std::size_t i = 0; i < vertices.size(); i += 3) {
    if (!std::isfinite(vertices[i]) || !std::isfinite(vertices[i + 1]) ||
        !std::isfinite(vertices[i + 2]))
      throw std::invalid_argument(name + ": expected finite numbers");
    points->emplace_back(vertices[i], vertices[i + 1], vertices[i + 2]);
  }
  auto faces = std::make_shared<std::vector<coal::Triangle>>();
  faces->reserve(triangles.size() / 3);
  for (std::size_t i = 0; i < triangles.size(); i += 3) {
    for (std::size_t j = i; j < i + 3; ++j)
      if (triangles[j] < 0 || static_cast<std::size_t>(triangles[j]) >= m)
        throw std::invalid_argument(name + ": triangle index out of range");
    faces->emplace_back(triangles[i], triangles[i + 1], triangles[i + 2]);
  }
  auto shape = std::make_shared<SupportedConvex>(
      points, static_cast<unsigned int>(m), faces, static_cast<unsigned int>(faces->size()));
  shape->computeLocalAABB();
  return shape;
}

VertexSupport::VertexSupport(const std::vector<coal::Vec3s>& points)
    : x_(static_cast<Eigen::Index>(points.size())),
      y_(static_cast<Eigen::Index>(points.size())),
      z_(static_cast<Eigen::Index>(points.size())) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    x_[k] = points[i][0], y_[k] = points[i][1], z_[k] = points[i][2];
  }
}

SupportedConvex::SupportedConvex(std::shared_ptr<std::vector<coal::Vec3s>> points,
                                 unsigned int num_points,
                                 std::shared_ptr<std::vector<coal::Triangle>> faces,
                                 unsigned int num_faces)
    : coal::Convex<coal::Triangle>(points, num_points, faces, num_faces),
      support_(*points),
      faces_(*points, *faces, support_) {
  user_data = this;  // the mark of() looks for
}

FacePlanes::FacePlanes(const std::vector<coal::Vec3s>& v,
                       const std::vector<coal::Triangle>& triangles,
                       const VertexSupport& support) {
  std::vector<std::array<double, 3>> normals;
  normals.reserve(triangles.size());
  for (const coal::Triangle& t : triangles) {
    coal::Vec3s n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
    const double length = n.norm();
    if (!(length > 0.0) || !std::isfinite(length)) continue;  // a degenerate triangle
    n /= length;
    // outwards: the side on which the triangle touches the support
    if (support(n) - n.dot(v[t[0]]) > support(-n) + n.dot(v[t[0]])) n = -n;
    normals.push_back({n[0], n[1], n[2]});
  }
  // coplanar triangles share one plane: equal normals (to 1e-9) kept once
  std::sort(normals.begin(), normals.end());
  std::vector<coal::Vec3s> kept;
  for (const auto& n : normals) {
    const coal::Vec3s u(n[0], n[1], n[2]);
    if (kept.empty() || (kept.back() - u).cwiseAbs().maxCoeff() > 1e-9) kept.push_back(u);
  }
  const auto count = static_cast<Eigen::Index>(kept.size());
  x_.resize(count), y_.resize(count), z_.resize(count), offset_.resize(count);
  for (Eigen::Index j = 0; j < count; ++j) {
    const coal::Vec3s& n = kept[static_cast<std::size_t>(j)];
    x_[j] = n[0], y_[j] = n[1], z_[j] = n[2];
    offset_[j] = support(n) * (1.0 + 1e-12) + 1e-15;  // rounded up: the plane holds it all
  }
}

bool FacePlanes::face_distance(const coal::Vec3s& p, double& distance,
                               coal::Vec3s& normal) const {
  if (offset_.size() == 0) return false;
  Eigen::Index f;
  const double b = (x_ * p[0] + y_ * p[1] + z_ * p[2] - offset_).maxCoeff(&f);
  normal = coal::Vec3s(x_[f], y_[f], z_[f]);
  if (b <= 0.0) {  // within every plane: inside the polytope
    distance = 0.0;
    return true;
  }
  const coal::Vec3s foot = p - b * normal;
  const double allowance = 1e-12 * (1.0 + p.norm() + offset_.abs().maxCoeff());
  if ((x_ * foot[0] + y_ * foot[1] + z_ * foot[2] - offset_).maxCoeff() > allowance) return false;
  distance = b;
  return true;
}

BodyHull::BodyHull(const std::vector<double>& vertices, const std::vector<int>& triangles)
    : shape_(make_convex(vertices, triangles, "hull")),
      support_(SupportedConvex::of(*shape_)) {
  for (const coal::Vec3s& v : *shape_->points) radius_ = std::max(radius_, v.norm());
  radius_ *= 1.0 + 1e-12;  // rounding: the ball must hold every vertex
}

double BodyHull::support(const coal::Vec3s& n) const { return (*support_)(n); }

}  // namespace kcplan
