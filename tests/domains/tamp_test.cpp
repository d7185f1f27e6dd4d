// The pieces of the TAMP loop over a real planner: room paths streamed in order of length, the
// streaming planner world's prefix tree of actions, whole streaming episodes, the domain's task
// planner and skeleton drawing as the Domain interface gives them, and the loop (run_tamp).

#include "ontime/domains/tamp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/domains/library_messages.hpp"
#include "ontime/domains/manipulation.hpp"
#include "ontime/domains/manipulation_world.hpp"
#include "ontime/domains/navigation.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/domains/task_planner.hpp"
#include "ontime/learn/online_belief.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/episode_runner.hpp"
#include "ontime/util/error.hpp"
#include "support/paper.hpp"

namespace ontime::domains {
namespace {

struct Fixture {
  NavigationDomain domain{load_navigation_world(testing::source_path("data/domains/navigation.json"))};
  Problem library{load_problem(testing::source_path("data/instances/navigation.json"))};
  PlannerWorldOptions options{EffortSettings{EffortUnit::collision_checks, 1200.0}, false, std::nullopt};
};

const Fixture& fixture() {
  static const Fixture instance;
  return instance;
}

std::vector<std::string> moves_of(const std::vector<std::string>& rooms) {
  std::vector<std::string> moves;
  for (std::size_t i = 1; i < rooms.size(); ++i) moves.push_back("move(" + rooms[i - 1] + "," + rooms[i] + ")");
  return moves;
}

std::vector<std::vector<std::string>> read_all(TaskPlanner& planner) {
  std::vector<std::vector<std::string>> paths;
  while (auto path = planner.next()) paths.push_back(*path);
  return paths;
}

TEST(RoomPaths, EverySimplePathOnceInOrderOfLength) {
  const NavigationWorld& world = fixture().domain.world();
  const auto planner = room_path_planners(world)();
  const std::vector<std::vector<std::string>> paths = read_all(*planner);
  // The same set as the world's own enumeration of simple room paths.
  std::set<std::vector<std::string>> expected;
  for (const auto& rooms : world.room_paths(world.start_room, world.goal_room)) expected.insert(moves_of(rooms));
  EXPECT_EQ(std::set<std::vector<std::string>>(paths.begin(), paths.end()), expected);
  EXPECT_EQ(paths.size(), expected.size());
  for (std::size_t k = 1; k < paths.size(); ++k) {
    EXPECT_LE(room_path_length(world, paths[k - 1]), room_path_length(world, paths[k]) + 1e-9) << "path " << k;
  }
  // Started over, and from a second planner of the same factory: the same sequence.
  planner->restart();
  EXPECT_EQ(read_all(*planner), paths);
  const TaskPlannerFactory factory = room_path_planners(world, 2);
  const auto first = factory();
  EXPECT_EQ(read_all(*first), std::vector<std::vector<std::string>>(paths.begin(), paths.begin() + 2));
}

// igraph's warnings reach the program through the library-message sink, never standard error
// raw. A world changed after it was read (the reader refuses an unreachable goal) makes igraph
// warn that it cannot reach the goal; the planner then finds no path.
TEST(RoomPaths, IgraphsWarningsGoThroughTheMessageSink) {
  NavigationWorld world = fixture().domain.world();
  std::erase_if(world.doors, [&world](const Door& door) {
    return door.rooms[0] == world.goal_room || door.rooms[1] == world.goal_room;
  });
  std::vector<std::string> messages;
  set_library_message_sink([&messages](std::string_view library, LibraryMessageLevel level, std::string_view text) {
    messages.push_back(std::string(library) + (level == LibraryMessageLevel::warning ? " warning: " : " error: ") +
                       std::string(text));
  });
  ::testing::internal::CaptureStderr();
  const auto planner = room_path_planners(world)();
  EXPECT_FALSE(planner->next().has_value());
  const std::string printed = ::testing::internal::GetCapturedStderr();
  set_library_message_sink(nullptr);
  EXPECT_EQ(printed, "");
  ASSERT_EQ(messages.size(), 1U);
  EXPECT_EQ(messages[0], "igraph warning: Couldn't reach some vertices");
}

// Hands out the given skeletons in order.
class ListPlanner final : public TaskPlanner {
 public:
  explicit ListPlanner(std::vector<std::vector<std::string>> skeletons) : skeletons_(std::move(skeletons)) {}
  void restart() override { next_ = 0; }
  std::optional<std::vector<std::string>> next() override {
    if (next_ >= skeletons_.size()) return std::nullopt;
    return skeletons_[next_++];
  }

