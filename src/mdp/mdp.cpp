#include "ontime/mdp/mdp.hpp"

#include <limits>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// A remaining-time bound that no deadline can meet; sums of a few of them do not overflow.
constexpr std::int64_t kUnreachable = Mdp::kUnreachableNeed;

std::int64_t least_steps(Steps steps) { return steps == kNever ? kUnreachable : steps; }

}  // namespace

Mdp::Mdp(const Problem& problem)
    : problem_(&problem), skeleton_count_(problem.skeleton_count()), deadline_(problem.deadline()) {
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
  group_rest_.assign(action_count, kUnreachable);
  for (int k = 0; k < skeleton_count_; ++k) {
    const std::size_t base = offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(k);
    for (int l = 0; l < lengths_[static_cast<std::size_t>(k)]; ++l) {
      std::int64_t& least = group_rest_[static_cast<std::size_t>(problem.action_at(k, l))];
      least = std::min(least, rest_[base + static_cast<std::size_t>(l) + 1]);
    }
  }
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
