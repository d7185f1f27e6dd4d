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
// The functions of a state are templates on its type S: State, or the exact solver's fixed-size
// copy of it (anything with time, refined[k], spent[k] and execution[k]).
//
// Exogenous chains and actions that expire (SPEC §9): every step also moves the chains (an
// observation carries their next joint state), a timed action's refinement records the static
// execution before it (State::restore by Problem::timed_slot), and a success's reward is the
// expected reward of executing the completed plan from the chains' state (execution_value).
//
// An Mdp refers to its Problem, which must outlive it. Its precomputed tables (hazards,
// execution supports, lower bounds on remaining time) make a transition O(K) with no
// allocation.

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "ontime/mdp/state.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

// A list of skeleton indices: inline, without allocation, for up to kInlineSkeletons entries;
// a longer list (wide problems only) moves to the heap.
class ChoiceList {
 public:
  // Appends skeleton index `choice` (below 65536), moving the list to the heap past kInlineSkeletons.
  void push_back(int choice) {
    if (size_ < inline_.size()) {
      inline_[size_] = static_cast<std::uint16_t>(choice);
    } else {
      if (size_ == inline_.size()) heap_.assign(inline_.begin(), inline_.end());
      heap_.push_back(static_cast<std::uint16_t>(choice));
    }
    ++size_;
  }
  // The i-th skeleton index; i must be below size().
  int operator[](std::size_t i) const noexcept { return begin()[i]; }
  // How many choices the list holds.
  std::size_t size() const noexcept { return size_; }
  // Whether the list holds no choice.
  bool empty() const noexcept { return size_ == 0; }
  // The first choice, inline or on the heap; valid until the next push_back.
  const std::uint16_t* begin() const noexcept { return size_ > inline_.size() ? heap_.data() : inline_.data(); }
  // One past the last choice.
  const std::uint16_t* end() const noexcept { return begin() + size_; }

 private:
  std::array<std::uint16_t, kInlineSkeletons> inline_{};
  std::vector<std::uint16_t> heap_;
  std::size_t size_ = 0;
};

// What one step of refinement effort revealed.
struct Observation {
  bool refined = false;  // a motion was found in this step
  Steps execution = 0;   // its execution time (may be kNever); only when refined
  // Backtracking (SPEC §7): the attempt gave up and blames this earlier action (its index), whose
  // motion and everything refined after it are discarded; -1: no backtrack. Never with `refined`.
  int culprit = -1;

  // The step ended with no motion found and no backtrack.
  static constexpr Observation not_yet() noexcept { return {}; }
  // A motion was found, to execute in `execution_steps` steps (may be kNever).
  static constexpr Observation found(Steps execution_steps) noexcept { return {true, execution_steps, -1}; }
  // The attempt gave up and blames the action at index `culprit_action`.
  static constexpr Observation backtracked(int culprit_action) noexcept { return {false, 0, culprit_action}; }
  // Whether the attempt backtracked (a culprit is named).
  bool is_backtrack() const noexcept { return culprit >= 0; }
  // Exogenous chains (SPEC §9): the chains' joint state after the step (Mdp::joint_chain_state);
  // ignored without chains.
  std::uint16_t chains = 0;

  // This observation with the chains' joint state after the step.
  constexpr Observation with_chains(std::uint16_t joint) const noexcept {
    Observation out = *this;
    out.chains = joint;
    return out;
  }
};

// Whether a state type holds the restore values of backtracking (State does; the exact solvers'
// compact copy only in its backtracking form). The Mdp's functions read and write them only then;
// a problem with backtracking needs such a state type.
template <class S>
inline constexpr bool kHoldsRestore = requires(S& state) {
  state.restore[0];
};
// Whether a state type holds the chains' joint state and its restore values hold the executions
// before timed actions (State does; the exact solvers' compact copy only in its timed form). A
// problem with chains or expiry (SPEC §9) needs such a state type.
template <class S>
inline constexpr bool kHoldsChains = kHoldsRestore<S>&& requires(S& state) {
  state.chains;
};

