#pragma once
// Internal (layered solver): the outcomes of a state of the layered search, straight from its
// key. TreeTables holds, per action of the prefix tree, the skeletons a step on it touches;
// Successors<W> walks a state's useful choices and their outcomes in the order of
// Mdp::useful_choices and Mdp::for_each_outcome (the order the memoised solver sums them in),
// and builds each successor's key from the state's key: the chosen group's fields rewritten and
// the groups that cannot succeed any more blanked (with a tolerance, also the weak ones, their
// share noted); in a split, the step on the bounded subtrees too. The forward pass asks for the
// keys, the backward pass for the probabilities only, from the same walk.
//
// Cost: per state, O(groups) to find the groups, then O(skeletons through the chosen action)
// per outcome; no allocation once a walk's scratch has grown.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "solve/expectimax.hpp"
#include "solve/layered/keys.hpp"

namespace ontime::layered {

// Per action of the prefix tree, what a step on it touches, looked up once per search: the
// skeletons through it (its group when it is their next action), the child actions they move
// on to when it is refined, and those that end with it.
class TreeTables {
 public:
  struct Node {
    int rep = -1;  // lowest skeleton through it: the choice naming its group
    int position = 0;
    bool completes = false;
    std::uint32_t members_begin = 0, members_end = 0;    // in members()
    std::uint32_t children_begin = 0, children_end = 0;  // in children()
    std::uint32_t ending_begin = 0, ending_end = 0;      // in ending()
  };

  explicit TreeTables(const Problem& problem) : nodes_(static_cast<std::size_t>(problem.action_count())) {
    for (int a = 0; a < problem.action_count(); ++a) {
      Node& node = nodes_[static_cast<std::size_t>(a)];
      if (problem.position(a) < 0) continue;
      const std::span<const int> through = problem.members(a);
      node.rep = through.front();
      node.position = problem.position(a);
      node.completes = problem.completes_a_skeleton(a);
      node.members_begin = static_cast<std::uint32_t>(members_.size());
      members_.insert(members_.end(), through.begin(), through.end());
      node.members_end = static_cast<std::uint32_t>(members_.size());
      node.children_begin = static_cast<std::uint32_t>(children_.size());
      node.ending_begin = static_cast<std::uint32_t>(ending_.size());
      for (const int k : through) {
        if (node.position + 1 >= problem.skeleton_length(k)) {
          ending_.push_back(k);
          continue;
        }
        const int child = problem.action_at(k, node.position + 1);
        if (problem.members(child).front() == k) children_.push_back(child);
      }
      node.children_end = static_cast<std::uint32_t>(children_.size());
      node.ending_end = static_cast<std::uint32_t>(ending_.size());
    }
  }

  const Node& node(int action) const noexcept { return nodes_[static_cast<std::size_t>(action)]; }
  std::span<const int> members(const Node& node) const noexcept {
    return {members_.data() + node.members_begin, node.members_end - node.members_begin};
  }
  std::span<const int> children(const Node& node) const noexcept {
    return {children_.data() + node.children_begin, node.children_end - node.children_begin};
  }
  std::span<const int> ending(const Node& node) const noexcept {
    return {ending_.data() + node.ending_begin, node.ending_end - node.ending_begin};
  }

 private:
  std::vector<Node> nodes_;
  std::vector<int> members_, children_, ending_;
};

// The outcomes of every useful choice of a state, in the order of Mdp::useful_choices and
// Mdp::for_each_outcome, with the successors' keys built from the state's key: a successor
// differs in the chosen group's fields and in groups that cannot succeed any more at the next
// step (blanked, as detail::blank_hopeless does); with a tolerance, groups whose clairvoyant
// chance is below it are blanked too, their share noted. In a split, unflagged states have one
// more choice, a step on the bounded subtrees: its outcome is the same state one layer on,
// flagged. One walk serves both passes: the backward pass asks only for the probabilities.
//
// Groups are found from the skeletons that are not blanked: a blanked slot (refined 0) would
// name the first action, shared with skeletons elsewhere in the tree that are still alive.
//
// With backtracking (SPEC §7) a key holds the whole state with its restore values and nothing
// is blanked (a step on a group that cannot succeed may still backtrack and restore an action
// others share), so the walk decodes the state and takes the MDP's own outcomes
// (Mdp::useful_choices, Mdp::for_each_outcome), exactly the memoised solver's. The same with
// chains or expiry (SPEC §9), whose keys hold the timed slots and the chains' joint state too
// (a step that cannot finish a plan may still wait for a chain), and whose successes are worth
// the MDP's expected reward over the chains' paths (Mdp::success_reward). Neither a tolerance
// nor a split is taken there (solve_layered refuses them).
template <std::size_t W>
class Successors {
 public:
  using Key = PackedState<W>;
  using Node = TreeTables::Node;

