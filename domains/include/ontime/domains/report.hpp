#pragma once
// The reports of the domain commands, in the core report's conventions (report/report.hpp): JSON
// for programs (the command line's --json and the dicts Python's ontime.domains functions return,
// which are this JSON read back) and text for people (the command line's readable output), so
// that the command line and Python give the same fields and the same numbers by construction.
// JSON is two-space indented without a final newline, every double written so that reading it
// back gives the same double; the drawings the plot scripts read are one-space indented.
//
// Also the live episodes' timeline as the CSV that python/plot_timeline.py draws.

#include <cstdint>
#include <optional>
#include <string>

#include "ontime/domains/collect_and_fit.hpp"
#include "ontime/domains/drawing.hpp"
#include "ontime/domains/manipulation_generator.hpp"
#include "ontime/domains/navigation_generator.hpp"
#include "ontime/domains/planner_run.hpp"
#include "ontime/domains/tamp.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/episode_runner.hpp"

namespace ontime::domains::report {

// How an episode ended: "success", "failure", or "undecided" (still running when it ended).
const char* status_name(Status status) noexcept;

// One row per step of a live episode (skeleton, action id, start, the seconds charged, refined,
// execution seconds; then its lane, "planning", or "start" for a start of the robot acting while
// planning with the execution's start and end), then one row per execution of the robot (lane
// "execution", skeleton -1, action id, start, execution seconds, start and end): what the timeline
// picture draws.
std::string timeline_csv(const Problem& problem, const EpisodeResult& result);
// The execution seconds of the plan a successful live episode executed (0 otherwise).
double executed_plan_seconds(const Problem& problem, const EpisodeResult& result);

// The drawings (drawing.hpp) as python/plot_map.py and python/plot_tamp.py read them.
std::string to_json(const MapDrawing& drawing);
std::string to_json(const EpisodeDrawing& drawing);

// A generated world: the file written and what it holds.
std::string to_json(const GeneratedWorld& world);
std::string to_text(const GeneratedWorld& world);
// A generated kitchen: the file written, its counts and its goal.
std::string to_json(const GeneratedKitchen& kitchen);
std::string to_text(const GeneratedKitchen& kitchen);

// The TAMP loop (tamp.hpp): the settings, the success rate, the skeletons found, the mean
// charges and, when kept, every episode with its charges and timeline.
struct Tamp {
  std::string domain = {};   // as named when loaded
  std::string world = {};    // the world file, as given
  std::string library = {};  // the library's source, as given
  const TampOptions* options = nullptr;
  const TampResult* result = nullptr;
  std::string picture_files = {};  // text: the files the drawn episode went to
};
// Its JSON (`ontime tamp --json`): the settings, the success rate, the skeletons found and the mean charges.
std::string to_json(const Tamp& tamp);
// Its text (`ontime tamp`): the same for people.
std::string to_text(const Tamp& tamp);
// The drawn episode: {"episode", "drawing", "timeline_csv"}.
std::string picture_json(const TampPicture& picture);

// Episodes against a domain's real planner (planner_run.hpp).
struct Run {
  std::string domain = {};
  std::string instance = {};  // the instance's source, as given
  const Problem* problem = nullptr;
  const PlannerRunOptions* options = nullptr;
  const PlannerRun* result = nullptr;
  std::optional<std::uint64_t> timeline_episode = {};  // text: the episode whose timeline was drawn
  std::string timeline_files = {};                     // and where
};
// Its JSON (`ontime run --json`): the settings, the success rate and the effort of the episodes.
std::string to_json(const Run& run);
// Its text (`ontime run`): the same for people.
std::string to_text(const Run& run);

// A collection and its fit (collect_and_fit.hpp); the result must hold the fit (the root rank's).
struct Collection {
  std::string domain = {};
  std::string world = {};  // the world file, as given
  const CollectAndFitOptions* options = nullptr;
  const CollectAndFitResult* result = nullptr;
};
// Its JSON (`ontime collect --json`): the settings, the attempts and motions found, the files written.
std::string to_json(const Collection& collection);
// Its text (`ontime collect`): the same for people.
std::string to_text(const Collection& collection);

}  // namespace ontime::domains::report