class Mdp {
 public:
  // One execution time an action's motion can take once found, with its probability.
  struct ExecutionOutcome {
    Steps steps;  // deadline + 1 stands for "too slow or never"
    double probability;
  };
  // What least_need returns for a skeleton that cannot succeed whatever the time left.
  static constexpr std::int64_t kUnreachableNeed = std::int64_t{1} << 40;

  // Throws UsageError for a problem whose robot acts while planning (Problem::acting() concurrent,
  // SPEC §10): that is ConcurrentMdp's model (ontime/mdp/concurrent_mdp.hpp).
  explicit Mdp(const Problem& problem);

  // The problem the MDP models (it must outlive the Mdp).
  const Problem& problem() const noexcept { return *problem_; }
  // The number of skeletons, K.
  int skeleton_count() const noexcept { return skeleton_count_; }
  // The deadline D in steps.
  Steps deadline() const noexcept { return deadline_; }

  // The initial state: time 0, nothing refined or spent, the chains in their start states.
  State start() const {
    State state(static_cast<std::size_t>(skeleton_count_),
                static_cast<std::size_t>(problem_->culprit_slot_count() + problem_->timed_slot_count()));
    state.chains = start_chains_;
    return state;
  }
  // Whether some action may backtrack (SPEC §7).
  bool has_backtracking() const noexcept { return problem_->has_backtracking(); }

  // Exogenous chains and expiry (SPEC §9). Whether the problem has chains, or chains or timed
  // actions; the number of joint states of the chains (1 without); the joint state of one state
  // per chain (by index, in the problem's order of chains) and chain c's state in a joint state.
  bool has_chains() const noexcept { return problem_->has_chains(); }
  bool is_timed() const noexcept { return problem_->is_timed(); }
  int joint_chain_states() const noexcept { return joint_count_; }
  // Throws UsageError naming `what` when the problem has chains or expiry: for the solvers and
  // tables that do not model them yet.
  void refuse_timed(std::string_view what) const;
  std::uint16_t joint_chain_state(std::span<const int> states) const;
  int chain_state(std::uint16_t joint, int chain) const noexcept {
    const auto c = static_cast<std::size_t>(chain);
    return (joint / chain_strides_[c]) % static_cast<int>(problem_->chains()[c].states.size());
  }
  // One joint state the chains may move to from `joint` in one step, with its probability.
  struct ChainStep {
    std::uint16_t next;
    double probability;
  };
  // Every joint state the chains may move to from `joint` in one step (probabilities summing to 1).
  std::span<const ChainStep> chain_steps(std::uint16_t joint) const noexcept {
    return {chain_steps_.data() + chain_step_offsets_[joint], chain_steps_.data() + chain_step_offsets_[joint + 1U]};
  }

  // The expected reward of executing skeleton k's plan from step `start` with the chains in joint
  // state `joint` (SPEC §9): `restore` holds the static execution before each timed action (by
  // Problem::timed_slot) and `execution` the plan's whole static execution. Each timed action
  // starts after the static execution before it and the chain-dependent executions drawn before
  // it; one that cannot start (after its last step, or its chain in a blocking state) fails the
  // plan; so does a finish after the deadline. Cost O(D * (gaps + the longest chain-dependent
  // execution) * joint states * chain steps per joint state); no allocation after a thread's
  // first call.
  double execution_value(int k, Steps start, std::uint16_t joint, const std::uint16_t* restore,
                         std::uint16_t execution) const;
  // The same for every start at once: out[t * joint_chain_states() + j] is the value from step t
  // in joint state j, (D + 1) * joint_chain_states() entries (computed backwards over the plan at
  // the cost of one execution_value): the exact solvers keep one table per plan.
  void execution_table(int k, const std::uint16_t* restore, std::uint16_t execution, std::vector<double>& out) const;
  // One execution of the same plan drawn from the model: the chains' steps and the
  // chain-dependent executions. The step the execution ends, or kNever when the plan fails (an
  // action that cannot start, a finish after the deadline).
  template <class Generator>
  Steps sample_execution(int k, Steps start, std::uint16_t joint, const std::uint16_t* restore, std::uint16_t execution,
                         Generator& generator) const;
  // The chains' step from `joint` drawn from the model.
  template <class Generator>
  std::uint16_t sample_chain_step(std::uint16_t joint, Generator& generator) const {
    const auto steps = chain_steps(joint);
    return steps[sample_index(
                     steps.size(), [&steps](std::size_t i) { return steps[i].probability; }, generator)]
        .next;
  }
  // The action skeleton k refines next, or -1 when it is fully refined (choosing it idles).
  template <class S>
  int next_action(const S& state, int k) const noexcept {
    const int refined = state.refined[static_cast<std::size_t>(k)];
    return refined < lengths_[static_cast<std::size_t>(k)]
               ? paths_[offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(refined)]
               : -1;
  }

