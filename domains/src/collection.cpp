#include "ontime/domains/collection.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "ontime/domains/collection_journal.hpp"
#include "ontime/util/byte_packing.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/parallel.hpp"
#include "ontime/util/random.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime::domains {
namespace {

struct Outcome {
  RefinementAttempt attempt;
  std::optional<Configuration> end;
};

// Times in the log are rounded to microseconds: plenty for durations of seconds, and short.
// (With the checks unit a planning time of exactly k steps, k * step * rate checks, stays exact.)
double round_to_microseconds(double seconds) { return std::round(seconds * 1e6) / 1e6; }

// `before`: the action before this one in the tree, blamed when the attempt gives up (SeSamE's
// rule); null for an action without one, whose giving up is recorded as a cut-off then.
Outcome attempt_once(const Domain& domain, const std::string& action, const std::string* before,
                     const Configuration& start, std::uint64_t seed, const CollectionOptions& options) {
  const std::unique_ptr<Refinement> refinement = domain.refine(action, start, seed, options.effort);
  for (Steps step = 1; step <= options.budget_steps; ++step) {
    if (refinement->advance(static_cast<double>(step) * options.step_seconds) != RefinementStatus::working) break;
  }
  Outcome outcome;
  if (refinement->status() == RefinementStatus::backtrack && before != nullptr) outcome.attempt.backtrack = *before;
  outcome.attempt.action = action;
  outcome.attempt.planning_seconds = round_to_microseconds(refinement->effort().seconds());
  outcome.attempt.collision_checks = refinement->effort().checks();
  outcome.attempt.found = refinement->status() == RefinementStatus::found;
  if (outcome.attempt.found) {
    outcome.attempt.execution_seconds = round_to_microseconds(refinement->execution_seconds());
    outcome.end = refinement->final_configuration();
  }
  return outcome;
}

void check_options(const CollectionOptions& options) {
  if (!(std::isfinite(options.step_seconds) && options.step_seconds > 0)) {
    throw std::invalid_argument("the step must be a positive number of seconds");
  }
  if (options.budget_steps < 1) throw std::invalid_argument("the cut-off must be at least 1 step");
  if (options.effort.unit == EffortUnit::collision_checks && !(options.effort.checks_per_second > 0)) {
    throw std::invalid_argument("the checks per second must be positive");
  }
}

// Sends the outcomes of the trials this rank ran (`mine`) to every other rank and takes in
// theirs; returns how many trials the other ranks ran.
std::uint64_t exchange_outcomes(const Ranks& ranks, const std::vector<TreeAction>& tree,
                                const std::vector<std::pair<std::size_t, std::uint64_t>>& mine,
                                std::vector<std::vector<Outcome>>& outcomes, std::vector<std::vector<bool>>& done) {
  BytePacker packer;
  for (const auto& [a, t] : mine) {
    const Outcome& outcome = outcomes[a][t];
    packer.put<std::uint64_t>(a);
    packer.put(t);
    packer.put(outcome.attempt.planning_seconds);
    packer.put(outcome.attempt.found);
    packer.put(outcome.attempt.execution_seconds);
    packer.put(outcome.attempt.collision_checks);
    packer.put(outcome.attempt.backtrack.has_value());
    if (outcome.attempt.backtrack) packer.put_string(*outcome.attempt.backtrack);
    packer.put(outcome.end.has_value());
    if (outcome.end) packer.put_vector(*outcome.end);
  }
  const std::vector<std::string> parts = ranks.all_gather(packer.bytes());
  std::uint64_t received = 0;
  for (std::size_t r = 0; r < parts.size(); ++r) {
    if (static_cast<int>(r) == ranks.rank()) continue;
    ByteUnpacker unpacker(parts[r]);
    while (!unpacker.done()) {
      const auto a = static_cast<std::size_t>(unpacker.get<std::uint64_t>());
      const auto t = unpacker.get<std::uint64_t>();
      Outcome& outcome = outcomes.at(a).at(t);
      outcome.attempt.action = tree.at(a).action;
      outcome.attempt.trial = t;
      outcome.attempt.planning_seconds = unpacker.get<double>();
      outcome.attempt.found = unpacker.get<bool>();
      outcome.attempt.execution_seconds = unpacker.get<double>();
      outcome.attempt.collision_checks = unpacker.get<std::optional<std::uint64_t>>();
      if (unpacker.get<bool>()) outcome.attempt.backtrack = unpacker.get_string();
      if (unpacker.get<bool>()) outcome.end = unpacker.get_vector<double>();
      done[a][t] = true;
      ++received;
    }
  }
  return received;
}

}  // namespace

