#pragma once
// An effort-allocation problem (SPEC §1): a deadline, abstract actions with planning- and
// execution-time distributions, and plan skeletons that share actions along common prefixes.
//
// Skeletons that list the same action id share that action: it is refined once for all of
// them. Sharing follows a common prefix, so the skeletons form a prefix tree (trie) whose
// nodes are the used actions. A Problem is immutable once built and validated.

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ontime/model/distribution.hpp"

namespace ontime {

struct Action {
  std::string id;          // e.g. "move(R1,R5)"
  Distribution planning;   // steps of effort until refined, t >= 1
  Distribution execution;  // steps to execute the refined motion, x >= 0
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
  // that does not follow a common prefix, planning mass at step 0, too many skeletons).
  Problem(std::string name, Steps deadline, double step_seconds, std::vector<Action> actions,
          std::vector<std::vector<int>> skeletons, std::string description = {});

  const std::string& name() const noexcept { return name_; }
  const std::string& description() const noexcept { return description_; }
  Steps deadline() const noexcept { return deadline_; }
  double step_seconds() const noexcept { return step_seconds_; }

  std::span<const Action> actions() const noexcept { return actions_; }
  const Action& action(int index) const { return actions_.at(static_cast<std::size_t>(index)); }
  int action_count() const noexcept { return static_cast<int>(actions_.size()); }
  // Index of the action with this id, or -1.
  int find_action(std::string_view id) const noexcept;

  int skeleton_count() const noexcept { return static_cast<int>(skeletons_.size()); }
  std::span<const int> skeleton(int k) const { return skeletons_.at(static_cast<std::size_t>(k)); }
  int skeleton_length(int k) const { return static_cast<int>(skeleton(k).size()); }
  // The action at position l (0-based) of skeleton k.
  int action_at(int k, int l) const { return skeleton(k)[static_cast<std::size_t>(l)]; }

  // Prefix tree. Every action used by some skeleton is one node.
  // Skeletons whose path passes through the action, ascending (N(k, l) of Eq. (1)).
  std::span<const int> members(int action) const { return members_.at(static_cast<std::size_t>(action)); }
  // Position of the action in the skeletons that use it; -1 when no skeleton uses it.
  int position(int action) const { return position_.at(static_cast<std::size_t>(action)); }
  // The preceding action on the path from the root, or -1 for a first action.
  int parent(int action) const { return parent_.at(static_cast<std::size_t>(action)); }
  // True when some skeleton ends with this action (refining it may complete a plan).
  bool completes_a_skeleton(int action) const { return completes_.at(static_cast<std::size_t>(action)) != 0; }

  // The skeletons as lists of action indices (a copy, e.g. to build a changed problem).
  std::vector<std::vector<int>> skeleton_lists() const { return skeletons_; }
  // This problem (name, deadline, step, skeletons, description) with other actions, in the same
  // order: e.g. other distributions for the same ids. Throws UsageError as the constructor does.
  Problem with_actions(std::vector<Action> actions) const {
    return {name_, deadline_, step_seconds_, std::move(actions), skeletons_, description_};
  }

 private:
  std::string name_;
  std::string description_;
  Steps deadline_;
  double step_seconds_;
  std::vector<Action> actions_;
  std::vector<std::vector<int>> skeletons_;
  std::vector<std::vector<int>> members_;
  std::vector<int> position_;
  std::vector<int> parent_;
  std::vector<char> completes_;
};

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
