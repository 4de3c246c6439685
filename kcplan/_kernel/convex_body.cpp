#include "convex_body.hpp"

#include <algorithm>
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
    : coal::Convex<coal::Triangle>(points, num_points, faces, num_faces), support_(*points) {
  user_data = this;  // the mark of() looks for
}

BodyHull::BodyHull(const std::vector<double>& vertices, const std::vector<int>& triangles)
    : shape_(make_convex(vertices, triangles, "hull")),
      support_(SupportedConvex::of(*shape_)) {
  for (const coal::Vec3s& v : *shape_->points) radius_ = std::max(radius_, v.norm());
  radius_ *= 1.0 + 1e-12;  // rounding: the ball must hold every vertex
}

double BodyHull::support(const coal::Vec3s& n) const { return (*support_)(n); }

}  // namespace kcplan