 private:
  std::vector<std::vector<std::string>> skeletons_;
  std::size_t next_ = 0;
};

TEST(StreamingPlannerWorld, SkeletonsShareTheirPrefixAndAMoveReachedAnotherWayIsANewAction) {
  const Fixture& f = fixture();
  StreamingWorldOptions streaming;
  streaming.library = &f.library;
  streaming.seconds_per_skeleton = 0.5;
  streaming.task_planners = [] {
    return std::make_unique<ListPlanner>(std::vector<std::vector<std::string>>{
        {"move(R1,R5)", "move(R5,R6)"}, {"move(R1,R5)", "move(R5,R8)"}, {"move(R1,R2)", "move(R5,R8)"}});
  };
  PlannerWorld world(f.domain, streaming, f.options);
  world.begin_episode(3);
  const auto first = world.next_skeleton();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->action_ids, (std::vector<std::string>{"move(R1,R5)", "move(R5,R6)"}));
  EXPECT_EQ(first->new_actions.size(), 2u);
  EXPECT_EQ(first->charged_seconds, 0.5);
  const auto second = world.next_skeleton();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->action_ids, (std::vector<std::string>{"move(R1,R5)", "move(R5,R8)"}));
  ASSERT_EQ(second->new_actions.size(), 1u);  // the first move is shared
  const auto third = world.next_skeleton();
  ASSERT_TRUE(third);
  EXPECT_EQ(third->action_ids, (std::vector<std::string>{"move(R1,R2)", "move(R5,R8)#2"}));
  ASSERT_EQ(third->new_actions.size(), 2u);
  const Action& copy = third->new_actions[1];
  const Action& original = f.library.action(f.library.find_action("move(R5,R8)"));
  EXPECT_EQ(copy.id, "move(R5,R8)#2");
  EXPECT_EQ(copy.planning.mean_finite(), original.planning.mean_finite());
  EXPECT_EQ(copy.execution.mean_finite(), original.execution.mean_finite());
  EXPECT_FALSE(world.next_skeleton());
  // The episode's actions: the prefix tree, each with the domain's action and its parent.
  ASSERT_EQ(world.actions().size(), 5u);
  EXPECT_EQ(world.actions()[4].action, "move(R5,R8)");
  EXPECT_EQ(world.actions()[4].parent, 3);
  // A new episode starts the tree and the task planner over.
  world.begin_episode(4);
  EXPECT_TRUE(world.actions().empty());
  EXPECT_EQ(world.next_skeleton()->action_ids, first->action_ids);
}

TEST(StreamingPlannerWorld, AnActionMissingFromTheLibraryIsRefused) {
  const Fixture& f = fixture();
  StreamingWorldOptions streaming;
  streaming.library = &f.library;
  streaming.task_planners = [] {
    return std::make_unique<ListPlanner>(std::vector<std::vector<std::string>>{{"move(R1,R6)"}});
  };
  PlannerWorld world(f.domain, streaming, f.options);
  world.begin_episode(1);
  EXPECT_THROW(world.next_skeleton(), std::invalid_argument);
}

TEST(StreamingPlannerWorld, WholeEpisodesOnTheRealPlannerAreTheSameForAnyThreadCount) {
  const Fixture& f = fixture();
  StreamingWorldOptions streaming;
  streaming.library = &f.library;
  streaming.task_planners = room_path_planners(f.domain.world());
  streaming.seconds_per_skeleton = 0.5;
  StreamingRun run;
  run.deadline = 15;
  run.step_seconds = f.library.step_seconds();
  run.period = 2;
  run.max_skeletons = 4;
  run.make_allocator = [](const Mdp& mdp) { return make_allocator_factory("dp-rerun", mdp)(); };
  MonteCarloOptions options;
  options.episodes = 16;
  options.seed = 2;
  options.live = LiveRun{};
  std::vector<int> found(options.episodes, 0);
  options.on_episode = [&found](std::uint64_t episode, const EpisodeResult& result) {
    found[episode] = result.skeletons;
  };
  options.threads = 1;
  const MonteCarloResult one =
      run_streaming_episodes(run, streaming_planner_worlds(f.domain, streaming, f.options), options);
  const std::vector<int> found_one = found;
  options.threads = 2;
  const MonteCarloResult two =
      run_streaming_episodes(run, streaming_planner_worlds(f.domain, streaming, f.options), options);
  EXPECT_EQ(one.successes, two.successes);
  EXPECT_EQ(found, found_one);
  for (const int skeletons : found) {
    EXPECT_GE(skeletons, 1);
    EXPECT_LE(skeletons, 4);
  }
  // Each skeleton's 0.5 s of search is charged: at least the first one's in every episode.
  EXPECT_GE(one.live_mean.outside, 0.5);
  EXPECT_GT(one.successes, 0u);
}