  struct Outcome {
    int choice = 0;  // a skeleton (the group's lowest index) or kWeakChoice
    double probability = 0;
    Status status = Status::running;
    Key key;              // running only
    bool extras = false;  // a tolerance dropped groups: the share below
    double factor = 1;    // product of (1 - G) over the dropped groups
    double boost = 0;     // best commit value among them
    double reward = 1;    // success only: the completed skeleton's reward (SPEC §8)
  };

  Successors(const Mdp& mdp, const TreeTables& tree, const KeyLayout& layout, const ValueBounds* bounds,
             double tolerance, bool split)
      : mdp_(&mdp),
        tree_(&tree),
        layout_(&layout),
        bounds_(bounds),
        tolerance_(tolerance),
        split_(split),
        deadline_(mdp.deadline()),
        skeletons_(mdp.skeleton_count()),
        backtracking_(mdp.has_backtracking()),
        timed_(mdp.is_timed()) {}

  // Calls sink(outcome) for every outcome, with keys (forward).
  template <class Sink>
  void expand(const Key& key, int t, Sink&& sink) {
    walk<true>(key, t, sink);
  }
  // The bytes of the plan tables the successes' rewards came from so far (chains or expiry).
  std::uint64_t plan_bytes() const noexcept { return plans_.bytes(); }
  // Calls sink(outcome) for every outcome, with its choice and probability only, in the same
  // order (backward).
  template <class Sink>
  void probabilities(const Key& key, int t, Sink&& sink) {
    walk<false>(key, t, sink);
  }

  // The start, blanked as a successor is, and reduced by the tolerance with its own share.
  Outcome start() {
    if (timed_) {
      Outcome outcome;
      outcome.key = layout_->encode<W>(detail::compact<detail::CompactTimedState>(
          mdp_->start(), skeletons_, detail::recorded_slots(mdp_->problem())));
      return outcome;
    }
    if (backtracking_) {
      Outcome outcome;
      outcome.key = layout_->encode<W>(detail::compact<detail::CompactBacktrackState>(
          mdp_->start(), skeletons_, mdp_->problem().culprit_slot_count()));
      return outcome;
    }
    CompactState state = detail::compact(mdp_->start(), skeletons_);
    detail::blank_hopeless(*mdp_, state);
    Outcome outcome;
    outcome.key = layout_->encode<W>(state);
    if (tolerance_ > 0) {
      find_groups(state);
      for (const Group& group : groups_) {
        if (!tolerated(group, group.spent, group.execution, 0)) continue;
        drop(outcome, group.node, group.refined, group.spent, group.execution, 0);
        clear_members(outcome.key, *group.node);
        blank_members(outcome.key, *group.node);
      }
    }
    return outcome;
  }

 private:
  struct Group {
    const Node* node;  // the next action its members share
    int action;
    int refined;
    std::uint16_t spent, execution;
  };

  void find_groups(const CompactState& state) {
    groups_.clear();
    for (int k = 0; k < skeletons_; ++k) {
      const auto slot = static_cast<std::size_t>(k);
      if (state.spent[slot] == detail::kBlankCounter) continue;
      const int action = mdp_->next_action(state, k);
      if (action < 0) continue;
      const Node& node = tree_->node(action);
      if (node.rep != k) continue;
      groups_.push_back({&node, action, state.refined[slot], state.spent[slot], state.execution[slot]});
    }
  }

  bool tolerated(const Group& group, std::uint16_t spent, std::uint16_t execution, std::int64_t time) const {
    return tolerance_ > 0 && bounds_->group_upper(group.node->rep, group.refined, spent, execution, time) < tolerance_;
  }
  bool tolerated(const Node& node, int refined, std::uint16_t spent, std::uint16_t execution, std::int64_t time) const {
    return tolerance_ > 0 && bounds_->group_upper(node.rep, refined, spent, execution, time) < tolerance_;
  }

  // Notes the share of a group dropped at `time` in the outcome.
  void drop(Outcome& outcome, const Node* node, int refined, std::uint16_t spent, std::uint16_t execution,
            std::int64_t time) const {
    outcome.extras = true;
    outcome.factor *= 1.0 - bounds_->group_upper(node->rep, refined, spent, execution, time);
    for (const int member : tree_->members(*node)) {
      outcome.boost = std::max(outcome.boost, bounds_->commit(member, refined, spent, execution, time));
    }
  }