  // Applies one step of effort on skeleton `choice` with its observed result, in place.
  // Throws UsageError when the choice or the observation is impossible (a refinement reported
  // for an idle choice, a negative execution time); `state` is then left as it was.
  template <class S>
  Status apply(S& state, int choice, const Observation& observation) const;

  // The skeleton that succeeded in the last `apply` that returned success: the lowest-index
  // skeleton that ends with the refined action and meets the deadline.
  template <class S>
  int completed_skeleton(const S& state, int choice) const;

  // The terminal reward of the success `apply` just returned on `choice` (SPEC §8): the completed
  // skeleton's reward at its finish, the state's CT plus its ET. 1 without rewards (the objective
  // is then the success probability, and p * 1 is p to the bit).
  template <class S>
  double success_reward(const S& state, int choice) const {
    if constexpr (kHoldsChains<S>) {
      if (is_timed()) {
        const int k = completed_skeleton(state, choice);
        const auto slot = static_cast<std::size_t>(k);
        return execution_value(k, state.time, state.chains, state.restore.data(), state.execution[slot]);
      }
    }
    if (!problem_->has_rewards()) return 1.0;
    const int k = completed_skeleton(state, choice);
    return problem_->reward_at(k, static_cast<Steps>(state.time + state.execution[static_cast<std::size_t>(k)]));
  }

  // Calls visit(probability, status, next_state) for every outcome of choosing `choice` in
  // `state` (SPEC §2). Outcomes with zero probability are skipped; execution times that
  // cannot meet the deadline are merged into one outcome.
  template <class S, class Visitor>
  void for_each_outcome(const S& state, int choice, Visitor&& visit) const;

  // Calls visit(probability, observation) for every observation choosing `choice` in
  // `state` can produce, in the order of for_each_outcome, without applying them.
  template <class S, class Visitor>
  void for_each_observation(const S& state, int choice, Visitor&& visit) const;
  // The same without the chains' step (Observation::chains 0): what refinement alone reveals.
  template <class S, class Visitor>
  void for_each_refinement(const S& state, int choice, Visitor&& visit) const;

  // Draws the observation of one step on `choice` from the model (hazard, then execution).
  // With chains, then draws their step.
  template <class S, class Generator>
  Observation sample_observation(const S& state, int choice, Generator& generator) const;
  // The refinement's draw alone (Observation::chains 0).
  template <class S, class Generator>
  Observation sample_refinement(const S& state, int choice, Generator& generator) const;

  // The choices worth considering: one per group of skeletons sharing their next action
  // (named by the group's lowest index), and only groups in which some skeleton can still
  // succeed. In increasing index order. Spending a step elsewhere cannot raise the success
  // probability. With backtracking every group with work left; with chains or expiry (SPEC §9)
  // every group with work left and an idle choice (a skeleton with none), since waiting may pay.
  template <class S>
  ChoiceList useful_choices(const S& state) const;
  // Whether some skeleton sharing the next action of `action`'s group can still succeed.
  template <class S>
  bool group_can_succeed(const S& state, int action) const noexcept;