// Through the Domain interface: navigation streams its room paths in order of length and draws
// them; a domain without a task planner of its own streams its fixed skeletons and draws none.
TEST(DomainInterface, TaskPlannersAndSkeletonPointsOfEachDomain) {
  const Fixture& f = fixture();
  const Domain& navigation = f.domain;
  const auto streamed = read_all(*navigation.task_planners(3)());
  EXPECT_EQ(streamed, read_all(*room_path_planners(f.domain.world(), 3)()));
  ASSERT_EQ(streamed.size(), 3U);
  EXPECT_EQ(navigation.skeleton_points(streamed[0]), room_path_points(f.domain.world(), streamed[0]));
  const LoadedDomain kitchen = load_domain("manipulation", testing::source_path("data/domains/manipulation.json"));
  EXPECT_EQ(read_all(*kitchen.domain->task_planners(16)()), kitchen.domain->skeletons());
  EXPECT_TRUE(kitchen.domain->skeleton_points(kitchen.domain->skeletons().front()).empty());
}

// dp-rerun on the office's first three room paths, 45 s, on the modelled clock, every episode kept.
TampOptions modelled_tamp(std::uint64_t episodes, std::uint64_t seed) {
  TampOptions options;
  options.solver = "dp-rerun";
  options.deadline = 45;
  options.effort = EffortSettings{EffortUnit::collision_checks, 1200.0};
  options.episodes = episodes;
  options.seed = seed;
  options.max_skeletons = 3;
  options.thinking = ThinkingModel{};
  options.keep_episodes = true;
  options.world_name = "navigation.json";
  options.threads = 1;
  return options;
}

// The loop on the modelled clock: the same episodes for any thread count, every one kept with the
// skeletons found, and the drawn episode the same as the run's.
TEST(RunTamp, TheModelledClockGivesTheSameEpisodesForAnyThreadCount) {
  const Fixture& f = fixture();
  TampOptions options = modelled_tamp(4, 3);
  options.picture_episode = 2;
  const TampResult one = run_tamp(f.domain, f.library, options);
  options.threads = 2;
  const TampResult two = run_tamp(f.domain, f.library, options);
  EXPECT_EQ(one.deadline_steps, 15);
  EXPECT_EQ(one.summary.successes, two.summary.successes);
  EXPECT_EQ(one.mean_skeletons_found, two.mean_skeletons_found);
  ASSERT_EQ(one.episodes.size(), 4U);
  for (std::size_t e = 0; e < one.episodes.size(); ++e) {
    EXPECT_EQ(one.episodes[e].status, two.episodes[e].status) << e;
    EXPECT_EQ(one.episodes[e].live.elapsed, two.episodes[e].live.elapsed) << e;
    EXPECT_GE(one.episodes[e].skeletons, 1);
  }
  ASSERT_TRUE(one.picture.has_value());
  EXPECT_EQ(one.picture->result.status, one.episodes[2].status);
  EXPECT_EQ(one.picture->result.live.elapsed, one.episodes[2].live.elapsed);
  EXPECT_EQ(static_cast<int>(one.picture->drawing.skeletons.size()), one.episodes[2].skeletons);
  for (const EpisodeSkeleton& skeleton : one.picture->drawing.skeletons) EXPECT_GE(skeleton.points.size(), 3U);

  options.deadline = 2;
  EXPECT_THROW(run_tamp(f.domain, f.library, options), UsageError);
}

// Learning across episodes (the online update), planning first and acting while planning (SPEC
// §10): sequences give the same episodes for any thread count, each sequence's first episode is the
// plain run's episode of the same index (it plans with the library itself), and the successes by
// episode add up to the run's.
class RunTampLearning : public ::testing::TestWithParam<Acting> {};

