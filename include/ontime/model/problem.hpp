#pragma once
// An effort-allocation problem (SPEC §1): a deadline, abstract actions with planning- and
// execution-time distributions, and plan skeletons that share actions along common prefixes.
//
// Skeletons that list the same action id share that action: it is refined once for all of
// them. Sharing follows a common prefix, so the skeletons form a prefix tree (trie) whose
// nodes are the used actions. An action may backtrack (SPEC §7): an attempt that gives up
// blames an action before it on its path, whose motion and everything refined after it are
// discarded. A Problem is immutable once built and validated.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ontime/model/distribution.hpp"
#include "ontime/model/exogenous_chain.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

// When the robot may execute refined actions (SPEC §10). plan_first, the paper's premise and the
// default: a skeleton is executed once every one of its actions is refined. concurrent: the robot
// executes refined actions while the planner refines the rest, and chooses when to start each one.
enum class Acting : std::uint8_t { plan_first, concurrent };
// The mode's name in instances and on the command line: "plan-first" or "concurrent".
std::string_view acting_name(Acting acting) noexcept;
// The mode named `name`, or nullopt for any other text.
std::optional<Acting> parse_acting(std::string_view name) noexcept;

// An earlier action an attempt that backtracks blames (SPEC §7), with its probability.
struct Culprit {
  std::string id;
  double probability = 0;
};

struct Action {
  Action() = default;
  // (A constructor rather than an aggregate, so that the many actions built without backtracking
  // name just their id and distributions.)
  Action(std::string action_id, Distribution planning_time, Distribution execution_time,
         Distribution backtrack_time = {}, std::vector<Culprit> blamed = {})
      : id(std::move(action_id)),
        planning(std::move(planning_time)),
        execution(std::move(execution_time)),
        backtrack(std::move(backtrack_time)),
        culprits(std::move(blamed)) {}

  std::string id;          // e.g. "move(R1,R5)"
  Distribution planning;   // steps of effort until refined, t >= 1
  Distribution execution;  // steps to execute the refined motion, x >= 0
  // Backtracking (SPEC §7), optional: backtrack(t) is the probability that an attempt gives up
  // after t steps and blames an earlier choice (its mass is the chance of backtracking at all;
  // planning and backtrack masses sum to at most 1), and `culprits` which action on the path
  // before it is blamed (probabilities summing to 1). All "never" and no culprits: the attempt
  // never backtracks, as in SPEC §2.
  Distribution backtrack;
  std::vector<Culprit> culprits;
  // Exogenous chains (SPEC §9), optional. The execution time drawn when the action's execution
  // starts, from `execution_by_state[s]` with s the state of the chain named `execution_chain` at
  // that moment (empty name: `execution`, drawn when the motion is found, as in SPEC §2).
  std::string execution_chain;
  std::vector<Distribution> execution_by_state;
  // Expiry: the execution cannot start after step `start_by` (kNever: no such limit), nor while
  // the chain named `blocking_chain` is in one of `blocking_states` (names); a plan that reaches
  // an action it cannot start fails.
  Steps start_by = kNever;
  std::string blocking_chain;
  std::vector<std::string> blocking_states;

  // Whether the action's execution depends on when it starts (a chain or an expiry).
  bool is_timed() const noexcept { return !execution_chain.empty() || start_by != kNever || !blocking_chain.empty(); }
};

// A broken chain rule of SPEC §9 in a Problem being built: the chain named, or the action and
// which of its fields ("execution", "expires"), and the rule. A UsageError like the other rules;
// instance files map it to its JSON place.
class ChainRuleError : public UsageError {
 public:
  // Message "chain 'c': rule", or "action 'a', field: rule" when `action` is not empty.
  ChainRuleError(std::string chain, std::string action, std::string field, const std::string& rule)
      : UsageError((action.empty() ? "chain '" + chain + "'" : "action '" + action + "', " + field) + ": " + rule),
        chain_(std::move(chain)),
        action_(std::move(action)),
        field_(std::move(field)),
        rule_(rule) {}
  // The chain named (empty when the rule is an action's).
  const std::string& chain() const noexcept { return chain_; }
  // The action's id; empty: the rule is the chain's.
  const std::string& action() const noexcept { return action_; }
  // The action's field the rule is about ("execution", "expires"); empty for a chain's rule.
  const std::string& field() const noexcept { return field_; }
  // The rule broken, as text.
  const std::string& rule() const noexcept { return rule_; }

 private:
  std::string chain_, action_, field_, rule_;
};