  // Whether skeleton k can still succeed from this state: it has actions left and the
  // least time it can still need (earliest completion of the current action given the
  // steps spent, plus the fastest planning and execution of the rest; with backtracking, or a
  // backtrack to an earlier action of its path that restores that action's execution before it)
  // fits the deadline.
  template <class S>
  bool can_succeed(const S& state, int k) const noexcept;
  template <class S>
  bool any_can_succeed(const S& state) const noexcept;

  // The least number of steps after CT that skeleton k still needs to succeed: its ET, the
  // earliest finish of its current action given the PT_k steps spent, that action's fastest
  // execution, and the fastest planning and execution of the rest; kUnreachableNeed (or more)
  // when nothing can make it succeed. can_succeed(state, k) is CT + least_need <= D. The
  // fields form of the exact solver's successors takes k's refined count, PT and ET.
  std::int64_t least_need(int k, int refined, std::uint16_t spent, std::uint16_t execution) const noexcept;
  template <class S>
  std::int64_t least_need(const S& state, int k) const noexcept {
    const auto slot = static_cast<std::size_t>(k);
    const std::int64_t need = least_need(k, state.refined[slot], state.spent[slot], state.execution[slot]);
    if constexpr (kHoldsRestore<S>) {
      if (has_backtracking()) return std::min(need, least_need_after_backtrack(state, k));
    }
    return need;
  }
  // With backtracking: the least need of skeleton k through a backtrack to an action c refined on
  // its path that some action may blame: at least one step to trigger it, then B_c and the
  // fastest planning and execution from c's position on (kUnreachableNeed without such c).
  template <class S>
  std::int64_t least_need_after_backtrack(const S& state, int k) const noexcept;

  // The least number of steps after CT before some skeleton whose next action is `action` (they
  // share its PT and ET) can succeed: the least least_need over them. can_succeed holds for
  // one of them exactly when CT + group_need <= D. Without backtracking only (the layered
  // solver's).
  std::int64_t group_need(int action, std::uint16_t spent, std::uint16_t execution) const noexcept {
    const auto a = static_cast<std::size_t>(action);
    if (spent > deadline_) return kUnreachableNeed;
    const Steps finish = next_finish_[a * static_cast<std::size_t>(deadline_ + 1) + spent];
    const Steps fastest = min_execution_[a];
    if (finish == kNever || fastest == kNever) return kUnreachableNeed;
    return std::int64_t{execution} + finish + fastest + group_rest_[a];
  }

  // The execution outcomes of finding `action`'s motion, in the order for_each_outcome uses.
  std::span<const ExecutionOutcome> execution_outcomes(int action) const noexcept {
    return execution_outcomes_[static_cast<std::size_t>(action)];
  }

  // The choice of an allocator when no skeleton can succeed any more (every choice is as
  // good): the lowest-index skeleton with actions left, else 0.
  template <class S>
  int first_with_work_left(const S& state) const noexcept;

  // P(the next step of effort on `action` finds a motion | `spent` steps of this attempt neither
  // found one nor backtracked).
  double hazard(int action, Steps spent) const noexcept {
    return spent < deadline_ ? hazards_[static_cast<std::size_t>(action) * static_cast<std::size_t>(deadline_) +
                                        static_cast<std::size_t>(spent)]
                             : 0.0;
  }
  // P(the next step of effort on `action` backtracks | the same): 0 without backtracking.
  double backtrack_hazard(int action, Steps spent) const noexcept {
    return spent < deadline_ && !backtrack_hazards_.empty()
               ? backtrack_hazards_[static_cast<std::size_t>(action) * static_cast<std::size_t>(deadline_) +
                                    static_cast<std::size_t>(spent)]
               : 0.0;
  }