TEST_P(RunTampLearning, SequencesThatLearnAcrossEpisodesStartFromTheLibraryAndReproduce) {
  const Fixture& f = fixture();
  TampOptions options = modelled_tamp(6, 5);
  options.acting = GetParam();
  const TampResult plain = run_tamp(f.domain, f.library, options);

  options.episodes = 3;
  options.adaptation = TampAdaptation{.strength = 1.0, .sequences = 2};
  const TampResult one = run_tamp(f.domain, f.library, options);
  options.threads = 2;
  const TampResult two = run_tamp(f.domain, f.library, options);
  ASSERT_EQ(one.episodes.size(), 6U);
  ASSERT_EQ(one.successes_by_episode.size(), 3U);
  EXPECT_EQ(one.successes_by_episode, two.successes_by_episode);
  EXPECT_EQ(one.successes_by_episode[0] + one.successes_by_episode[1] + one.successes_by_episode[2],
            one.summary.successes);
  EXPECT_EQ(one.summary.episodes, 6U);
  for (std::size_t e = 0; e < 6; ++e) {
    EXPECT_EQ(one.episodes[e].status, two.episodes[e].status) << e;
    EXPECT_EQ(one.episodes[e].live.elapsed, two.episodes[e].live.elapsed) << e;
  }
  for (const std::size_t first : {std::size_t{0}, std::size_t{3}}) {
    EXPECT_EQ(one.episodes[first].status, plain.episodes[first].status) << first;
    EXPECT_EQ(one.episodes[first].live.elapsed, plain.episodes[first].live.elapsed) << first;
    EXPECT_EQ(one.episodes[first].attempts.size(), plain.episodes[first].attempts.size()) << first;
  }
  // Every episode saw some effort on some action: what the next one learns from.
  for (const EpisodeResult& episode : one.episodes) {
    Steps effort = 0;
    for (const ActionAttempt& attempt : episode.attempts) effort += attempt.effort;
    EXPECT_GT(effort, 0);
  }

  options.adaptation = TampAdaptation{.strength = 0.0, .sequences = 2};
  EXPECT_THROW(run_tamp(f.domain, f.library, options), UsageError);
  options.adaptation = TampAdaptation{.strength = 1.0, .sequences = 0};
  EXPECT_THROW(run_tamp(f.domain, f.library, options), UsageError);
  options.adaptation = TampAdaptation{.strength = 1.0, .sequences = 2};
  options.picture_episode = 0;
  EXPECT_THROW(run_tamp(f.domain, f.library, options), UsageError);
}

INSTANTIATE_TEST_SUITE_P(BothActingModes, RunTampLearning, ::testing::Values(Acting::plan_first, Acting::concurrent),
                         [](const ::testing::TestParamInfo<Acting>& mode) {
                           return mode.param == Acting::concurrent ? std::string("Concurrent")
                                                                   : std::string("PlanFirst");
                         });