// What succeeding with a plan skeleton is worth (SPEC §8): `value` if its execution ended at step 0,
// falling by `per_step` for every step of the finish time f = CT + ET (the step its execution ends,
// at most the deadline): value - per_step * f. The default, 1 at every finish, makes the objective
// the success probability of SPEC §2; with per_step 0 the reward is `value` exactly, whatever f.
// A Problem keeps every reward within [0, 1] at every finish up to its deadline.
struct SkeletonReward {
  double value = 1.0;
  double per_step = 0.0;

  // (A real finish: a live session's plan ends between steps.)
  double at(double finish) const noexcept { return value - per_step * finish; }
  bool is_unit() const noexcept { return value == 1.0 && per_step == 0.0; }
  friend bool operator==(const SkeletonReward&, const SkeletonReward&) = default;
};

// A broken reward rule of SPEC §8 in a Problem being built: the skeleton's index and the rule.
// A UsageError like the other rules; instance files map it to its JSON place.
class RewardError : public UsageError {
 public:
  // Message "skeleton k's reward: rule".
  RewardError(int skeleton, const std::string& rule)
      : UsageError("skeleton " + std::to_string(skeleton) + "'s reward: " + rule), skeleton_(skeleton), rule_(rule) {}
  // The index of the skeleton whose reward breaks the rule.
  int skeleton() const noexcept { return skeleton_; }
  // The rule broken, as text.
  const std::string& rule() const noexcept { return rule_; }

 private:
  int skeleton_;
  std::string rule_;
};

// A broken backtracking rule of SPEC §7 in a Problem being built: the action, the culprit named
// (empty when the rule is about the action's backtrack distribution) and the rule. A UsageError,
// so that code building problems catches it as any; instance files map it to its JSON place.
class BacktrackingError : public UsageError {
 public:
  // Message "action 'a', culprit 'c': rule" (without the culprit when it is empty).
  BacktrackingError(std::string action, std::string culprit, const std::string& rule)
      : UsageError("action '" + action + "'" + (culprit.empty() ? "" : ", culprit '" + culprit + "'") + ": " + rule),
        action_(std::move(action)),
        culprit_(std::move(culprit)),
        rule_(rule) {}
  // The id of the action whose backtracking breaks the rule.
  const std::string& action() const noexcept { return action_; }
  // The id of the culprit named; empty when the rule is about the backtrack distribution.
  const std::string& culprit() const noexcept { return culprit_; }
  // The rule broken, as text.
  const std::string& rule() const noexcept { return rule_; }

 private:
  std::string action_, culprit_, rule_;
};

class Problem {
 public:
  static constexpr Steps kMaxDeadline = 10'000;
  // Skeleton indices are stored in 16 bits (choice lists, search trees); the exact solver
  // takes far fewer (kMaxExactSkeletons in state.hpp).
  static constexpr int kMaxSkeletons = 65'535;
  static constexpr int kMaxSkeletonLength = 255;  // l_k is stored in 8 bits

  // skeletons[k] lists indices into `actions`. Throws UsageError when a rule of
  // SPEC §1 is broken (bad deadline, empty or repeating skeleton, duplicate skeleton, sharing
  // that does not follow a common prefix, planning mass at step 0, too many skeletons),
  // BacktrackingError for a broken rule of SPEC §7 (backtrack mass at step 0 or with planning
  // above 1, culprits that are not before the action on its path, probabilities outside [0, 1]
  // or not summing to 1, culprits without backtracking or backtracking without culprits), and
  // RewardError for a broken rule of SPEC §8, ChainRuleError for one of SPEC §9. `rewards` has one entry per skeleton,
  // or none: 1 for every skeleton.
  Problem(std::string name, Steps deadline, double step_seconds, std::vector<Action> actions,
          std::vector<std::vector<int>> skeletons, std::string description = {},
          std::vector<SkeletonReward> rewards = {}, std::vector<ExogenousChain> chains = {});

  // The instance's name.
  const std::string& name() const noexcept { return name_; }
  // Free text about the instance; may be empty.
  const std::string& description() const noexcept { return description_; }
  // The deadline D in steps, 1 to kMaxDeadline.
  Steps deadline() const noexcept { return deadline_; }
  // The duration of one step in seconds.
  double step_seconds() const noexcept { return step_seconds_; }

