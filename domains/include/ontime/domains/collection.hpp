#pragma once
// The collection pipeline: refine every action of a domain's skeleton tree many times and log
// every attempt (planner log, ontime/planner_log.hpp), ready for ontime::fit_problem.
//
// Trial t of an action starts where a successful refinement of the action before it ended:
// the (t mod m)-th of its m successful refinements, in trial order; a first action starts at
// the domain's initial configuration. (If no refinement of the action before succeeded, the
// domain draws a fallback start.) An attempt gets one step of effort at a time, exactly as an
// allocator would give it (advance(1 step), advance(2 steps), ...), and is cut off after
// `budget_steps` steps without a motion. An attempt that gives up (RefinementStatus::backtrack)
// ends there and is logged with `backtrack` naming the action before it in the tree (SeSamE's
// rule, docs/spec.md §7); an action without one (a first action, every_action) logs it as cut off.
//
// With CollectionOptions::every_action, the actions are instead every action the domain can
// refine, each on its own (every_action_list): a library that covers any skeleton.
//
// Determinism: trial t of the a-th action of the tree draws everything from
// stream_seed(stream_seed(seed, a), t), whichever thread runs it, and the log lists actions in
// tree order and trials in order. In the collision-checks effort unit the same seed therefore
// gives the same log byte for byte, for any number of threads or of MPI ranks
// (CollectionOptions::ranks), and a collection resumed from its journal (collection_journal.hpp)
// the same log as one never interrupted.
//
// The trials run layer by layer, a layer being the actions of one depth in the tree (a
// collection of every action is one layer): within a layer all trials are independent and go to
// the threads (and ranks) together, so a slow action does not hold up the others.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/model/distribution.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime::domains {

class CollectionJournal;

// The actions of the skeletons' prefix tree, parents before children (breadth first, in order
// of first appearance), each with the index of the action before it (-1 for a first action).
// An action without a parent starts at the domain's initial configuration, or, when
// `fallback_start` is set, at a start the domain draws (Domain::fallback_start) for each trial.
struct TreeAction {
  std::string action;
  int parent = -1;
  bool fallback_start = false;
};
// The prefix tree of `skeletons` (action ids) as described above.
std::vector<TreeAction> skeleton_tree(const std::vector<std::vector<std::string>>& skeletons);

// Domain::every_action() as actions without parents: those that may start at the initial
// configuration start there, every other one at a fallback start. Navigation: a move out of the
// start room starts at the start pose, any other move(Ri,Rj) at a collision-free pose drawn
// uniformly in Ri — the distribution of where a move(Rh,Ri) ends, since its goal pose is drawn
// uniformly among the collision-free poses of Ri. (Within a skeleton the end is also
// conditioned on that move having been found, which favours easy goals slightly.) Throws
// UsageError when the domain cannot list its actions.
std::vector<TreeAction> every_action_list(const Domain& domain);

struct CollectionOptions {
  std::uint64_t trials = 1000;  // attempts per action
  std::uint64_t seed = 1;
  unsigned threads = 0;  // 0: one per hardware thread
  EffortSettings effort;
  double step_seconds = 1.0;  // one step of effort
  Steps budget_steps = 1;     // cut-off
  // Collect every action of the domain on its own (every_action_list) instead of the actions of
  // its skeleton tree.
  bool every_action = false;
  // Every record carries the world's name (Domain::name) and the action's feature vector there
  // (Domain::action_features): a log of a corpus across worlds for conditional time models.
  bool features = false;
  std::string world_name;  // the name records carry with `features`; empty: the domain's scene title
  // Called with the number of attempts done and the total (from one thread at a time).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  // When set: trials it holds are taken from it instead of being run again, and every trial
  // run is recorded in it as soon as it is finished.
  CollectionJournal* journal = nullptr;
  // When set, the trials are split over these ranks (ontime/ranks.hpp; every rank makes the same
  // call with its own journal): each rank runs its share of a layer of the tree (the actions of
  // one depth) on its own threads, then the ranks exchange the outcomes, and every rank returns
  // the whole log, the same as one process's.
  const Ranks* ranks = nullptr;
};

struct CollectionResult {
  std::vector<RefinementAttempt> log;  // actions in collection_actions() order, trials in order
  std::uint64_t collision_checks = 0;  // over all attempts
  double seconds = 0;                  // wall-clock time of the collection
};

// The actions a collection with these options refines, in log order: every_action_list(domain)
// or skeleton_tree(domain.skeletons()); UsageError when that is empty.
std::vector<TreeAction> collection_actions(const Domain& domain, const CollectionOptions& options);

// Runs the collection described at the top: `options.trials` attempts of each of collection_actions(domain,
// options), logged in that order. UsageError as collection_actions, or when features cannot be recorded.
CollectionResult collect(const Domain& domain, const CollectionOptions& options);

// One refined motion per action of a skeleton, executed one after the other from the domain's
// initial configuration (for pictures). Each action gets up to `attempts` attempts of
// `budget_steps` steps from where the action before it ended; when all are cut off, the action
// before it is refined anew (some ends are hard to go on from) and the action tried again from
// there, up to `attempts` times per position; an attempt that gives up (backtrack) goes back to
// the action before at once. Throws ontime::UsageError when that fails too.
std::vector<std::vector<Configuration>> refine_skeleton(const Domain& domain, const std::vector<std::string>& skeleton,
                                                        std::uint64_t seed, const CollectionOptions& options,
                                                        int attempts = 20);

}  // namespace ontime::domains