 private:
  // The UsageErrors of apply (out of line: the templates stay free of message building).
  [[noreturn]] void reject_choice(int choice) const;
  [[noreturn]] static void reject_idle_refinement(int choice);
  [[noreturn]] static void reject_execution(Steps execution);
  [[noreturn]] void reject_culprit(int action, int culprit) const;
  [[noreturn]] void reject_chains(std::uint16_t joint) const;
  // The chains' tables and the timed paths (SPEC §9).
  void index_chains(const Problem& problem);
  // The backtracking tables (SPEC §7): hazards, culprit slots along the paths and below each one.
  void index_backtracking(const Problem& problem);

  // Backtracking to `culprit` (SPEC §7): every skeleton through it goes back to its position
  // with the execution recorded before it; the restore values at and below it are cleared.
  template <class S>
  void backtrack(S& state, int culprit) const noexcept;

  std::uint16_t saturate_execution(std::int64_t steps) const noexcept {
    return static_cast<std::uint16_t>(steps > deadline_ ? deadline_ + 1 : steps);
  }

  const Problem* problem_;
  int skeleton_count_;
  Steps deadline_;
  std::vector<int> lengths_;              // A_k
  std::vector<std::size_t> offsets_;      // start of skeleton k in paths_
  std::vector<int> paths_;                // actions of all skeletons, concatenated
  std::vector<std::int64_t> rest_;        // least planning+execution of positions l.. of k (offsets_ + l)
  std::vector<std::int64_t> group_rest_;  // per action: the least rest_ after it over the skeletons through it
  std::vector<double> hazards_;           // [action][spent], spent < deadline
  std::vector<Steps> next_finish_;        // [action][spent]: least t >= 1 with p(spent + t) > 0, or kNever
  std::vector<std::vector<ExecutionOutcome>> execution_outcomes_;  // per action
  std::vector<Steps> min_execution_;                               // per action, kNever if none
  // Exogenous chains (SPEC §9): the joint state at the start, each chain's stride in a joint
  // state, and per joint state its steps (chain_steps_ from chain_step_offsets_[j] to [j + 1]).
  std::uint16_t start_chains_ = 0;
  int joint_count_ = 1;
  std::vector<int> chain_strides_;
  std::vector<std::uint32_t> chain_step_offsets_;
  std::vector<ChainStep> chain_steps_;
  // Per skeleton, its timed actions in the order of its path.
  std::vector<std::vector<int>> timed_path_;
  // Backtracking only (empty otherwise).
  std::vector<double> backtrack_hazards_;  // [action][spent], spent < deadline
  // Per skeleton and position (offsets_ + k + l, as rest_): the culprit slot of the action there
  // that some action may blame, else -1.
  std::vector<int> slot_at_;
  // Per culprit slot: the slots of the actions at or below it in the prefix tree (itself first),
  // culprit and timed slots alike.
  std::vector<std::vector<int>> slots_below_;
};

template <class S, class Visitor>
void Mdp::for_each_observation(const S& state, int choice, Visitor&& visit) const {
  if constexpr (kHoldsChains<S>) {
    if (has_chains()) {
      // Every refinement outcome with every step of the chains (they move whatever happens).
      const auto steps = chain_steps(state.chains);
      for_each_refinement(state, choice, [&](double probability, const Observation& observation) {
        for (const ChainStep& step : steps) visit(probability * step.probability, observation.with_chains(step.next));
      });
      return;
    }
  }
  for_each_refinement(state, choice, std::forward<Visitor>(visit));
}