  void set_members(Key& key, const Node& node, int refined, std::uint16_t spent, std::uint16_t execution) const {
    for (const int member : tree_->members(node)) {
      key.words[static_cast<std::size_t>(layout_->word(member))] |= layout_->value(member, refined, spent, execution);
    }
  }
  void blank_members(Key& key, const Node& node) const {
    for (const int member : tree_->members(node)) {
      key.words[static_cast<std::size_t>(layout_->word(member))] |= layout_->blank(member);
    }
  }
  void clear_members(Key& key, const Node& node) const {
    for (const int member : tree_->members(node)) {
      key.words[static_cast<std::size_t>(layout_->word(member))] &= ~layout_->mask(member);
    }
  }

  // With backtracking, chains or expiry: the MDP's outcomes of the decoded state (`scratch`,
  // of the state type that holds what the key holds), in its order (the backward pass takes
  // the observations' probabilities without applying them).
  template <bool kKeys, class Compact, class Sink>
  void walk_whole(const Key& key, int t, Compact& scratch, Sink& sink) {
    layout_->decode(key, t, scratch);
    for (const int choice : mdp_->useful_choices(scratch)) {
      if constexpr (kKeys) {
        mdp_->for_each_outcome(scratch, choice, [&](double probability, Status status, const Compact& next) {
          Outcome outcome;
          outcome.choice = choice;
          outcome.probability = probability;
          outcome.status = status;
          if (status == Status::running) outcome.key = layout_->encode<W>(next);
          if (status == Status::success) outcome.reward = success_reward(next, choice);
          sink(static_cast<const Outcome&>(outcome));
        });
      } else {
        mdp_->for_each_observation(scratch, choice, [&](double probability, const Observation&) {
          Outcome outcome;
          outcome.choice = choice;
          outcome.probability = probability;
          sink(static_cast<const Outcome&>(outcome));
        });
      }
    }
  }

  template <class Compact>
  double success_reward(const Compact& state, int choice) {
    if constexpr (kHoldsChains<Compact>) {
      return plans_.reward(*mdp_, state, choice);
    } else {
      return mdp_->success_reward(state, choice);
    }
  }

  template <bool kKeys, class Sink>
  void walk(const Key& key, int t, Sink& sink) {
    if (timed_) {
      walk_whole<kKeys>(key, t, timed_state_, sink);
      return;
    }
    if (backtracking_) {
      walk_whole<kKeys>(key, t, back_state_, sink);
      return;
    }
    layout_->decode(key, t, state_);
    const bool flagged = layout_->flagged(key);
    find_groups(state_);
    const std::int64_t next_time = t + 1;
    const std::int64_t room = std::int64_t{deadline_} - next_time;  // a group needing more is hopeless
    // Per group: alive at the next step (the MDP's test), and kept (alive and not dropped).
    Key base;
    int alive_count = 0;
    if constexpr (kKeys) {
      alive_.assign(groups_.size(), 0);
      kept_.assign(groups_.size(), 0);
      base = key;  // a flagged state's successors stay flagged
      for (std::size_t g = 0; g < groups_.size(); ++g) {
        const Group& group = groups_[g];
        alive_[g] = mdp_->group_need(group.action, group.spent, group.execution) <= room;
        alive_count += alive_[g];
        kept_[g] = alive_[g] && !tolerated(group, group.spent, group.execution, next_time);
        if (!kept_[g]) {
          clear_members(base, *group.node);
          blank_members(base, *group.node);
        }
      }
    }
    for (std::size_t g = 0; g < groups_.size(); ++g) {
      const Group& group = groups_[g];
      const double found = mdp_->hazard(group.action, group.spent);
      Outcome shared;  // what this choice's outcomes have in common: the other groups
      shared.choice = group.node->rep;
      bool others_alive = false, others_kept = false;
      if constexpr (kKeys) {
        shared.key = base;
        clear_members(shared.key, *group.node);
        others_alive = alive_count - alive_[g] > 0;
        for (std::size_t h = 0; h < groups_.size(); ++h) {
          if (h == g || !alive_[h]) continue;
          if (kept_[h]) {
            others_kept = true;
          } else {
            const Group& other = groups_[h];
            drop(shared, other.node, other.refined, other.spent, other.execution, next_time);
          }
        }
      }
      if (found < 1.0) {
        Outcome outcome = shared;
        outcome.probability = 1.0 - found;
        if constexpr (kKeys) missed_outcome(outcome, group, others_alive, others_kept, next_time);
        sink(static_cast<const Outcome&>(outcome));
      }
      if (found > 0.0) {
        for (const Mdp::ExecutionOutcome& execution : mdp_->execution_outcomes(group.action)) {
          Outcome outcome = shared;
          outcome.probability = found * execution.probability;
          if constexpr (kKeys) found_outcome(outcome, group, execution.steps, others_alive, others_kept, next_time);
          sink(static_cast<const Outcome&>(outcome));
        }
      }
    }
    if (split_ && !flagged) {
      Outcome outcome;
      outcome.choice = kWeakChoice;
      outcome.probability = 1.0;
      if constexpr (kKeys) {
        outcome.key = base;
        layout_->set_flag(outcome.key, true);
        bool any_kept = false;
        for (std::size_t h = 0; h < groups_.size(); ++h) {
          if (!alive_[h]) continue;
          if (kept_[h]) {
            any_kept = true;
          } else {
            const Group& other = groups_[h];
            drop(outcome, other.node, other.refined, other.spent, other.execution, next_time);
          }
        }
        finish_running(outcome, alive_count > 0, next_time);
        if (outcome.status == Status::running && !any_kept) outcome.status = Status::failure;
      }
      sink(static_cast<const Outcome&>(outcome));
    }
  }

