#include "ontime/solve/concurrent_contiguous_success.hpp"

#include <algorithm>
#include <array>
#include <span>
#include <string>

#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/util/error.hpp"

namespace ontime {

ConcurrentContiguousSuccess::ConcurrentContiguousSuccess(const ConcurrentMdp& mdp, Aggregation aggregation,
                                                         Timing timing)
    : mdp_(&mdp),
      aggregation_(aggregation),
      relaxed_(timing == Timing::relax && mdp.is_timed()),
      deadline_(mdp.deadline()) {
  const Problem& problem = mdp.problem();
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    std::vector<char> after(static_cast<std::size_t>(problem.skeleton_length(k)) + 1, 0);
    for (int l = problem.skeleton_length(k); l-- > 0;) {
      after[static_cast<std::size_t>(l)] = static_cast<char>(after[static_cast<std::size_t>(l) + 1] != 0 ||
                                                             !problem.culprits(problem.action_at(k, l)).empty());
    }
    gives_up_after_.push_back(std::move(after));
  }
  if (timing != Timing::exact || !mdp.is_timed()) return;
  check_supported(mdp, aggregation);
  devoted_.reserve(static_cast<std::size_t>(mdp.skeleton_count()));
  for (int k = 0; k < mdp.skeleton_count(); ++k) {
    devoted_.push_back(std::make_unique<ConcurrentSolver>(
        mdp, [model = &mdp, k](const ConcurrentState& state) { return devoted_move(*model, state, k); }));
  }
}

ConcurrentContiguousSuccess::~ConcurrentContiguousSuccess() = default;
ConcurrentContiguousSuccess::ConcurrentContiguousSuccess(ConcurrentContiguousSuccess&&) noexcept = default;
ConcurrentContiguousSuccess& ConcurrentContiguousSuccess::operator=(ConcurrentContiguousSuccess&&) noexcept = default;

void ConcurrentContiguousSuccess::check_supported(const ConcurrentMdp& mdp, Aggregation aggregation) {
  if (mdp.is_timed() && aggregation != Aggregation::self) {
    throw UsageError(mdp.problem().name() + ": aggregation '" + std::string(to_string(aggregation)) +
                     "' has no form with chains or expiry (SPEC §9) in Eq. (1) acting while planning (SPEC §10); "
                     "'self' is the one taken");
  }
}

ConcurrentMdp::Move ConcurrentContiguousSuccess::devoted_move(const ConcurrentMdp& mdp, const ConcurrentState& state,
                                                              int k) {
  if (!ConcurrentMdp::is_live(state, k)) return {};
  const Problem& problem = mdp.problem();
  const int depth = mdp.executed_depth(state);
  const int refined = ConcurrentMdp::refined(state, k);
  if (ConcurrentMdp::robot_left(state) == 0 && refined > depth) {
    const int next = problem.action_at(k, depth);
    if (!mdp.is_timed()) return {next, ConcurrentMdp::kWait};
    // With chains or expiry it starts as soon as it may: until then the planner refines k.
    const std::vector<int> startable = mdp.startable(state);
    if (std::binary_search(startable.begin(), startable.end(), next)) return {next, ConcurrentMdp::kWait};
  }
  if (refined < problem.skeleton_length(k)) return {-1, k};
  return {};
}

std::uint64_t ConcurrentContiguousSuccess::memo_key(int k, int l, Steps time, std::int64_t last) {
  return (static_cast<std::uint64_t>(k) << 40U) | (static_cast<std::uint64_t>(l) << 32U) |
         (static_cast<std::uint64_t>(time) << 16U) | static_cast<std::uint64_t>(last);
}

double ConcurrentContiguousSuccess::ending(int k, std::int64_t finish) const {
  if (finish > deadline_) return 0.0;
  const Problem& problem = mdp_->problem();
  return problem.has_rewards() ? problem.reward_at(k, static_cast<Steps>(finish)) : 1.0;
}

std::span<const Mdp::ExecutionOutcome> ConcurrentContiguousSuccess::execution_outcomes(
    int action, std::array<Mdp::ExecutionOutcome, 1>& fastest) const {
  if (!relaxed_ || mdp_->problem().execution_chain(action) < 0) {
    return mdp_->plan_first_mdp().execution_outcomes(action);
  }
  const Steps steps = mdp_->fastest_execution(action);
  fastest[0] = {steps == kNever ? deadline_ + 1 : steps, 1.0};
  return fastest;
}