  // Every action, indexed as the skeletons index them.
  std::span<const Action> actions() const noexcept { return actions_; }
  // The action at `index`; throws std::out_of_range outside [0, action_count()).
  const Action& action(int index) const { return actions_.at(static_cast<std::size_t>(index)); }
  // How many actions, used by skeletons or not.
  int action_count() const noexcept { return static_cast<int>(actions_.size()); }
  // Index of the action with this id, or -1.
  int find_action(std::string_view id) const noexcept;

  // How many skeletons, K.
  int skeleton_count() const noexcept { return static_cast<int>(skeletons_.size()); }
  // Skeleton k as action indices, first to last; throws std::out_of_range outside [0, K).
  std::span<const int> skeleton(int k) const { return skeletons_.at(static_cast<std::size_t>(k)); }
  // The number of actions of skeleton k, l_k.
  int skeleton_length(int k) const { return static_cast<int>(skeleton(k).size()); }
  // The action at position l (0-based) of skeleton k.
  int action_at(int k, int l) const { return skeleton(k)[static_cast<std::size_t>(l)]; }

  // Rewards (SPEC §8). Whether some skeleton's reward is not 1 at every finish (the objective is
  // then the expected reward, else the success probability); skeleton k's reward; its value when
  // its execution ends at step `finish`; the largest reward any skeleton can earn.
  bool has_rewards() const noexcept { return has_rewards_; }
  std::span<const SkeletonReward> rewards() const noexcept { return rewards_; }
  const SkeletonReward& reward(int k) const { return rewards_.at(static_cast<std::size_t>(k)); }
  double reward_at(int k, Steps finish) const { return reward(k).at(static_cast<double>(finish)); }
  double max_reward() const noexcept { return max_reward_; }

  // Exogenous chains (SPEC §9): the chains, whether there are any; the index of the chain an
  // action's execution depends on (-1: none), of the chain that may block it (-1: none) and
  // whether state s of that chain blocks it.
  std::span<const ExogenousChain> chains() const noexcept { return chains_; }
  bool has_chains() const noexcept { return !chains_.empty(); }
  int execution_chain(int action) const { return execution_chain_.at(static_cast<std::size_t>(action)); }
  int blocking_chain(int action) const { return blocking_chain_.at(static_cast<std::size_t>(action)); }
  bool blocks(int action, int state) const {
    return blocking_.at(static_cast<std::size_t>(action)).at(static_cast<std::size_t>(state)) != 0;
  }
  // Whether the problem has chains or timed actions (Action::is_timed): its plans' values depend
  // on when their actions start. The slot of a timed action (State::restore holds the static
  // execution before it on its path there; the timed slots follow the culprit slots), or -1; how
  // many such slots.
  bool is_timed() const noexcept { return has_chains() || timed_slots_ > 0; }
  int timed_slot(int action) const { return timed_slot_.at(static_cast<std::size_t>(action)); }
  int timed_slot_count() const noexcept { return timed_slots_; }

  // Prefix tree. Every action used by some skeleton is one node.
  // Skeletons whose path passes through the action, ascending (N(k, l) of Eq. (1)).
  std::span<const int> members(int action) const { return members_.at(static_cast<std::size_t>(action)); }
  // Position of the action in the skeletons that use it; -1 when no skeleton uses it.
  int position(int action) const { return position_.at(static_cast<std::size_t>(action)); }
  // The preceding action on the path from the root, or -1 for a first action.
  int parent(int action) const { return parent_.at(static_cast<std::size_t>(action)); }
  // True when some skeleton ends with this action (refining it may complete a plan).
  bool completes_a_skeleton(int action) const { return completes_.at(static_cast<std::size_t>(action)) != 0; }

  // Backtracking (SPEC §7). Whether some action may backtrack; an action's culprits as action
  // indices with their probabilities; the slot of an action that is some action's culprit
  // (State::restore holds the execution before it there), or -1; how many such slots.
  struct CulpritIndex {
    int action;
    double probability;
  };
  // Whether some action may backtrack (some action is a culprit).
  bool has_backtracking() const noexcept { return culprit_slots_ > 0; }
  // The culprits `action` blames when it backtracks; empty when it never does.
  std::span<const CulpritIndex> culprits(int action) const {
    return culprit_indices_.at(static_cast<std::size_t>(action));
  }
  // The slot of `action` in State::restore, or -1 when it is no action's culprit.
  int culprit_slot(int action) const { return culprit_slot_.at(static_cast<std::size_t>(action)); }
  // How many culprit slots (actions some action blames).
  int culprit_slot_count() const noexcept { return culprit_slots_; }

