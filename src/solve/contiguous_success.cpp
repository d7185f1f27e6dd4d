#include "ontime/solve/contiguous_success.hpp"

#include <algorithm>

#include "ontime/util/error.hpp"

namespace ontime {

std::string_view to_string(Aggregation aggregation) noexcept {
  switch (aggregation) {
    case Aggregation::sum:
      return "sum";
    case Aggregation::max:
      return "max";
    case Aggregation::self:
      return "self";
  }
  return "sum";
}

Aggregation parse_aggregation(std::string_view text) {
  if (text == "sum") return Aggregation::sum;
  if (text == "max") return Aggregation::max;
  if (text == "self") return Aggregation::self;
  throw UsageError("unknown aggregation '" + std::string(text) + "' (expected sum, max or self)");
}

ContiguousSuccessTable::ContiguousSuccessTable(const Mdp& mdp, Aggregation aggregation)
    : mdp_(&mdp), aggregation_(aggregation), deadline_(mdp.deadline()) {
  mdp.refuse_timed("Eq. (1)");
  const Problem& problem = mdp.problem();
  const auto deadline = static_cast<std::size_t>(deadline_);
  const std::size_t row = deadline + 2;  // G(v), v = 0 .. D + 1
  const std::size_t planning_row = 2 * deadline + 1;

  planning_.assign(static_cast<std::size_t>(problem.action_count()) * planning_row, 0.0);
  survival_.assign(static_cast<std::size_t>(problem.action_count()) * deadline, 0.0);
  for (int a = 0; a < problem.action_count(); ++a) {
    const Distribution& planning = problem.action(a).planning;
    const auto base = static_cast<std::size_t>(a);
    for (std::size_t t = 0; t < planning_row; ++t) {
      planning_[base * planning_row + t] = planning.pmf(static_cast<Steps>(t));
    }
    for (std::size_t spent = 0; spent < deadline; ++spent) {
      survival_[base * deadline + spent] = planning.survival(static_cast<Steps>(spent));
    }
  }

  int longest = 0;
  offsets_.resize(static_cast<std::size_t>(problem.skeleton_count()));
  std::size_t slots = 0;
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    offsets_[static_cast<std::size_t>(k)] = slots;
    slots += static_cast<std::size_t>(problem.skeleton_length(k));
    longest = std::max(longest, problem.skeleton_length(k));
  }
  continuation_.assign(slots * row, 0.0);
  // PS(k, l, 0, U) with an unconditioned planning time, U = 0 .. D (zero at U >= D).
  std::vector<double> unconditioned(slots * (deadline + 1), 0.0);
  fresh_.assign(slots * (deadline + 1), 0.0);
  bound_.assign(slots * (deadline + 1), 0.0);

