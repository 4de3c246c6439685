// A guard (what one query at a robot pose proves about the space around it) and the
// bounded cache of guards and validity of the states a planner keeps.
// Python twin: kcplan/certification/guard.py (BodyGuard, Guard, GuardCache).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <limits>
#include <memory>
#include <unordered_map>
#include <vector>

#include "pose.hpp"
#include "robot.hpp"
#include "world.hpp"

namespace kcplan {

/// One obstacle piece seen from one body: the unit direction n from the piece towards the
/// body (nz = 0 in 2D), the body's slack sigma = n . c - |A R^T n| - offset - margin by
/// which it clears the piece's plane (-inf without a plane), and its clearance to the piece.
struct PlaneRow {
  double nx, ny, nz, slack, clearance;
};

/// What a guard knows about one body: its clearance (never an overestimate), the planes
/// of the pieces within `horizon` and its centre's offset from the robot's origin, R p_k
/// (region guards only), and that horizon.
struct BodyGuard {
  double clearance = 0.0;
  double horizon = 0.0;
  std::vector<PlaneRow> planes;
  std::array<double, 3> arm{0.0, 0.0, 0.0};
};

/// Measurements at one robot pose, one BodyGuard per body, in the robot's order.
struct Guard {
  std::vector<BodyGuard> bodies;
  double clearance = 0.0;  ///< the smallest body clearance

  /// A clearance-only guard: body k has clearance and horizon clearances[k].
  static Guard of_clearances(const double* clearances, std::size_t count) {
    Guard g;
    g.bodies.resize(count);
    g.clearance = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < count; ++k) {
      g.bodies[k].clearance = g.bodies[k].horizon = clearances[k];
      g.clearance = std::min(g.clearance, clearances[k]);
    }
    return g;
  }

  /// A guard from a region query at `pose` (one region per body). Body k at world pose
  /// (R, c) has its lowest point along n at n . c - |A R^T n|; it lies strictly on the free
  /// side of n . x <= offset exactly when that exceeds offset, and `margin` (a length)
  /// absorbs the rounding of this evaluation.
  static Guard from_regions(const Pose& pose, const std::vector<FreeRegion>& regions,
                            const Robot& robot, double margin) {
    Guard g;
    g.bodies.resize(regions.size());
    g.clearance = std::numeric_limits<double>::infinity();
    for (const FreeRegion& r : regions)
      if (!(r.clearance() > 0.0)) {
        std::vector<double> zeros(regions.size(), 0.0);
        return of_clearances(zeros.data(), zeros.size());
      }
    std::array<double, 3> c;
    Quat q;
    for (std::size_t k = 0; k < regions.size(); ++k) {
      const FreeRegion& region = regions[k];
      BodyGuard& body = g.bodies[k];
      const std::array<double, 3>& a = robot.bodies()[k].semi_axes;  // a[2] = 0 in 2D
      robot.body_pose(pose, k, c, q);
      const Quat conjugate = q.conjugate();
      body.planes.reserve(region.planes.size());
      for (const Plane& p : region.planes) {
        double slack = -std::numeric_limits<double>::infinity();
        if (p.offset < std::numeric_limits<double>::infinity()) {
          const std::array<double, 3> u = conjugate.rotate({p.n[0], p.n[1], p.n[2]});  // R^T n
          const double h = std::sqrt((a[0] * u[0]) * (a[0] * u[0]) + (a[1] * u[1]) * (a[1] * u[1]) +
                                     (a[2] * u[2]) * (a[2] * u[2]));
          slack = p.n[0] * c[0] + p.n[1] * c[1] + p.n[2] * c[2] - h - p.offset - margin;
        }
        body.planes.push_back({p.n[0], p.n[1], p.n[2], slack, p.clearance});
      }
      body.clearance = region.clearance();
      body.horizon = region.horizon;
      for (int i = 0; i < 3; ++i) body.arm[i] = c[i] - pose.t[i];
      g.clearance = std::min(g.clearance, body.clearance);
    }
    return g;
  }
};

/// Guards and validity of states, keyed by the exact bits of their N numbers.
///
/// OMPL copies states bit for bit, so a state handed back has exactly the numbers it had
/// when it was measured, and a different state can never hit another's entry. At most
/// `max_entries` guards and as many validity marks are kept; when a table is full the
/// oldest quarter of it is dropped. `Value` is the guard type; it has a `clearance`
/// (> 0: the state is free). Rigid robots key by their flat pose (GuardCache), arms by
/// their joint vector (ArmGuardCache in arm_certifier.hpp).
template <std::size_t N, class Value>
class StateCache {
 public:
  using Key = std::array<std::uint64_t, N>;

  explicit StateCache(std::size_t max_entries = 200000) : max_entries_(max_entries) {
    if (max_entries == 0) throw std::invalid_argument("max_entries: expected at least 1");
  }

  /// The key of `count` <= N numbers (the rest zero).
  static Key key_of(const double* values, std::size_t count) {
    Key k{};
    std::memcpy(k.data(), values, sizeof(double) * count);
    return k;
  }

  /// The guard measured at this state, or null. Shared: a guard dropped from a full cache
  /// stays alive for whoever still holds it.
  std::shared_ptr<const Value> guard(const Key& key) const {
    auto it = guards_.find(key);
    return it == guards_.end() ? nullptr : it->second;
  }
  std::shared_ptr<const Value> add_guard(const Key& key, Value guard) {
    bound(guards_, guard_order_);
    auto stored = std::make_shared<const Value>(std::move(guard));
    auto [it, inserted] = guards_.insert_or_assign(key, stored);
    (void)it;
    if (inserted) guard_order_.push_back(key);
    return stored;
  }
  /// 1 valid, 0 invalid, -1 never checked.
  int validity(const Key& key) const {
    if (auto g = guard(key)) return g->clearance > 0.0;
    auto it = valid_.find(key);
    return it == valid_.end() ? -1 : it->second;
  }
  void add_validity(const Key& key, bool valid) {
    bound(valid_, valid_order_);
    auto [it, inserted] = valid_.insert_or_assign(key, valid);
    (void)it;
    if (inserted) valid_order_.push_back(key);
  }
  std::size_t size() const { return guards_.size(); }
  std::size_t validity_size() const { return valid_.size(); }
  std::size_t max_entries() const { return max_entries_; }

 private:
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 1469598103934665603ull;
      for (std::uint64_t v : k) h = (h ^ v) * 1099511628211ull, h ^= h >> 29;
      return static_cast<std::size_t>(h);
    }
  };
  template <class Table>
  void bound(Table& table, std::deque<Key>& order) {
    if (table.size() < max_entries_) return;
    const std::size_t drop = std::max<std::size_t>(1, max_entries_ / 4);
    for (std::size_t i = 0; i < drop && !order.empty(); ++i) {
      table.erase(order.front());
      order.pop_front();
    }
  }

  std::size_t max_entries_;
  std::unordered_map<Key, std::shared_ptr<const Value>, Hash> guards_;
  std::unordered_map<Key, bool, Hash> valid_;
  std::deque<Key> guard_order_, valid_order_;
};

/// The guards of a rigid robot, keyed by its flat pose.
class GuardCache : public StateCache<7, Guard> {
 public:
  using StateCache::StateCache;
  static Key key(const Pose& pose) { return key_of(pose.raw.data(), pose.size); }
};

}  // namespace kcplan
