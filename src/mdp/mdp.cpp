#include "ontime/mdp/mdp.hpp"

#include <algorithm>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// A remaining-time bound that no deadline can meet; sums of a few of them do not overflow.
constexpr std::int64_t kUnreachable = Mdp::kUnreachableNeed;

std::int64_t least_steps(Steps steps) { return steps == kNever ? kUnreachable : steps; }

// The fastest execution of a chain-dependent action in any state of its chain (kNever: none).
Steps least_chain_execution(const Action& action) {
  Steps least = kNever;
  for (const Distribution& execution : action.execution_by_state) {
    if (execution.min_step() != kNever)
      least = least == kNever ? execution.min_step() : std::min(least, execution.min_step());
  }
  return least;
}

}  // namespace

Mdp::Mdp(const Problem& problem)
    : problem_(&problem), skeleton_count_(problem.skeleton_count()), deadline_(problem.deadline()) {
  // This MDP is SPEC §2's, plan first: a problem whose robot acts while planning (SPEC §10) has
  // other states and transitions (ConcurrentMdp), and reading it as plan-first would give numbers
  // of another model under its name.
  if (problem.acting() != Acting::plan_first) {
    throw UsageError(problem.name() +
                     " acts while planning (acting \"concurrent\", SPEC §10): the plan-first model does not take "
                     "it; that mode has its own (ConcurrentMdp, ConcurrentSession, the commands' --act concurrent), "
                     "or read it plan-first (--act plan-first)");
  }
  const auto deadline = static_cast<std::size_t>(deadline_);
  const auto action_count = static_cast<std::size_t>(problem.action_count());

  hazards_.assign(action_count * deadline, 0.0);
  next_finish_.assign(action_count * (deadline + 1), kNever);
  execution_outcomes_.assign(action_count, {});
  min_execution_.assign(action_count, kNever);
  for (std::size_t a = 0; a < action_count; ++a) {
    const Action& action = problem.actions()[a];
    for (std::size_t spent = 0; spent < deadline; ++spent) {
      hazards_[a * deadline + spent] = action.planning.hazard(static_cast<Steps>(spent));
    }
    // Least t >= 1 with p(spent + t) > 0, filled from the end of the support backwards.
    const auto masses = action.planning.masses();
    Steps next_support = kNever;
    for (std::size_t u = masses.size(); u-- > 0;) {
      if (u <= deadline) {
        next_finish_[a * (deadline + 1) + u] = next_support == kNever ? kNever : next_support - static_cast<Steps>(u);
      }
      if (masses[u] > 0) next_support = static_cast<Steps>(u);
    }
    for (std::size_t spent = masses.size(); spent <= deadline; ++spent) {
      next_finish_[a * (deadline + 1) + spent] = kNever;
    }

    if (problem.execution_chain(static_cast<int>(a)) >= 0) {
      // Drawn when the execution starts (SPEC §9): finding the motion adds nothing to ET; the
      // least time still counts its fastest execution in any state of the chain.
      execution_outcomes_[a].push_back({0, 1.0});
      min_execution_[a] = least_chain_execution(action);
      continue;
    }
    double too_slow = action.execution.never();
    const auto execution = action.execution.masses();
    for (std::size_t x = 0; x < execution.size(); ++x) {
      if (execution[x] <= 0) continue;
      if (x <= deadline) {
        execution_outcomes_[a].push_back({static_cast<Steps>(x), execution[x]});
      } else {
        too_slow += execution[x];
      }
    }
    if (too_slow > 0) execution_outcomes_[a].push_back({deadline_ + 1, too_slow});
    min_execution_[a] = action.execution.min_step();
  }

  lengths_.resize(static_cast<std::size_t>(skeleton_count_));
  offsets_.resize(static_cast<std::size_t>(skeleton_count_));
  for (int k = 0; k < skeleton_count_; ++k) {
    const auto path = problem.skeleton(k);
    lengths_[static_cast<std::size_t>(k)] = static_cast<int>(path.size());
    offsets_[static_cast<std::size_t>(k)] = paths_.size();
    paths_.insert(paths_.end(), path.begin(), path.end());
  }
  // rest_[offsets_[k] + k + l]: least planning + execution of positions l .. A_k - 1 of k.
  rest_.assign(paths_.size() + static_cast<std::size_t>(skeleton_count_), 0);
  for (int k = 0; k < skeleton_count_; ++k) {
    const std::size_t base = offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(k);
    const int length = lengths_[static_cast<std::size_t>(k)];
    rest_[base + static_cast<std::size_t>(length)] = 0;
    for (int l = length; l-- > 0;) {
      const Action& action = problem.action(problem.action_at(k, l));
      const Steps fastest =
          action.execution_chain.empty() ? action.execution.min_step() : least_chain_execution(action);
      const std::int64_t least = least_steps(action.planning.min_step()) + least_steps(fastest);
      rest_[base + static_cast<std::size_t>(l)] =
          std::min(kUnreachable, rest_[base + static_cast<std::size_t>(l) + 1] + least);
    }
  }
  if (problem.is_timed()) index_chains(problem);
  if (problem.has_backtracking()) index_backtracking(problem);

  group_rest_.assign(action_count, kUnreachable);
  for (int k = 0; k < skeleton_count_; ++k) {
    const std::size_t base = offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(k);
    for (int l = 0; l < lengths_[static_cast<std::size_t>(k)]; ++l) {
      std::int64_t& least = group_rest_[static_cast<std::size_t>(problem.action_at(k, l))];
      least = std::min(least, rest_[base + static_cast<std::size_t>(l) + 1]);
    }
  }
}

