#include "ontime/domains/collection.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "ontime/domains/collection_journal.hpp"
#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/navigation_generator.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/util/error.hpp"
#include "support/mini_world.hpp"
#include "support/paper.hpp"
#include "support/thread_ranks.hpp"

namespace ontime::domains {
namespace {

const NavigationDomain& office() {
  static const NavigationDomain domain(load_navigation_world(testing::source_path("data/domains/navigation.json")));
  return domain;
}

CollectionOptions options(std::uint64_t trials, std::uint64_t seed, unsigned threads) {
  CollectionOptions result;
  result.trials = trials;
  result.seed = seed;
  result.threads = threads;
  result.effort = EffortSettings{EffortUnit::collision_checks, 1200.0};
  result.step_seconds = 3.0;
  result.budget_steps = 22;
  return result;
}

std::string text(const std::vector<RefinementAttempt>& log) {
  std::string all;
  for (const RefinementAttempt& attempt : log) all += planner_log_line(attempt);
  return all;
}

TEST(Collection, TheSkeletonTreeListsParentsFirst) {
  const std::vector<TreeAction> tree = skeleton_tree(office().skeletons());
  ASSERT_EQ(tree.size(), 15u);  // 16 positions, move(R1,R5) shared
  EXPECT_EQ(tree[0].action, "move(R1,R2)");
  EXPECT_EQ(tree[1].action, "move(R1,R5)");
  EXPECT_EQ(tree[2].action, "move(R1,R10)");
  for (std::size_t a = 0; a < tree.size(); ++a) {
    if (tree[a].parent >= 0) {
      EXPECT_LT(static_cast<std::size_t>(tree[a].parent), a);
      // The parent's move ends where this one starts.
      EXPECT_EQ(move_rooms(tree[static_cast<std::size_t>(tree[a].parent)].action)[1], move_rooms(tree[a].action)[0]);
    } else {
      EXPECT_EQ(move_rooms(tree[a].action)[0], "R1");
    }
  }
}

TEST(Collection, TheCheckUnitGivesIdenticalLogsForIdenticalSeedsWhateverTheThreads) {
  const CollectionResult one = collect(office(), options(3, 9, 1));
  const CollectionResult two = collect(office(), options(3, 9, 2));
  ASSERT_EQ(one.log.size(), 45u);
  EXPECT_EQ(text(one.log), text(two.log));
  EXPECT_EQ(one.collision_checks, two.collision_checks);
  const CollectionResult other = collect(office(), options(3, 10, 2));
  EXPECT_NE(text(one.log), text(other.log));
}

TEST(Collection, LogsEveryAttemptWithItsEffortAndCutsOffAtTheBudget) {
  CollectionOptions settings = options(4, 2, 2);
  settings.budget_steps = 2;  // 7200 checks: the narrow doors are often cut off
  const CollectionResult result = collect(office(), settings);
  ASSERT_EQ(result.log.size(), 60u);
  std::size_t cut_off = 0;
  for (std::size_t i = 0; i < result.log.size(); ++i) {
    const RefinementAttempt& attempt = result.log[i];
    EXPECT_EQ(attempt.trial, i % 4);
    ASSERT_TRUE(attempt.collision_checks.has_value());
    EXPECT_NEAR(attempt.planning_seconds, static_cast<double>(*attempt.collision_checks) / 1200.0, 5e-7);
    if (attempt.found) {
      EXPECT_GT(attempt.execution_seconds, 0.0);
    } else {
      ++cut_off;
      EXPECT_GE(*attempt.collision_checks, 7200u);
      EXPECT_EQ(whole_steps_within(attempt.planning_seconds, 3.0), 2);
    }
  }
  EXPECT_GT(cut_off, 0u);
}

TEST(Collection, DrawsAFallbackStartWhenNoRefinementOfTheParentSucceeded) {
  CollectionOptions settings = options(2, 1, 1);
  settings.budget_steps = 1;
  settings.effort.checks_per_second = 20;  // 60 checks a step: hardly anything is found
  const CollectionResult result = collect(office(), settings);
  ASSERT_EQ(result.log.size(), 30u);  // every action still gets its attempts
  const std::vector<TreeAction> tree = skeleton_tree(office().skeletons());
  std::map<std::string, int> found;
  for (const RefinementAttempt& attempt : result.log) found[attempt.action] += attempt.found ? 1 : 0;
  int orphans = 0;  // actions refined although no refinement of their parent succeeded
  for (const TreeAction& node : tree) {
    if (node.parent >= 0 && found[tree[static_cast<std::size_t>(node.parent)].action] == 0) ++orphans;
  }
  EXPECT_GT(orphans, 0);
}

TEST(Collection, RefinesAWholeSkeletonForPictures) {
  const auto motions = refine_skeleton(office(), office().skeletons()[3], 1, options(1, 1, 1));
  ASSERT_EQ(motions.size(), 4u);
  for (std::size_t l = 1; l < motions.size(); ++l) EXPECT_EQ(motions[l].front(), motions[l - 1].back());
  EXPECT_EQ(motions[0].front(), office().initial_configuration());
}

const ManipulationDomain& kitchen() {
  static const ManipulationDomain domain(
      load_manipulation_world(testing::source_path("data/domains/manipulation.json")));
  return domain;
}

// The kitchen's collection settings, cut off after `budget` steps.
CollectionOptions kitchen_options(std::uint64_t trials, std::uint64_t seed, unsigned threads, Steps budget) {
  CollectionOptions result = options(trials, seed, threads);
  result.effort.checks_per_second = kitchen().world().collection.checks_per_second;
  result.step_seconds = kitchen().world().collection.step_seconds;
  result.budget_steps = budget;
  return result;
}

std::filesystem::path fresh(const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / ("ontime_collection_test_" + name);
  std::filesystem::remove(path);
  return path;
}

std::string contents(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// An interruption after 20 attempts (an exception out of the progress callback, as a crash
// would stop the run), then a resumed run: the same log as an uninterrupted one.
TEST(CollectionJournal, AnInterruptedCollectionResumesToTheSameLog) {
  const CollectionOptions settings = options(3, 9, 2);
  const std::string whole = text(collect(office(), settings).log);
  const auto path = fresh("resume.checkpoint");
  {
    CollectionJournal journal(path, office(), settings, "world text", false);
    CollectionOptions interrupted = settings;
    interrupted.journal = &journal;
    interrupted.progress = [](std::uint64_t done, std::uint64_t) {
      if (done == 20) throw std::runtime_error("interrupted");
    };
    EXPECT_THROW(collect(office(), interrupted), std::runtime_error);
  }
  CollectionJournal journal(path, office(), settings, "world text", true);
  EXPECT_GE(journal.finished().size(), 20u);
  EXPECT_LT(journal.finished().size(), 45u);
  CollectionOptions resumed = settings;
  resumed.journal = &journal;
  resumed.threads = 1;
  std::uint64_t first_progress = 0;
  resumed.progress = [&](std::uint64_t done, std::uint64_t) {
    if (first_progress == 0) first_progress = done;
  };
  EXPECT_EQ(text(collect(office(), resumed).log), whole);
  EXPECT_EQ(first_progress, journal.finished().size() + 1);  // the resumed trials count as done
  journal.remove();
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(CollectionJournal, KeepsTheEndConfigurationsTheNextActionStartsFrom) {
  CollectionOptions settings = kitchen_options(1, 3, 1, 3);
  const auto path = fresh("kitchen.checkpoint");
  {
    CollectionJournal journal(path, kitchen(), settings, "kitchen", false);
    settings.journal = &journal;
    settings.progress = [](std::uint64_t done, std::uint64_t) {
      if (done == 3) throw std::runtime_error("interrupted");
    };
    EXPECT_THROW(collect(kitchen(), settings), std::runtime_error);
  }
  const CollectionJournal journal(path, kitchen(), settings, "kitchen", true);
  ASSERT_EQ(journal.finished().size(), 3u);
  for (const JournalTrial& trial : journal.finished()) {
    ASSERT_EQ(trial.end.has_value(), trial.attempt.found);
    if (trial.end) {
      EXPECT_EQ(trial.end->size(), kitchen().initial_configuration().size());  // robot and objects
    }
  }
  std::filesystem::remove(path);
}

TEST(CollectionJournal, RefusesAnotherCollectionAndNeverDropsWorkSilently) {
  const CollectionOptions settings = options(2, 4, 1);
  const auto path = fresh("refuse.checkpoint");
  {
    CollectionJournal journal(path, office(), settings, "world text", false);
    CollectionOptions with_journal = settings;
    with_journal.journal = &journal;
    collect(office(), with_journal);
  }
  const std::string full = contents(path);
  ASSERT_EQ(std::count(full.begin(), full.end(), '\n'), 31);  // the settings and 30 trials
  // Not resuming: refused (in the library's words, not the CLI's flags), the file kept.
  try {
    CollectionJournal(path, office(), settings, "world text", false);
    ADD_FAILURE() << "expected UsageError";
  } catch (const UsageError& error) {
    EXPECT_NE(std::string(error.what()).find("resume the collection or delete it"), std::string::npos) << error.what();
    EXPECT_EQ(std::string(error.what()).find("--"), std::string::npos) << error.what();
  }
  // Another seed or another world file: refused, naming the setting.
  CollectionOptions other = settings;
  other.seed = 5;
  try {
    CollectionJournal(path, office(), other, "world text", true);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "line 1");
    EXPECT_NE(error.rule().find("'seed' is 4 there, 5 here"), std::string::npos) << error.what();
  }
  EXPECT_THROW(CollectionJournal(path, office(), settings, "another world", true), InputError);
  // A last line cut short by a crash is dropped (and its trial run again).
  std::ofstream(path, std::ios::binary | std::ios::trunc) << full.substr(0, full.size() - 7);
  {
    const CollectionJournal journal(path, office(), settings, "world text", true);
    EXPECT_EQ(journal.finished().size(), 29u);
  }
  EXPECT_EQ(contents(path), full.substr(0, full.rfind('\n', full.size() - 2) + 1));
  // A damaged line in the middle is an error with its line number.
  std::string damaged = full;
  damaged.replace(damaged.find("\"record\""), 8, "\"recurd\"");
  std::ofstream(path, std::ios::binary | std::ios::trunc) << damaged;
  try {
    CollectionJournal(path, office(), settings, "world text", true);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "line 2");
  }
  std::filesystem::remove(path);
}

// A small generated building (2 x 3 rooms) without skeletons.
const NavigationDomain& small_building() {
  static const NavigationDomain domain([] {
    BuildingOptions building;
    building.rows = 2;
    building.cols = 3;
    building.seed = 5;
    return generate_navigation_world(building);
  }());
  return domain;
}

TEST(Collection, EveryActionCollectsEachDirectedDoorOnceFromItsOwnStart) {
  const NavigationDomain& domain = small_building();
  const NavigationWorld& world = domain.world();
  CollectionOptions settings = options(3, 4, 1);
  settings.every_action = true;
  const std::vector<TreeAction> actions = collection_actions(domain, settings);
  ASSERT_EQ(actions.size(), 2 * world.doors.size());
  std::set<std::pair<std::string, std::string>> moves;
  for (const TreeAction& node : actions) {
    EXPECT_EQ(node.parent, -1);
    const std::vector<std::string> rooms = move_rooms(node.action);
    moves.emplace(rooms.at(0), rooms.at(1));
    // Out of the start room from the start pose; any other move from a pose drawn in its room.
    EXPECT_EQ(node.fallback_start, rooms[0] != world.start_room) << node.action;
  }
  for (const Door& door : world.doors) {
    EXPECT_EQ(moves.count({door.rooms[0], door.rooms[1]}), 1u);
    EXPECT_EQ(moves.count({door.rooms[1], door.rooms[0]}), 1u);
  }

  const CollectionResult one = collect(domain, settings);
  settings.threads = 2;
  const CollectionResult two = collect(domain, settings);
  ASSERT_EQ(one.log.size(), 3 * actions.size());
  EXPECT_EQ(text(one.log), text(two.log));
  EXPECT_EQ(one.collision_checks, two.collision_checks);
  for (std::size_t i = 0; i < one.log.size(); ++i) {
    EXPECT_EQ(one.log[i].action, actions[i / 3].action);
    EXPECT_EQ(one.log[i].trial, i % 3);
  }
  // The log fits as a library: one single-action skeleton per directed door, in log order.
  const SkeletonList library = single_action_skeletons(one.log, "every.jsonl");
  ASSERT_EQ(library.skeletons.size(), actions.size());
  for (std::size_t a = 0; a < actions.size(); ++a) {
    EXPECT_EQ(library.skeletons[a], std::vector<std::string>{actions[a].action});
  }
  FitOptions fit;
  fit.step_seconds = 3.0;
  fit.deadline = 22;
  const FitResult fitted = fit_problem(one.log, "every.jsonl", library, fit);
  EXPECT_EQ(fitted.problem.skeleton_count(), static_cast<int>(actions.size()));
}

TEST(Collection, AWorldWithoutSkeletonsNeedsEveryAction) {
  EXPECT_TRUE(small_building().skeletons().empty());
  EXPECT_THROW(collect(small_building(), options(1, 1, 1)), UsageError);
  // A domain that cannot list its actions refuses the every-action collection.
  CollectionOptions settings = kitchen_options(1, 1, 1, 1);
  settings.every_action = true;
  EXPECT_THROW(collect(kitchen(), settings), UsageError);
}

// The office floor without features (Domain's defaults): a domain whose extractor cannot describe
// its actions.
class Featureless final : public Domain {
 public:
  const std::string& name() const override { return office().name(); }
  const std::vector<std::vector<std::string>>& skeletons() const override { return office().skeletons(); }
  Configuration initial_configuration() const override { return office().initial_configuration(); }
  std::unique_ptr<Refinement> refine(const std::string& action, const Configuration& start, std::uint64_t seed,
                                     const EffortSettings& effort) const override {
    return office().refine(action, start, seed, effort);
  }
  Configuration fallback_start(const std::string& action, std::uint64_t seed) const override {
    return office().fallback_start(action, seed);
  }
  Scene scene() const override { return office().scene(); }
  std::vector<std::array<double, 2>> trace(const std::vector<Configuration>& motion) const override {
    return office().trace(motion);
  }
  std::vector<std::array<double, 2>> outline(const Configuration& configuration) const override {
    return office().outline(configuration);
  }
};

// With features, every record names its world and carries its action's feature vector there;
// the times are those of the collection without them. A domain without features refuses before
// any trial; the kitchen's records carry its features.
TEST(Collection, FeaturesNameTheWorldAndDescribeEachAction) {
  CollectionOptions plain = options(2, 6, 2);
  plain.every_action = true;
  CollectionOptions described = plain;
  described.features = true;
  described.world_name = "building-s6";
  const std::vector<RefinementAttempt> without = collect(small_building(), plain).log;
  const std::vector<RefinementAttempt> with = collect(small_building(), described).log;
  ASSERT_EQ(with.size(), without.size());
  for (std::size_t i = 0; i < with.size(); ++i) {
    EXPECT_EQ(with[i].world, "building-s6");
    EXPECT_EQ(with[i].features, small_building().action_features(with[i].action)) << with[i].action;
    EXPECT_EQ(with[i].features.size(), small_building().feature_names().size());
    RefinementAttempt stripped = with[i];
    stripped.world.reset();
    stripped.features.clear();
    EXPECT_EQ(stripped, without[i]);
  }
  CollectionOptions refused = options(1, 1, 1);
  refused.features = true;
  refused.progress = [](std::uint64_t, std::uint64_t) { FAIL() << "a trial ran"; };
  EXPECT_THROW(collect(Featureless(), refused), UsageError);

  CollectionOptions kitchen_features = kitchen_options(1, 1, 2, 1);
  kitchen_features.features = true;
  const std::vector<RefinementAttempt> kitchen_log = collect(kitchen(), kitchen_features).log;
  ASSERT_EQ(kitchen_log.size(), 36u);
  for (const RefinementAttempt& attempt : kitchen_log) {
    EXPECT_EQ(attempt.world, "kitchen-manipulation");
    EXPECT_EQ(attempt.features, kitchen().action_features(attempt.action)) << attempt.action;
    EXPECT_EQ(attempt.features.size(), kitchen().feature_names().size());
  }
}

TEST(CollectionJournal, AnEveryActionCollectionResumesToTheSameLog) {
  CollectionOptions settings = options(2, 6, 2);
  settings.every_action = true;
  const std::string whole = text(collect(small_building(), settings).log);
  const auto path = fresh("every-action.checkpoint");
  {
    CollectionJournal journal(path, small_building(), settings, "world text", false);
    CollectionOptions interrupted = settings;
    interrupted.journal = &journal;
    interrupted.progress = [](std::uint64_t done, std::uint64_t) {
      if (done == 10) throw std::runtime_error("interrupted");
    };
    EXPECT_THROW(collect(small_building(), interrupted), std::runtime_error);
  }
  EXPECT_NE(contents(path).find("\"every_action\":true"), std::string::npos);
  CollectionJournal journal(path, small_building(), settings, "world text", true);
  EXPECT_GE(journal.finished().size(), 10u);
  CollectionOptions resumed = settings;
  resumed.journal = &journal;
  resumed.threads = 1;
  EXPECT_EQ(text(collect(small_building(), resumed).log), whole);
  journal.remove();
}

TEST(Collection, TheKitchenGivesIdenticalLogsForIdenticalSeedsWhateverTheThreads) {
  CollectionOptions settings = kitchen_options(2, 5, 1, 2);
  const CollectionResult one = collect(kitchen(), settings);
  settings.threads = 2;
  const CollectionResult two = collect(kitchen(), settings);
  ASSERT_EQ(one.log.size(), 72u);
  EXPECT_EQ(text(one.log), text(two.log));
  std::size_t found = 0;
  for (const RefinementAttempt& attempt : one.log) found += attempt.found ? 1 : 0;
  EXPECT_GT(found, 20u);
}

// Split over ranks (played by threads here), a collection gives every rank one process's log.
TEST(Collection, RanksCollectTheLogOfOneProcess) {
  CollectionOptions settings = options(5, 9, 1);
  const std::string whole = text(collect(office(), settings).log);
  CollectionOptions every = options(2, 6, 1);
  every.every_action = true;
  const std::string every_whole = text(collect(small_building(), every).log);
  for (const int size : {2, 3}) {
    std::vector<std::string> logs(static_cast<std::size_t>(size)), every_logs(static_cast<std::size_t>(size));
    testing::run_on_ranks(size, [&](const Ranks& ranks) {
      CollectionOptions split = settings;
      split.ranks = &ranks;
      logs[static_cast<std::size_t>(ranks.rank())] = text(collect(office(), split).log);
      CollectionOptions every_split = every;
      every_split.ranks = &ranks;
      every_logs[static_cast<std::size_t>(ranks.rank())] = text(collect(small_building(), every_split).log);
    });
    for (int rank = 0; rank < size; ++rank) {
      EXPECT_EQ(logs[static_cast<std::size_t>(rank)], whole) << size << " ranks, rank " << rank;
      EXPECT_EQ(every_logs[static_cast<std::size_t>(rank)], every_whole) << size << " ranks, rank " << rank;
    }
  }
}

// Each rank journals its own trials in its own file; a collection cut short on 2 ranks resumes
// on 3 ranks, or on one process, to the log of an uninterrupted one, and then the files go.
TEST(CollectionJournal, EveryRanksFinishedTrialsResumeUnderAnyNumberOfRanks) {
  const CollectionOptions settings = options(4, 9, 1);
  const std::string whole = text(collect(office(), settings).log);
  for (const int resumed_on : {1, 3}) {
    const auto path = fresh("ranks.checkpoint");
    testing::run_on_ranks(2, [&](const Ranks& ranks) {
      CollectionJournal journal(path, office(), settings, "world text", false, &ranks);
      CollectionOptions interrupted = settings;
      interrupted.journal = &journal;
      interrupted.ranks = &ranks;
      // Both ranks stop within the first layer (6 trials each), as a cancelled job would.
      interrupted.progress = [](std::uint64_t done, std::uint64_t) {
        if (done == 3) throw std::runtime_error("cancelled");
      };
      EXPECT_THROW(collect(office(), interrupted), std::runtime_error);
    });
    ASSERT_TRUE(std::filesystem::exists(path));
    ASSERT_TRUE(std::filesystem::exists(CollectionJournal::part_path(path, 1)));
    EXPECT_EQ(CollectionJournal::parts(path).size(), 2u);
    EXPECT_THROW(CollectionJournal(path, office(), settings, "world text", false), UsageError);
    {
      const CollectionJournal read(path, office(), settings, "world text", true);
      EXPECT_EQ(read.finished().size(), 6u);  // 3 trials from each rank's file
    }
    std::vector<std::string> logs(static_cast<std::size_t>(resumed_on));
    testing::run_on_ranks(resumed_on, [&](const Ranks& ranks) {
      CollectionJournal journal(path, office(), settings, "world text", true, &ranks);
      CollectionOptions resumed = settings;
      resumed.journal = &journal;
      resumed.ranks = &ranks;
      logs[static_cast<std::size_t>(ranks.rank())] = text(collect(office(), resumed).log);
      journal.remove();
    });
    for (const std::string& log : logs) EXPECT_EQ(log, whole) << "resumed on " << resumed_on;
    EXPECT_TRUE(CollectionJournal::parts(path).empty()) << "resumed on " << resumed_on;
    EXPECT_FALSE(std::filesystem::exists(CollectionJournal::part_path(path, 2)));
  }
}

const ManipulationDomain& grasp_kitchen() {
  static const ManipulationDomain domain(
      load_manipulation_world(testing::source_path("data/domains/kitchen-grasps.json")));
  return domain;
}

// In the kitchen whose cubby takes only one pair of grasps, a place with another grasp gives up
// after the world's placement draws and blames the pick before it (SeSamE's rule): the log names
// it, ranks exchange the record whole, and without the budget the same attempts never end.
TEST(Collection, APlaceThatGivesUpBlamesThePickBeforeIt) {
  const ManipulationWorld& world = grasp_kitchen().world();
  CollectionOptions settings = options(3, 1, 2);
  settings.effort.checks_per_second = world.collection.checks_per_second;
  settings.step_seconds = world.collection.step_seconds;
  settings.budget_steps = 20;
  const CollectionResult result = collect(grasp_kitchen(), settings);
  ASSERT_EQ(result.log.size(), 15u);
  std::map<std::string, int> backtracked, found;
  for (const RefinementAttempt& attempt : result.log) {
    if (attempt.backtrack) {
      ++backtracked[attempt.action];
      EXPECT_FALSE(attempt.found);
      EXPECT_GT(attempt.planning_seconds, 0);
      EXPECT_LT(attempt.planning_seconds, 20 * settings.step_seconds) << "gave up before the cut-off";
      if (attempt.action == "move+place(B1,S)") {
        EXPECT_EQ(*attempt.backtrack, "move+pick(B1)");
      }
      if (attempt.action == "move+place(B1,S)[B1]") {
        EXPECT_EQ(*attempt.backtrack, "move+pick(B1)[B1]");
      }
    }
    found[attempt.action] += attempt.found ? 1 : 0;
  }
  // The direct placement is infeasible: every attempt gives up; picks never do.
  EXPECT_EQ(backtracked["move+place(B1,S)"], 3);
  EXPECT_EQ(backtracked["move+pick(B1)"], 0);
  EXPECT_EQ(found["move+pick(B1)"], 3);

  testing::run_on_ranks(2, [&](const Ranks& ranks) {
    CollectionOptions split = settings;
    split.ranks = &ranks;
    EXPECT_EQ(text(collect(grasp_kitchen(), split).log), text(result.log)) << "rank " << ranks.rank();
  });

  ManipulationWorld patient = world;
  patient.planner.placement_draws = 0;
  const ManipulationDomain never_gives_up(patient);
  settings.budget_steps = 6;
  for (const RefinementAttempt& attempt : collect(never_gives_up, settings).log) {
    EXPECT_FALSE(attempt.backtrack.has_value()) << attempt.action;
    if (attempt.action == "move+place(B1,S)") {
      EXPECT_FALSE(attempt.found);
      EXPECT_GE(attempt.planning_seconds, 6 * settings.step_seconds) << "cut off at the budget";
    }
  }
}

}  // namespace
}  // namespace ontime::domains
