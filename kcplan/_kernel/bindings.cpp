// Python bindings of the kernel: thin wrappers, no logic. Every C++ exception becomes a
// Python exception (std::invalid_argument -> ValueError) through nanobind.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>
#include <nanobind/stl/vector.h>

#include "arm_certifier.hpp"
#include "arm_motion_validator.hpp"
#include "arm_planner.hpp"
#include "certifier.hpp"
#include "enclosing.hpp"
#include "pair_proof.hpp"

namespace nb = nanobind;
using namespace nb::literals;
using kcplan::Pose;

namespace {

Pose pose_of(const std::vector<double>& p, int dimension) {
  const int size = kcplan::pose_size(dimension);
  if (static_cast<int>(p.size()) != size)
    throw std::invalid_argument("pose: expected " + std::to_string(size) + " numbers in " +
                                std::to_string(dimension) + "D, got " + std::to_string(p.size()));
  return Pose::from_flat(p.data(), size);
}

Pose se2(double x, double y, double yaw) {
  const double p[3] = {x, y, yaw};
  return Pose::from_flat(p, 3);
}

Pose se3(double x, double y, double z, double qx, double qy, double qz, double qw) {
  const double p[7] = {x, y, z, qx, qy, qz, qw};
  return Pose::from_flat(p, 7);
}

void require(const kcplan::World& w, int dimension) {
  if (w.robot().dimension() != dimension)
    throw std::invalid_argument("pose: this world is " + std::to_string(w.robot().dimension()) +
                                "D");
}

nb::dict world_counters(const kcplan::World& w) {
  nb::dict d;
  d["collision_queries"] = w.counters.collision_queries;
  d["distance_queries"] = w.counters.distance_queries;
  d["region_queries"] = w.counters.region_queries;
  d["region_pairs"] = w.counters.region_pairs;
  d["body_queries"] = w.counters.body_queries;
  return d;
}

nb::dict cloud_counters(const kcplan::World& w) {
  const kcplan::CloudCounters c = w.cloud_counters();
  nb::dict d;
  d["queries"] = c.queries;
  d["nodes"] = c.nodes;
  d["points"] = c.points;
  d["exact"] = c.exact;
  return d;
}

nb::dict certifier_counters(const kcplan::CertifierCounters& c) {
  nb::dict d;
#define KC_COUNTER(name) d[#name] = c.name
  KC_COUNTER(edges); KC_COUNTER(rejected); KC_COUNTER(rejected_end_state);
  KC_COUNTER(rejected_sweep); KC_COUNTER(rejected_occupancy); KC_COUNTER(rejected_probe);
  KC_COUNTER(rejected_guard);
  KC_COUNTER(not_proven); KC_COUNTER(certified_by_endpoints); KC_COUNTER(certified_one_guard);
  KC_COUNTER(guards); KC_COUNTER(endpoint_guards); KC_COUNTER(cached_guards);
  KC_COUNTER(bisection_nodes); KC_COUNTER(collision_queries); KC_COUNTER(occupancy_rejections);
  KC_COUNTER(occupancy_queries); KC_COUNTER(probes);
  KC_COUNTER(probed_edges); KC_COUNTER(screened_edges);
#undef KC_COUNTER
  return d;
}

nb::list guard_bodies(const kcplan::Guard& g) {
  nb::list bodies;
  for (const kcplan::BodyGuard& b : g.bodies) {
    nb::list planes;
    for (const kcplan::PlaneRow& p : b.planes)
      planes.append(nb::make_tuple(p.nx, p.ny, p.nz, p.slack, p.clearance));
    bodies.append(nb::make_tuple(b.clearance, planes, b.horizon));
  }
  return bodies;
}

std::vector<double> flat(const coal::Transform3s& t) {
  const coal::Matrix3s& R = t.getRotation();
  const coal::Vec3s& x = t.getTranslation();
  return {R(0, 0), R(0, 1), R(0, 2), x[0], R(1, 0), R(1, 1), R(1, 2), x[1],
          R(2, 0), R(2, 1), R(2, 2), x[2], 0.0,     0.0,     0.0,     1.0};
}

nb::list frames_of(const std::vector<coal::Transform3s>& frames) {
  nb::list out;
  for (const coal::Transform3s& t : frames) out.append(flat(t));
  return out;
}

const double* joints_of(const kcplan::Chain& chain, const std::vector<double>& q) {
  if (static_cast<int>(q.size()) != chain.dof())
    throw std::invalid_argument("state: expected " + std::to_string(chain.dof()) +
                                " joint values, got " + std::to_string(q.size()));
  return q.data();
}

/// The rows of a flat vector of `dof`-number states.
std::vector<std::vector<double>> rows_of(const std::vector<double>& flat, int dof) {
  std::vector<std::vector<double>> out;
  for (std::size_t i = 0; i + dof <= flat.size(); i += dof)
    out.emplace_back(flat.begin() + i, flat.begin() + i + dof);
  return out;
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "kcplan's compiled certification kernel (see kcplan._kernel).";

  nb::class_<kcplan::Robot>(m, "Robot")
      .def(nb::init<int, const std::vector<double>&, const std::vector<double>&>(),
           "dimension"_a, "semi_axes"_a, "poses"_a)
      .def_prop_ro("dimension", &kcplan::Robot::dimension)
      .def("__len__", &kcplan::Robot::size)
      .def_prop_ro("is_single", &kcplan::Robot::is_single)
      .def_prop_ro("core_radius", &kcplan::Robot::core_radius)
      .def_prop_ro("reach", &kcplan::Robot::reach)
      .def_prop_ro("levers", [](const kcplan::Robot& r) {
        std::vector<double> out;
        for (const kcplan::Body& b : r.bodies()) out.push_back(b.lever());
        return out;
      });

  nb::enum_<kcplan::CloudOrder>(m, "CloudOrder",
                                "How a point cloud's tree orders its points (point_cloud.hpp)")
      .value("morton", kcplan::CloudOrder::morton)
      .value("median", kcplan::CloudOrder::median);

  nb::class_<kcplan::World>(m, "World")
      .def(nb::init<const kcplan::Robot&, double, double, double>(), "robot"_a,
           "half_height"_a, "rtol"_a, "atol"_a)
      .def("add_prism", &kcplan::World::add_prism, "xy"_a)
      .def("add_box", &kcplan::World::add_box, "centre"_a, "rotation"_a, "half"_a)
      .def("add_convex", &kcplan::World::add_convex, "vertices"_a, "triangles"_a)
      .def("add_sphere", &kcplan::World::add_sphere, "centre"_a, "radius"_a)
      .def("add_ellipsoid", &kcplan::World::add_ellipsoid, "centre"_a, "rotation"_a,
           "extents"_a)
      .def("add_cylinder", &kcplan::World::add_cylinder, "centre"_a, "rotation"_a, "radius"_a,
           "half_height"_a)
      .def("add_mesh", &kcplan::World::add_mesh, "vertices"_a, "triangles"_a)
      .def(
          "add_points",
          [](kcplan::World& w,
             nb::ndarray<const double, nb::shape<-1, 3>, nb::c_contig, nb::device::cpu> points,
             double radius, kcplan::CloudOrder order) {
            w.add_points(points.data(), points.shape(0), radius, order);
          },
          "points"_a, "radius"_a, "order"_a = kcplan::CloudOrder::morton)
      .def("set_reach", &kcplan::World::set_reach, "centre"_a, "radius"_a,
           "A ball (metres) that holds every body at every state, padding included: the "
           "clouds added after it keep only the points whose balls meet it")
      .def_prop_ro("cloud_points", [](const kcplan::World& w) { return w.cloud_points(); },
                   "Points every cloud kept (those within reach)")
      .def("finalize", &kcplan::World::finalize)
      .def_prop_rw("padding", &kcplan::World::padding, &kcplan::World::set_padding,
                   "Metres every body keeps from every obstacle (MoveIt's link padding)")
      .def("set_body_padding", &kcplan::World::set_body_padding, "k"_a, "padding"_a,
           "Metres body k keeps from every obstacle instead of `padding` (MoveIt's per-link "
           "padding); setting `padding` again undoes it")
      .def("padding_of", &kcplan::World::padding_of, "shape"_a,
           "The padding shape k keeps (a ball standing for several bodies: the largest)")
      .def_prop_ro("n_objects", &kcplan::World::n_objects)
      .def_prop_ro("dimension", [](const kcplan::World& w) { return w.robot().dimension(); })
      .def_prop_ro("atol", &kcplan::World::atol)
      .def_prop_ro("rtol", &kcplan::World::rtol)
      .def("in_collision",
           [](kcplan::World& w, const std::vector<double>& p) {
             return w.in_collision(pose_of(p, w.robot().dimension()));
           }, "pose"_a)
      .def("in_collision_se2",
           [](kcplan::World& w, double x, double y, double yaw) {
             require(w, 2);
             return w.in_collision(se2(x, y, yaw));
           })
      .def("in_collision_se3",
           [](kcplan::World& w, double x, double y, double z, double qx, double qy, double qz,
              double qw) {
             require(w, 3);
             return w.in_collision(se3(x, y, z, qx, qy, qz, qw));
           })
      .def("body_distances",
           [](kcplan::World& w, const std::vector<double>& p) {
             std::vector<double> out(w.robot().size());
             w.body_distances(pose_of(p, w.robot().dimension()), out.data());
             return out;
           }, "pose"_a)
      .def("safe_body_clearances",
           [](kcplan::World& w, const std::vector<double>& p) {
             std::vector<double> out(w.robot().size());
             w.safe_body_clearances(pose_of(p, w.robot().dimension()), out.data());
             return out;
           }, "pose"_a)
      .def("free_regions",
           [](kcplan::World& w, const std::vector<double>& p, double horizon) {
             if (!(horizon >= 0.0)) throw std::invalid_argument("horizon: expected a number >= 0");
             std::vector<kcplan::FreeRegion> regions;
             const bool free = w.free_regions(pose_of(p, w.robot().dimension()), horizon, regions);
             nb::list out;
             for (const kcplan::FreeRegion& r : regions) {
               nb::list planes;
               for (const kcplan::Plane& q : r.planes)
                 planes.append(nb::make_tuple(q.n[0], q.n[1], q.n[2], q.offset, q.clearance));
               out.append(nb::make_tuple(planes, r.horizon));
             }
             return nb::make_tuple(free, out);
           }, "pose"_a, "horizon"_a)
      .def("ball_collides", &kcplan::World::ball_collides, "centre"_a, "radius"_a)
      .def("sweep_core_collides", &kcplan::World::sweep_core_collides, "a"_a, "b"_a, "radius"_a)
      .def_prop_ro("counters", &world_counters)
      .def_prop_ro("cloud_counters", &cloud_counters)
      .def(
          "set_cloud_bounds",
          [](kcplan::World& w, bool dop, bool gjk_planes, bool centre_line) {
            w.set_cloud_bounds(kcplan::CloudBounds{dop, gjk_planes, centre_line});
          },
          "dop"_a = true, "gjk_planes"_a = true, "centre_line"_a = true,
          "Which cheaper bounds the clouds ask before GJK (point_cloud.hpp CloudBounds)")
      .def_prop_rw("cloud_tolerance", &kcplan::World::cloud_tolerance,
                   &kcplan::World::set_cloud_tolerance,
                   "How far below its distance a cloud's answer may lie, relative, beyond the "
                   "verdict's threshold (world.hpp; 0: exact)")
      .def("set_cloud_order", &kcplan::World::set_cloud_order, "order"_a,
           "Rebuild every cloud's tree in this order (an ablation: the answers stay the same)")
      .def_prop_ro("body_query_counts", [](const kcplan::World& w) { return w.body_query_counts; })
      .def("reset_counters", [](kcplan::World& w) {
        w.counters = kcplan::WorldCounters{};
        w.reset_cloud_counters();
        std::fill(w.body_query_counts.begin(), w.body_query_counts.end(), 0);
      });

  nb::class_<kcplan::EdgeCertifier>(m, "EdgeCertifier")
      .def(
          "__init__",
          [](kcplan::EdgeCertifier* self, kcplan::World& world,
             const std::vector<std::string>& certificates, bool discrete, int max_guards,
             double horizon, bool sweep_test, bool occupancy, int probes, std::array<double, 3> low,
             std::array<double, 3> high, std::size_t cache_entries,
             const std::vector<double>& levels, const std::vector<std::vector<double>>& rows,
             double scale, bool learn_schedule) {
            kcplan::CertifierOptions o;
            o.certificates = certificates, o.discrete = discrete, o.max_guards = max_guards;
            o.horizon = horizon, o.sweep_test = sweep_test, o.occupancy = occupancy;
            o.probes = probes, o.learn_schedule = learn_schedule;
            o.low = low, o.high = high, o.cache_entries = cache_entries;
            std::unique_ptr<kcplan::KCPolytope> polytope;
            if (!levels.empty())
              polytope = std::make_unique<kcplan::KCPolytope>(
                  levels, rows, world.robot().dimension() == 2 ? 3 : 6, scale);
            new (self) kcplan::EdgeCertifier(world, o, std::move(polytope));
          },
          "world"_a, "certificates"_a, "discrete"_a, "max_guards"_a, "horizon"_a,
          "sweep_test"_a, "occupancy"_a, "probes"_a, "low"_a, "high"_a, "cache_entries"_a,
          "ladder_levels"_a, "ladder_rows"_a, "ladder_scale"_a, "learn_schedule"_a = true,
          nb::keep_alive<1, 2>())
      .def("check",
           [](kcplan::EdgeCertifier& c, const std::vector<double>& p1,
              const std::vector<double>& p2, double resolution, bool probe) {
             const int n = c.world().robot().dimension();
             return c.check(pose_of(p1, n), pose_of(p2, n), resolution, probe);
           }, "pose1"_a, "pose2"_a, "resolution"_a = 0.01, "probe"_a = true)
      .def("check_se2",
           [](kcplan::EdgeCertifier& c, double x1, double y1, double yaw1, double x2, double y2,
              double yaw2, double resolution) {
             require(c.world(), 2);
             return c.check(se2(x1, y1, yaw1), se2(x2, y2, yaw2), resolution);
           }, "x1"_a, "y1"_a, "yaw1"_a, "x2"_a, "y2"_a, "yaw2"_a, "resolution"_a = 0.01)
      .def("check_se3",
           [](kcplan::EdgeCertifier& c, double x1, double y1, double z1, double a1, double b1,
              double c1, double d1, double x2, double y2, double z2, double a2, double b2,
              double c2, double d2, double resolution) {
             require(c.world(), 3);
             return c.check(se3(x1, y1, z1, a1, b1, c1, d1), se3(x2, y2, z2, a2, b2, c2, d2),
                            resolution);
           }, "x1"_a, "y1"_a, "z1"_a, "qx1"_a, "qy1"_a, "qz1"_a, "qw1"_a, "x2"_a, "y2"_a, "z2"_a,
           "qx2"_a, "qy2"_a, "qz2"_a, "qw2"_a, "resolution"_a = 0.01)
      .def("screen",
           [](kcplan::EdgeCertifier& c, const std::vector<double>& p1,
              const std::vector<double>& p2, double step) {
             const int n = c.world().robot().dimension();
             return c.screen(pose_of(p1, n), pose_of(p2, n), step);
           }, "pose1"_a, "pose2"_a, "step"_a)
      .def("screen_se2",
           [](kcplan::EdgeCertifier& c, double x1, double y1, double yaw1, double x2, double y2,
              double yaw2, double step) {
             require(c.world(), 2);
             return c.screen(se2(x1, y1, yaw1), se2(x2, y2, yaw2), step);
           }, "x1"_a, "y1"_a, "yaw1"_a, "x2"_a, "y2"_a, "yaw2"_a, "step"_a)
      .def("screen_se3",
           [](kcplan::EdgeCertifier& c, double x1, double y1, double z1, double a1, double b1,
              double c1, double d1, double x2, double y2, double z2, double a2, double b2,
              double c2, double d2, double step) {
             require(c.world(), 3);
             return c.screen(se3(x1, y1, z1, a1, b1, c1, d1), se3(x2, y2, z2, a2, b2, c2, d2),
                             step);
           }, "x1"_a, "y1"_a, "z1"_a, "qx1"_a, "qy1"_a, "qz1"_a, "qw1"_a, "x2"_a, "y2"_a, "z2"_a,
           "qx2"_a, "qy2"_a, "qz2"_a, "qw2"_a, "step"_a)
      .def("state_valid",
           [](kcplan::EdgeCertifier& c, const std::vector<double>& p) {
             return c.state_valid(pose_of(p, c.world().robot().dimension()));
           }, "pose"_a)
      .def("state_valid_se2",
           [](kcplan::EdgeCertifier& c, double x, double y, double yaw) {
             require(c.world(), 2);
             return c.state_valid(se2(x, y, yaw));
           })
      .def("state_valid_se3",
           [](kcplan::EdgeCertifier& c, double x, double y, double z, double qx, double qy,
              double qz, double qw) {
             require(c.world(), 3);
             return c.state_valid(se3(x, y, z, qx, qy, qz, qw));
           })
      .def("measure",
           [](kcplan::EdgeCertifier& c, const std::vector<double>& p) {
             const kcplan::Guard g = c.measure(pose_of(p, c.world().robot().dimension()));
             return nb::make_tuple(g.clearance, guard_bodies(g));
           }, "pose"_a)
      .def_prop_ro("counters", [](const kcplan::EdgeCertifier& c) {
        return certifier_counters(c.counters);
      })
      .def_prop_ro("covered", [](const kcplan::EdgeCertifier& c) {
        nb::dict d;
        for (std::size_t i = 0; i < c.certificates().size(); ++i)
          d[c.certificates()[i]->name()] = c.covered()[i];
        return d;
      })
      .def_prop_ro("cache_size", [](const kcplan::EdgeCertifier& c) { return c.cache().size(); })
      .def_prop_ro("validity_cache_size",
                   [](const kcplan::EdgeCertifier& c) { return c.cache().validity_size(); })
      .def_prop_ro("horizon", &kcplan::EdgeCertifier::horizon)
      .def_prop_ro("margin", &kcplan::EdgeCertifier::margin)
      .def_prop_ro("sweep_test", &kcplan::EdgeCertifier::sweep_test)
      .def_prop_ro("occupancy", &kcplan::EdgeCertifier::occupancy)
      .def_prop_ro("probes", &kcplan::EdgeCertifier::probes)
      .def_prop_ro("learn_schedule", &kcplan::EdgeCertifier::learn_schedule)
      .def_prop_ro("discrete", &kcplan::EdgeCertifier::discrete);

  nb::class_<kcplan::Chain>(m, "Chain")
      .def(nb::init<const std::vector<int>&, const std::vector<double>&, const std::vector<double>&,
                    const std::vector<bool>&, const std::vector<int>&, const std::vector<double>&,
                    const std::vector<double>&, const std::vector<int>&,
                    const std::vector<double>&, const std::vector<double>&,
                    const std::vector<std::vector<double>>&, const std::vector<std::vector<int>>&,
                    const std::vector<bool>&>(),
           "parents"_a, "placements"_a, "axes"_a, "prismatic"_a, "states"_a, "lower"_a,
           "upper"_a, "body_joints"_a, "body_placements"_a, "semi_axes"_a,
           "hull_vertices"_a = std::vector<std::vector<double>>(),
           "hull_triangles"_a = std::vector<std::vector<int>>(),
           "wraps"_a = std::vector<bool>())
      .def("edge_end", [](const kcplan::Chain& c, const std::vector<double>& q1,
                          const std::vector<double>& q2) {
        std::vector<double> out(c.dof());
        const double* end = c.edge_end(joints_of(c, q1), joints_of(c, q2), out.data());
        return std::vector<double>(end, end + c.dof());
      }, "q1"_a, "q2"_a, "where the straight edge from q1 towards q2 ends (a wrapping angle "
      "the shorter way round; kcplan/_kernel/chain.hpp Chain::edge_end)")
      .def_prop_ro("dof", &kcplan::Chain::dof)
      .def_prop_ro("n_bodies", [](const kcplan::Chain& c) { return c.bodies().size(); })
      .def_prop_ro("n_hulls", [](const kcplan::Chain& c) {
        std::size_t n = 0;
        for (const kcplan::ChainBody& b : c.bodies()) n += b.hull != nullptr;
        return n;
      })
      .def("hull_support",
           [](const kcplan::Chain& c, std::size_t k, const std::array<double, 3>& n) {
        if (k >= c.bodies().size() || !c.bodies()[k].hull)
          throw std::invalid_argument("hull_support: expected the index of a body with a hull");
        return c.bodies()[k].hull->support(coal::Vec3s(n[0], n[1], n[2]));
      }, "k"_a, "n"_a, "max over body k's hull vertices v (its own frame) of n . v "
      "(kcplan/_kernel/convex_body.hpp VertexSupport)")
      .def_prop_ro("point_speeds", &kcplan::Chain::point_speeds)
      .def_prop_ro("carries", &kcplan::Chain::carries)
      .def("relative_speeds", &kcplan::Chain::relative_speeds, "pairs"_a)
      .def("admits", [](const kcplan::Chain& c, const std::vector<double>& q) {
        return c.admits(joints_of(c, q));
      }, "q"_a)
      .def("joint_frames", [](const kcplan::Chain& c, const std::vector<double>& q) {
        std::vector<coal::Transform3s> frames;
        c.joint_frames(joints_of(c, q), frames);
        return frames_of(frames);
      }, "q"_a)
      .def("levers", [](const kcplan::Chain& c, const std::vector<double>& q) {
        std::vector<coal::Transform3s> joints, frames;
        c.body_frames(joints_of(c, q), joints, frames);
        std::vector<double> out(c.bodies().size() * c.dof());
        c.levers(joints, frames, out.data());
        return out;
      }, "q"_a)
      .def("lever_growth", [](const kcplan::Chain& c, const std::vector<double>& dq) {
        std::vector<double> out(c.bodies().size() * c.dof());
        c.lever_growth(joints_of(c, dq), out.data());
        return out;
      }, "dq"_a)
      .def("first_order_speeds", [](const kcplan::Chain& c, const std::vector<double>& q,
                                    const std::vector<double>& dq) {
        std::vector<coal::Transform3s> joints, frames;
        c.body_frames(joints_of(c, q), joints, frames);
        std::vector<double> centres, out(c.bodies().size());
        for (const coal::Transform3s& f : frames)
          for (int i = 0; i < 3; ++i) centres.push_back(f.getTranslation()[i]);
        c.first_order_speeds(joints, centres.data(), joints_of(c, dq), out.data());
        return out;
      }, "q"_a, "dq"_a)
      .def("turn_speeds", [](const kcplan::Chain& c, const std::vector<double>& dq) {
        std::vector<double> out(c.bodies().size());
        c.turn_speeds(joints_of(c, dq), out.data());
        return out;
      }, "dq"_a)
      .def("point_accelerations", [](const kcplan::Chain& c, const std::vector<double>& dq) {
        std::vector<double> out(c.bodies().size());
        c.point_accelerations(joints_of(c, dq), out.data());
        return out;
      }, "dq"_a)
      .def("body_frames", [](const kcplan::Chain& c, const std::vector<double>& q) {
        std::vector<coal::Transform3s> joints, frames;
        c.body_frames(joints_of(c, q), joints, frames);
        return frames_of(frames);
      }, "q"_a);

  nb::class_<kcplan::ArmWorld>(m, "ArmWorld")
      .def(nb::init<const kcplan::Chain&, const std::vector<std::array<int, 2>>&, double, double>(),
           "chain"_a, "pairs"_a, "rtol"_a, "atol"_a)
      .def_prop_ro("scene", [](kcplan::ArmWorld& w) -> kcplan::World& { return w.scene(); },
                   nb::rv_policy::reference_internal)
      .def_prop_ro("chain", &kcplan::ArmWorld::chain, nb::rv_policy::reference_internal)
      .def_prop_ro("n_pairs", [](const kcplan::ArmWorld& w) { return w.pairs().size(); })
      .def("in_collision", [](kcplan::ArmWorld& w, const std::vector<double>& q) {
        return w.in_collision(joints_of(w.chain(), q));
      }, "q"_a)
      .def("safe_clearances", [](kcplan::ArmWorld& w, const std::vector<double>& q) {
        std::vector<double> scene(w.chain().bodies().size()), pairs(w.pairs().size());
        w.safe_clearances(joints_of(w.chain(), q), scene.data(), pairs.data());
        return nb::make_tuple(scene, pairs);
      }, "q"_a)
      .def("pair_first_order", [](kcplan::ArmWorld& w, const std::vector<double>& q,
                                  const std::vector<double>& dq) {
        const kcplan::Chain& chain = w.chain();
        std::vector<coal::Transform3s> joints, frames;
        chain.body_frames(joints_of(chain, q), joints, frames);
        std::vector<double> centres;
        for (const coal::Transform3s& f : frames)
          for (int i = 0; i < 3; ++i) centres.push_back(f.getTranslation()[i]);
        kcplan::PairFirstOrder first(chain, w.pairs());
        first.edge(joints_of(chain, dq));
        first.guard(joints, centres.data());
        std::vector<std::array<double, 2>> out;
        for (std::size_t m = 0; m < w.pairs().size(); ++m)
          out.push_back({first.speed(m), first.accel(m)});
        return out;
      }, "q"_a, "dq"_a)
      .def("grown_clear", [](kcplan::ArmWorld& w, const std::vector<double>& q, double scale) {
        const std::vector<coal::Transform3s>& frames = w.place(joints_of(w.chain(), q));
        std::vector<bool> out(frames.size());
        for (std::size_t k = 0; k < frames.size(); ++k) out[k] = w.grown_clear(k, frames, scale);
        return out;
      }, "q"_a, "scale"_a)
      .def_prop_ro("counters", [](kcplan::ArmWorld& w) {
        nb::dict d = world_counters(w.scene());
        d["pair_queries"] = w.pair_queries;
        d["part_queries"] = w.part_queries;
        return d;
      })
      .def("reset_counters", [](kcplan::ArmWorld& w) {
        w.scene().counters = kcplan::WorldCounters{};
        std::fill(w.scene().body_query_counts.begin(), w.scene().body_query_counts.end(), 0);
        w.pair_queries = 0, w.part_queries = 0;
      });

  m.def(
      "khachiyan_weights",
      [](nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu> points,
         double tol, std::int64_t max_iterations, std::int64_t refresh, double tie) {
        return kcplan::khachiyan_weights(points.data(), static_cast<std::int64_t>(points.shape(0)),
                                         static_cast<int>(points.shape(1)), tol, max_iterations,
                                         refresh, tie);
      },
      "points"_a, "tol"_a, "max_iterations"_a, "refresh"_a, "tie"_a,
      "Khachiyan's weights of the minimum-volume ellipsoid around the rows of points "
      "(centred hull vertices): kcplan/_kernel/enclosing.hpp");

  m.def(
      "prove_pairs_apart",
      [](kcplan::ArmWorld& world, std::int64_t max_boxes, std::size_t first) {
        std::vector<kcplan::PairProof> proofs;
        {
          nb::gil_scoped_release free;  // worlds of one chain may be proven in threads
          proofs = kcplan::prove_pairs_apart(world, max_boxes, first);
        }
        nb::list out;
        static const char* names[] = {"apart", "touches", "unknown"};
        for (const kcplan::PairProof& p : proofs)
          out.append(nb::make_tuple(names[p.verdict], p.boxes, p.least, p.witness));
        return out;
      },
      "world"_a, "max_boxes"_a, "first"_a = 0,
      "(verdict, boxes, least clearance, witness) of each self pair of the world, the "
      "first's seed `first`: kcplan/_kernel/pair_proof.hpp");

  nb::class_<kcplan::ArmCertifier>(m, "ArmCertifier")
      .def(
          "__init__",
          [](kcplan::ArmCertifier* self, kcplan::ArmWorld& world, int max_guards,
             std::size_t cache_entries, bool probes, bool part_balls, bool first_order,
             double kc_inflation, bool planes) {
            kcplan::ArmCertifierOptions o;
            o.max_guards = max_guards, o.cache_entries = cache_entries, o.probes = probes;
            o.part_balls = part_balls, o.first_order = first_order;
            o.kc_inflation = kc_inflation, o.planes = planes;
            new (self) kcplan::ArmCertifier(world, o);
          },
          "world"_a, "max_guards"_a = 256, "cache_entries"_a = 200000, "probes"_a = true,
          "part_balls"_a = true, "first_order"_a = true, "kc_inflation"_a = 0.0,
          "planes"_a = true, nb::keep_alive<1, 2>())
      .def("check", [](kcplan::ArmCertifier& c, const std::vector<double>& q1,
                       const std::vector<double>& q2, bool probe) {
        const kcplan::Chain& chain = c.world().chain();
        return c.check(joints_of(chain, q1), joints_of(chain, q2), probe);
      }, "q1"_a, "q2"_a, "probe"_a = true)
      .def("screen", [](kcplan::ArmCertifier& c, const std::vector<double>& q1,
                        const std::vector<double>& q2, double step) {
        const kcplan::Chain& chain = c.world().chain();
        return c.screen(joints_of(chain, q1), joints_of(chain, q2), step);
      }, "q1"_a, "q2"_a, "step"_a = kcplan::ArmCertifier::kProbeStep)
      .def("state_valid", [](kcplan::ArmCertifier& c, const std::vector<double>& q) {
        return c.state_valid(joints_of(c.world().chain(), q));
      }, "q"_a)
      .def("check_blend", [](kcplan::ArmCertifier& c, const std::vector<double>& a,
                             const std::vector<double>& corner, const std::vector<double>& b,
                             int max_guards) {
        const kcplan::Chain& chain = c.world().chain();
        return c.check_blend(joints_of(chain, a), joints_of(chain, corner), joints_of(chain, b),
                             max_guards);
      }, "a"_a, "corner"_a, "b"_a, "max_guards"_a,
      "Whether the quadratic Bezier blend through a, corner, b is proven free "
      "(kcplan/_kernel/arm_certifier.hpp)")
      .def("measure", [](kcplan::ArmCertifier& c, const std::vector<double>& q) {
        const kcplan::ArmGuard g = c.measure(joints_of(c.world().chain(), q));
        return nb::make_tuple(g.clearance, g.scene, g.pairs);
      }, "q"_a)
      .def_prop_ro("counters", [](const kcplan::ArmCertifier& c) {
        nb::dict d = certifier_counters(c.counters);
        d["refined_pairs"] = c.refined_pairs;
        d["refined_bodies"] = c.refined_bodies;
        d["skipped_groups"] = c.skipped_groups;
        d["grown_queries"] = c.grown_queries;
        d["kc_reaches"] = c.kc_reaches;
        d["plane_queries"] = c.plane_queries;
        d["plane_reaches"] = c.plane_reaches;
        return d;
      })
      .def_prop_ro("covered", [](const kcplan::ArmCertifier& c) {
        nb::dict d;
        d["ball"] = c.covered_ball;
        return d;
      })
      .def_prop_ro("cache_size", [](const kcplan::ArmCertifier& c) { return c.cache().size(); })
      .def_prop_ro("max_guards", &kcplan::ArmCertifier::max_guards)
      .def_prop_ro("probes", &kcplan::ArmCertifier::probes)
      .def_prop_ro("part_balls", &kcplan::ArmCertifier::part_balls)
      .def_prop_ro("first_order", &kcplan::ArmCertifier::first_order)
      .def_prop_ro("kc_inflation", &kcplan::ArmCertifier::kc_inflation)
      .def_prop_ro("planes", &kcplan::ArmCertifier::planes);

  nb::class_<kcplan::ArmMotionValidator>(m, "ArmMotionValidator",
      "Decides an arm's straight edge for the compiled planner "
      "(kcplan/_kernel/arm_motion_validator.hpp)")
      .def("check", [](kcplan::ArmMotionValidator& v, const std::vector<double>& q1,
                       const std::vector<double>& q2) {
        return v.check(joints_of(v.chain(), q1), joints_of(v.chain(), q2));
      }, "q1"_a, "q2"_a, "Whether the edge q1 -> q2 may be used (q1 assumed valid)")
      .def("state_valid", [](kcplan::ArmMotionValidator& v, const std::vector<double>& q) {
        return v.state_valid(joints_of(v.chain(), q));
      }, "q"_a)
      .def_prop_ro("certified", &kcplan::ArmMotionValidator::certified)
      .def_ro("edges", &kcplan::ArmMotionValidator::edges);
  nb::class_<kcplan::CertifiedArmMotions, kcplan::ArmMotionValidator>(m, "CertifiedArmMotions")
      .def(nb::init<kcplan::ArmCertifier&>(), "certifier"_a, nb::keep_alive<1, 2>());
  nb::class_<kcplan::ScreenedArmMotions, kcplan::ArmMotionValidator>(m, "ScreenedArmMotions")
      .def(nb::init<kcplan::ArmCertifier&, double>(), "certifier"_a, "step"_a,
           nb::keep_alive<1, 2>())
      .def_prop_ro("step", &kcplan::ScreenedArmMotions::step);
  nb::class_<kcplan::DiscreteArmMotions, kcplan::ArmMotionValidator>(m, "DiscreteArmMotions")
      .def(nb::init<kcplan::ArmWorld&, double>(), "world"_a, "step"_a, nb::keep_alive<1, 2>())
      .def_ro("states", &kcplan::DiscreteArmMotions::states);

  nb::class_<kcplan::ArmPlan>(m, "ArmPlan", "What ArmRRTConnect.solve did")
      .def_ro("solved", &kcplan::ArmPlan::solved)
      .def_ro("solve_seconds", &kcplan::ArmPlan::solve_seconds)
      .def_ro("simplify_seconds", &kcplan::ArmPlan::simplify_seconds)
      .def_ro("iterations", &kcplan::ArmPlan::iterations)
      .def_ro("tree_states", &kcplan::ArmPlan::tree_states)
      .def_ro("tree_edges", &kcplan::ArmPlan::tree_edges)
      .def_ro("path_edges", &kcplan::ArmPlan::path_edges)
      .def_ro("repaired_edges", &kcplan::ArmPlan::repaired_edges)
      .def_ro("attempts", &kcplan::ArmPlan::attempts)
      .def_ro("shortcut_edges", &kcplan::ArmPlan::shortcut_edges);

  nb::class_<kcplan::ArmRRTConnect>(m, "ArmRRTConnect",
      "RRT-Connect for arms in C++ (kcplan/_kernel/arm_planner.hpp)")
      .def(nb::init<const kcplan::Chain&, kcplan::ArmMotionValidator&,
                    kcplan::ArmMotionValidator*>(),
           "chain"_a, "tree"_a, "path"_a.none() = nullptr, nb::keep_alive<1, 2>(),
           nb::keep_alive<1, 3>(), nb::keep_alive<1, 4>())
      .def("solve", [](kcplan::ArmRRTConnect& p, const std::vector<double>& start, const std::vector<double>& goal,
                       double range, double time_limit, std::uint64_t seed, bool simplify,
                       double repair_share, bool kd_tree) {
        const kcplan::Chain& chain = p.chain();
        kcplan::ArmPlannerOptions o;
        o.range = range, o.time_limit = time_limit, o.seed = seed, o.simplify = simplify;
        o.repair_share = repair_share, o.kd_tree = kd_tree;
        kcplan::ArmPlan plan = p.solve(joints_of(chain, start), joints_of(chain, goal), o);
        return nb::make_tuple(plan, rows_of(plan.path, chain.dof()),
                              rows_of(plan.raw_path, chain.dof()));
      }, "start"_a, "goal"_a, "range"_a, "time_limit"_a, "seed"_a = 0,
      "simplify"_a = true, "repair_share"_a = 1.0, "kd_tree"_a = true,
      "(ArmPlan, path rows, raw path rows) of one search from start to goal");
}