template <class S, class Visitor>
void Mdp::for_each_refinement(const S& state, int choice, Visitor&& visit) const {
  const int action = next_action(state, choice);
  if (action < 0) {
    visit(1.0, Observation::not_yet());
    return;
  }
  const Steps spent = state.spent[static_cast<std::size_t>(choice)];
  const double found = hazard(action, spent);
  const double back = backtrack_hazard(action, spent);
  if (back <= 0.0) {
    if (found < 1.0) visit(1.0 - found, Observation::not_yet());
  } else if (found + back < 1.0) {
    visit(1.0 - found - back, Observation::not_yet());
  }
  if (found > 0.0) {
    for (const ExecutionOutcome& outcome : execution_outcomes_[static_cast<std::size_t>(action)]) {
      visit(found * outcome.probability, Observation::found(outcome.steps));
    }
  }
  if (back > 0.0) {
    for (const Problem::CulpritIndex& culprit : problem_->culprits(action)) {
      if (culprit.probability > 0) visit(back * culprit.probability, Observation::backtracked(culprit.action));
    }
  }
}

template <class S, class Visitor>
void Mdp::for_each_outcome(const S& state, int choice, Visitor&& visit) const {
  for_each_observation(state, choice, [&](double probability, const Observation& observation) {
    S next = state;
    const Status status = apply(next, choice, observation);
    visit(probability, status, next);
  });
}

template <class S, class Generator>
Observation Mdp::sample_observation(const S& state, int choice, Generator& generator) const {
  const Observation observation = sample_refinement(state, choice, generator);
  if constexpr (kHoldsChains<S>) {
    if (has_chains()) return observation.with_chains(sample_chain_step(state.chains, generator));
  }
  return observation;
}

template <class Generator>
Steps Mdp::sample_execution(int k, Steps start, std::uint16_t joint, const std::uint16_t* restore,
                            std::uint16_t execution, Generator& generator) const {
  std::int64_t time = start;
  std::uint16_t before = 0;
  for (const int action : timed_path_[static_cast<std::size_t>(k)]) {
    const std::uint16_t at = restore[problem_->timed_slot(action)];
    for (; before < at && time <= deadline_; ++before, ++time) joint = sample_chain_step(joint, generator);
    before = at;
    const Action& model = problem_->action(action);
    const int blocking = problem_->blocking_chain(action);
    if (time > deadline_ || (model.start_by != kNever && time > model.start_by) ||
        (blocking >= 0 && problem_->blocks(action, chain_state(joint, blocking)))) {
      return kNever;
    }
    const int chain = problem_->execution_chain(action);
    if (chain < 0) continue;
    const Steps drawn = model.execution_by_state[static_cast<std::size_t>(chain_state(joint, chain))].sample(generator);
    if (drawn == kNever || time + drawn > deadline_) return kNever;
    for (Steps x = 0; x < drawn; ++x) joint = sample_chain_step(joint, generator);
    time += drawn;
  }
  time += execution >= before ? execution - before : 0;
  return time <= deadline_ ? static_cast<Steps>(time) : kNever;
}

template <class S, class Generator>
Observation Mdp::sample_refinement(const S& state, int choice, Generator& generator) const {
  const int action = next_action(state, choice);
  if (action < 0) return Observation::not_yet();
  const Steps spent = state.spent[static_cast<std::size_t>(choice)];
  const double found = hazard(action, spent);
  const double u = uniform01(generator);
  if (!(u < found)) {
    // (Without backtracking this is the only draw of a step that finds nothing.)
    const double back = backtrack_hazard(action, spent);
    if (!(u < found + back)) return Observation::not_yet();
    const auto culprits = problem_->culprits(action);
    const std::size_t blamed = sample_index(
        culprits.size(), [&culprits](std::size_t i) { return culprits[i].probability; }, generator);
    return Observation::backtracked(culprits[blamed].action);
  }
  const auto& outcomes = execution_outcomes_[static_cast<std::size_t>(action)];
  const std::size_t drawn = sample_index(
      outcomes.size(), [&outcomes](std::size_t i) { return outcomes[i].probability; }, generator);
  return Observation::found(outcomes[drawn].steps);
}