  // Later positions first: G(k, l) needs PS(k', l + 1) of the skeletons sharing position l.
  for (int l = longest; l-- > 0;) {
    for (int k = 0; k < problem.skeleton_count(); ++k) {
      if (problem.skeleton_length(k) <= l) continue;
      const std::size_t slot = offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(l);
      const int action = problem.action_at(k, l);
      const Distribution& execution = problem.action(action).execution;
      double* g = &continuation_[slot * row];
      if (l + 1 == problem.skeleton_length(k) && problem.has_rewards()) {
        // With rewards (SPEC §8): the expected reward of the finish v + x, not the chance it fits.
        const auto masses = execution.masses();
        for (std::size_t v = 1; v <= deadline; ++v) {
          double total = 0;
          for (std::size_t x = 0; x < masses.size() && v + x <= deadline; ++x) {
            total += masses[x] * problem.reward_at(k, static_cast<Steps>(v + x));
          }
          g[v] = total;
        }
      } else if (l + 1 == problem.skeleton_length(k)) {
        for (std::size_t v = 1; v <= deadline; ++v) g[v] = execution.cdf(static_cast<Steps>(deadline - v));
      } else {
        // PS(k', l + 1, 0, u) of a sharing skeleton k'; a k' that ends with this action is
        // complete, and succeeds exactly when u <= D (worth its reward then, 1 without rewards).
        const auto next_value = [&](int other, std::size_t u) -> double {
          if (problem.skeleton_length(other) == l + 1) {
            return u <= deadline ? problem.reward_at(other, static_cast<Steps>(u)) : 0.0;
          }
          if (u >= deadline) return 0.0;
          const std::size_t next = offsets_[static_cast<std::size_t>(other)] + static_cast<std::size_t>(l) + 1;
          return unconditioned[next * (deadline + 1) + u];
        };
        const auto masses = execution.masses();
        for (std::size_t v = 1; v <= deadline; ++v) {
          double total = 0;
          for (std::size_t x = 0; x < masses.size() && v + x <= deadline; ++x) {
            if (masses[x] <= 0) continue;
            double combined = 0;
            if (aggregation_ == Aggregation::self) {
              combined = next_value(k, v + x);
            } else {
              for (const int other : problem.members(action)) {
                const double value = next_value(other, v + x);
                combined = aggregation_ == Aggregation::sum ? combined + value : std::max(combined, value);
              }
            }
            total += masses[x] * combined;
          }
          g[v] = total;
        }
      }
      const double* p = &planning_[static_cast<std::size_t>(action) * planning_row];
      const double start = survival_[static_cast<std::size_t>(action) * deadline];
      double later = 0;  // max of G(v) over v > used
      for (std::size_t used = deadline; used-- > 0;) {
        double value = 0;
        for (std::size_t t = 1; used + t <= deadline; ++t) value += p[t] * g[used + t];
        unconditioned[slot * (deadline + 1) + used] = value;
        // The query's own arithmetic (the same sum, divided by S(0)), so that a fresh value
        // read here equals the one computed on demand to the last bit.
        fresh_[slot * (deadline + 1) + used] = start > 0 ? value / start : 0.0;
        later = std::max(later, g[used + 1]);
        bound_[slot * (deadline + 1) + used] = later * kBoundMargin;
      }
    }
  }
}

double ContiguousSuccessTable::success_probability(int k, int l, Steps spent, Steps used) const noexcept {
  if (used < 0 || used >= deadline_ || spent < 0 || spent >= deadline_) return 0.0;
  const int action = mdp_->problem().action_at(k, l);
  const auto deadline = static_cast<std::size_t>(deadline_);
  const double remaining = survival_[static_cast<std::size_t>(action) * deadline + static_cast<std::size_t>(spent)];
  if (remaining <= 0) return 0.0;
  const double* p = &planning_[static_cast<std::size_t>(action) * (2 * deadline + 1) + static_cast<std::size_t>(spent)];
  const double* g =
      &continuation_[(offsets_[static_cast<std::size_t>(k)] + static_cast<std::size_t>(l)) * (deadline + 2) +
                     static_cast<std::size_t>(used)];
  const std::size_t terms = deadline - static_cast<std::size_t>(used);
  double value = 0;
  for (std::size_t t = 1; t <= terms; ++t) value += p[t] * g[t];
  return value / remaining;
}

double ContiguousSuccessTable::upper_bound(const State& state, int k) const noexcept {
  const auto index = static_cast<std::size_t>(k);
  if (mdp_->next_action(state, k) < 0) return 0.0;
  return upper_bound(k, state.refined[index], std::int64_t{state.time} + state.execution[index]);
}

double ContiguousSuccessTable::success_probability(const State& state, int k) const noexcept {
  const auto slot = static_cast<std::size_t>(k);
  if (mdp_->next_action(state, k) < 0) return 0.0;
  const std::int64_t used = std::int64_t{state.time} + state.execution[slot];
  if (state.spent[slot] == 0) return fresh_success_probability(k, state.refined[slot], used);
  return success_probability(k, state.refined[slot], state.spent[slot], static_cast<Steps>(used));
}

}  // namespace ontime
