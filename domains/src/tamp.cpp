#include "ontime/domains/tamp.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "episode_options.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/learn/online_belief.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime::domains {

namespace {

// Acting while planning: how far the task planner's stream goes (the session still holds at most
// max_skeletons skeletons at once).
constexpr int kConcurrentTaskPaths = 1000;

}  // namespace

Steps tamp_deadline_steps(const Problem& library, double deadline) {
  return static_cast<Steps>(std::floor(deadline / library.step_seconds() + 1e-9));
}

void check_tamp_request(const Domain& domain, const Problem& library, const TampOptions& options,
                        const ParameterSpelling& spelling) {
  if (options.thinking && options.effort.unit != EffortUnit::collision_checks) {
    throw UsageError(fmt::format("{} model needs {} checks (wall-clock effort is real time)",
                                 spell_parameter(spelling, "clock"), spell_parameter(spelling, "effort")));
  }
  if (options.picture_episode && *options.picture_episode >= options.episodes) {
    throw UsageError(fmt::format("{} {}: the run has episodes 0 to {}", spell_parameter(spelling, "picture-episode"),
                                 *options.picture_episode, options.episodes - 1));
  }
  if (options.acting == Acting::concurrent) {
    if (!allocator_registry().find(options.solver).acts_while_planning()) {
      throw UsageError(
          fmt::format("allocator '{}' does not act while planning (SPEC §10) yet: it has no commit rule; "
                      "{} do",
                      options.solver, fmt::join(allocator_registry().acting_names(), ", ")));
    }
  }
  if (options.adaptation) {
    if (options.picture_episode) {
      throw UsageError(fmt::format("{} is not taken with {}: a picture redraws its episode with the library alone",
                                   spell_parameter(spelling, "picture-episode"),
                                   spell_parameter(spelling, "adapt-strength")));
    }
    if (options.adaptation->sequences < 1) {
      throw UsageError(fmt::format("{} must be at least 1", spell_parameter(spelling, "sequences")));
    }
    if (!(std::isfinite(options.adaptation->strength) && options.adaptation->strength > 0)) {
      throw UsageError(fmt::format("{} {}: the prior's strength must be a positive number of attempts",
                                   spell_parameter(spelling, "adapt-strength"), options.adaptation->strength));
    }
  }
  const double steps = std::floor(options.deadline / library.step_seconds() + 1e-9);
  if (!(steps >= 1) || steps > static_cast<double>(Problem::kMaxDeadline)) {
    throw UsageError(fmt::format("{} {}: {} steps of {} s; a deadline takes 1 to {} steps",
                                 spell_parameter(spelling, "deadline"), options.deadline, steps, library.step_seconds(),
                                 Problem::kMaxDeadline));
  }
  // Every action the task planner may produce must be in the library: its skeletons are checked
  // as they come (the streaming world throws for one that is not), and here up front.
  const auto planner = domain.task_planners(options.max_skeletons)();
  for (int k = 0; k < options.max_skeletons; ++k) {
    const auto skeleton = planner->next();
    if (!skeleton) break;
    for (const std::string& action : *skeleton) {
      if (library.find_action(action) < 0) {
        throw InputError(options.library_source, "actions",
                         fmt::format("no action '{}', which the task planner's skeleton {} needs", action, k + 1));
      }
    }
  }
}