void Mdp::index_backtracking(const Problem& problem) {
  const auto deadline = static_cast<std::size_t>(deadline_);
  const auto action_count = static_cast<std::size_t>(problem.action_count());
  backtrack_hazards_.assign(action_count * deadline, 0.0);
  for (std::size_t a = 0; a < action_count; ++a) {
    const Action& action = problem.actions()[a];
    if (action.backtrack.never() >= 1.0) continue;
    // An attempt ends at t with a motion (p) or a backtrack (q); S(t) = P(it has not ended by t),
    // summed from the end (as Distribution's survival) so that late hazards keep their digits.
    const auto found = action.planning.masses();
    const auto back = action.backtrack.masses();
    const std::size_t length = std::max(found.size(), back.size());
    const auto mass = [&](std::span<const double> masses, std::size_t t) {
      return t < masses.size() ? masses[t] : 0.0;
    };
    double listed = 0;
    for (std::size_t t = 0; t < length; ++t) listed += mass(found, t) + mass(back, t);
    std::vector<double> survival(length + 1, std::max(0.0, 1.0 - listed));  // survival[t] = S(t)
    for (std::size_t t = length; t-- > 0;) survival[t] = survival[t + 1] + mass(found, t + 1) + mass(back, t + 1);
    for (std::size_t spent = 0; spent < deadline; ++spent) {
      const double remaining = spent < survival.size() ? survival[spent] : survival.back();
      const double p = mass(found, spent + 1);
      const double q = mass(back, spent + 1);
      if (remaining <= 0.0 || p + q <= 0.0) {
        hazards_[a * deadline + spent] = 0.0;
        continue;
      }
      // Both within [0, 1] and summing to at most 1 despite rounding.
      const double end = std::min(1.0, (p + q) / remaining);
      hazards_[a * deadline + spent] = end * (p / (p + q));
      backtrack_hazards_[a * deadline + spent] = end * (q / (p + q));
    }
  }

  // Where each culprit stands on each path, and the culprits at or below each one.
  slot_at_.assign(paths_.size() + static_cast<std::size_t>(skeleton_count_), -1);
  for (int k = 0; k < skeleton_count_; ++k) {
    const std::size_t base = offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(k);
    for (int l = 0; l < lengths_[static_cast<std::size_t>(k)]; ++l) {
      slot_at_[base + static_cast<std::size_t>(l)] = problem.culprit_slot(problem.action_at(k, l));
    }
  }
  // With chains or expiry the timed slots of those actions too: a backtrack un-refines them, and
  // zeroed slots keep equivalent states equal.
  slots_below_.assign(static_cast<std::size_t>(problem.culprit_slot_count()), {});
  for (int c = 0; c < problem.action_count(); ++c) {
    const int slot = problem.culprit_slot(c);
    if (slot < 0) continue;
    std::vector<int>& below = slots_below_[static_cast<std::size_t>(slot)];
    below.push_back(slot);
    if (problem.timed_slot(c) >= 0) below.push_back(problem.timed_slot(c));
    for (int d = 0; d < problem.action_count(); ++d) {
      if (d == c) continue;
      for (int up = problem.parent(d); up >= 0; up = problem.parent(up)) {
        if (up == c) {
          if (problem.culprit_slot(d) >= 0) below.push_back(problem.culprit_slot(d));
          if (problem.timed_slot(d) >= 0) below.push_back(problem.timed_slot(d));
          break;
        }
      }
    }
  }
}

