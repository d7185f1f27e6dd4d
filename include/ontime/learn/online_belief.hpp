#pragma once
// What a robot believes of a world's planning times while it refines there: a prediction (a
// conditional time model's, a library, a pooled fit) as the prior of every action, updated by each
// attempt the robot makes (found after t steps, backtracked after t steps, or cut off after c
// steps without either) with the posterior of online_update.hpp, and handed back as an instance
// whose planning distributions, and backtrack distributions of actions that backtrack (SPEC §7),
// are the posterior means (docs/learning.md, "Online update").
//
//   ontime::OnlineBelief belief(predicted_library, /*strength=*/100);
//   for (each episode) {
//     ontime::Session session(belief.believed_for(problem), maker, seed);  // plans with the posterior
//     ... drive it ...
//     belief.observe(session.problem(), session.attempts());             // what it saw
//   }
//
// Actions are matched by action_base_id (problem.hpp): an episode's node "move(A,B)#2", and the
// prior's own node of that name when it has one, learn with the prior's "move(A,B)" (one
// posterior, from that action's prior), and are all planned with its posterior; a node of the
// prior whose base backtracks while it does not, or the other way round, learns on its own.
// Execution times and culprits stay the prior's (the planning time is what a world's clutter and
// doors change most, and what the allocators' choices hinge on).
//
// Backtracking (SPEC §7): an action whose prior backtracks (it has culprits) learns its planning
// and backtrack distributions together, as competing risks: every attempt of a session
// (ActionAttempt: the current one and those a backtrack ended) is found, backtracked or cut off at
// its step. Its believed planning and backtrack masses sum to at most 1, so the believed instance
// is valid whatever the attempts. An action whose prior does not backtrack has no culprit to
// blame: an attempt of it that backtracked counts as cut off there (it survived its steps without a
// motion), and its believed instance still never backtracks.
//
// Guarantees: an action never observed keeps its prior distributions bit for bit; the posterior
// of an observed one is PlanningPosterior's (conjugate: the order of the attempts does not
// matter; it tends to the Kaplan-Meier estimate of the action's own attempts, with backtracks the
// Aalen-Johansen estimate). The horizon is the prior's deadline: an attempt found later, or cut
// off later, counts as cut off there; for an action that backtracks, the prior's last step when
// that is later (beyond the deadline no attempt is observed, so the prior's hazards stay there and
// its backtrack mass is never lost). Cost: O(t) per attempt (no allocation after an action's
// first), O(actions x deadline) for believed().

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "ontime/learn/online_update.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/session.hpp"

namespace ontime {

class OnlineBelief {
 public:
  // `prior`: every action the robot may refine, with its prior distributions (e.g. `ontime
  // predict --library`). Throws UsageError for a strength that is not positive and finite.
  OnlineBelief(Problem prior, double strength);

  // What a session saw of the action `id` names (by action_base_id): the attempts a backtrack
  // ended, then the current one; an attempt with no effort is no data. Throws UsageError for an
  // action the prior lacks.
  void observe(std::string_view id, const ActionAttempt& attempt);
  // Every attempt of one episode, by action index of `problem`, the episode's (Session::attempts,
  // EpisodeResult::attempts with its problem). Throws UsageError for sizes that differ or an
  // action the prior lacks (before observing any).
  void observe(const Problem& problem, std::span<const ActionAttempt> attempts);

  // The prior with every observed action's posterior mean as its planning distribution, and as its
  // backtrack distribution when it backtracks.
  Problem believed() const;
  // `structure` (an episode's problem, a world's instance) with the believed distributions, each
  // action by its id or its action_base_id (with_distributions_of). Throws UsageError for an action
  // the prior lacks, or another deadline or step.
  Problem believed_for(const Problem& structure) const;

  // The planning distribution believed for the action `id` names (UsageError if unknown).
  Distribution planning(std::string_view id) const;
  // The backtrack distribution believed for the action `id` names (UsageError if unknown): the
  // prior's for an action that does not backtrack, or was not observed.
  Distribution backtrack(std::string_view id) const;

  // The prior instance, as given.
  const Problem& prior() const noexcept { return prior_; }
  // The prior's worth in attempts, for every action.
  double strength() const noexcept { return strength_; }
  // Attempts observed so far (those with effort).
  std::size_t observations() const noexcept { return observations_; }

 private:
  // The prior action whose posterior learns from `id`: its base's when the prior has it.
  int index_of(std::string_view id) const;
  // The posterior of prior action `index` before any attempt.
  PlanningPosterior prior_posterior(int index) const;

  Problem prior_;
  double strength_;
  std::vector<int> base_;  // by prior action: the action whose posterior it shares (its base, or itself)
  std::vector<std::optional<PlanningPosterior>> posteriors_;  // by prior action, made at its first attempt
  std::size_t observations_ = 0;
};

}  // namespace ontime
