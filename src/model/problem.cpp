#include "ontime/model/problem.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

[[noreturn]] void reject(const std::string& rule) { throw UsageError(rule); }

}  // namespace

Problem::Problem(std::string name, Steps deadline, double step_seconds, std::vector<Action> actions,
                 std::vector<std::vector<int>> skeletons, std::string description, std::vector<SkeletonReward> rewards,
                 std::vector<ExogenousChain> chains)
    : name_(std::move(name)),
      description_(std::move(description)),
      deadline_(deadline),
      step_seconds_(step_seconds),
      actions_(std::move(actions)),
      skeletons_(std::move(skeletons)),
      rewards_(std::move(rewards)),
      chains_(std::move(chains)) {
  if (deadline_ < 1 || deadline_ > kMaxDeadline) {
    reject("deadline must be between 1 and " + std::to_string(kMaxDeadline) + " steps");
  }
  if (!(std::isfinite(step_seconds_) && step_seconds_ > 0)) reject("step_seconds must be positive");
  if (skeletons_.empty()) reject("at least one skeleton is needed");
  if (skeletons_.size() > static_cast<std::size_t>(kMaxSkeletons)) {
    reject("at most " + std::to_string(kMaxSkeletons) + " skeletons are supported");
  }
  std::set<std::string> ids;
  for (const Action& action : actions_) {
    if (action.id.empty()) reject("action ids must be non-empty");
    if (!ids.insert(action.id).second) reject("action id '" + action.id + "' is listed twice");
    if (action.planning.pmf(0) > 0) reject("action '" + action.id + "': planning steps start at 1");
  }

  const std::size_t count = actions_.size();
  members_.assign(count, {});
  position_.assign(count, -1);
  parent_.assign(count, -1);
  completes_.assign(count, 0);
  std::set<std::vector<int>> distinct;
  for (std::size_t k = 0; k < skeletons_.size(); ++k) {
    const std::vector<int>& path = skeletons_[k];
    if (path.empty()) reject("skeleton " + std::to_string(k) + " is empty");
    if (path.size() > static_cast<std::size_t>(kMaxSkeletonLength)) {
      reject("skeleton " + std::to_string(k) + " is longer than " + std::to_string(kMaxSkeletonLength));
    }
    if (!distinct.insert(path).second) reject("skeleton " + std::to_string(k) + " is listed twice");
    std::set<int> seen;
    for (std::size_t l = 0; l < path.size(); ++l) {
      const int action = path[l];
      if (action < 0 || static_cast<std::size_t>(action) >= count) {
        reject("skeleton " + std::to_string(k) + " names an unknown action");
      }
      if (!seen.insert(action).second) {
        reject("skeleton " + std::to_string(k) + " repeats action '" + actions_[static_cast<std::size_t>(action)].id +
               "'");
      }
      const auto slot = static_cast<std::size_t>(action);
      const int parent = l == 0 ? -1 : path[l - 1];
      if (members_[slot].empty()) {
        position_[slot] = static_cast<int>(l);
        parent_[slot] = parent;
      } else if (position_[slot] != static_cast<int>(l) || parent_[slot] != parent) {
        reject("action '" + actions_[slot].id +
               "' is shared by skeletons that differ before it; shared actions must follow a common prefix");
      }
      members_[slot].push_back(static_cast<int>(k));
    }
    completes_[static_cast<std::size_t>(path.back())] = 1;
  }
  check_rewards();
  index_culprits();
  index_chains();
}