double ConcurrentContiguousSuccess::attempt_survival(int action, Steps spent) const {
  const Action& attempt = mdp_->problem().action(action);
  double ended = 0.0;
  for (Steps u = 1; u <= spent; ++u) ended += attempt.planning.pmf(u) + attempt.backtrack.pmf(u);
  return 1.0 - ended;
}

// value, fresh and after_found recurse one level per action of the skeleton (at most
// Problem::kMaxSkeletonLength deep, whatever the deadline), each level memoised by fresh.
// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentContiguousSuccess::value(int k, int l, Steps spent, Steps time, std::int64_t backlog) {
  if (mdp_->has_backtracking()) {
    throw UsageError("Eq. (1) acting while planning with backtracking needs the restore values: value it from a state");
  }
  if (mdp_->is_timed() && !relaxed_) {
    throw UsageError(
        "Eq. (1) acting while planning with chains or expiry (SPEC §9) values the devoted policy from a state: the "
        "robot's backlog is not a number there");
  }
  if (time + backlog > deadline_) return 0.0;
  const Problem& problem = mdp_->problem();
  const Distribution& planning = problem.action(problem.action_at(k, l)).planning;
  const double survival = planning.survival(spent);
  if (survival <= 0.0) return 0.0;
  double total = 0.0;
  for (Steps t = 1; time + t <= deadline_; ++t) {
    const double found = planning.pmf(spent + t);
    if (found > 0.0) total += found * after_found(k, l, time + t, std::max<std::int64_t>(backlog - t, 0));
  }
  return total / survival;
}

double ConcurrentContiguousSuccess::value(const ConcurrentState& state, int k) {
  if (!devoted_.empty()) {
    // Once k is dropped the devoted policy starts nothing: the episode cannot end through it.
    if (!ConcurrentMdp::is_live(state, k)) return 0.0;
    return devoted_[static_cast<std::size_t>(k)]->solve(state);
  }
  if (mdp_->has_backtracking()) return give_up_value(state, k);
  const Problem& problem = mdp_->problem();
  const std::int64_t free = mdp_->robot_free(state, k);
  const Steps now = ConcurrentMdp::time(state);
  const int refined = ConcurrentMdp::refined(state, k);
  if (refined == problem.skeleton_length(k)) return ending(k, free);
  return value(k, refined, mdp_->spent(state, k), now, free - now);
}

// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentContiguousSuccess::fresh(int k, int l, Steps time, std::int64_t backlog) {
  if (time + backlog > deadline_) return 0.0;
  const std::uint64_t key = memo_key(k, l, time, backlog);
  if (const auto found = fresh_.find(key); found != fresh_.end()) return found->second;
  const double computed = value(k, l, 0, time, backlog);
  fresh_.emplace(key, computed);
  return computed;
}

// NOLINTNEXTLINE(misc-no-recursion)
double ConcurrentContiguousSuccess::after_found(int k, int l, Steps time, std::int64_t backlog) {
  const Problem& problem = mdp_->problem();
  const int action = problem.action_at(k, l);
  std::array<Mdp::ExecutionOutcome, 1> fastest{};
  double total = 0.0;
  for (const Mdp::ExecutionOutcome& outcome : execution_outcomes(action, fastest)) {
    const std::int64_t after = backlog + outcome.steps;
    if (time + after > deadline_) continue;
    const auto worth = [&](int m) {  // NOLINT(misc-no-recursion)
      return problem.skeleton_length(m) == l + 1 ? ending(m, time + after) : fresh(m, l + 1, time, after);
    };
    double combined = 0.0;
    if (aggregation_ == Aggregation::self) {
      combined = worth(k);
    } else {
      for (const int m : problem.members(action)) {
        combined = aggregation_ == Aggregation::sum ? combined + worth(m) : std::max(combined, worth(m));
      }
    }
    total += outcome.probability * combined;
  }
  return total;
}

double ConcurrentContiguousSuccess::give_up_need(const GiveUpKey& key, bool& ready) {
  if (key.time >= deadline_) return 0.0;  // no step left, and position l is not refined
  if (const auto known = give_up_memo_.find(key); known != give_up_memo_.end()) return known->second;
  pending_.push_back(key);
  ready = false;
  return 0.0;
}