void Mdp::reject_culprit(int action, int culprit) const {
  throw UsageError("a backtrack blaming action " + std::to_string(culprit) +
                   (action < 0 ? std::string(" on an idle step")
                               : " is not one of the culprits of action " + problem_->action(action).id));
}

void Mdp::reject_choice(int choice) const {
  throw UsageError("skeleton index " + std::to_string(choice) + " out of range [0, " + std::to_string(skeleton_count_) +
                   ")");
}

void Mdp::reject_idle_refinement(int choice) {
  throw UsageError("skeleton " + std::to_string(choice) + " has nothing left to refine; its step was idle");
}

void Mdp::reject_execution(Steps execution) {
  throw UsageError("execution time must be >= 0 steps (got " + std::to_string(execution) + ")");
}

void Mdp::index_chains(const Problem& problem) {
  const auto chains = problem.chains();
  chain_strides_.assign(chains.size(), 1);
  joint_count_ = 1;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    chain_strides_[c] = joint_count_;
    joint_count_ *= static_cast<int>(chains[c].states.size());  // at most kMaxChainStates (Problem checks)
    start_chains_ = static_cast<std::uint16_t>(start_chains_ + chains[c].start * chain_strides_[c]);
  }
  // Each joint state's steps: the product of its chains' rows, zero entries left out.
  chain_step_offsets_.assign(1, 0);
  for (int joint = 0; joint < joint_count_; ++joint) {
    std::vector<ChainStep> steps{{0, 1.0}};
    for (std::size_t c = 0; c < chains.size(); ++c) {
      const auto& row = chains[c].transitions[static_cast<std::size_t>(
          chain_state(static_cast<std::uint16_t>(joint), static_cast<int>(c)))];
      std::vector<ChainStep> more;
      for (const ChainStep& step : steps) {
        for (std::size_t s = 0; s < row.size(); ++s) {
          if (row[s] <= 0) continue;
          more.push_back({static_cast<std::uint16_t>(step.next + static_cast<int>(s) * chain_strides_[c]),
                          step.probability * row[s]});
        }
      }
      steps = std::move(more);
    }
    chain_steps_.insert(chain_steps_.end(), steps.begin(), steps.end());
    chain_step_offsets_.push_back(static_cast<std::uint32_t>(chain_steps_.size()));
  }
  timed_path_.assign(static_cast<std::size_t>(skeleton_count_), {});
  for (int k = 0; k < skeleton_count_; ++k) {
    for (const int action : problem.skeleton(k)) {
      if (problem.timed_slot(action) >= 0) timed_path_[static_cast<std::size_t>(k)].push_back(action);
    }
  }
}

std::uint16_t Mdp::joint_chain_state(std::span<const int> states) const {
  const auto chains = problem_->chains();
  if (states.size() != chains.size()) {
    throw UsageError("one state per chain is needed (" + std::to_string(chains.size()) + ", got " +
                     std::to_string(states.size()) + ")");
  }
  int joint = 0;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    if (states[c] < 0 || states[c] >= static_cast<int>(chains[c].states.size())) {
      throw UsageError("chain '" + chains[c].name + "' has no state " + std::to_string(states[c]));
    }
    joint += states[c] * chain_strides_[c];
  }
  return static_cast<std::uint16_t>(joint);
}

double Mdp::execution_value(int k, Steps start, std::uint16_t joint, const std::uint16_t* restore,
                            std::uint16_t execution) const {
  if (start > deadline_) return 0.0;
  thread_local std::vector<double> table;
  execution_table(k, restore, execution, table);
  return table[static_cast<std::size_t>(start) * static_cast<std::size_t>(joint_count_) + joint];
}