// The kitchen whose cubby takes one pair of grasps (a refinement there gives up and blames the grasp,
// SPEC §7), with data/instances/kitchen-grasps.json as the library and a prior of strength 10:
// every sequence learns planning and backtracking together, and every episode plans with a valid
// believed library. The sessions record each attempt as the planner made it: every backtrack the
// world counted ends one attempt as backtracked, and every refinement it started is one attempt,
// ended or current; each sequence's first episode is the run without learning.
TEST(RunTamp, SequencesInAKitchenThatBacktracksLearnPlanningAndBacktrackingTogether) {
  const ManipulationDomain domain(load_manipulation_world(testing::source_path("data/domains/kitchen-grasps.json")));
  const Problem library = load_problem(testing::source_path("data/instances/kitchen-grasps.json"));
  TampOptions options = modelled_tamp(6, 1);
  options.deadline = 280;  // 40 steps of 7 s
  options.effort = EffortSettings{EffortUnit::collision_checks, domain.world().collection.checks_per_second};
  options.max_skeletons = 16;
  options.world_name = "kitchen-grasps.json";
  const TampResult plain = run_tamp(domain, library, options);
  options.episodes = 3;
  options.adaptation = TampAdaptation{.strength = 10.0, .sequences = 2};
  const TampResult learning = run_tamp(domain, library, options);
  ASSERT_EQ(learning.episodes.size(), 6U);
  ASSERT_EQ(learning.successes_by_episode.size(), 3U);
  EXPECT_EQ(learning.successes_by_episode[0] + learning.successes_by_episode[1] + learning.successes_by_episode[2],
            learning.summary.successes);
  for (const std::size_t first : {std::size_t{0}, std::size_t{3}}) {
    EXPECT_EQ(learning.episodes[first].status, plain.episodes[first].status) << first;
    EXPECT_EQ(learning.episodes[first].live.elapsed, plain.episodes[first].live.elapsed) << first;
  }
  std::size_t backtracked = 0, attempts = 0;
  for (const EpisodeResult& episode : learning.episodes) {
    for (const ActionAttempt& attempt : episode.attempts) {
      attempts += attempt.ended.size() + (attempt.effort > 0 ? 1 : 0);
      for (const EndedAttempt& ended : attempt.ended) backtracked += ended.backtracked ? 1 : 0;
    }
  }
  EXPECT_GT(backtracked, 0U);
  EXPECT_EQ(static_cast<double>(backtracked), learning.summary.world_statistics.find("backtracks").value_or(-1));
  EXPECT_EQ(static_cast<double>(attempts), learning.summary.world_statistics.find("refinements_started").value_or(-1));
  // The belief of the first sequence after its episodes: a valid library (the constructor checks
  // that planning and backtracking sum to at most 1), whose backtracking action learned both.
  OnlineBelief belief(library, 10.0);
  for (std::size_t e = 0; e < 3; ++e) {
    ASSERT_NE(learning.episodes[e].problem, nullptr);
    belief.observe(*learning.episodes[e].problem, learning.episodes[e].attempts);
  }
  const Problem believed = belief.believed();
  const int place = library.find_action("move+place(B1,S)");
  EXPECT_NE(believed.action(place).backtrack, library.action(place).backtrack);
  EXPECT_LE(2.0 - believed.action(place).planning.never() - believed.action(place).backtrack.never(),
            1.0 + Distribution::kSumTolerance);
}

// After a commit the streaming world passes over the room paths that do not begin with what the
// robot executed: every skeleton it streams then begins with that prefix.
TEST(StreamingPlannerWorld, AfterACommitEverySkeletonBeginsWithWhatTheRobotExecuted) {
  const Fixture& f = fixture();
  StreamingWorldOptions streaming;
  streaming.library = &f.library;
  streaming.task_planners = room_path_planners(f.domain.world());
  PlannerWorld world(f.domain, streaming, f.options);
  world.begin_episode(1);
  const std::optional<FoundSkeleton> first = world.next_skeleton();
  ASSERT_TRUE(first.has_value());
  ASSERT_GE(first->action_ids.size(), 2U);
  world.commit({0});  // the first skeleton's first move
  int streamed = 0;
  std::set<std::vector<std::string>> seen;
  while (std::optional<FoundSkeleton> next = world.next_skeleton()) {
    ASSERT_FALSE(next->action_ids.empty());
    EXPECT_EQ(next->action_ids.front(), first->action_ids.front());
    EXPECT_TRUE(seen.insert(next->action_ids).second);
    ++streamed;
  }
  // Every simple room path through that first move but the first skeleton itself.
  std::size_t through = 0;
  const NavigationWorld& map = f.domain.world();
  const std::string first_move = world.actions().front().action;
  for (const auto& rooms : map.room_paths(map.start_room, map.goal_room)) {
    through += moves_of(rooms).front() == first_move ? 1 : 0;
  }
  EXPECT_EQ(static_cast<std::size_t>(streamed) + 1, through);
}