double ConcurrentContiguousSuccess::give_up_attempt(const GiveUpKey& key, Steps spent, bool& ready) {
  const Problem& problem = mdp_->problem();
  const int k = key.skeleton;
  const int l = key.position;
  const int action_index = problem.action_at(k, l);
  const Action& action = problem.action(action_index);
  const bool blamed = problem.culprit_slot(action_index) >= 0;
  const std::int64_t beyond = std::int64_t{deadline_} + 1;
  double total = 0.0;
  for (std::int64_t t = 1; key.time + t <= deadline_; ++t) {
    const auto now = static_cast<std::int32_t>(key.time + t);
    const double found = action.planning.pmf(static_cast<Steps>(spent + t));
    if (found > 0.0) {
      // The robot starts the motion when it is free; the later positions see that start.
      const std::int64_t start = std::max<std::int64_t>(key.free, now);
      const std::uint32_t next_restores =
          restores_.append(key.restores, blamed ? static_cast<std::uint32_t>(start) : 0U);
      double continuation = 0.0;
      for (const Mdp::ExecutionOutcome& outcome : mdp_->plan_first_mdp().execution_outcomes(action_index)) {
        const std::int64_t finish = std::min(start + outcome.steps, beyond);
        const auto worth = [&](int m) {
          if (problem.skeleton_length(m) == l + 1) return ending(m, finish);
          return give_up_need(GiveUpKey{m, l + 1, now, static_cast<std::int32_t>(finish), next_restores}, ready);
        };
        double combined = 0.0;
        if (aggregation_ == Aggregation::self) {
          combined = worth(k);
        } else {
          for (const int m : problem.members(action_index)) {
            combined = aggregation_ == Aggregation::sum ? combined + worth(m) : std::max(combined, worth(m));
          }
        }
        continuation += outcome.probability * combined;
      }
      total += found * continuation;
    }
    const double back = action.backtrack.pmf(static_cast<Steps>(spent + t));
    if (back > 0.0) {
      // A culprit already started (S < now) cannot be undone: the action is blocked, k dropped.
      double continuation = 0.0;
      for (const Problem::CulpritIndex& culprit : problem.culprits(action_index)) {
        const int position = problem.position(culprit.action);
        const std::uint32_t before = restores_.prefix(key.restores, l, position);
        // Not started by now: it was found before now, so it waits for the robot, free at its start.
        const auto start = static_cast<std::int32_t>(restores_.at(key.restores, l, position));
        if (start < now) continue;
        continuation += culprit.probability * give_up_need(GiveUpKey{k, position, now, start, before}, ready);
      }
      total += back * continuation;
    }
  }
  return total;
}

double ConcurrentContiguousSuccess::give_up_settled(const GiveUpKey& key, Steps spent) {
  for (;;) {
    bool ready = true;
    const double total = give_up_attempt(key, spent, ready);
    if (ready) return total;
    while (!pending_.empty()) {
      const GiveUpKey needed = pending_.back();
      if (give_up_memo_.contains(needed)) {
        pending_.pop_back();
        continue;
      }
      bool settled = true;
      const double value = give_up_attempt(needed, 0, settled);
      // Not settled: what it needs is now above it on the stack, and it is summed again after.
      if (settled) {
        give_up_memo_.emplace(needed, value);
        pending_.pop_back();
      }
    }
  }
}

double ConcurrentContiguousSuccess::give_up_value(const ConcurrentState& state, int k) {
  const Problem& problem = mdp_->problem();
  const Steps now = ConcurrentMdp::time(state);
  const int refined = ConcurrentMdp::refined(state, k);
  const int depth = mdp_->executed_depth(state);
  const std::int64_t beyond = std::int64_t{deadline_} + 1;
  // The robot goes on eagerly from now: each refined action after E starts when the robot is free.
  std::int64_t free = std::int64_t{now} + ConcurrentMdp::robot_left(state);
  std::uint32_t restores = 0;
  for (int position = 0; position < refined; ++position) {
    const int action = problem.action_at(k, position);
    if (position < depth) {  // executed or executing: blamed, it blocks (S = 0 < any later step)
      restores = restores_.append(restores, 0U);
      continue;
    }
    const std::int64_t start = std::min(free, beyond);
    // A culprit refined and not started: the policy starts it when the robot is free, S = F, the
    // restore value a later give-up reads (as give_up_attempt appends it).
    restores = restores_.append(restores, problem.culprit_slot(action) >= 0 ? static_cast<std::uint32_t>(start) : 0U);
    free = std::min(start + mdp_->execution(state, action), beyond);
  }
  if (refined == problem.skeleton_length(k)) return ending(k, free);
  const Steps spent = mdp_->spent(state, k);
  const double alive = attempt_survival(problem.action_at(k, refined), spent);
  if (alive <= 0.0 || now >= deadline_) return 0.0;
  const GiveUpKey key{k, refined, static_cast<std::int32_t>(now), static_cast<std::int32_t>(free), restores};
  if (spent == 0) {
    bool ready = true;
    const double known = give_up_need(key, ready);
    if (ready) return known;
  }
  return give_up_settled(key, spent) / alive;
}