inline std::int64_t Mdp::least_need(int k, int refined, std::uint16_t spent, std::uint16_t execution) const noexcept {
  const auto slot = static_cast<std::size_t>(k);
  if (refined >= lengths_[slot] || spent > deadline_) return kUnreachableNeed;
  const auto action = static_cast<std::size_t>(paths_[offsets_[slot] + static_cast<std::size_t>(refined)]);
  const Steps finish = next_finish_[action * static_cast<std::size_t>(deadline_ + 1) + spent];
  const Steps fastest = min_execution_[action];
  if (finish == kNever || fastest == kNever) return kUnreachableNeed;
  return std::int64_t{execution} + finish + fastest +
         rest_[offsets_[slot] + slot + static_cast<std::size_t>(refined) + 1];
}

template <class S>
std::int64_t Mdp::least_need_after_backtrack(const S& state, int k) const noexcept {
  const auto slot = static_cast<std::size_t>(k);
  const std::size_t base = offsets_[slot] + slot;
  std::int64_t least = kUnreachableNeed;
  // The refined actions of k's path (positions 0 .. refined - 1) that some action may blame.
  for (int l = 0; l < state.refined[slot]; ++l) {
    const int culprit_slot = slot_at_[base + static_cast<std::size_t>(l)];
    if (culprit_slot < 0) continue;
    least = std::min(least, 1 + std::int64_t{state.restore[static_cast<std::size_t>(culprit_slot)]} +
                                rest_[base + static_cast<std::size_t>(l)]);
  }
  return least;
}

template <class S>
bool Mdp::can_succeed(const S& state, int k) const noexcept {
  return std::int64_t{state.time} + least_need(state, k) <= deadline_;
}

template <class S>
bool Mdp::any_can_succeed(const S& state) const noexcept {
  for (int k = 0; k < skeleton_count_; ++k) {
    if (can_succeed(state, k)) return true;
  }
  return false;
}

template <class S>
int Mdp::first_with_work_left(const S& state) const noexcept {
  for (int k = 0; k < skeleton_count_; ++k) {
    if (next_action(state, k) >= 0) return k;
  }
  return 0;
}

template <class S>
bool Mdp::group_can_succeed(const S& state, int action) const noexcept {
  for (const int member : problem_->members(action)) {
    if (can_succeed(state, member)) return true;
  }
  return false;
}

template <class S>
ChoiceList Mdp::useful_choices(const S& state) const {
  ChoiceList choices;
  // With backtracking a step on a group that cannot succeed may still backtrack and restore an
  // action that other skeletons share; with chains or expiry (SPEC §9) such a step, or an idle
  // one, waits, which may be worth more than finishing a plan now (a door may open). Then every
  // group with work left is worth considering, and one idle choice if some skeleton has none.
  const bool timed = is_timed();
  const bool every_group = timed || has_backtracking();
  bool idle = timed;  // an idle choice is still to be offered
  for (int k = 0; k < skeleton_count_; ++k) {
    const int action = next_action(state, k);
    if (action < 0) {
      if (idle) choices.push_back(k);
      idle = false;
    } else if (problem_->members(action).front() == k && (every_group || group_can_succeed(state, action))) {
      choices.push_back(k);
    }
  }
  return choices;
}

