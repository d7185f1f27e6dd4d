// `ontime tamp --world W --library L --deadline S --solver NAME`: the whole deadline-aware TAMP loop
// on the clock. A task planner streams skeletons (room paths in order of length for a navigation
// world, else the domain's skeletons in order), each arriving in the episode's live session as it
// is found and charged its search time; the allocator decides which action the real motion planner
// (OMPL + FCL) refines next; the distributions it decides with come from a library of fitted
// actions (e.g. every doorway move, collected once). Episodes, their success rate and charges,
// and a picture of one episode: the map with the skeletons found coloured by the effort they got,
// and the timeline of its session. The loop is domains::run_tamp (tamp.hpp) and the output the
// domains report's; this command parses the flags, writes the picture's files and prints.

#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <vector>

#include "cluster_job.hpp"
#include "common.hpp"
#include "data_paths.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/domains/tamp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"
#include "timeline_plot.hpp"

namespace ontime::cli {

void add_tamp_command(CLI::App& app) {
  struct Options {
    std::string domain = "navigation";
    std::string world;
    std::string library;
    std::string solver;
    double deadline = 0;
    std::string effort = "checks";
    std::uint64_t episodes = 100;
    std::uint64_t seed = 1;
    unsigned threads = 0;
    double task_seconds = 0.5;
    int period = 2;
    int max_skeletons = 16;
    double decision_share = 0.5;
    std::string clock = "real";
    ThinkingModel thinking;
    std::string picture;
    std::uint64_t picture_episode = 0;
    bool no_plot = false;
    bool json = false;
    double adapt_strength = 0;
    std::uint64_t sequences = 1;
    std::string act;  // empty: the library's own mode
    AllocatorFlags allocator;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "tamp", "The whole TAMP loop on the clock: skeletons streamed by a task planner, refined by the real planner");
  command->add_option("--domain", options->domain, "Domain")->capture_default_str();
  command->add_option("--world", options->world, "World file (default: data/domains/DOMAIN.json)");
  command
      ->add_option("--library", options->library,
                   "Instance whose actions give the distributions of every action the task planner may produce "
                   "(e.g. fitted from `collect --every-move`)")
      ->required();
  add_number_option(*command, "--deadline", options->deadline,
                    "Deadline in seconds (whole steps of the library's step_seconds count)", 1e-9)
      ->required();
  add_solver_option(*command, options->solver);
  command->add_option("--effort", options->effort, "Effort unit: checks (deterministic) or wall")
      ->capture_default_str();
  add_number_option(*command, "--episodes", options->episodes, "Episodes", std::uint64_t{1});
  add_number_option(*command, "--seed", options->seed, "Seed of the episodes (episode i uses stream i of it)");
  add_threads_option(*command, options->threads, "Worker threads (0: one per hardware thread)");
  add_number_option(*command, "--task-seconds", options->task_seconds,
                    "Search seconds charged to the deadline for each skeleton the task planner finds", 0.0, 1e6);
  add_number_option(*command, "--arrival-period", options->period,
                    "Steps between two skeletons of the task planner (sooner when none found can still succeed)", 1,
                    10'000);
  add_number_option(*command, "--max-skeletons", options->max_skeletons, "Skeletons the task planner finds at most", 1,
                    Problem::kMaxSkeletons);
  add_number_option(*command, "--decision-share", options->decision_share,
                    "Share of a slice an anytime allocator thinks per decision (without its own budget)", 1e-9, 1e6);
  command
      ->add_option("--clock", options->clock,
                   "real: the allocator's thinking and the task planner's search take the real time they take (a "
                   "robot's view); model: thinking is charged by --decision-seconds and --iteration-seconds, and "
                   "nothing real is on the clock, so the same seed gives the same episodes on any machine (reports)")
      ->check(CLI::IsMember({"real", "model"}))
      ->capture_default_str();
  add_number_option(*command, "--decision-seconds", options->thinking.seconds_per_decision,
                    "--clock model: seconds charged per decision", 0.0, 1e6);
  add_number_option(*command, "--iteration-seconds", options->thinking.seconds_per_iteration,
                    "--clock model: seconds charged per search iteration of an anytime allocator", 1e-12, 1e6);
  command->add_option("--picture", options->picture,
                      "Draw one episode: the map into this PNG (data beside it as .json) and the timeline into "
                      "NAME-timeline.png (data as .csv)");
  add_number_option(*command, "--picture-episode", options->picture_episode, "The episode --picture draws");
  command->add_flag("--no-plot", options->no_plot, "With --picture: write the data only");
  add_number_option(*command, "--adapt-strength", options->adapt_strength,
                    "Learn across episodes: each sequence's episodes plan with the library updated by every attempt of "
                    "the episodes before (the online update), the library a prior worth this many attempts",
                    1e-9, 1e9);
  add_number_option(*command, "--sequences", options->sequences,
                    "With --adapt-strength: independent sequences of --episodes episodes each", std::uint64_t{1});
  add_act_option(*command, options->act,
                 "Concurrent: the robot executes each motion it starts while the task planner and the planner work on; "
                 "after each start the task planner streams only paths from where the robot is committed to go (not "
                 "with --adapt-strength)");
  command->add_flag("--json", options->json, "Print JSON (with every episode and its timeline)");
  options->allocator.add_to(*command);
  command->callback([options, command] {
    if (options->picture.empty() && (command->count("--picture-episode") > 0 || options->no_plot)) {
      throw UsageError("--picture-episode and --no-plot need --picture");
    }
    if (command->count("--sequences") > 0 && command->count("--adapt-strength") == 0) {
      throw UsageError("--sequences needs --adapt-strength");
    }
    if (!options->picture.empty() && command->count("--adapt-strength") > 0) {
      throw UsageError(
          "--picture is not taken with --adapt-strength: a picture redraws its episode with the library "
          "alone");
    }
    if (options->clock == "real" &&
        (command->count("--decision-seconds") > 0 || command->count("--iteration-seconds") > 0)) {
      throw UsageError("--decision-seconds and --iteration-seconds need --clock model");
    }
    const std::filesystem::path world_file =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world_file);
    const Problem library = load_problem(options->library);
    std::filesystem::path map_png, map_data, timeline_png, timeline_data;
    if (!options->picture.empty()) {
      map_png = options->picture;
      map_data = std::filesystem::path(map_png).replace_extension(".json");
      timeline_png = map_png.parent_path() / (map_png.stem().string() + "-timeline.png");
      timeline_data = std::filesystem::path(timeline_png).replace_extension(".csv");
      std::vector<OutputFile> outputs{{"--picture (map data)", map_data}, {"--picture (timeline data)", timeline_data}};
      if (!options->no_plot) {
        outputs.push_back({"--picture", map_png});
        outputs.push_back({"--picture (timeline)", timeline_png});
      }
      check_outputs(outputs, {world_file, options->library});
    }

    domains::TampOptions tamp;
    tamp.solver = options->solver;
    tamp.parameters = options->allocator.values();
    tamp.deadline = options->deadline;
    tamp.effort = domains::effort_settings(loaded.defaults, options->effort);
    tamp.episodes = options->episodes;
    tamp.seed = options->seed;
    tamp.threads = options->threads;
    tamp.task_seconds = options->task_seconds;
    tamp.arrival_period = options->period;
    tamp.max_skeletons = options->max_skeletons;
    tamp.decision_share = options->decision_share;
    tamp.acting = options->act.empty() ? library.acting() : *parse_acting(options->act);
    if (options->clock == "model") tamp.thinking = options->thinking;
    tamp.keep_episodes = options->json;
    if (!options->picture.empty()) tamp.picture_episode = options->picture_episode;
    if (command->count("--adapt-strength") > 0) {
      tamp.adaptation = domains::TampAdaptation{.strength = options->adapt_strength, .sequences = options->sequences};
    }
    tamp.world_name = world_file.filename().string();
    tamp.library_source = options->library;
    tamp.ranks = job_ranks();
    ProgressBar progress("tamp");
    tamp.progress = [&progress](std::uint64_t done, std::uint64_t total) { progress.update(done, total); };
    const domains::TampResult result = domains::run_tamp(*loaded.domain, library, tamp, flag_spelling());

    if (result.picture && is_job_root()) {  // rank 0 writes
      const domains::TampPicture& picture = *result.picture;
      write_file_atomically(map_data, domains::report::to_json(picture.drawing) + "\n");
      write_file_atomically(timeline_data, domains::report::timeline_csv(*picture.result.problem, picture.result));
      if (!options->no_plot) {
        run_python_script("plot_tamp.py", map_png, [&](const std::string& figure) {
          return std::vector<std::string>{"--data", map_data.string(), "--output", figure};
        });
        plot_timeline(*picture.result.problem, picture.result, timeline_data, timeline_png, picture.drawing.title);
      }
    }
    const domains::report::Tamp report{
        .domain = options->domain,
        .world = world_file.string(),
        .library = options->library,
        .options = &tamp,
        .result = &result,
        .picture_files = map_data.empty()
                             ? std::string()
                             : map_data.string() + ", " + timeline_data.string() +
                                   (options->no_plot ? "" : ", " + map_png.string() + ", " + timeline_png.string())};
    fmt::print("{}", options->json ? domains::report::to_json(report) + "\n" : domains::report::to_text(report));
  });
}

}  // namespace ontime::cli