// Acting while planning in the loop (SPEC §10) on the modelled clock: the same episodes for any
// thread count; the robot starts a first motion while the planner still refines (a start before a
// later planner step), and an episode's skeletons at its end all begin with what the robot executed.
TEST(RunTamp, ActingWhilePlanningCommitsWhilePlanningAndStreamsThroughWhatTheRobotExecuted) {
  const Fixture& f = fixture();
  TampOptions options = modelled_tamp(6, 3);
  options.acting = Acting::concurrent;
  const TampResult one = run_tamp(f.domain, f.library, options);
  options.threads = 2;
  const TampResult two = run_tamp(f.domain, f.library, options);
  EXPECT_EQ(one.summary.successes, two.summary.successes);
  EXPECT_GT(one.summary.successes, 0U);
  ASSERT_EQ(one.episodes.size(), 6U);
  bool committed_while_planning = false;
  for (std::size_t e = 0; e < one.episodes.size(); ++e) {
    const EpisodeResult& episode = one.episodes[e];
    EXPECT_EQ(episode.status, two.episodes[e].status) << e;
    EXPECT_EQ(episode.live.elapsed, two.episodes[e].live.elapsed) << e;
    EXPECT_EQ(episode.executions, two.episodes[e].executions) << e;
    const auto first_start = std::find_if(episode.timeline.begin(), episode.timeline.end(),
                                          [](const LiveStep& step) { return step.started >= 0; });
    committed_while_planning |=
        first_start != episode.timeline.end() &&
        std::any_of(first_start, episode.timeline.end(), [](const LiveStep& step) { return step.action >= 0; });
    ASSERT_NE(episode.problem, nullptr);
    for (int k = 0; k < episode.problem->skeleton_count(); ++k) {
      const std::span<const int> path = episode.problem->skeleton(k);
      ASSERT_GE(path.size(), episode.executions.size()) << e;
      for (std::size_t i = 0; i < episode.executions.size(); ++i) {
        EXPECT_EQ(path[i], episode.executions[i].action) << "episode " << e << " skeleton " << k;
      }
    }
    if (episode.status == Status::success) {
      EXPECT_EQ(static_cast<int>(episode.executions.size()), episode.problem->skeleton_length(episode.solution));
      EXPECT_LE(episode.executions.back().end, options.deadline + 1e-9);
    }
  }
  EXPECT_TRUE(committed_while_planning);
  options.solver = "ppo";
  EXPECT_THROW(run_tamp(f.domain, f.library, options), UsageError);
}

// The timeline CSV of a concurrent episode on a manual clock (two actions, slices of 2 s): a row
// per planner step and per start, then the robot's lane, one row per execution from start to end.
TEST(TimelineCsv, ActingWhilePlanningAddsTheRobotsLaneAfterThePlannersColumns) {
  const Problem problem = parse_problem(R"({"deadline": 8, "step_seconds": 2, "acting": "concurrent",
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"2": 1}}},
                "b": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"1": 1}}}},
    "skeletons": [["a", "b"]]})",
                                        "two-moves");
  const ConcurrentMdp mdp(problem);
  ManualClock clock;
  ConcurrentSession session(mdp, clock);
  session.decide({-1, 0});
  clock.advance(2);
  session.report_refined_seconds(3.0);
  session.decide({0, ConcurrentMdp::kWait});  // a from 2 s
  session.decide({-1, 0});
  clock.advance(2);
  session.report_refined_seconds(1.0);
  session.report_execution_finished(0);       // at 4 s, a second sooner than its motion said
  session.decide({1, ConcurrentMdp::kWait});  // b from 4 s to 5 s
  ASSERT_EQ(session.status(), Status::success);
  EpisodeResult result;
  result.status = session.status();
  result.solution = session.solution();
  result.timeline = session.timeline();
  result.executions = session.executions();
  const std::string zero = "0.000000000";
  const auto seconds = [](int whole) { return std::to_string(whole) + ".000000000"; };
  const std::string expected =
      std::string(
          "skeleton,action,start,outside_seconds,decision_seconds,planning_seconds,overrun_seconds,observe_seconds,"
          "refined,execution_seconds,lane,execution_start,execution_end\n") +
      // skeleton, action (quoted), start, outside, decision, planning, overrun, observe, refined, execution
      "0,\"a\"," + zero + "," + zero + "," + zero + "," + seconds(2) + "," + zero + "," + zero + ",1," + seconds(3) +
      ",planning,,\n" + "-1,\"a\"," + seconds(2) + "," + zero + "," + zero + "," + zero + "," + zero + "," + zero +
      ",0," + zero + ",start," + seconds(2) + "," + seconds(4) + "\n" + "0,\"b\"," + seconds(2) + "," + zero + "," +
      zero + "," + seconds(2) + "," + zero + "," + zero + ",1," + seconds(1) + ",planning,,\n" + "-1,\"b\"," +
      seconds(4) + "," + zero + "," + zero + "," + zero + "," + zero + "," + zero + ",0," + zero + ",start," +
      seconds(4) + "," + seconds(5) + "\n" + "-1,\"a\"," + seconds(2) + ",0,0,0,0,0,0," + seconds(2) + ",execution," +
      seconds(2) + "," + seconds(4) + "\n" + "-1,\"b\"," + seconds(4) + ",0,0,0,0,0,0," + seconds(1) + ",execution," +
      seconds(4) + "," + seconds(5) + "\n";
  EXPECT_EQ(report::timeline_csv(problem, result), expected);
}

}  // namespace
}  // namespace ontime::domains
