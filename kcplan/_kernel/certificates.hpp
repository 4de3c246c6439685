// Edge certificates: sound rules that prove a stretch of an edge free from one guard.
// Python twin: kcplan/certification/certificates/ (ball.py, region.py, polytope.py); the proofs
// are in those modules' docstrings, the rules here are the same, line for line.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "guard.hpp"
#include "pose.hpp"
#include "robot.hpp"

namespace kcplan {

/// A certificate reads a guard measured at the edge's pose q(m) and proves every pose q(s)
/// with m - minus <= s <= m + plus collision-free. It never queries the world; what it
/// cannot prove it reports as (0, 0). Several certificates' proofs from one guard form an
/// interval around m, so the certifier takes the largest reach on each side.
class Certificate {
 public:
  virtual ~Certificate() = default;
  virtual const char* name() const = 0;
  virtual void reach(const Guard& guard, const Edge& edge, double m, double& minus,
                     double& plus) const = 0;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Conservative advancement with a clearance ball per body: body k stays free while
/// |s - m| (|dt| + L_k |w|) <= d_k, with the lever L_k = |p_k| + a_max - a_min ("rotation")
/// or the reach |p_k| + a_max ("ball").
class ClearanceBall final : public Certificate {
 public:
  ClearanceBall(const Robot& robot, bool rotation_aware) : rotation_aware_(rotation_aware) {
    for (const Body& b : robot.bodies()) levers_.push_back(rotation_aware ? b.lever() : b.reach());
  }
  const char* name() const override { return rotation_aware_ ? "rotation" : "ball"; }
  void reach(const Guard& guard, const Edge& edge, double, double& minus,
             double& plus) const override {
    double r = kInf;
    const double v = edge.translation_speed(), w = edge.rotation_speed();
    for (std::size_t k = 0; k < levers_.size(); ++k) {
      const double speed = v + levers_[k] * w;
      if (speed > 0.0) r = std::min(r, guard.bodies[k].clearance / speed);
    }
    minus = plus = r;
  }

 private:
  bool rotation_aware_;
  std::vector<double> levers_;
};

/// Separating planes of every piece within each body's horizon: piece i stays on its side
/// while its slack lasts, or within its clearance ball; pieces beyond the horizon are
/// covered by the ball of radius `horizon`. How body k's centre may move in x = s - m:
/// "region-lever" by at most |x| (|dt| + |p_k| |w|), the lever rule; "region" by
/// x (dt + w x R p_k) to first order and within |p_k| (x |w|)^2 / 2 of that, the arc rule,
/// each reach the larger of the two rules' (proofs in region.py).
class FreeRegionPlanes final : public Certificate {
 public:
  FreeRegionPlanes(const Robot& robot, bool arc) : arc_(arc) {
    for (const Body& b : robot.bodies()) {
      levers_.push_back(b.lever());
      shape_levers_.push_back(b.a_max - b.a_min);
      offsets_.push_back(b.offset());
    }
  }
  const char* name() const override { return arc_ ? "region" : "region-lever"; }
  void reach(const Guard& guard, const Edge& edge, double, double& minus,
             double& plus) const override {
    minus = plus = kInf;
    const double v = edge.translation_speed(), w = edge.rotation_speed();
    const std::array<double, 3>& dt = edge.dt();
    const std::array<double, 3> spin = edge.spin();
    for (std::size_t k = 0; k < levers_.size(); ++k) {
      const BodyGuard& body = guard.bodies[k];
      const double turn = levers_[k] * w, speed = v + turn;
      if (speed <= 0.0) continue;
      // the arc rule: the centre's velocity c' = dt + w x R p_k, and its curvature term
      const std::array<double, 3>& r = body.arm;
      const double swing[3] = {spin[1] * r[2] - spin[2] * r[1], spin[2] * r[0] - spin[0] * r[2],
                               spin[0] * r[1] - spin[1] * r[0]};
      const double cx = dt[0] + swing[0], cy = dt[1] + swing[1], cz = dt[2] + swing[2];
      const double shape_turn = shape_levers_[k] * w;
      // a body at the origin has no arc: the two rules are one (bend = inf: the lever's)
      const double bend = arc_ && offsets_[k] > 0.0 ? 0.5 * offsets_[k] * w * w : kInf;
      const double arc_speed = std::sqrt(cx * cx + cy * cy + cz * cz) + shape_turn;
      // how long the body stays within distance d of where it is at m
      const auto within = [&](double d) {
        return std::max(d / speed, arc_reach(d, arc_speed, bend));
      };
      const double horizon = within(body.horizon);
      plus = std::min(plus, horizon), minus = std::min(minus, horizon);
      for (const PlaneRow& p : body.planes) {
        const double ball = within(p.clearance);
        if (p.slack > 0.0) {
          const double along = p.nx * dt[0] + p.ny * dt[1] + p.nz * dt[2];
          const double away = p.nx * cx + p.ny * cy + p.nz * cz;  // n . c', off the piece
          double rate = turn - along;  // slack used up per unit s going forward
          const double ahead =
              std::max(rate > 0.0 ? p.slack / rate : kInf,
                       arc_reach(p.slack, shape_turn - away, bend));
          rate = turn + along;  // ... going backward
          const double behind =
              std::max(rate > 0.0 ? p.slack / rate : kInf,
                       arc_reach(p.slack, shape_turn + away, bend));
          plus = std::min(plus, std::max(ahead, ball));
          minus = std::min(minus, std::max(behind, ball));
        } else {
          plus = std::min(plus, ball), minus = std::min(minus, ball);
        }
      }
    }
  }