template <class S>
Status Mdp::apply(S& state, int choice, const Observation& observation) const {
  if (choice < 0 || choice >= skeleton_count_) {
    reject_choice(choice);
  }
  const int action = next_action(state, choice);
  // Checked before the state changes, so that a rejected observation leaves it as it was.
  if (observation.refined && action < 0) {
    reject_idle_refinement(choice);
  }
  if (observation.refined && observation.execution < 0) {
    reject_execution(observation.execution);
  }
  if constexpr (kHoldsChains<S>) {
    if (has_chains() && observation.chains >= joint_count_) reject_chains(observation.chains);
  }
  if (observation.culprit >= 0) {
    // A backtrack: only on an action step, blaming one of that action's culprits.
    bool listed = false;
    if (action >= 0 && !observation.refined) {
      for (const Problem::CulpritIndex& culprit : problem_->culprits(action))
        listed |= culprit.action == observation.culprit;
    }
    if (!listed) reject_culprit(action, observation.culprit);
    if constexpr (kHoldsRestore<S>) {
      ++state.time;
      if constexpr (kHoldsChains<S>) {
        if (has_chains()) state.chains = observation.chains;  // they move whatever happens
      }
      backtrack(state, observation.culprit);
      if (state.time >= deadline_ || !any_can_succeed(state)) return Status::failure;
      return Status::running;
    } else {
      reject_culprit(action, observation.culprit);  // (a state type without restore values)
    }
  }
  ++state.time;
  if constexpr (kHoldsChains<S>) {
    if (has_chains()) state.chains = observation.chains;
  }
  // An idle step (action < 0) only spends time.
  if (action >= 0 && !observation.refined) {
    for (const int member : problem_->members(action)) {
      std::uint16_t& spent = state.spent[static_cast<std::size_t>(member)];
      if (spent <= deadline_) ++spent;
    }
  } else if (action >= 0) {
    // A chain-dependent execution is drawn when it starts (SPEC §9): none is added now.
    const Steps observed = is_timed() && problem_->execution_chain(action) >= 0 ? Steps{0} : observation.execution;
    const std::int64_t total = observed == kNever
                                   ? std::int64_t{deadline_} + 1
                                   : std::int64_t{state.execution[static_cast<std::size_t>(choice)]} + observed;
    const std::uint16_t execution = saturate_execution(total);
    if constexpr (kHoldsRestore<S>) {
      if (has_backtracking()) {
        const int culprit_slot = problem_->culprit_slot(action);
        if (culprit_slot >= 0) {
          state.restore[static_cast<std::size_t>(culprit_slot)] = state.execution[static_cast<std::size_t>(choice)];
        }
      }
    }
    if constexpr (kHoldsChains<S>) {
      if (is_timed()) {
        const int timed_slot = problem_->timed_slot(action);
        if (timed_slot >= 0) {
          state.restore[static_cast<std::size_t>(timed_slot)] = state.execution[static_cast<std::size_t>(choice)];
        }
      }
    }
    for (const int member : problem_->members(action)) {
      const auto slot = static_cast<std::size_t>(member);
      ++state.refined[slot];
      state.spent[slot] = 0;
      state.execution[slot] = execution;
    }
    if (problem_->completes_a_skeleton(action) && std::int64_t{state.time} + execution <= deadline_) {
      return Status::success;
    }
  }
  if (state.time >= deadline_ || !any_can_succeed(state)) return Status::failure;
  return Status::running;
}

template <class S>
void Mdp::backtrack(S& state, int culprit) const noexcept {
  static_assert(kHoldsRestore<S>, "a problem with backtracking needs a state type that holds its restore values");
  const int position = problem_->position(culprit);
  const auto culprit_slot = static_cast<std::size_t>(problem_->culprit_slot(culprit));  // a culprit has one
  const std::uint16_t restored = state.restore[culprit_slot];
  for (const int member : problem_->members(culprit)) {
    const auto slot = static_cast<std::size_t>(member);
    if (state.refined[slot] <= position) continue;
    state.refined[slot] = static_cast<std::uint8_t>(position);
    state.spent[slot] = 0;
    state.execution[slot] = restored;
  }
  for (const int below : slots_below_[culprit_slot]) state.restore[static_cast<std::size_t>(below)] = 0;
}

template <class S>
int Mdp::completed_skeleton(const S& state, int choice) const {
  const auto slot = static_cast<std::size_t>(choice);
  if (state.refined[slot] == 0) return -1;
  const int action = paths_[offsets_[slot] + state.refined[slot] - 1U];
  for (const int member : problem_->members(action)) {
    const auto index = static_cast<std::size_t>(member);
    if (state.refined[index] == lengths_[index]) return member;
  }
  return -1;
}

}  // namespace ontime