std::vector<TreeAction> skeleton_tree(const std::vector<std::vector<std::string>>& skeletons) {
  std::vector<TreeAction> tree;
  std::map<std::string, int> index_of;
  std::size_t longest = 0;
  for (const auto& skeleton : skeletons) longest = std::max(longest, skeleton.size());
  for (std::size_t position = 0; position < longest; ++position) {
    for (const auto& skeleton : skeletons) {
      if (position >= skeleton.size()) continue;
      const std::string& action = skeleton[position];
      if (index_of.contains(action)) continue;
      const int parent = position == 0 ? -1 : index_of.at(skeleton[position - 1]);
      index_of.emplace(action, static_cast<int>(tree.size()));
      tree.push_back(TreeAction{action, parent});
    }
  }
  return tree;
}

std::vector<TreeAction> every_action_list(const Domain& domain) {
  std::vector<TreeAction> list;
  for (const StandaloneAction& action : domain.every_action()) {
    list.push_back(TreeAction{action.action, -1, !action.from_initial_configuration});
  }
  if (list.empty()) throw UsageError("the " + domain.name() + " domain cannot list every action it refines");
  return list;
}

std::vector<TreeAction> collection_actions(const Domain& domain, const CollectionOptions& options) {
  if (options.every_action) return every_action_list(domain);
  std::vector<TreeAction> tree = skeleton_tree(domain.skeletons());
  if (tree.empty()) {
    throw UsageError("the " + domain.name() +
                     " world has no skeletons: collect every action on its own instead (--every-action)");
  }
  return tree;
}