 private:
  /// The least x > 0 with budget - rate x - bend x^2 = 0 (inf when there is none); 0 for
  /// no budget, and without the arc rule (bend = inf).
  static double arc_reach(double budget, double rate, double bend) {
    if (bend == kInf || !(budget > 0.0)) return 0.0;
    if (budget == kInf) return kInf;
    if (bend <= 0.0) return rate > 0.0 ? budget / rate : kInf;
    const double root = std::sqrt(rate * rate + 4.0 * bend * budget);
    // each form free of cancellation on its side of rate = 0
    return rate > 0.0 ? 2.0 * budget / (rate + root) : (root - rate) / (2.0 * bend);
  }

  bool arc_;
  std::vector<double> levers_, shape_levers_, offsets_;
};

/// The paper's convex lower bound P_eps of the largest free guard (1 + eps) E_a on a
/// ladder: eps <= clearance / max(a); the guard covers the gauge of P_eps along the
/// edge's KC direction on each side. The rows are A_i / c_i of each level's polytope,
/// built and proven sound in Python (kcplan/kc/convex.py, cached by certification/ladder.py).
class KCPolytope final : public Certificate {
 public:
  /// `levels` increasing inflations; `rows[l]` the scaled rows of level l, flat
  /// (count x width, width 3 in 2D and 6 in 3D); `scale` = max(a).
  KCPolytope(std::vector<double> levels, std::vector<std::vector<double>> rows, int width,
             double scale)
      : levels_(std::move(levels)), rows_(std::move(rows)), width_(width), scale_(scale) {
    if (levels_.size() != rows_.size() || levels_.empty() || (width != 3 && width != 6) ||
        !(scale > 0.0))
      throw std::invalid_argument("ladder: expected one row block per level, width 3 or 6");
    for (std::size_t l = 0; l < levels_.size(); ++l)
      if (rows_[l].empty() || rows_[l].size() % width ||
          (l && !(levels_[l] > levels_[l - 1])))
        throw std::invalid_argument("ladder: levels must increase and rows be count x width");
    for (const std::vector<double>& block : rows_)
      for (double v : block)
        if (!std::isfinite(v)) throw std::invalid_argument("ladder: rows must be finite");
  }
  const char* name() const override { return "polytope"; }
  void reach(const Guard& guard, const Edge& edge, double m, double& minus,
             double& plus) const override {
    // the largest level with eps <= clearance / scale (Python's bisect_right - 1)
    const double e = guard.clearance / scale_;
    const int level = static_cast<int>(std::upper_bound(levels_.begin(), levels_.end(), e) -
                                       levels_.begin()) - 1;
    if (level < 0) {
      minus = plus = 0.0;
      return;
    }
    double d[6];
    edge.direction(m, d);
    const std::vector<double>& A = rows_[level];
    double top = -kInf, bottom = kInf;
    for (std::size_t i = 0; i < A.size(); i += width_) {
      double p = 0.0;
      for (int j = 0; j < width_; ++j) p += A[i + j] * d[j];
      top = std::max(top, p), bottom = std::min(bottom, p);
    }
    plus = top > 0.0 ? 1.0 / top : kInf;
    minus = bottom < 0.0 ? -1.0 / bottom : kInf;
  }

 private:
  std::vector<double> levels_;
  std::vector<std::vector<double>> rows_;
  int width_;
  double scale_;
};

}  // namespace kcplan
