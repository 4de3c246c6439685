#include "pair_proof.hpp"

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>

namespace kcplan {
namespace {

/// A sub-box of the joint box, measured: the pair's certain clearance d at its centre and
/// the most the pair's distance can change within it (reach).
struct Box {
  std::vector<double> lo, hi;
  double d = 0.0, reach = 0.0;
  std::size_t cut = 0;  // the joint of the largest rho w: where to cut it
  double slack() const { return d - reach * (1.0 + 1e-9); }  // > 0: apart (rounding: 1e-9)
};

/// Best first: the box nearest to touching at the top of the heap.
bool looser(const Box& a, const Box& b) { return a.slack() > b.slack(); }

}  // namespace

std::vector<PairProof> prove_pairs_apart(ArmWorld& world, std::int64_t max_boxes,
                                         std::size_t first) {
  if (max_boxes < 1) throw std::invalid_argument("max_boxes: expected at least 1");
  const Chain& chain = world.chain();
  const std::size_t dof = static_cast<std::size_t>(chain.dof()), pairs = world.pairs().size();
  const std::vector<double> rho = chain.relative_speeds(world.pairs());
  std::vector<PairProof> out(pairs);
  std::vector<Box> heap;
  std::vector<double> centre(dof);
  std::vector<coal::Transform3s> joints, frames;
  for (std::size_t m = 0; m < pairs; ++m) {
    PairProof& proof = out[m];
    const double* speed = &rho[m * dof];
    // measure a box (one distance query at its centre); false: the pair touches there
    const auto measure = [&](Box& box) {
      double widest = -1.0;
      box.reach = 0.0;
      for (std::size_t j = 0; j < dof; ++j) {
        centre[j] = 0.5 * (box.lo[j] + box.hi[j]);
        const double span = speed[j] * (box.hi[j] - box.lo[j]);
        box.reach += 0.5 * span;
        if (span > widest) widest = span, box.cut = j;
      }
      chain.body_frames(centre.data(), joints, frames);
      ++proof.boxes;
      box.d = world.pair_clearance(m, frames);
      if (box.d > 0.0) return true;
      proof.verdict = PairProof::kTouches;
      proof.least = 0.0;
      proof.witness = centre;
      return false;
    };
    // a pair that touches mostly does so at many configurations: a few random ones
    // (seeded: the same verdicts every time) end its search sooner than the boxes would
    std::mt19937 random(static_cast<unsigned>(first + m));
    Box sample{chain.lower(), chain.upper()};
    bool touches = false;
    for (int i = 0; i < kWitnessSamples && !touches; ++i) {
      for (std::size_t j = 0; j < dof; ++j)
        sample.lo[j] = sample.hi[j] =
            std::uniform_real_distribution<double>(chain.lower()[j], chain.upper()[j])(random);
      touches = !measure(sample);
    }
    if (touches) continue;
    heap.assign(1, Box{chain.lower(), chain.upper()});
    if (!measure(heap[0])) continue;
    proof.verdict = PairProof::kUnknown;
    while (proof.boxes + 2 <= max_boxes) {
      if (heap.front().slack() > 0.0) {  // the tightest box is apart: every box is
        proof.verdict = PairProof::kApart;
        proof.least = std::numeric_limits<double>::infinity();
        for (const Box& b : heap) proof.least = std::min(proof.least, b.d);
        break;
      }
      std::pop_heap(heap.begin(), heap.end(), looser);
      Box lower = std::move(heap.back());
      heap.pop_back();
      Box upper = lower;  // cut across the joint that moves the pair most
      const double middle = 0.5 * (lower.lo[lower.cut] + lower.hi[lower.cut]);
      lower.hi[lower.cut] = upper.lo[upper.cut] = middle;
      for (Box* b : {&lower, &upper}) {
        if (!measure(*b)) {
          touches = true;
          break;
        }
        heap.push_back(std::move(*b));
        std::push_heap(heap.begin(), heap.end(), looser);
      }
      if (touches) break;
    }
  }
  return out;
}

}  // namespace kcplan