  // The MDP's own end of an outcome that did not succeed: out of time, or nothing alive.
  void finish_running(Outcome& outcome, bool anything_alive, std::int64_t next_time) const {
    outcome.status = next_time >= deadline_ || !anything_alive ? Status::failure : Status::running;
  }

  // The chosen group's step finds nothing: its PT grows by one.
  void missed_outcome(Outcome& outcome, const Group& group, bool others_alive, bool others_kept,
                      std::int64_t next_time) const {
    const auto spent = static_cast<std::uint16_t>(group.spent + 1);
    const bool alive = mdp_->group_need(group.action, spent, group.execution) <= std::int64_t{deadline_} - next_time;
    finish_running(outcome, alive || others_alive, next_time);
    if (outcome.status != Status::running) return;
    const bool kept = alive && !tolerated(group, spent, group.execution, next_time);
    if (kept) {
      set_members(outcome.key, *group.node, group.refined, spent, group.execution);
    } else {
      blank_members(outcome.key, *group.node);
      if (alive) drop(outcome, group.node, group.refined, spent, group.execution, next_time);
    }
    if (!kept && !others_kept) outcome.status = Status::failure;
  }

  // The chosen group's motion is found with `steps` of execution (deadline + 1: too slow).
  void found_outcome(Outcome& outcome, const Group& group, Steps steps, bool others_alive, bool others_kept,
                     std::int64_t next_time) const {
    const std::int64_t total = std::int64_t{group.execution} + steps;
    const auto execution = static_cast<std::uint16_t>(total > deadline_ ? deadline_ + 1 : total);
    const Node& node = *group.node;
    if (node.completes && next_time + execution <= deadline_) {
      outcome.status = Status::success;
      outcome.extras = false;
      // The one skeleton ending at this node (two ending at the same node would be the same path).
      const Problem& problem = mdp_->problem();
      outcome.reward = problem.has_rewards()
                           ? problem.reward_at(tree_->ending(node).front(), static_cast<Steps>(next_time + execution))
                           : 1.0;
      return;
    }
    const std::int64_t room = std::int64_t{deadline_} - next_time;
    const int refined = group.refined + 1;
    // The members move on to the child actions, or end here (too slow: blanked).
    for (const int member : tree_->ending(node)) {
      outcome.key.words[static_cast<std::size_t>(layout_->word(member))] |= layout_->blank(member);
    }
    bool alive_any = false, kept_any = false;
    for (const int child : tree_->children(node)) {
      const Node& next = tree_->node(child);
      const bool alive = mdp_->group_need(child, 0, execution) <= room;
      const bool kept = alive && !tolerated(next, refined, 0, execution, next_time);
      alive_any = alive_any || alive;
      kept_any = kept_any || kept;
      if (kept) {
        set_members(outcome.key, next, refined, 0, execution);
      } else {
        blank_members(outcome.key, next);
        if (alive) drop(outcome, &next, refined, 0, execution, next_time);
      }
    }
    finish_running(outcome, alive_any || others_alive, next_time);
    if (outcome.status == Status::running && !kept_any && !others_kept) outcome.status = Status::failure;
  }

  const Mdp* mdp_;
  const TreeTables* tree_;
  const KeyLayout* layout_;
  const ValueBounds* bounds_;
  double tolerance_;
  bool split_;
  Steps deadline_;
  int skeletons_;
  bool backtracking_;
  bool timed_;
  // Scratch of one walk, kept to avoid allocation per state.
  CompactState state_;
  detail::CompactBacktrackState back_state_;
  detail::CompactTimedState timed_state_;
  detail::PlanValues plans_;  // with chains or expiry: the successes' rewards
  std::vector<Group> groups_;
  std::vector<char> alive_, kept_;
};

}  // namespace ontime::layered
