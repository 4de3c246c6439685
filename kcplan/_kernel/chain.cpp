#include "chain.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace kcplan {
namespace {

coal::Transform3s transform_of(const double* h, const char* what) {
  for (int i = 0; i < 16; ++i)
    if (!std::isfinite(h[i])) throw std::invalid_argument(std::string(what) + ": expected finite numbers");
  coal::Matrix3s R;
  R << h[0], h[1], h[2], h[4], h[5], h[6], h[8], h[9], h[10];
  return coal::Transform3s(R, coal::Vec3s(h[3], h[7], h[11]));
}

}  // namespace

Chain::Chain(const std::vector<int>& parents, const std::vector<double>& placements,
             const std::vector<double>& axes, const std::vector<bool>& prismatic,
             const std::vector<int>& states, const std::vector<double>& lower,
             const std::vector<double>& upper, const std::vector<int>& body_joints,
             const std::vector<double>& body_placements, const std::vector<double>& semi_axes,
             const std::vector<std::vector<double>>& hull_vertices,
             const std::vector<std::vector<int>>& hull_triangles,
             const std::vector<bool>& wraps)
    : lower_(lower), upper_(upper) {
  const std::size_t n = parents.size(), dof = lower.size();
  if (placements.size() != 16 * n || axes.size() != 3 * n || prismatic.size() != n ||
      states.size() != n)
    throw std::invalid_argument(
        "chain: expected 16 placement, 3 axis numbers, a kind and a state index per joint");
  if (dof == 0 || dof > static_cast<std::size_t>(kMaxJoints) || upper.size() != dof)
    throw std::invalid_argument("chain: expected 1 to 24 joints with a lower and upper limit each");
  for (std::size_t j = 0; j < dof; ++j)
    if (!(lower[j] <= upper[j]) || !std::isfinite(lower[j]) || !std::isfinite(upper[j]))
      throw std::invalid_argument("chain: expected finite limits with lower <= upper");
  for (std::size_t i = 0; i < n; ++i) {
    ChainJoint joint;
    joint.parent = parents[i];
    if (joint.parent < 0 || joint.parent > static_cast<int>(i))
      throw std::invalid_argument("chain: a joint's parent must come before it");
    joint.placement = transform_of(&placements[16 * i], "chain: joint placement");
    joint.axis = coal::Vec3s(axes[3 * i], axes[3 * i + 1], axes[3 * i + 2]);
    const double norm = joint.axis.norm();
    if (!(norm > 0.0) || !std::isfinite(norm))
      throw std::invalid_argument("chain: expected a non-zero finite joint axis");
    joint.axis /= norm;
    joint.prismatic = prismatic[i];
    joint.state = states[i];
    if (joint.state < 0 || joint.state >= static_cast<int>(dof))
      throw std::invalid_argument("chain: a joint's state index is out of range");
    joints_.push_back(joint);
  }
  if (!wraps.empty()) {
    if (wraps.size() != dof) throw std::invalid_argument("chain: expected a wrap flag per joint or none");
    for (const ChainJoint& joint : joints_)
      if (joint.prismatic && wraps[joint.state])
        throw std::invalid_argument("chain: only a revolute joint's angle may wrap");
    if (std::find(wraps.begin(), wraps.end(), true) != wraps.end()) wraps_ = wraps;
  }
  const std::size_t count = body_joints.size();
  if (body_placements.size() != 16 * count || semi_axes.size() != 3 * count)
    throw std::invalid_argument("chain: expected 16 placement numbers and 3 semi-axes per body");
  if (hull_vertices.size() != hull_triangles.size() ||
      (!hull_vertices.empty() && hull_vertices.size() != count))
    throw std::invalid_argument("chain: expected hull vertices and triangles for every body or none");
  for (std::size_t k = 0; k < count; ++k) {
    ChainBody body;
    body.joint = body_joints[k];
    if (body.joint < 0 || body.joint > static_cast<int>(n))
      throw std::invalid_argument("chain: a body's joint is out of range");
    body.placement = transform_of(&body_placements[16 * k], "chain: body placement");
    for (int i = 0; i < 3; ++i) {
      const double a = semi_axes[3 * k + i];
      if (!(a > 0.0) || !std::isfinite(a))
        throw std::invalid_argument("chain: semi-axes must be positive finite numbers");
      body.semi_axes[i] = a;
      body.a_max = std::max(body.a_max, a);
    }
    if (!hull_vertices.empty() && !hull_vertices[k].empty()) {
      body.hull = std::make_shared<const BodyHull>(hull_vertices[k], hull_triangles[k]);
      for (const coal::Vec3s& v : *body.hull->shape()->points) {
        double inside = 0.0;  // |diag(a)^-1 v|^2: at most 1 inside the ellipsoid
        for (int i = 0; i < 3; ++i) inside += (v[i] / body.semi_axes[i]) * (v[i] / body.semi_axes[i]);
        if (!(inside <= 1.0))  // strictly: every speed bound is the ellipsoid's
          throw std::invalid_argument("chain: a body's hull must lie inside its semi-axes' ellipsoid");
      }
    }
    bodies_.push_back(body);
  }
  bound_speeds();
}