// relaxed_attempt and relaxed_fresh recurse one level per action of the skeleton (a give-up ends
// the relaxed episode, so nothing goes back), each level memoised by relaxed_fresh.
// NOLINTNEXTLINE(misc-no-recursion)
ConcurrentContiguousSuccess::GiveUpRelaxed ConcurrentContiguousSuccess::relaxed_attempt(int k, int l, Steps spent,
                                                                                        Steps time, std::int64_t free) {
  const Problem& problem = mdp_->problem();
  const int action_index = problem.action_at(k, l);
  const Action& action = problem.action(action_index);
  const std::int64_t beyond = std::int64_t{deadline_} + 1;
  const bool last = l + 1 == problem.skeleton_length(k);
  std::array<Mdp::ExecutionOutcome, 1> fastest{};
  const std::span<const Mdp::ExecutionOutcome> outcomes = execution_outcomes(action_index, fastest);
  GiveUpRelaxed total;
  for (Steps t = 1; time + t <= deadline_; ++t) {
    const Steps now = time + t;
    const double found = action.planning.pmf(spent + t);
    if (found > 0.0) {
      // The robot starts the motion when it is free, and is free again at the end of its execution.
      const std::int64_t start = std::max<std::int64_t>(free, now);
      GiveUpRelaxed after;
      for (const Mdp::ExecutionOutcome& outcome : outcomes) {
        const std::int64_t finish = std::min(start + outcome.steps, beyond);
        if (last) {
          after.reward += outcome.probability * ending(k, finish);
          continue;
        }
        const GiveUpRelaxed next = relaxed_fresh(k, l + 1, now, finish);
        after.reward += outcome.probability * next.reward;
        after.give_up += outcome.probability * next.give_up;
      }
      total.reward += found * after.reward;
      total.give_up += found * after.give_up;
    }
    total.give_up += action.backtrack.pmf(spent + t);  // ends the relaxed episode, whoever is blamed
  }
  return total;
}

// NOLINTNEXTLINE(misc-no-recursion)
ConcurrentContiguousSuccess::GiveUpRelaxed ConcurrentContiguousSuccess::relaxed_fresh(int k, int l, Steps time,
                                                                                      std::int64_t free) {
  // No step left; or the robot past the deadline and nothing left that may give up.
  if (time >= deadline_) return {};
  if (free > deadline_ && gives_up_after_[static_cast<std::size_t>(k)][static_cast<std::size_t>(l)] == 0) return {};
  // Computed before it is stored: the recursion inserts more values (and may move the table).
  const std::uint64_t key = memo_key(k, l, time, free);
  if (const auto found = relaxed_memo_.find(key); found != relaxed_memo_.end()) return found->second;
  const GiveUpRelaxed computed = relaxed_attempt(k, l, 0, time, free);
  relaxed_memo_.emplace(key, computed);
  return computed;
}

ConcurrentContiguousSuccess::GiveUpRelaxed ConcurrentContiguousSuccess::give_up_relaxed(const ConcurrentState& state,
                                                                                        int k) {
  const Problem& problem = mdp_->problem();
  const Steps now = ConcurrentMdp::time(state);
  // The robot runs k's refined actions after E back to back from now (with Timing::relax, an
  // execution drawn when it starts at its fastest).
  const std::int64_t free = std::min(mdp_->robot_free(state, k), std::int64_t{deadline_} + 1);
  const int refined = ConcurrentMdp::refined(state, k);
  if (refined == problem.skeleton_length(k)) return {ending(k, free), 0.0};
  const Steps spent = mdp_->spent(state, k);
  if (spent == 0) return relaxed_fresh(k, refined, now, free);
  const double alive = attempt_survival(problem.action_at(k, refined), spent);
  if (alive <= 0.0 || now >= deadline_) return {};
  const GiveUpRelaxed total = relaxed_attempt(k, refined, spent, now, free);
  return {total.reward / alive, total.give_up / alive};
}

}  // namespace ontime
