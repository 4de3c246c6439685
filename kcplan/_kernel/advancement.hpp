// Conservative advancement: guards in the middle of what is left open of an edge.
// Python twin: kcplan/certification/certifier.py advance(); the rigid and the arm certifiers
// both advance by it.
#pragma once

#include <utility>
#include <vector>

namespace kcplan {

/// How an advancement ended.
enum class Advanced { kCovered, kRejected, kNotProven };

/// Cover [lo, hi] by guards: a guard at the middle m of each stretch [s0, s1] left open,
/// until none is. `reach(m, s0, s1, g_lo, g_hi)` measures the guard at m and sets the
/// stretch (g_lo, g_hi) around m it proves free, or returns false when the guard touches
/// an obstacle (kRejected). kNotProven: `max_guards` were placed, or a guard proved no
/// stretch. `guards` gets the number placed; `pending` is scratch.
template <class Reach>
Advanced advance(double lo, double hi, int max_guards,
                 std::vector<std::pair<double, double>>& pending, Reach&& reach, int& guards) {
  pending.clear();
  pending.emplace_back(lo, hi);
  guards = 0;
  while (!pending.empty()) {
    const auto [s0, s1] = pending.back();
    pending.pop_back();
    if (guards >= max_guards) return Advanced::kNotProven;
    const double m = 0.5 * (s0 + s1);
    double g_lo, g_hi;
    ++guards;
    if (!reach(m, s0, s1, g_lo, g_hi)) return Advanced::kRejected;
    if (g_hi - g_lo <= 1e-12) return Advanced::kNotProven;
    if (g_lo > s0) pending.emplace_back(s0, g_lo);
    if (g_hi < s1) pending.emplace_back(g_hi, s1);
  }
  return Advanced::kCovered;
}

}  // namespace kcplan
