// Bindings of the learn layer: fitting an instance from a planner log, drawing a log from an
// instance, and training the ppo policy.

#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "bindings.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/learn/log_sampling.hpp"
#include "ontime/learn/ppo_training.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/skeleton_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/output_set.hpp"

namespace ontime::python {

void bind_learn(py::module_& m) {
  m.def(
      "_fit",
      [](const std::string& log, bool log_is_path, const std::string& skeleton_data, bool skeletons_are_path,
         Number<double, "step", 0.0> step, Number<Steps, "deadline", 1> deadline,
         Number<double, "laplace", 0.0> laplace, const std::string& name, const std::string& description) {
        const std::string log_source = log_is_path ? log : "<records>";
        const std::vector<RefinementAttempt> attempts =
            log_is_path ? load_planner_log(log) : parse_planner_log(log, log_source);
        const SkeletonList skeletons =
            skeletons_are_path ? load_skeleton_file(skeleton_data) : parse_skeleton_file(skeleton_data, "<skeletons>");
        FitOptions options;
        options.step_seconds = step;
        options.deadline = deadline;
        options.laplace = laplace;
        options.name = name;
        options.description = description;
        if (!(step > 0) || !std::isfinite(step)) throw UsageError("step must be a positive number of seconds");
        if (deadline < 1 || deadline > Problem::kMaxDeadline) {
          throw UsageError("deadline must be in [1, " + std::to_string(Problem::kMaxDeadline) + "] steps");
        }
        const py::gil_scoped_release release;
        return std::make_shared<Problem>(fit_problem(attempts, log_source, skeletons, options).problem);
      },
      py::arg("log"), py::arg("log_is_path"), py::arg("skeleton_data"), py::arg("skeletons_are_path"), py::arg("step"),
      py::arg("deadline"), py::arg("laplace"), py::arg("name"), py::arg("description"));

  m.def(
      "sample_log",
      [](const py::object& problem, const py::object& path, Number<std::uint64_t, "attempts", 1> attempts, Seed seed,
         std::optional<Number<Steps, "cutoff", 1>> cutoff) {
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        const std::string file = py::str(py::module_::import("os").attr("fspath")(path));
        LogSamplingOptions options;
        options.attempts_per_action = attempts;
        options.seed = seed;
        options.cutoff_steps = cutoff ? static_cast<Steps>(*cutoff) : 0;
        const py::gil_scoped_release release;
        return write_sampled_planner_log(*mdp->problem, options, file);
      },
      py::arg("problem"), py::arg("path"), py::kw_only(), py::arg("attempts") = 1000, py::arg("seed") = 1,
      py::arg("cutoff") = py::none(),
      "Draws a planner log from the problem's own distributions and writes it to `path` (JSON Lines), as `ontime "
      "sample-log` does: `attempts` per action, attempt i of action a from stream i of stream a of `seed`, cut "
      "off after `cutoff` steps (default: the deadline). Returns the records written.");

  m.def(
      "train_ppo",
      [](const py::object& problem, const py::object& out, Episodes episodes, Seed seed, const py::object& progress) {
        check_episodes(episodes);
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        const std::string path = py::str(py::module_::import("os").attr("fspath")(out));
        std::optional<PpoTraining> training;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              counters.total = episodes;
              training = train_ppo(mdp->mdp, episodes, seed, {}, [&](std::uint64_t done, std::uint64_t) {
                if (stop()) throw Cancelled("training stopped at the caller's request");
                counters.done = done;
              });
              // The policy and its learning curve as one set, as `ontime train --no-plot` writes them
              // (an older plot beside the policy would describe another training: it goes).
              const std::filesystem::path policy(path);
              OutputSet files(policy.has_parent_path() ? policy.parent_path() : std::filesystem::path("."));
              stage_ppo_training(files, *training, policy);
              files.remove_on_commit(learning_curve_path(policy, ".curve.png"));
              files.commit();
            },
            progress);
        py::list curve;
        for (const LearningCurvePoint& point : training->curve) {
          py::dict row;
          row["epoch"] = point.epoch;
          row["episodes"] = point.episodes;
          row["steps"] = point.steps;
          row["success_rate"] = point.success_rate;
          row["mean_episode_length"] = point.mean_episode_length;
          row["actor_steps"] = point.actor_steps;
          row["seconds"] = point.seconds;
          curve.append(row);
        }
        return curve;
      },
      py::arg("problem"), py::arg("out"), py::kw_only(), py::arg("episodes") = 10'000, py::arg("seed") = 1,
      py::arg("progress") = py::none(),
      "Trains the ppo policy on simulated episodes (as `ontime train`), writes it to `out` with its learning curve "
      "beside it (OUT.curve.csv; both only when training finished, together) and returns the learning curve as a "
      "list of dicts. Use it with "
      "make_allocator(problem, 'ppo', policy=out).");
}

}  // namespace ontime::python
