// Bindings of the learn layer: fitting an instance from a planner log, conditional time models,
// drawing a log from an instance, and training the ppo policy.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "bindings.hpp"
#include "ontime/learn/attempt_scores.hpp"
#include "ontime/learn/chain_fitting.hpp"
#include "ontime/learn/conditional_model.hpp"
#include "ontime/learn/fitting.hpp"
#include "ontime/learn/log_sampling.hpp"
#include "ontime/learn/online_adaptation.hpp"
#include "ontime/learn/online_belief.hpp"
#include "ontime/learn/online_update.hpp"
#include "ontime/learn/ppo_training.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/model/skeleton_file.hpp"
#include "ontime/report/conditional_report.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/output_set.hpp"

namespace ontime::python {

namespace {

using Model = std::shared_ptr<ConditionalTimeModel>;
using FeatureArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

py::tuple predicted_tuple(const PredictedTimes& times) { return py::make_tuple(times.planning, times.execution); }

void bind_conditional(py::module_& m) {
  py::class_<ConditionalTimeModel, Model>(
      m, "ConditionalTimeModel",
      "A conditional time model (docs/learning.md): an action's planning and execution distributions predicted "
      "from its feature vector. Made by fit_conditional or load_conditional_model.")
      .def_property_readonly("kind", &ConditionalTimeModel::kind)
      .def_property_readonly("feature_names", &ConditionalTimeModel::feature_names)
      .def_property_readonly("step_seconds", &ConditionalTimeModel::step_seconds)
      .def_property_readonly("horizon", &ConditionalTimeModel::horizon)
      .def_property_readonly("training_rows", &ConditionalTimeModel::training_rows)
      .def_property_readonly("training_worlds", &ConditionalTimeModel::training_worlds)
      .def(
          "predict",
          [](const ConditionalTimeModel& model, const FeatureArray& features) -> py::object {
            if (features.ndim() == 1)
              return predicted_tuple(model.predict({features.data(), static_cast<std::size_t>(features.size())}));
            if (features.ndim() != 2) throw UsageError("features are one vector or a 2-D array of one row per action");
            // One batch (a boosted model answers it in one XGBoost call per booster).
            const auto count = static_cast<std::size_t>(features.shape(0));
            const auto columns = static_cast<std::size_t>(features.shape(1));
            py::list rows;
            for (const PredictedTimes& times : model.predict_rows({features.data(), count * columns}, count)) {
              rows.append(predicted_tuple(times));
            }
            return rows;
          },
          py::arg("features"),
          "(planning, execution) Distributions for one feature vector, or a list of them for a 2-D array (one row "
          "per action). Raises UsageError for the wrong number of features or a value that is not finite.")
      .def("to_json", &ConditionalTimeModel::to_json, "The model file's text.")
      .def(
          "save",
          [](const ConditionalTimeModel& model, const py::object& path) {
            write_file_atomically(path_argument(path, "path"), model.to_json());
          },
          py::arg("path"), "Writes the model file (atomically).");

  m.def(
      "_fit_conditional",
      [](const std::vector<std::string>& logs, bool are_paths, Number<double, "step", 0.0> step,
         const std::string& kind, const std::vector<std::string>& feature_names,
         Number<Steps, "horizon", 0, Problem::kMaxDeadline> horizon,
         Number<double, "ridge", 0.0, ConditionalFitOptions::kMaxRidge> ridge,
         Number<int, "bins", 0, Problem::kMaxDeadline> bins, Number<int, "trees", 1, 10000> trees,
         Number<int, "depth", 1, 16> depth, Number<double, "learning_rate", 0.0, 1.0> learning_rate,
         Number<double, "min_child_weight", 0.0> min_child_weight, const std::string& aft_distribution,
         Number<double, "aft_scale", 0.0, 100.0> aft_scale) {
        ConditionalFitOptions options;
        options.kind = kind;
        options.feature_names = feature_names;
        options.horizon = horizon;
        options.ridge = ridge;
        options.bins = bins;
        options.trees = trees;
        options.depth = depth;
        options.learning_rate = learning_rate;
        options.min_child_weight = min_child_weight;
        options.aft_distribution = aft_distribution;
        options.aft_scale = aft_scale;
        const py::gil_scoped_release release;
        const ConditionalData data =
            are_paths ? load_conditional_data(std::vector<std::filesystem::path>(logs.begin(), logs.end()), step)
                      : conditional_data(parse_planner_log(logs.at(0), "<records>"), step, "<records>");
        return Model(fit_conditional_model(data, options));
      },
      py::arg("logs"), py::arg("are_paths"), py::arg("step"), py::arg("kind"), py::arg("feature_names"),
      py::arg("horizon"), py::arg("ridge"), py::arg("bins"), py::arg("trees"), py::arg("depth"),
      py::arg("learning_rate"), py::arg("min_child_weight"), py::arg("aft_distribution"), py::arg("aft_scale"));

  py::class_<PlanningPosterior>(
      m, "PlanningPosterior",
      "The online update of one action's planning distribution (docs/learning.md): a prior Distribution worth "
      "`strength` attempts, updated by every attempt found or cut off; mean() is the posterior to plan with. With "
      "`backtrack` (the prior's backtrack Distribution, SPEC §7) the planning and backtrack distributions are "
      "learned together as competing risks: attempts may also backtrack (observe_backtrack), and backtrack_mean() "
      "is the posterior backtrack distribution, whose mass sums with mean()'s to at most 1.")
      .def(py::init([](const Distribution& prior, Number<Steps, "horizon", 1, Distribution::kMaxStep> horizon,
                       Number<double, "strength", 0.0> strength, const std::optional<Distribution>& backtrack) {
             return backtrack ? PlanningPosterior(prior, *backtrack, horizon, strength)
                              : PlanningPosterior(prior, horizon, strength);
           }),
           py::arg("prior"), py::arg("horizon"), py::arg("strength"), py::kw_only(), py::arg("backtrack") = py::none())
      .def(
          "observe_found",
          [](PlanningPosterior& posterior, Number<Steps, "steps", 1> steps) { posterior.observe_found(steps); },
          py::arg("steps"), "A motion found after `steps` steps.")
      .def(
          "observe_backtrack",
          [](PlanningPosterior& posterior, Number<Steps, "steps", 1> steps) { posterior.observe_backtrack(steps); },
          py::arg("steps"), "An attempt that gave up and backtracked after `steps` steps.")
      .def(
          "observe_cut_off",
          [](PlanningPosterior& posterior, Number<Steps, "steps", 0> steps) { posterior.observe_cut_off(steps); },
          py::arg("steps"), "An attempt cut off after `steps` steps without a motion or a backtrack.")
      .def("mean", &PlanningPosterior::mean, "The posterior mean Distribution (over 1..horizon, the rest never).")
      .def("backtrack_mean", &PlanningPosterior::backtrack_mean,
           "The posterior mean backtrack Distribution (over 1..horizon, the rest never).")
      .def(
          "predictive_found",
          [](const PlanningPosterior& posterior, Number<Steps, "steps"> steps) {
            return posterior.predictive_found(steps);
          },
          py::arg("steps"),
          "The posterior predictive probability that the next attempt finds a motion at step `steps` (P(T = steps)).")
      .def(
          "predictive_backtrack",
          [](const PlanningPosterior& posterior, Number<Steps, "steps"> steps) {
            return posterior.predictive_backtrack(steps);
          },
          py::arg("steps"), "The posterior predictive probability that the next attempt backtracks at step `steps`.")
      .def(
          "predictive_cut_off",
          [](const PlanningPosterior& posterior, Number<Steps, "steps"> steps) {
            return posterior.predictive_cut_off(steps);
          },
          py::arg("steps"),
          "The posterior predictive probability that the next attempt is cut off after `steps` steps (P(T > steps)).")
      .def_property_readonly("observations", &PlanningPosterior::observations)
      .def_property_readonly("strength", &PlanningPosterior::strength)
      .def_property_readonly("horizon", &PlanningPosterior::horizon);

  py::class_<OnlineBelief>(
      m, "OnlineBelief",
      "A robot's belief of a world's planning times (docs/learning.md, \"Online update\"): `prior` (a Problem or "
      "an instance's path: a prediction, a library) worth `strength` attempts, updated by every attempt the "
      "robot makes; believed() is the prior with the posterior means, to plan the next episode with.\n\n"
      "    belief = ontime.OnlineBelief(predicted, strength=100)\n"
      "    session = ontime.LiveSession(belief.believed_for(problem), 'dp-rerun')\n"
      "    ... drive it ...\n"
      "    belief.observe(session.problem, session.attempts)")
      .def(py::init([](const py::object& prior, Number<double, "strength", 1e-9, 1e9> strength) {
             return OnlineBelief(*to_mdp(prior, "prior")->problem, strength);
           }),
           py::arg("prior"), py::arg("strength"))
      .def(
          "observe",
          [](OnlineBelief& belief, const std::string& action_id, Number<Steps, "effort", 0> effort, bool found,
             bool backtracked) {
            if (found && backtracked) throw UsageError("an attempt ends with a motion or by backtracking, not both");
            belief.observe(action_id, backtracked ? ActionAttempt{0, false, {EndedAttempt{effort, false, true}}}
                                                  : ActionAttempt{effort, found});
          },
          py::arg("action_id"), py::arg("effort"), py::arg("found").noconvert(), py::kw_only(),
          py::arg("backtracked").noconvert() = false,
          "One attempt on an action (by id or base id): found after `effort` steps, backtracked after them "
          "(backtracked=True), or cut off after them.")
      .def(
          "observe",
          [](OnlineBelief& belief, const py::object& problem, const std::vector<ActionAttempt>& attempts) {
            const std::shared_ptr<MdpHandle> episode = to_mdp(problem);
            if (attempts.size() != static_cast<std::size_t>(episode->problem->action_count())) {
              throw UsageError("parameter 'attempts': one per action of the problem: " +
                               std::to_string(episode->problem->action_count()) + ", not " +
                               std::to_string(attempts.size()));
            }
            belief.observe(*episode->problem, attempts);
          },
          py::arg("problem"), py::arg("attempts"),
          "Every attempt of one episode: a session's problem and its attempts, by action index.")
      .def("believed", &OnlineBelief::believed, "The prior with every observed action's posterior mean (a Problem).")
      .def(
          "believed_for",
          [](const OnlineBelief& belief, const py::object& structure) {
            return belief.believed_for(*to_mdp(structure, "structure")->problem);
          },
          py::arg("structure"),
          "`structure`'s skeletons with the believed distributions, each action by its id or base id.")
      .def("planning", &OnlineBelief::planning, py::arg("action_id"), "The planning Distribution believed now.")
      .def("backtrack", &OnlineBelief::backtrack, py::arg("action_id"),
           "The backtrack Distribution believed now (the prior's for an action that does not backtrack).")
      .def_property_readonly("prior", &OnlineBelief::prior)
      .def_property_readonly("strength", &OnlineBelief::strength)
      .def_property_readonly("observations", &OnlineBelief::observations);

  m.def(
      "load_conditional_model",
      [](const py::object& path) { return Model(load_conditional_model(path_argument(path, "path"))); },
      py::arg("path"), "Reads a model file (`ontime fit --conditional`); InputError names the place and rule.");

  m.def(
      "fit_strength",
      [](const Required<ConditionalTimeModel, "model">& model, const std::vector<py::object>& logs,
         const std::vector<double>& strengths) {
        if (logs.empty()) throw UsageError("parameter 'logs': give at least one planner log");
        if (strengths.empty()) throw UsageError("parameter 'strengths': give at least one strength");
        for (const double strength : strengths) {
          if (!(std::isfinite(strength) && strength > 0)) {
            throw UsageError("parameter 'strengths': every strength must be a finite number > 0 (got " +
                             std::string(py::str(py::float_(strength))) + ")");
          }
        }
        std::vector<std::filesystem::path> paths;
        for (const py::object& log : logs) {
          paths.emplace_back(path_argument(log, "logs"));
        }
        std::vector<StrengthScore> scores;
        std::size_t attempts = 0;
        {
          const py::gil_scoped_release release;
          const ConditionalData data = load_conditional_data_for(*model, "given", paths);
          attempts = data.rows();
          scores = score_prior_strengths(*model, data, strengths);
        }
        py::list list;
        const StrengthScore* best = &scores.front();
        for (const StrengthScore& score : scores) {
          list.append(py::dict(py::arg("strength") = score.strength, py::arg("nll") = score.nll));
          if (score.nll < best->nll) best = &score;
        }
        return py::dict(py::arg("attempts") = attempts, py::arg("scores") = list, py::arg("best") = best->strength);
      },
      py::arg("model"), py::arg("logs"), py::kw_only(),
      py::arg("strengths") = std::vector<double>{0.5, 1, 2, 5, 10, 20, 50, 100, 200},
      "`ontime fit-strength`: the prequential log score of each prior strength on logs of worlds the model was "
      "not fitted on (each attempt scored by the posterior before it is seen); returns attempts, scores "
      "(strength, nll) and the best strength.");

  m.def(
      "conditional_model_kinds",
      [] {
        py::list kinds;
        for (const ConditionalModelKind& kind : conditional_model_kinds()) {
          py::list parameters;
          for (const ConditionalParameter& p : kind.parameters) {
            parameters.append(py::dict(py::arg("name") = p.name, py::arg("default") = p.default_value,
                                       py::arg("meaning") = p.meaning));
          }
          kinds.append(py::dict(py::arg("name") = kind.name, py::arg("description") = kind.description,
                                py::arg("parameters") = parameters));
        }
        return kinds;
      },
      "The kinds of conditional time model with their declared parameters.");
}

}  // namespace

void bind_chain_fitting(py::module_& m) {
  py::class_<ChainFit>(m, "ChainFit", "What ontime.fit_chain fitted: the chain and what it was fitted to.")
      .def_readonly("chain", &ChainFit::chain)
      .def_readonly("transitions_counted", &ChainFit::transitions)
      .def_readonly("runs", &ChainFit::runs)
      .def_readonly("log_likelihood", &ChainFit::log_likelihood)
      .def_readonly("arrival", &ChainFit::arrival, "birth-death: the probability of an arrival per step")
      .def_readonly("service", &ChainFit::service, "birth-death: the probability of a service per step");

  m.def(
      "_fit_chain",
      [](const std::vector<std::string>& logs, const std::vector<std::vector<std::string>>& sequences,
         const std::string& kind, const std::string& name, Number<double, "prior", 0.0> prior,
         const std::vector<std::string>& states, Number<std::int64_t, "capacity", 0, kMaxChainStates - 1> capacity) {
        ChainFitOptions options;
        options.kind = chain_kind(kind);
        options.name = name;
        options.prior = prior;
        options.states = states;
        options.capacity = capacity;
        const py::gil_scoped_release release;
        std::vector<ChainRun> runs;
        for (const std::string& log : logs) {
          std::vector<ChainRun> read = load_chain_observations(log);
          runs.insert(runs.end(), std::make_move_iterator(read.begin()), std::make_move_iterator(read.end()));
        }
        for (std::size_t i = 0; i < sequences.size(); ++i) {
          runs.push_back(ChainRun{"sequences[" + std::to_string(i) + "]", std::to_string(i), 0, sequences[i]});
        }
        return fit_chain(runs, options);
      },
      py::arg("logs"), py::arg("sequences"), py::arg("kind"), py::arg("name"), py::arg("prior"), py::arg("states"),
      py::arg("capacity"));
}

void bind_learn(py::module_& m) {
  bind_conditional(m);
  bind_chain_fitting(m);
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
      "score",
      [](const py::object& problem, const std::vector<py::object>& logs, Number<Steps, "horizon", 0> horizon,
         Number<double, "floor", 0.0, 1.0> floor, bool skip_unknown) {
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        if (logs.empty()) throw UsageError("parameter 'logs': give at least one planner log");
        std::vector<std::string> paths;
        for (const py::object& log : logs) paths.emplace_back(path_argument(log, "logs"));
        report::ScoreReport report{.instance = instance_label(problem, *mdp->problem),
                                   .logs = paths,
                                   .problem = mdp->problem.get(),
                                   .options = {.horizon = horizon, .floor = floor, .skip_unknown = skip_unknown},
                                   .scores = {}};
        {
          const py::gil_scoped_release release;
          std::vector<RefinementAttempt> attempts;
          for (const std::string& path : paths) {
            std::vector<RefinementAttempt> records = load_planner_log(path);
            attempts.insert(attempts.end(), std::make_move_iterator(records.begin()),
                            std::make_move_iterator(records.end()));
          }
          report.scores =
              score_attempts(attempts, *mdp->problem, paths.size() == 1 ? paths.front() : "the logs", report.options);
        }
        return json_object(report::attempt_scores_json(report));
      },
      py::arg("problem"), py::arg("logs"), py::kw_only(), py::arg("horizon") = 0, py::arg("floor") = 1e-6,
      py::arg("skip_unknown").noconvert() = false,
      "`ontime score`: how well the problem's distributions explain the attempts of planner logs (paths): the "
      "censoring-aware planning log score, the integrated Brier score and the execution log score, as the "
      "command's --json fields (docs/learning.md).");