CollectionResult collect(const Domain& domain, const CollectionOptions& options) {
  check_options(options);
  const auto started = std::chrono::steady_clock::now();
  const std::vector<TreeAction> tree = collection_actions(domain, options);
  // The feature vectors first, so that a world without what the extractor needs stops the
  // collection before any trial.
  std::vector<std::vector<double>> features(options.features ? tree.size() : 0);
  const std::string world_name =
      !options.features ? std::string() : (options.world_name.empty() ? domain.scene().title : options.world_name);
  for (std::size_t a = 0; a < features.size(); ++a) {
    try {
      features[a] = domain.action_features(tree[a].action);
    } catch (const std::invalid_argument& error) {
      throw UsageError(std::string("cannot record features: ") + error.what());
    }
  }
  const std::uint64_t total = options.trials * tree.size();
  std::uint64_t finished = 0;
  std::mutex progress_mutex;

  // outcomes[a][t]: trial t of action a, once run (or read back from the journal).
  std::vector<std::vector<Outcome>> outcomes(tree.size(), std::vector<Outcome>(options.trials));
  std::vector<std::vector<bool>> done(tree.size(), std::vector<bool>(options.trials, false));
  if (options.journal != nullptr) {
    for (const JournalTrial& trial : options.journal->finished()) {
      const std::uint64_t t = trial.attempt.trial.value();
      outcomes.at(trial.action).at(t) = Outcome{trial.attempt, trial.end};
      done[trial.action][t] = true;
      ++finished;
    }
  }

  // The actions in layers by their depth in the tree: an action's trials need the ends of its
  // parent's, so a layer starts once the layer before has ended; within a layer every trial of
  // every action is independent. (The tree lists parents before children.)
  std::vector<std::size_t> depth(tree.size(), 0);
  std::size_t layers = 0;
  for (std::size_t a = 0; a < tree.size(); ++a) {
    if (tree[a].parent >= 0) depth[a] = depth[static_cast<std::size_t>(tree[a].parent)] + 1;
    layers = std::max(layers, depth[a] + 1);
  }

  // ends[a]: end configurations of the successful refinements of action a, in trial order.
  std::vector<std::vector<Configuration>> ends(tree.size());
  const Ranks* ranks = options.ranks;
  for (std::size_t layer = 0; layer < layers; ++layer) {
    // The layer's trials still to run, in tree and trial order; each rank runs its interleaved
    // share of them (rank_units), a like share of every action.
    std::vector<std::pair<std::size_t, std::uint64_t>> pending;
    for (std::size_t a = 0; a < tree.size(); ++a) {
      if (depth[a] != layer) continue;
      for (std::uint64_t t = 0; t < options.trials; ++t) {
        if (!done[a][t]) pending.emplace_back(a, t);
      }
    }
    std::vector<std::pair<std::size_t, std::uint64_t>> mine;
    const RankUnits units = rank_units(pending.size(), ranks);
    for (std::uint64_t i = 0; i < units.count; ++i) mine.push_back(pending[units.unit(i)]);
    // A trial is seconds of planning: hand them out one by one.
    for_each_block(mine.size(), options.threads, 1, [&](unsigned) {
      return [&](std::uint64_t begin, std::uint64_t end) {
        for (std::uint64_t i = begin; i < end; ++i) {
          const auto [a, t] = mine[i];
          const TreeAction& node = tree[a];
          const std::vector<Configuration>* starts =
              node.parent < 0 ? nullptr : &ends[static_cast<std::size_t>(node.parent)];
          const std::uint64_t trial_seed = stream_seed(stream_seed(options.seed, a), t);
          Configuration start;
          if (starts == nullptr && !node.fallback_start) {
            start = domain.initial_configuration();
          } else if (starts != nullptr && !starts->empty()) {
            start = (*starts)[t % starts->size()];
          } else {
            start = domain.fallback_start(node.action, stream_seed(trial_seed, 1));
          }
          Outcome& outcome = outcomes[a][t];
          const std::string* before = node.parent < 0 ? nullptr : &tree[static_cast<std::size_t>(node.parent)].action;
          outcome = attempt_once(domain, node.action, before, start, stream_seed(trial_seed, 0), options);
          outcome.attempt.trial = t;
          if (options.journal != nullptr) options.journal->record(JournalTrial{a, outcome.attempt, outcome.end});
          if (options.progress) {
            const std::lock_guard lock(progress_mutex);
            options.progress(++finished, total);
          }
        }
      };
    });
    for (const auto& [a, t] : mine) done[a][t] = true;
    if (split_over_ranks(ranks)) {
      finished += exchange_outcomes(*ranks, tree, mine, outcomes, done);
      if (options.progress) options.progress(finished, total);
    }
    for (std::size_t a = 0; a < tree.size(); ++a) {
      if (depth[a] != layer) continue;
      for (const Outcome& outcome : outcomes[a]) {
        if (outcome.end) ends[a].push_back(*outcome.end);
      }
    }
  }

  CollectionResult result;
  result.log.reserve(total);
  for (std::size_t a = 0; a < outcomes.size(); ++a) {
    for (Outcome& outcome : outcomes[a]) {
      result.collision_checks += outcome.attempt.collision_checks.value_or(0);
      if (options.features) {
        outcome.attempt.world = world_name;
        outcome.attempt.features = features[a];
      }
      result.log.push_back(std::move(outcome.attempt));
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

std::vector<std::vector<Configuration>> refine_skeleton(const Domain& domain, const std::vector<std::string>& skeleton,
                                                        std::uint64_t seed, const CollectionOptions& options,
                                                        int attempts) {
  check_options(options);
  std::vector<std::vector<Configuration>> motions;  // motions[l]: the motion refined for position l
  std::vector<Configuration> ends;                  // ends[l]: where it ended
  std::vector<std::uint64_t> tried(skeleton.size(), 0), restarts(skeleton.size(), 0);
  while (motions.size() < skeleton.size()) {
    const std::size_t l = motions.size();
    const Configuration& at = l == 0 ? domain.initial_configuration() : ends.back();
    bool found = false;
    bool gave_up = false;  // the refiner blamed the action before: back to it at once (SeSamE)
    for (int attempt = 0; attempt < attempts && !found && !gave_up; ++attempt) {
      const std::uint64_t attempt_seed = stream_seed(stream_seed(seed, l), tried[l]++);
      const std::unique_ptr<Refinement> refinement = domain.refine(skeleton[l], at, attempt_seed, options.effort);
      RefinementStatus status = RefinementStatus::working;
      for (Steps step = 1; step <= options.budget_steps && status == RefinementStatus::working; ++step) {
        status = refinement->advance(static_cast<double>(step) * options.step_seconds);
      }
      found = status == RefinementStatus::found;
      gave_up = status == RefinementStatus::backtrack && l > 0;
      if (found) {
        motions.push_back(refinement->motion());
        ends.push_back(refinement->final_configuration());
      }
    }
    if (found) continue;
    if (l == 0 || restarts[l]++ == static_cast<std::uint64_t>(attempts)) {
      throw UsageError("no motion found for " + skeleton[l] + " in " + std::to_string(tried[l]) + " attempts of " +
                       std::to_string(options.budget_steps) + " steps each" +
                       (gave_up ? ", the last giving up on the motion of the action before it" : ""));
    }
    motions.pop_back();  // refine the action before anew, then this one from its new end
    ends.pop_back();
  }
  return motions;
}

}  // namespace ontime::domains