  // The skeletons as lists of action indices (a copy, e.g. to build a changed problem).
  std::vector<std::vector<int>> skeleton_lists() const { return skeletons_; }
  // When the robot may execute refined actions (SPEC §10): the instance's "acting", plan-first by
  // default. Every solver, allocator and session built on Mdp takes plan-first problems only
  // (Mdp's constructor refuses the other mode); ConcurrentMdp models concurrent ones.
  Acting acting() const noexcept { return acting_; }
  // This problem with another acting mode, everything else kept.
  Problem with_acting(Acting acting) const {
    Problem copy = *this;
    copy.acting_ = acting;
    return copy;
  }
  // This problem (name, deadline, step, skeletons, description, rewards, chains) with other actions, in
  // the same order: e.g. other distributions for the same ids. Throws UsageError as the
  // constructor does.
  Problem with_actions(std::vector<Action> actions) const {
    Problem copy{name_, deadline_, step_seconds_, std::move(actions), skeletons_, description_, rewards_, chains_};
    copy.acting_ = acting_;
    return copy;
  }
  // This problem with other rewards (SPEC §8; none: 1 for every skeleton), its chains kept. Throws
  // RewardError or UsageError as the constructor does.
  Problem with_rewards(std::vector<SkeletonReward> rewards) const {
    Problem copy{name_, deadline_, step_seconds_, actions_, skeletons_, description_, std::move(rewards), chains_};
    copy.acting_ = acting_;
    return copy;
  }

 private:
  std::string name_;
  std::string description_;
  Steps deadline_;
  double step_seconds_;
  std::vector<Action> actions_;
  std::vector<std::vector<int>> skeletons_;
  std::vector<SkeletonReward> rewards_;
  std::vector<ExogenousChain> chains_;
  Acting acting_ = Acting::plan_first;
  std::vector<int> execution_chain_;
  std::vector<int> blocking_chain_;
  std::vector<std::vector<char>> blocking_;
  std::vector<int> timed_slot_;
  int timed_slots_ = 0;
  bool has_rewards_ = false;
  double max_reward_ = 1.0;
  std::vector<std::vector<int>> members_;
  std::vector<int> position_;
  std::vector<int> parent_;
  std::vector<char> completes_;
  std::vector<std::vector<CulpritIndex>> culprit_indices_;
  std::vector<int> culprit_slot_;
  int culprit_slots_ = 0;

  void index_culprits();
  void check_rewards();
  void index_chains();
};

// How one attempt to refine `action` ends (SPEC §7: a motion and a backtrack as competing risks),
// given `spent` steps of it that ended neither way: at the first step t > spent where P(motion by
// t) + P(backtrack by t), the motion counted first at its step, passes the mass already ended
// plus u times the rest (u uniform in [0, 1)). {kNever, false} when no step up to `last` does.
// The one draw of an attempt: the hidden world, sampled logs and Thompson sampling use it.
struct AttemptEnd {
  Steps step = kNever;
  bool found = false;  // a motion; else the attempt backtracked
};
// The end of one attempt at `action` as above, for the uniform draw `u` in [0, 1).
AttemptEnd draw_attempt_end(const Action& action, double u, Steps spent = 0, Steps last = kNever);

// The earlier action an attempt at `action` that backtracks blames, drawn with the culprits'
// probabilities.
template <class Generator>
int draw_culprit(const Problem& problem, int action, Generator& generator) {
  const auto culprits = problem.culprits(action);
  return culprits[sample_index(
                      culprits.size(), [&culprits](std::size_t i) { return culprits[i].probability; }, generator)]
      .action;
}

// The action an id names in the world: the id without a trailing "#n" (one or more digits). A
// skeletons' prefix tree holds an action reached under another prefix as a node of its own,
// "move(R8,R9)#2" (the streaming TAMP loop and generated buildings name it so); it is the same
// action, with the same distributions, features and refinement. An id without such a suffix is
// its own base.
std::string_view action_base_id(std::string_view id) noexcept;

// `structure` (its name, skeletons, deadline and step) with every action's distributions taken
// from the action of the same id in `distributions` (failing that, of the same action_base_id): the instance an
// allocator plans with when its beliefs differ from the world's (a prediction, a pooled fit, a posterior), in the state
// layout of `structure`, so that its decisions can be scored in the true instance. Throws
// UsageError naming the first action `distributions` lacks, or a deadline or step that differs.
Problem with_distributions_of(const Problem& structure, const Problem& distributions);

}  // namespace ontime