TampResult run_tamp(const Domain& domain, const Problem& library, const TampOptions& options,
                    const ParameterSpelling& spelling) {
  check_tamp_request(domain, library, options, spelling);
  TampResult result;
  result.deadline_steps = tamp_deadline_steps(library, options.deadline);
  result.step_seconds = library.step_seconds();
  StreamingRun streaming;
  streaming.name = fmt::format("{} ({})", domain.name(), options.world_name);
  streaming.deadline = result.deadline_steps;
  streaming.step_seconds = library.step_seconds();
  streaming.period = options.arrival_period;
  streaming.max_skeletons = options.max_skeletons;
  streaming.make_allocator = [solver = options.solver, parameters = options.parameters](const Mdp& mdp) {
    return make_allocator_factory(solver, mdp, parameters)();
  };
  StreamingWorldOptions stream;
  stream.library = &library;
  stream.task_planners = domain.task_planners(options.max_skeletons);
  if (options.acting == Acting::concurrent) {
    streaming.make_concurrent_allocator = [solver = options.solver,
                                           parameters = options.parameters](const ConcurrentMdp& mdp) {
      return make_concurrent_allocator_factory(solver, mdp, parameters)();
    };
    // After a commit the task planner reads on for the paths through what the robot executed, so
    // its stream goes on past the first max_skeletons paths (the session holds at most that many).
    stream.task_planners = domain.task_planners(kConcurrentTaskPaths);
  }
  stream.seconds_per_skeleton = options.task_seconds;
  PlannerWorldOptions planner;
  planner.effort = options.effort;
  planner.thinking = options.thinking;

  MonteCarloOptions episodes = detail::monte_carlo_options(options);
  const std::uint64_t sequences = options.adaptation ? options.adaptation->sequences : 1;
  const std::uint64_t total = options.episodes * sequences;
  episodes.episodes = total;
  // An anytime allocator given its own budget (its kind's declared decision budget: e.g.
  // iterations, time-budget) thinks that much per decision, charged all the same; otherwise the
  // session gives it decision_share of a slice.
  episodes.decision_budget = allocator_registry().decision_budget(options.solver, options.parameters);
  episodes.live = LiveRun{LiveOptions{.decision_share = options.decision_share}, options.keep_episodes};
  if (options.keep_episodes) result.episodes.resize(total);
  std::vector<int> skeletons_found(total, 0);
  std::vector<std::uint8_t> succeeded(total, 0);
  // With adaptation, each sequence's belief and the library it believes now: episodes of one
  // sequence run in order on one thread, so no two threads touch one sequence's slot.
  struct Learning {
    std::optional<OnlineBelief> belief;
    Problem library;
  };
  std::vector<std::optional<Learning>> learning(options.adaptation ? sequences : 0);
  if (options.adaptation) {
    episodes.sequence_length = options.episodes;
    streaming.keep_problem = true;
    episodes.before_episode = [&](std::uint64_t episode, World& world) {
      std::optional<Learning>& mine = learning[episode / options.episodes];
      if (episode % options.episodes == 0) {
        mine.emplace(Learning{OnlineBelief(library, options.adaptation->strength), library});
      } else {
        mine->library = mine->belief->believed();
      }
      // The worlds are the streaming planner worlds made below.
      dynamic_cast<PlannerWorld&>(world).set_library(mine->library);
    };
  }
  // Each episode writes its own slot: no two threads touch one.
  episodes.on_episode = [&](std::uint64_t episode, const EpisodeResult& outcome) {
    skeletons_found[episode] = outcome.skeletons;
    succeeded[episode] = outcome.status == Status::success ? 1 : 0;
    if (options.adaptation && outcome.problem != nullptr) {
      // What the episode's attempts taught (another rank's episodes come without their problem,
      // after every episode ended: that rank learned from them).
      learning[episode / options.episodes]->belief->observe(*outcome.problem, outcome.attempts);
    }
    if (options.keep_episodes) result.episodes[episode] = outcome;
  };
  result.summary = run_streaming_episodes(streaming, streaming_planner_worlds(domain, stream, planner), episodes);
  for (const int found : skeletons_found) result.mean_skeletons_found += found;
  result.mean_skeletons_found /= static_cast<double>(total);
  if (options.adaptation) {
    result.successes_by_episode.assign(options.episodes, 0);
    for (std::uint64_t episode = 0; episode < total; ++episode) {
      result.successes_by_episode[episode % options.episodes] += succeeded[episode];
    }
  }
  result.refinements_started = result.summary.world_statistics.find("refinements_started").value_or(0.0) /
                               static_cast<double>(result.summary.episodes);
  result.backtracks =
      result.summary.world_statistics.find("backtracks").value_or(0.0) / static_cast<double>(result.summary.episodes);

  // The picture: the episode run again on its own, so that its world still holds its motions.
  if (options.picture_episode && is_root_rank(options.ranks)) {
    PlannerWorld world(domain, stream, planner);
    LiveRun live = *episodes.live;
    live.keep_timeline = true;
    EpisodeResult shown = run_streaming_episode(streaming, world, stream_seed(options.seed, *options.picture_episode),
                                                episodes.decision_budget, nullptr, live);
    if (shown.problem != nullptr) {
      const std::string title = fmt::format(
          "{} on {}, episode {}: {} at {:.1f} s of {:.1f} s, {} skeletons", options.solver, options.world_name,
          *options.picture_episode, report::status_name(shown.status), shown.live.elapsed,
          static_cast<double>(result.deadline_steps) * result.step_seconds, shown.skeletons);
      EpisodeDrawing drawing = episode_drawing(domain, world, shown, title);
      result.picture = TampPicture{*options.picture_episode, std::move(shown), std::move(drawing)};
    }
  }
  return result;
}

}  // namespace ontime::domains
