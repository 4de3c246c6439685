// Who decides an arm's straight joint-space edge for the compiled planner: the
// certifier (a proof), its screen (probes, no proof) or discrete state checks (the
// stock twin). OMPL's base/MotionValidator.h is the model; the Python side picks one in
// kcplan/planning/native.py.
#pragma once

#include <cstdint>

#include "arm_certifier.hpp"
#include "arm_world.hpp"

namespace kcplan {

/// Decides whether the straight edge q1 -> q2 of an arm (chain().dof() joint values each)
/// may be used, as OMPL's MotionValidator::checkMotion does: q1 is assumed valid and q2
/// is checked. Implementations say whether a true answer is a proof (certified()).
/// Not thread-safe (the world's objects are reused).
class ArmMotionValidator {
 public:
  virtual ~ArmMotionValidator() = default;
  /// Whether the edge q1 -> q2 may be used (q1 valid).
  virtual bool check(const double* q1, const double* q2) = 0;
  /// check() of an edge a screen has passed already (a lazy planner's path edge): the
  /// same answer, perhaps without asking again what the screen asked.
  virtual bool check_screened(const double* q1, const double* q2) { return check(q1, q2); }
  /// Whether the state q is within the limits and free.
  virtual bool state_valid(const double* q) = 0;
  /// The arm whose edges it decides.
  virtual const Chain& chain() const = 0;
  /// Whether check()'s true means that no body touches anything anywhere on the edge.
  virtual bool certified() const = 0;
  /// Make later checks stricter after one of them let a bad edge through (a screen's
  /// probes twice as dense); false when there is nothing to tighten.
  virtual bool tighten() { return false; }
  /// The checks asked.
  std::int64_t edges = 0;
};

/// Edges proven free by ArmCertifier::check (probes, then guards): a true is a proof.
/// check_screened() skips the probes, which only reject early and prove nothing.
class CertifiedArmMotions final : public ArmMotionValidator {
 public:
  explicit CertifiedArmMotions(ArmCertifier& certifier) : certifier_(certifier) {}
  bool check(const double* q1, const double* q2) override {
    ++edges;
    return certifier_.check(q1, q2);
  }
  bool check_screened(const double* q1, const double* q2) override {
    ++edges;
    return certifier_.check(q1, q2, false);
  }
  bool state_valid(const double* q) override { return certifier_.state_valid(q); }
  const Chain& chain() const override { return certifier_.world().chain(); }
  bool certified() const override { return true; }

 private:
  ArmCertifier& certifier_;
};

/// Edges screened by ArmCertifier::screen: q2 and collision probes at most `step` apart
/// (radians of joint-space distance, L2; at most ArmCertifier::kMaxProbes). Not a proof:
/// a lazy planner certifies the path it returns with a CertifiedArmMotions.
class ScreenedArmMotions final : public ArmMotionValidator {
 public:
  ScreenedArmMotions(ArmCertifier& certifier, double step);
  bool check(const double* q1, const double* q2) override {
    ++edges;
    return certifier_.screen(q1, q2, step_);
  }
  bool state_valid(const double* q) override { return certifier_.state_valid(q); }
  const Chain& chain() const override { return certifier_.world().chain(); }
  bool certified() const override { return false; }
  /// Halves the step.
  bool tighten() override {
    step_ *= 0.5;
    return true;
  }
  double step() const { return step_; }

 private:
  ArmCertifier& certifier_;
  double step_;
};

/// The stock twin: q2, then states at most `step` apart (radians of joint-space
/// distance, L2) in OMPL's DiscreteMotionValidator order (the midpoints of the intervals
/// left, breadth first), one ArmWorld::in_collision query each, with no cap and no cache;
/// along q1 -> Chain::edge_end(q1, q2), as the certifier's edge.
/// Not a proof: the edge may touch between two checked states.
class DiscreteArmMotions final : public ArmMotionValidator {
 public:
  DiscreteArmMotions(ArmWorld& world, double step);
  bool check(const double* q1, const double* q2) override;
  bool state_valid(const double* q) override;
  const Chain& chain() const override { return world_.chain(); }
  bool certified() const override { return false; }
  /// States checked, the ends included.
  std::int64_t states = 0;

 private:
  ArmWorld& world_;
  double step_;
  std::vector<double> q_, end_;
};

}  // namespace kcplan
