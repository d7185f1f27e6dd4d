#pragma once
// A domain's collection from start to instance (`ontime collect`, ontime.domains.collect_and_fit):
// every action of the skeleton tree (or, with every_action, every action the domain can refine)
// refined `trials` times with the real motion planner (collection.hpp), the planner log written
// (JSON lines or an OMPL benchmark log), the instance fitted from it (learn/fitting.hpp) and
// written. Every finished trial goes to a checkpoint first (collection_journal.hpp), so that an
// interrupted collection resumes (`resume`) to the same files; the checkpoint is deleted once the
// outputs are written.
//
// Settings left at 0 take the world file's (step, deadline, checker speed); the cut-off defaults
// to the deadline. Same seed, same files, whatever the threads or ranks (collision-checks effort).
// Cost: trials x actions refinements of up to the cut-off's effort each.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "ontime/domains/collection.hpp"
#include "ontime/domains/domain.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/util/memory.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime::domains {

struct CollectAndFitOptions {
  std::uint64_t trials = 1000;    // attempts per action
  std::uint64_t seed = 1;         // trial t of action a uses stream t of stream a
  unsigned threads = 0;           // 0: one per hardware thread
  std::string effort = "checks";  // or "wall"
  double checks_per_second = 0;   // 0: the world file's
  double step_seconds = 0;        // 0: the world file's
  Steps deadline = 0;             // of the instance; 0: the world file's
  Steps budget = 0;               // cut-off of an attempt in steps; 0: the deadline
  double laplace = 0;             // smoothing of the fit
  bool every_action = false;
  // Records carry the world (the world file's name without its extension) and the action's
  // feature vector there (CollectionOptions::features).
  bool features = false;
  std::string log_format = "jsonl";  // or "ompl-benchmark"
  std::filesystem::path log;
  std::filesystem::path instance;
  std::filesystem::path checkpoint;  // empty: the log's path followed by ".checkpoint"
  bool resume = false;
  const Ranks* ranks = nullptr;
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

// The collection these options ask of a domain with these defaults (progress and journal unset).
CollectionOptions collection_options(const DomainDefaults& defaults, const CollectAndFitOptions& options);
// The instance's deadline: the option's, else the world file's.
Steps collection_deadline(const DomainDefaults& defaults, const CollectAndFitOptions& options);
// Where the checkpoint goes.
std::filesystem::path checkpoint_path(const CollectAndFitOptions& options);

struct CollectAndFitResult {
  CollectionOptions collection;  // as run (progress and journal unset)
  Steps deadline = 0;
  CollectionResult result;
  std::size_t resumed_attempts = 0;  // taken from the checkpoint
  std::uint64_t found = 0;           // attempts that found a motion
  std::filesystem::path checkpoint;
  // The fit, on the root rank (which writes the files); other ranks only collect.
  std::optional<FitResult> fit;
};

// Collects, writes the log, fits and writes the instance. The world file's text is part of the
// checkpoint's identity. Throws UsageError for a checkpoint of an unfinished collection without
// `resume` (named as `spelling` writes it), an unknown log format or a domain without skeletons.
CollectAndFitResult collect_and_fit(const Domain& domain, const DomainDefaults& defaults,
                                    const std::filesystem::path& world, const CollectAndFitOptions& options,
                                    const ParameterSpelling& spelling = nullptr);

}  // namespace ontime::domains
