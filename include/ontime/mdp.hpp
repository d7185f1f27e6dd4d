#pragma once
// The effort-allocation MDP of SPEC §2: legal choices, the transition of one step of effort,
// the enumerated outcomes of a choice, and whether a skeleton can still succeed.
//
// Choosing skeleton k spends one step on its next action a, for every skeleton whose next
// action is a (they share it, and share the whole state of it). With the hazard
// h = p(PT_k + 1) / (1 - F(PT_k)) the motion is found and an execution time x ~ e is drawn.
// Success as soon as a skeleton completes with CT' + ET <= D; failure when CT' >= D without
// success, or earlier, as soon as no skeleton can still succeed (this changes no value).
//
// An Mdp refers to its Problem, which must outlive it. Its precomputed tables (hazards,
// execution supports, lower bounds on remaining time) make a transition O(K) with no
// allocation.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "ontime/problem.hpp"
#include "ontime/random.hpp"
#include "ontime/state.hpp"

namespace ontime {

// A short list of skeleton indices, without allocation (at most Problem::kMaxSkeletons).
class ChoiceList {
 public:
  void push_back(int choice) noexcept { items_[size_++] = static_cast<std::uint8_t>(choice); }
  int operator[](std::size_t i) const noexcept { return items_[i]; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  const std::uint8_t* begin() const noexcept { return items_.data(); }
  const std::uint8_t* end() const noexcept { return items_.data() + size_; }

 private:
  std::array<std::uint8_t, Problem::kMaxSkeletons> items_{};
  std::size_t size_ = 0;
};

// What one step of refinement effort revealed.
struct Observation {
  bool refined = false;  // a motion was found in this step
  Steps execution = 0;   // its execution time (may be kNever); only when refined

  static constexpr Observation not_yet() noexcept { return {}; }
  static constexpr Observation found(Steps execution_steps) noexcept { return {true, execution_steps}; }
};

class Mdp {
 public:
  explicit Mdp(const Problem& problem);

  const Problem& problem() const noexcept { return *problem_; }
  int skeleton_count() const noexcept { return skeleton_count_; }
  Steps deadline() const noexcept { return deadline_; }

  State start() const noexcept { return State{}; }

  // The action skeleton k refines next, or -1 when it is fully refined (choosing it idles).
  int next_action(const State& state, int k) const noexcept {
    const int refined = state.refined[static_cast<std::size_t>(k)];
    return refined < lengths_[static_cast<std::size_t>(k)]
               ? paths_[offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(refined)]
               : -1;
  }

  // Applies one step of effort on skeleton `choice` with its observed result, in place.
  // Throws UsageError when the choice or the observation is impossible (a refinement reported
  // for an idle choice, a negative execution time); `state` is then left as it was.
  Status apply(State& state, int choice, const Observation& observation) const;

  // The skeleton that succeeded in the last `apply` that returned success: the lowest-index
  // skeleton that ends with the refined action and meets the deadline.
  int completed_skeleton(const State& state, int choice) const;

  // Calls visit(probability, status, next_state) for every outcome of choosing `choice` in
  // `state` (SPEC §2). Outcomes with zero probability are skipped; execution times that
  // cannot meet the deadline are merged into one outcome.
  template <class Visitor>
  void for_each_outcome(const State& state, int choice, Visitor&& visit) const;

  // Calls visit(probability, observation) for every observation choosing `choice` in
  // `state` can produce, in the order of for_each_outcome, without applying them.
  template <class Visitor>
  void for_each_observation(const State& state, int choice, Visitor&& visit) const;

  // Draws the observation of one step on `choice` from the model (hazard, then execution).
  template <class Generator>
  Observation sample_observation(const State& state, int choice, Generator& generator) const;

  // The choices worth considering: one per group of skeletons sharing their next action
  // (named by the group's lowest index), and only groups in which some skeleton can still
  // succeed. In increasing index order. Spending a step elsewhere cannot raise the success
  // probability.
  ChoiceList useful_choices(const State& state) const noexcept;
  // Whether some skeleton sharing the next action of `action`'s group can still succeed.
  bool group_can_succeed(const State& state, int action) const noexcept;

  // Whether skeleton k can still succeed from this state: it has actions left and the
  // least time it can still need (earliest completion of the current action given the
  // steps spent, plus the fastest planning and execution of the rest) fits the deadline.
  bool can_succeed(const State& state, int k) const noexcept;
  bool any_can_succeed(const State& state) const noexcept;

  // The choice of an allocator when no skeleton can succeed any more (every choice is as
  // good): the lowest-index skeleton with actions left, else 0.
  int first_with_work_left(const State& state) const noexcept;

  // P(the next step of effort on `action` finds a motion | `spent` steps did not).
  double hazard(int action, Steps spent) const noexcept {
    return spent < deadline_ ? hazards_[static_cast<std::size_t>(action) * static_cast<std::size_t>(deadline_) +
                                        static_cast<std::size_t>(spent)]
                             : 0.0;
  }

 private:
  struct ExecutionOutcome {
    Steps steps;  // deadline + 1 stands for "too slow or never"
    double probability;
  };

  std::uint16_t saturate_execution(std::int64_t steps) const noexcept {
    return static_cast<std::uint16_t>(steps > deadline_ ? deadline_ + 1 : steps);
  }

  const Problem* problem_;
  int skeleton_count_;
  Steps deadline_;
  std::vector<int> lengths_;          // A_k
  std::vector<std::size_t> offsets_;  // start of skeleton k in paths_
  std::vector<int> paths_;            // actions of all skeletons, concatenated
  std::vector<std::int64_t> rest_;    // least planning+execution of positions l.. of k (offsets_ + l)
  std::vector<double> hazards_;       // [action][spent], spent < deadline
  std::vector<Steps> next_finish_;    // [action][spent]: least t >= 1 with p(spent + t) > 0, or kNever
  std::vector<std::vector<ExecutionOutcome>> execution_outcomes_;  // per action
  std::vector<Steps> min_execution_;                               // per action, kNever if none
};

template <class Visitor>
void Mdp::for_each_observation(const State& state, int choice, Visitor&& visit) const {
  const int action = next_action(state, choice);
  if (action < 0) {
    visit(1.0, Observation::not_yet());
    return;
  }
  const double found = hazard(action, state.spent[static_cast<std::size_t>(choice)]);
  if (found < 1.0) visit(1.0 - found, Observation::not_yet());
  if (found > 0.0) {
    for (const ExecutionOutcome& outcome : execution_outcomes_[static_cast<std::size_t>(action)]) {
      visit(found * outcome.probability, Observation::found(outcome.steps));
    }
  }
}

template <class Visitor>
void Mdp::for_each_outcome(const State& state, int choice, Visitor&& visit) const {
  for_each_observation(state, choice, [&](double probability, const Observation& observation) {
    State next = state;
    const Status status = apply(next, choice, observation);
    visit(probability, status, next);
  });
}

template <class Generator>
Observation Mdp::sample_observation(const State& state, int choice, Generator& generator) const {
  const int action = next_action(state, choice);
  if (action < 0) return Observation::not_yet();
  const double found = hazard(action, state.spent[static_cast<std::size_t>(choice)]);
  if (!(uniform01(generator) < found)) return Observation::not_yet();
  const auto& outcomes = execution_outcomes_[static_cast<std::size_t>(action)];
  const std::size_t drawn = sample_index(
      outcomes.size(), [&outcomes](std::size_t i) { return outcomes[i].probability; }, generator);
  return Observation::found(outcomes[drawn].steps);
}

}  // namespace ontime
