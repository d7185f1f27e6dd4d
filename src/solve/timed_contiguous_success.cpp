#include "ontime/solve/timed_contiguous_success.hpp"

#include <vector>

#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"

namespace ontime {
namespace {

// The one choice k in every state, states keyed whole (the chains and the executions before
// timed actions included), as the exact solver keys a timed instance.
class FixedChoicePolicy {
 public:
  using Compact = detail::CompactTimedState;
  explicit FixedChoicePolicy(int choice) noexcept : choice_(choice) {}
  void choices(const Compact&, std::vector<int>& out) const { out.push_back(choice_); }
  static const Compact& key(const Compact& state) { return state; }

 private:
  int choice_;
};

}  // namespace

struct TimedContiguousSuccess::Impl {
  std::vector<detail::Expectimax<FixedChoicePolicy>> searches;  // one per skeleton
};

TimedContiguousSuccess::TimedContiguousSuccess(const Mdp& mdp, std::size_t max_states)
    : impl_(std::make_unique<Impl>()) {
  if (!mdp.is_timed()) {
    throw UsageError("Eq. (1) with chains: the instance has no chain and no expiry (Eq. (1)'s tables serve it)");
  }
  impl_->searches.reserve(static_cast<std::size_t>(mdp.skeleton_count()));
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    impl_->searches.emplace_back(mdp, FixedChoicePolicy(k), max_states, 0.0, "Eq. (1) with chains");
  }
}

TimedContiguousSuccess::~TimedContiguousSuccess() = default;
TimedContiguousSuccess::TimedContiguousSuccess(TimedContiguousSuccess&&) noexcept = default;
TimedContiguousSuccess& TimedContiguousSuccess::operator=(TimedContiguousSuccess&&) noexcept = default;

double TimedContiguousSuccess::expected_reward(const State& state, int k) {
  return impl_->searches.at(static_cast<std::size_t>(k)).solve(state).value;
}

std::size_t TimedContiguousSuccess::memoised() const noexcept {
  std::size_t total = 0;
  for (const auto& search : impl_->searches) total += search.memo().size();
  return total;
}

}  // namespace ontime