Chain Chain::with_bodies(std::vector<ChainBody> bodies) const {
  Chain out;
  out.joints_ = joints_, out.lower_ = lower_, out.upper_ = upper_, out.wraps_ = wraps_;
  out.bodies_ = std::move(bodies);
  for (const ChainBody& b : out.bodies_)
    if (b.joint < 0 || b.joint > static_cast<int>(joints_.size()) || !(b.a_max > 0.0))
      throw std::invalid_argument("chain: a body's joint is out of range or its size not positive");
  out.bound_speeds();
  return out;
}

void Chain::bound_speeds() {
  const std::size_t n = joints_.size(), dof = lower_.size(), count = bodies_.size();
  // the speed bounds (kcplan/arm/bounds.py chain_speeds): how far joint i's origin lies
  // from its parent's over the whole joint box
  std::vector<double> hop(n + 1, 0.0);
  for (std::size_t i = 1; i <= n; ++i) {
    const ChainJoint& joint = joints_[i - 1];
    hop[i] = joint.placement.getTranslation().norm();
    if (joint.prismatic)
      hop[i] += std::max(std::abs(lower_[joint.state]), std::abs(upper_[joint.state]));
  }
  rho_.assign(count * dof, 0.0);
  carries_.assign(count * dof, false);
  for (std::size_t k = 0; k < count; ++k) {
    double reach = bodies_[k].placement.getTranslation().norm() + bodies_[k].a_max;
    for (int i = bodies_[k].joint; i > 0; i = joints_[i - 1].parent) {  // reach bounds |x - o_i|
      const ChainJoint& joint = joints_[i - 1];
      rho_[k * dof + joint.state] = joint.prismatic ? 1.0 : reach;
      carries_[k * dof + joint.state] = true;
      reach += hop[i];
    }
  }
}

bool Chain::admits(const double* q) const {
  for (std::size_t j = 0; j < lower_.size(); ++j) {
    if (q[j] >= lower_[j] && q[j] <= upper_[j]) continue;  // NaN fails
    if (!(wraps(static_cast<int>(j)) && std::isfinite(q[j]))) return false;
  }
  return true;
}

double Chain::canonical(int j, double v) const {
  if (!wraps(j)) return v;
  const double turn = 2.0 * M_PI;
  return v - turn * std::floor((v + M_PI) / turn);
}

double Chain::difference(int j, double a, double b) const {
  return wraps(j) ? canonical(j, b - a) : b - a;
}

const double* Chain::edge_end(const double* q1, const double* q2, double* out) const {
  if (wraps_.empty()) return q2;
  for (int j = 0; j < dof(); ++j) out[j] = wraps_[j] ? q1[j] + difference(j, q1[j], q2[j]) : q2[j];
  return out;
}

void Chain::joint_frames(const double* q, std::vector<coal::Transform3s>& out) const {
  out.resize(joints_.size() + 1);
  out[0].setIdentity();
  for (std::size_t i = 1; i <= joints_.size(); ++i) {
    const ChainJoint& joint = joints_[i - 1];
    const double value = q[joint.state];
    coal::Transform3s motion;
    if (joint.prismatic)
      motion = coal::Transform3s(coal::Matrix3s::Identity(), value * joint.axis);
    else
      motion = coal::Transform3s(Eigen::AngleAxisd(value, joint.axis).toRotationMatrix(),
                                 coal::Vec3s::Zero());
    out[i] = out[joint.parent] * joint.placement * motion;
  }
}

void Chain::body_frames(const double* q, std::vector<coal::Transform3s>& joints,
                        std::vector<coal::Transform3s>& out) const {
  joint_frames(q, joints);
  place_bodies(joints, out);
}

void Chain::place_bodies(const std::vector<coal::Transform3s>& joints,
                         std::vector<coal::Transform3s>& out) const {
  out.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    out[k] = joints[bodies_[k].joint] * bodies_[k].placement;
}

void Chain::levers(const std::vector<coal::Transform3s>& joints,
                   const std::vector<coal::Transform3s>& bodies, double* out) const {
  const std::size_t dof = lower_.size();
  std::fill(out, out + bodies_.size() * dof, 0.0);
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const coal::Vec3s& c = bodies[k].getTranslation();
    for (int i = bodies_[k].joint; i > 0; i = joints_[i - 1].parent) {
      const ChainJoint& joint = joints_[i - 1];
      out[k * dof + joint.state] =
          joint.prismatic ? 1.0 : (c - joints[i].getTranslation()).norm() + bodies_[k].a_max;
    }
  }
}