void Problem::index_chains() {
  std::set<std::string> names;
  std::int64_t joint = 1;
  for (const ExogenousChain& chain : chains_) {
    if (chain.name.empty()) throw ChainRuleError(chain.name, "", "", "a chain's name is not empty");
    if (!names.insert(chain.name).second) throw ChainRuleError(chain.name, "", "", "the chain is declared twice");
    if (const std::optional<ChainFault> fault = find_chain_fault(chain)) {
      throw ChainRuleError(chain.name, "", "", fault->place + ": " + fault->rule);
    }
    joint *= chain.state_count();
    if (joint > kMaxChainStates) {
      throw ChainRuleError(chain.name, "", "",
                           "the chains' states together (their product) exceed " + std::to_string(kMaxChainStates));
    }
  }
  const auto find_chain = [&](const std::string& name) {
    for (std::size_t c = 0; c < chains_.size(); ++c) {
      if (chains_[c].name == name) return static_cast<int>(c);
    }
    return -1;
  };
  const std::size_t count = actions_.size();
  execution_chain_.assign(count, -1);
  blocking_chain_.assign(count, -1);
  blocking_.assign(count, {});
  timed_slot_.assign(count, -1);
  for (std::size_t a = 0; a < count; ++a) {
    const Action& action = actions_[a];
    // After the culprits' slots (index_culprits runs first): one State::restore holds both.
    if (action.is_timed()) timed_slot_[a] = culprit_slots_ + timed_slots_++;
    if (!action.execution_chain.empty()) {
      const int chain = find_chain(action.execution_chain);
      if (chain < 0) throw ChainRuleError(action.execution_chain, action.id, "execution", "no such chain");
      const ExogenousChain& declared = chains_[static_cast<std::size_t>(chain)];
      if (action.execution_by_state.size() != declared.states.size()) {
        throw ChainRuleError(declared.name, action.id, "execution",
                             "one execution distribution per state of the chain is needed (" +
                                 std::to_string(declared.states.size()) + ", got " +
                                 std::to_string(action.execution_by_state.size()) + ")");
      }
      execution_chain_[a] = chain;
    } else if (!action.execution_by_state.empty()) {
      throw ChainRuleError("", action.id, "execution", "execution distributions by state need a chain");
    }
    if (action.start_by != kNever && (action.start_by < 0 || action.start_by > deadline_)) {
      throw ChainRuleError(
          "", action.id, "expires",
          "the last step to start must lie between 0 and the deadline (got " + std::to_string(action.start_by) + ")");
    }
    if (!action.blocking_chain.empty()) {
      const int chain = find_chain(action.blocking_chain);
      if (chain < 0) throw ChainRuleError(action.blocking_chain, action.id, "expires", "no such chain");
      const ExogenousChain& declared = chains_[static_cast<std::size_t>(chain)];
      if (action.blocking_states.empty()) {
        throw ChainRuleError(declared.name, action.id, "expires", "the states that block the action are missing");
      }
      std::vector<char> blocked(declared.states.size(), 0);
      for (const std::string& state : action.blocking_states) {
        const int index = declared.state_index(state);
        if (index < 0) throw ChainRuleError(declared.name, action.id, "expires", "no state '" + state + "'");
        if (blocked[static_cast<std::size_t>(index)] != 0) {
          throw ChainRuleError(declared.name, action.id, "expires", "the state '" + state + "' is listed twice");
        }
        blocked[static_cast<std::size_t>(index)] = 1;
      }
      blocking_chain_[a] = chain;
      blocking_[a] = std::move(blocked);
    } else if (!action.blocking_states.empty()) {
      throw ChainRuleError("", action.id, "expires", "blocking states need a chain");
    }
  }
}

void Problem::check_rewards() {
  if (rewards_.empty()) rewards_.assign(skeletons_.size(), SkeletonReward{});
  if (rewards_.size() != skeletons_.size()) {
    reject(std::to_string(rewards_.size()) + " rewards for " + std::to_string(skeletons_.size()) +
           " skeletons: one reward per skeleton is needed");
  }
  max_reward_ = 0.0;
  for (std::size_t k = 0; k < rewards_.size(); ++k) {
    const SkeletonReward& reward = rewards_[k];
    const int index = static_cast<int>(k);
    if (!(std::isfinite(reward.value) && reward.value >= 0.0 && reward.value <= 1.0)) {
      throw RewardError(index, "the value must be a number within [0, 1]");
    }
    if (!(std::isfinite(reward.per_step) && reward.per_step >= 0.0)) {
      throw RewardError(index, "the fall per step must be a number of at least 0");
    }
    if (reward.at(static_cast<double>(deadline_)) < 0.0) {
      throw RewardError(index, "the reward falls below 0 before the deadline (value - per_step * deadline < 0)");
    }
    has_rewards_ = has_rewards_ || !reward.is_unit();
    max_reward_ = std::max(max_reward_, reward.value);
  }
}

