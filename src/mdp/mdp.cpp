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

}  // namespace

Mdp::Mdp(const Problem& problem)
    : problem_(&problem), skeleton_count_(problem.skeleton_count()), deadline_(problem.deadline()) {
  bool timed = problem.has_chains();
  for (const Action& action : problem.actions()) timed = timed || action.is_timed();
  if (timed) {
    throw UsageError(problem.name() +
                     ": exogenous chains and actions that expire (SPEC §9) are read and checked, but no solver or "
                     "allocator takes them yet");
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
      const std::int64_t least = least_steps(action.planning.min_step()) + least_steps(action.execution.min_step());
      rest_[base + static_cast<std::size_t>(l)] =
          std::min(kUnreachable, rest_[base + static_cast<std::size_t>(l) + 1] + least);
    }
  }
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
  slots_below_.assign(static_cast<std::size_t>(problem.culprit_slot_count()), {});
  for (int c = 0; c < problem.action_count(); ++c) {
    const int slot = problem.culprit_slot(c);
    if (slot < 0) continue;
    std::vector<int>& below = slots_below_[static_cast<std::size_t>(slot)];
    below.push_back(slot);
    for (int d = 0; d < problem.action_count(); ++d) {
      if (d == c || problem.culprit_slot(d) < 0) continue;
      for (int up = problem.parent(d); up >= 0; up = problem.parent(up)) {
        if (up == c) {
          below.push_back(problem.culprit_slot(d));
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

}  // namespace ontime