void Mdp::execution_table(int k, const std::uint16_t* restore, std::uint16_t execution,
                          std::vector<double>& out) const {
  const auto deadline = static_cast<std::size_t>(deadline_);
  const auto joints = static_cast<std::size_t>(joint_count_);
  const std::size_t cells = (deadline + 1) * joints;
  const auto& timed = timed_path_[static_cast<std::size_t>(k)];
  // Backwards over the plan: `value` holds U(t, j), the expected reward from the point where the
  // static execution before the next timed action (or the static rest) begins at step t with the
  // chains in j. Scratch per thread: the solvers' many calls do not allocate.
  thread_local std::vector<double> value, moved;
  // One step of waiting: U'(t, j) = sum over j' of P(j, j') U(t + 1, j'); 0 at the deadline.
  const auto wait_one_step = [&]() {
    moved.assign(cells, 0.0);
    for (std::size_t t = 0; t < deadline; ++t) {
      for (std::size_t j = 0; j < joints; ++j) {
        double sum = 0.0;
        for (const ChainStep& step : chain_steps(static_cast<std::uint16_t>(j))) {
          sum += step.probability * value[(t + 1) * joints + step.next];
        }
        moved[t * joints + j] = sum;
      }
    }
    value.swap(moved);
  };
  // After the last timed action: the static rest, then the reward at the finish.
  const std::uint16_t last = timed.empty() ? 0 : restore[problem_->timed_slot(timed.back())];
  const std::size_t rest = execution >= last ? execution - last : 0U;
  value.assign(cells, 0.0);
  for (std::size_t t = 0; t + rest <= deadline; ++t) {
    const double reward = problem_->reward_at(k, static_cast<Steps>(t + rest));
    for (std::size_t j = 0; j < joints; ++j) value[t * joints + j] = reward;
  }
  thread_local std::vector<double> started, waited;
  for (std::size_t i = timed.size(); i-- > 0;) {
    const int action = timed[i];
    const Action& model = problem_->action(action);
    const int chain = problem_->execution_chain(action);
    if (chain >= 0) {
      // Started at t in j: x ~ execution_by_state[its chain's state in j], then U(t + x, .) after
      // x steps of the chains. waited = U moved by x steps, for x = 0, 1, ...
      started.assign(cells, 0.0);
      waited = value;
      Steps longest = 0;
      for (const Distribution& by_state : model.execution_by_state) {
        if (by_state.max_step() != kNever) longest = std::max(longest, by_state.max_step());
      }
      for (Steps x = 0; x <= std::min<Steps>(longest, deadline_); ++x) {
        if (x > 0) {
          value.swap(waited);
          wait_one_step();
          value.swap(waited);
        }
        for (std::size_t t = 0; t + static_cast<std::size_t>(x) <= deadline; ++t) {
          for (std::size_t j = 0; j < joints; ++j) {
            const double p =
                model.execution_by_state[static_cast<std::size_t>(chain_state(static_cast<std::uint16_t>(j), chain))]
                    .pmf(x);
            if (p > 0.0) started[t * joints + j] += p * waited[t * joints + j];
          }
        }
      }
      value.swap(started);
    }
    // It cannot start after its last step, nor in a blocking state.
    const int blocking = problem_->blocking_chain(action);
    for (std::size_t t = 0; t <= deadline; ++t) {
      const bool late = model.start_by != kNever && static_cast<Steps>(t) > model.start_by;
      for (std::size_t j = 0; j < joints; ++j) {
        if (late || (blocking >= 0 && problem_->blocks(action, chain_state(static_cast<std::uint16_t>(j), blocking)))) {
          value[t * joints + j] = 0.0;
        }
      }
    }
    // The static execution before it, since the previous timed action (or the plan's start).
    const std::uint16_t at = restore[problem_->timed_slot(action)];
    const std::uint16_t previous = i > 0 ? restore[problem_->timed_slot(timed[i - 1])] : 0;
    for (std::uint16_t gap = previous; gap < at; ++gap) wait_one_step();
  }
  out.swap(value);
}

void Mdp::refuse_timed(std::string_view what) const {
  if (!is_timed()) return;
  throw UsageError(std::string(what) + ": " + problem_->name() +
                   " has exogenous chains or actions that expire (SPEC §9), not modelled there yet; the memoised exact "
                   "solver, exact evaluation and the allocators listed with 'chains' ('ontime allocators') model them");
}

void Mdp::reject_chains(std::uint16_t joint) const {
  throw UsageError("the chains' joint state " + std::to_string(joint) + " is out of range [0, " +
                   std::to_string(joint_count_) + ")");
}

}  // namespace ontime