  m.def(
      "sample_log",
      [](const py::object& problem, const py::object& path, Number<std::uint64_t, "attempts", 1> attempts, Seed seed,
         std::optional<Number<Steps, "cutoff", 1>> cutoff) {
        const std::shared_ptr<MdpHandle> mdp = to_mdp(problem);
        const std::string file = path_argument(path, "path");
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
      [](const py::object& problem, const py::object& out, Episodes episodes, Seed seed, const py::object& progress,
         const std::optional<std::string>& act) {
        check_episodes(episodes);
        check_callable(progress, "progress");
        // Read as a problem: one acting while planning makes no plan-first Mdp.
        const std::shared_ptr<const Problem> chosen = problem_with_acting(problem, act);
        const std::string path = path_argument(out, "out");
        std::optional<PpoTraining> training;
        run_interruptibly(
            [&](const std::function<bool()>& stop, Progress& counters) {
              counters.total = episodes;
              const auto report = [&](std::uint64_t done, std::uint64_t) {
                if (stop()) throw Cancelled("training stopped at the caller's request");
                counters.done = done;
              };
              if (chosen->acting() == Acting::concurrent) {
                const ConcurrentMdp mdp(*chosen);
                training = train_ppo(mdp, episodes, seed, {}, report);
              } else {
                const Mdp mdp(*chosen);
                training = train_ppo(mdp, episodes, seed, {}, report);
              }
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
      py::arg("progress") = py::none(), py::arg("act") = py::none(),
      "Trains the ppo policy on simulated episodes (as `ontime train`), writes it to `out` with its learning curve "
      "beside it (OUT.curve.csv; both only when training finished, together) and returns the learning curve as a "
      "list of dicts. Use it with "
      "make_allocator(problem, 'ppo', policy=out). act='concurrent' (or a problem acting while planning; `--act`, "
      "SPEC §10) trains a policy that chooses each start and step, for evaluate(act='concurrent', solver='ppo', "
      "policy=out).");
}

}  // namespace ontime::python
