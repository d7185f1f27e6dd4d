#pragma once
// What a robot believes of a world's planning times while it refines there: a prediction (a
// conditional time model's, a library, a pooled fit) as the prior of every action, updated by each
// attempt the robot makes (found after t steps, or cut off after c steps without a motion) with
// the beta-Stacy posterior of online_update.hpp, and handed back as an instance whose planning
// distributions are the posterior means (docs/learning.md, "Online update").
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
// posterior, from that action's prior), and are all planned with its posterior. Execution times stay the
// prior's (the planning time is what a world's clutter and doors change most, and what the
// allocators' choices hinge on).
//
// Guarantees: an action never observed keeps its prior distribution bit for bit; the posterior
// of an observed one is PlanningPosterior's (conjugate: the order of the attempts does not
// matter; it tends to the Kaplan-Meier estimate of the action's own attempts). The horizon is the
// prior's deadline: an attempt found later, or cut off later, counts as cut off there. Cost:
// O(t) per attempt (no allocation after an action's first), O(actions x deadline) for believed().

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

  // One attempt on the action `id` names (by action_base_id); an attempt with no effort is no
  // data. Throws UsageError for an action the prior lacks.
  void observe(std::string_view id, const ActionAttempt& attempt);
  // Every attempt of one episode, by action index of `problem`, the episode's (Session::attempts,
  // EpisodeResult::attempts with its problem). Throws UsageError for sizes that differ or an
  // action the prior lacks (before observing any).
  void observe(const Problem& problem, std::span<const ActionAttempt> attempts);

  // The prior with every observed action's posterior mean as its planning distribution.
  Problem believed() const;
  // `structure` (an episode's problem, a world's instance) with the believed distributions, each
  // action by its id or its action_base_id (with_distributions_of). Throws UsageError for an action
  // the prior lacks, or another deadline or step.
  Problem believed_for(const Problem& structure) const;

  // The planning distribution believed for the action `id` names (UsageError if unknown).
  Distribution planning(std::string_view id) const;

  // The prior instance, as given.
  const Problem& prior() const noexcept { return prior_; }
  // The prior's worth in attempts, for every action.
  double strength() const noexcept { return strength_; }
  // Attempts observed so far (those with effort).
  std::size_t observations() const noexcept { return observations_; }

 private:
  // The prior action whose posterior learns from `id`: its base's when the prior has it.
  int index_of(std::string_view id) const;

  Problem prior_;
  double strength_;
  std::vector<int> base_;  // by prior action: the action whose posterior it shares (its base, or itself)
  std::vector<std::optional<PlanningPosterior>> posteriors_;  // by prior action, made at its first attempt
  std::size_t observations_ = 0;
};

}  // namespace ontime