void Problem::index_culprits() {
  const std::size_t count = actions_.size();
  culprit_indices_.assign(count, {});
  culprit_slot_.assign(count, -1);
  for (std::size_t a = 0; a < count; ++a) {
    const Action& action = actions_[a];
    const double backtracking = 1.0 - action.backtrack.never();
    if (action.backtrack.pmf(0) > 0) throw BacktrackingError(action.id, "", "backtrack steps start at 1");
    if (backtracking > 0 && 1.0 - action.planning.never() + backtracking > 1.0 + Distribution::kSumTolerance) {
      throw BacktrackingError(action.id, "", "planning and backtrack probabilities sum above 1");
    }
    if (backtracking <= 0) {
      if (!action.culprits.empty()) {
        throw BacktrackingError(action.id, action.culprits.front().id, "culprits without a backtrack distribution");
      }
      continue;
    }
    if (action.culprits.empty()) throw BacktrackingError(action.id, "", "an action that backtracks needs culprits");
    double total = 0;
    for (const Culprit& culprit : action.culprits) {
      if (!(culprit.probability >= 0.0 && culprit.probability <= 1.0)) {
        throw BacktrackingError(action.id, culprit.id, "a probability must be within [0, 1]");
      }
      const int index = find_action(culprit.id);
      if (index < 0) throw BacktrackingError(action.id, culprit.id, "no such action");
      // A culprit is an action before this one on its path: an ancestor in the prefix tree.
      bool before = false;
      for (int up = parent_[a]; up >= 0 && !before; up = parent_[static_cast<std::size_t>(up)]) before = up == index;
      if (!before) {
        const bool after = [&] {
          for (int up = parent_[static_cast<std::size_t>(index)]; up >= 0; up = parent_[static_cast<std::size_t>(up)]) {
            if (up == static_cast<int>(a)) return true;
          }
          return false;
        }();
        throw BacktrackingError(action.id, culprit.id,
                                index == static_cast<int>(a)
                                    ? "an action cannot blame itself"
                                    : (after ? "the culprit comes after the failing action"
                                             : "the culprit is not before the action on its skeletons' path"));
      }
      for (const CulpritIndex& earlier : culprit_indices_[a]) {
        if (earlier.action == index) throw BacktrackingError(action.id, culprit.id, "the culprit is listed twice");
      }
      culprit_indices_[a].push_back({index, culprit.probability});
      total += culprit.probability;
    }
    if (std::abs(total - 1.0) > Distribution::kSumTolerance) {
      throw BacktrackingError(action.id, "", "the culprits' probabilities sum to " + std::to_string(total) + ", not 1");
    }
    for (const CulpritIndex& culprit : culprit_indices_[a]) {
      int& slot = culprit_slot_[static_cast<std::size_t>(culprit.action)];
      if (slot < 0) slot = culprit_slots_++;
    }
  }
}

int Problem::find_action(std::string_view id) const noexcept {
  for (std::size_t i = 0; i < actions_.size(); ++i) {
    if (actions_[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

std::string_view acting_name(Acting acting) noexcept {
  return acting == Acting::concurrent ? "concurrent" : "plan-first";
}

std::optional<Acting> parse_acting(std::string_view name) noexcept {
  if (name == "plan-first") return Acting::plan_first;
  if (name == "concurrent") return Acting::concurrent;
  return std::nullopt;
}

std::string_view action_base_id(std::string_view id) noexcept {
  const std::size_t hash = id.rfind('#');
  if (hash == std::string_view::npos || hash == 0 || hash + 1 == id.size()) return id;
  for (std::size_t i = hash + 1; i < id.size(); ++i) {
    if (id[i] < '0' || id[i] > '9') return id;
  }
  return id.substr(0, hash);
}

Problem with_distributions_of(const Problem& structure, const Problem& distributions) {
  if (distributions.deadline() != structure.deadline()) {
    reject("the deadlines differ (" + std::to_string(distributions.deadline()) + " and " +
           std::to_string(structure.deadline()) + " steps)");
  }
  // (A relative slack: steps are written as decimals in instance files.)
  if (std::abs(distributions.step_seconds() - structure.step_seconds()) > 1e-9 * structure.step_seconds()) {
    reject("the steps differ (" + std::to_string(distributions.step_seconds()) + " s and " +
           std::to_string(structure.step_seconds()) + " s)");
  }
  std::vector<Action> actions(structure.actions().begin(), structure.actions().end());
  for (Action& action : actions) {
    int source = distributions.find_action(action.id);
    if (source < 0) source = distributions.find_action(action_base_id(action.id));
    if (source < 0) reject("no distributions for the action " + action.id);
    const Action& from = distributions.action(source);
    action.planning = from.planning;
    action.execution = from.execution;
    action.backtrack = from.backtrack;
    action.culprits = from.culprits;
  }
  return structure.with_actions(std::move(actions));
}

AttemptEnd draw_attempt_end(const Action& action, double u, Steps spent, Steps last) {
  // Beyond both distributions' last steps nothing more ends.
  const auto last_of = [](const Distribution& d) { return d.max_step() == kNever ? Steps{0} : d.max_step(); };
  last = std::min(last, std::max(last_of(action.planning), last_of(action.backtrack)));
  double ended = 0;
  for (Steps t = 1; t <= spent; ++t) ended += action.planning.pmf(t) + action.backtrack.pmf(t);
  const double threshold = ended + u * (1.0 - ended);
  double cumulative = ended;
  for (Steps t = spent + 1; t <= last; ++t) {
    cumulative += action.planning.pmf(t);
    if (threshold < cumulative) return {t, true};
    cumulative += action.backtrack.pmf(t);
    if (threshold < cumulative) return {t, false};
  }
  return {};
}

}  // namespace ontime
