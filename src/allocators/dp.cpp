#include "ontime/allocators/dp.hpp"

namespace ontime {
namespace {

int best_single_skeleton(const Mdp& mdp) {
  const ContiguousSuccessTable table(mdp, Aggregation::self);
  int best = 0;
  double best_value = -1;
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    const double value = table.success_probability(k, 0, 0, 0);
    if (value > best_value) {
      best_value = value;
      best = k;
    }
  }
  return best;
}

}  // namespace

DpAllocator::DpAllocator(const Mdp& mdp) : chosen_(best_single_skeleton(mdp)) {}

}  // namespace ontime