void Chain::lever_growth(const double* dq, double* out) const {
  const std::size_t dof = lower_.size();
  std::fill(out, out + bodies_.size() * dof, 0.0);
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    double below = 0.0;  // sum of |dq_i| rho[k, i] over the joints walked so far
    for (int i = bodies_[k].joint; i > 0; i = joints_[i - 1].parent) {
      const ChainJoint& joint = joints_[i - 1];
      const double step = std::abs(dq[joint.state]);
      if (!joint.prismatic) out[k * dof + joint.state] = step * below;
      below += step * rho_[k * dof + joint.state];
    }
  }
}

void Chain::joint_twists(const std::vector<coal::Transform3s>& joints, const double* dq,
                         std::vector<coal::Vec3s>& w, std::vector<coal::Vec3s>& u) const {
  w.assign(joints_.size() + 1, coal::Vec3s::Zero()), u = w;
  for (std::size_t i = 1; i <= joints_.size(); ++i) {
    const ChainJoint& joint = joints_[i - 1];
    w[i] = w[joint.parent], u[i] = u[joint.parent];
    const coal::Vec3s axis = joints[i].getRotation() * joint.axis;
    const double step = dq[joint.state];
    if (joint.prismatic) {
      u[i] += step * axis;
    } else {
      w[i] += step * axis;
      u[i] -= step * axis.cross(joints[i].getTranslation());
    }
  }
}

void Chain::twists(const std::vector<coal::Transform3s>& joints, const double* centres,
                   const double* dq, std::vector<coal::Vec3s>& w_out,
                   std::vector<coal::Vec3s>& u_out) const {
  std::vector<coal::Vec3s> w, u;
  joint_twists(joints, dq, w, u);
  w_out.resize(bodies_.size()), u_out.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const int i = bodies_[k].joint;
    const coal::Vec3s c(centres[3 * k], centres[3 * k + 1], centres[3 * k + 2]);
    w_out[k] = w[i], u_out[k] = w[i].cross(c) + u[i];
  }
}

void Chain::first_order_speeds(const std::vector<coal::Transform3s>& joints, const double* centres,
                               const double* dq, double* out) const {
  std::vector<coal::Vec3s> w, u;
  twists(joints, centres, dq, w, u);
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    out[k] = first_order_speed(k, w[k], u[k]);
}

void Chain::turn_speeds(const double* dq, double* out) const {
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    double turn = 0.0;
    for (int i = bodies_[k].joint; i > 0; i = joints_[i - 1].parent)
      if (!joints_[i - 1].prismatic) turn += std::abs(dq[joints_[i - 1].state]);
    out[k] = turn;
  }
}

void Chain::axis_turns(const double* dq, std::vector<double>& S) const {
  S.assign(joints_.size() + 1, 0.0);
  for (std::size_t i = 1; i <= joints_.size(); ++i) {
    const int parent = joints_[i - 1].parent;
    S[i] = S[parent];
    if (parent > 0 && !joints_[parent - 1].prismatic) S[i] += std::abs(dq[joints_[parent - 1].state]);
  }
}

double Chain::point_acceleration(std::size_t k, const double* dq,
                                 const std::vector<double>& S) const {
  const std::size_t dof = lower_.size();
  double below = 0.0, M = 0.0;
  for (int i = bodies_[k].joint; i > 0; i = joints_[i - 1].parent) {
    const ChainJoint& joint = joints_[i - 1];
    const double step = std::abs(dq[joint.state]);
    below += step * rho_[k * dof + joint.state];
    M += joint.prismatic ? step * S[i] : step * (2.0 * S[i] * rho_[k * dof + joint.state] + below);
  }
  return M * (1.0 + 1e-12);  // and rounding
}

void Chain::point_accelerations(const double* dq, double* out) const {
  std::vector<double> S;
  axis_turns(dq, S);
  for (std::size_t k = 0; k < bodies_.size(); ++k) out[k] = point_acceleration(k, dq, S);
}

std::vector<double> Chain::relative_speeds(const std::vector<std::array<int, 2>>& pairs) const {
  const std::size_t dof = lower_.size();
  std::vector<double> out(pairs.size() * dof, 0.0);
  for (std::size_t m = 0; m < pairs.size(); ++m) {
    const std::size_t k = pairs[m][0], l = pairs[m][1];
    if (k >= bodies_.size() || l >= bodies_.size())
      throw std::invalid_argument("pairs: a body index is out of range");
    for (std::size_t j = 0; j < dof; ++j) {
      const bool ck = carries_[k * dof + j], cl = carries_[l * dof + j];
      // a joint that carries both moves them as one rigid body: no distance changes
      out[m * dof + j] = (ck && !cl ? rho_[k * dof + j] : 0.0) + (cl && !ck ? rho_[l * dof + j] : 0.0);
    }
  }
  return out;
}

}  // namespace kcplan
