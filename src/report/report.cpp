#include "ontime/report/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <nlohmann/json.hpp>

namespace ontime::report {
namespace {

using Json = nlohmann::ordered_json;

std::string dump(const Json& value) { return value.dump(2); }

Json parameters_object(const AllocatorKind& kind, const ParameterValues& values) {
  Json out = Json::object();
  const ParameterReader reader(kind, values);
  for (const Parameter& parameter : kind.parameters) out[parameter.name] = reader.text(parameter.name);
  return out;
}

Json latency_object(const LatencySummary& latency) {
  return Json{{"median", latency.median_us},
              {"p99", latency.p99_us},
              {"mean", latency.mean_us},
              {"max", latency.max_us},
              {"decisions", latency.decisions}};
}

Json statistics_object(const Statistics& statistics) {
  Json out = Json::object();
  for (const Statistics::Counter& counter : statistics.counters()) out[counter.name] = counter.value;
  return out;
}

std::string first_action_of(const Solve& solve) {
  const int first = solve.search ? solve.search->first_choice : solve.solution.first_choice;
  return first >= 0 ? solve.problem->action(solve.mdp->next_action(solve.mdp->start(), first)).id : "";
}

Json state_object(const State& state, int skeletons) {
  Json refined = Json::array(), spent = Json::array(), execution = Json::array();
  for (int k = 0; k < skeletons; ++k) {
    const auto slot = static_cast<std::size_t>(k);
    refined.push_back(state.refined[slot]);
    // Blanked slots (skeletons that can no longer succeed) are written as null.
    spent.push_back(state.spent[slot] == 0xFFFF ? Json(nullptr) : Json(state.spent[slot]));
    execution.push_back(state.execution[slot] == 0xFFFF ? Json(nullptr) : Json(state.execution[slot]));
  }
  return Json{{"time", state.time}, {"refined", refined}, {"spent", spent}, {"execution", execution}};
}

Json exact_object(const ExactPart& part) {
  Json out;
  if (part.value) out["value"] = *part.value;
  if (part.lower) {
    out["lower_bound"] = *part.lower;
    out["upper_bound"] = *part.upper;
  }
  out["cap_reached"] = part.cap_reached;
  out["states"] = part.states;
  out["seconds"] = part.seconds;
  return out;
}

std::string exact_text(const ExactPart& part) {
  if (part.value) return fmt::format("{:.4f}", *part.value);
  if (part.lower) return fmt::format("[{:.4f}, {:.4f}]", *part.lower, *part.upper);
  return "cap reached";
}

std::size_t display_width(const std::string& text) {
  // Display width: count UTF-8 code points, not bytes (for "±" and "µ").
  std::size_t width = 0;
  for (const char c : text) width += (static_cast<unsigned char>(c) & 0xC0) != 0x80 ? 1 : 0;
  return width;
}

}  // namespace

std::string parameters_json(const AllocatorKind& kind, const ParameterValues& values) {
  return dump(parameters_object(kind, values));
}

std::string to_json(const Evaluation& evaluation) {
  const MonteCarloResult& result = evaluation.result;
  Json out;
  out["solver"] = evaluation.solver;
  out["parameters"] = parameters_object(allocator_registry().find(evaluation.solver), evaluation.parameters);
  out["instance"] = evaluation.instance;
  if (!evaluation.belief.empty()) out["belief"] = evaluation.belief;
  if (evaluation.problem->acting() == Acting::concurrent) {
    // Only when acting while planning, so that plan-first outputs stay as they were.
    out["acting"] = acting_name(Acting::concurrent);
    out["commit_rule"] = allocator_registry().find(evaluation.solver).commit_rule;
  }
  out["episodes"] = result.episodes;
  out["seed"] = evaluation.seed;
  out["successes"] = result.successes;
  out["success_rate"] = result.success_rate;
  out["ci95"] = result.ci95;
  const bool rewards = evaluation.problem->has_rewards();
  if (rewards) {
    out["mean_reward"] = result.mean_reward;
    out["reward_ci95"] = result.reward_ci95;
  }
  if (evaluation.timing) {
    out["decision_time_us"] = latency_object(result.decision_time);
    out["seconds"] = result.seconds;
  }
  out["statistics"] = statistics_object(result.statistics);
  if (evaluation.exact) {
    out["exact_success_probability"] = evaluation.exact->success_probability;
    if (rewards) out["exact_expected_reward"] = evaluation.exact->expected_reward;
    out["exact_states"] = evaluation.exact->states;
  }
  if (evaluation.regret) {
    Json regret;
    regret["optimum"] = evaluation.regret->optimum;
    regret["mean"] = evaluation.regret->mean;
    regret["ci95"] = evaluation.regret->ci95;
    regret["episodes"] = evaluation.regret->episodes;
    out["regret"] = regret;
  }
  return dump(out);
}

std::string to_text(const Evaluation& evaluation) {
  const MonteCarloResult& result = evaluation.result;
  std::string out = fmt::format("solver          {}\n", evaluation.solver);
  out += fmt::format("instance        {} ({}), deadline {}\n", evaluation.instance, evaluation.problem->name(),
                     evaluation.problem->deadline());
  if (!evaluation.belief.empty()) out += fmt::format("planned with    {}\n", evaluation.belief);
  if (evaluation.problem->acting() == Acting::concurrent) {
    out += fmt::format("acting          concurrent (SPEC §10); commit rule: {}\n",
                       allocator_registry().find(evaluation.solver).commit_rule);
  }
  out += fmt::format("success rate    {:.4f} ± {:.4f}  ({} of {} episodes, seed {})\n", result.success_rate,
                     result.ci95, result.successes, result.episodes, evaluation.seed);
  const bool rewards = evaluation.problem->has_rewards();
  if (rewards) out += fmt::format("mean reward     {:.4f} ± {:.4f}\n", result.mean_reward, result.reward_ci95);
  if (evaluation.exact) {
    out += fmt::format("exact           {:.6f}  ({} states)\n", evaluation.exact->success_probability,
                       evaluation.exact->states);
    if (rewards) out += fmt::format("exact reward    {:.6f}\n", evaluation.exact->expected_reward);
  }
  if (evaluation.regret) {
    const RegretEstimate& regret = *evaluation.regret;
    out += fmt::format("regret          {:.6f} ± {:.6f}  (optimum {:.6f}: success probability {:.6f}, {:.2f}% of it)\n",
                       regret.mean, regret.ci95, regret.optimum, regret.optimum - regret.mean,
                       regret.optimum > 0 ? 100.0 * (regret.optimum - regret.mean) / regret.optimum : 100.0);
  }
  if (!evaluation.timing) return out;
  out +=
      fmt::format("decision time   median {:.3f} µs, p99 {:.3f} µs, mean {:.3f} µs, max {:.3f} µs over {} decisions\n",
                  result.decision_time.median_us, result.decision_time.p99_us, result.decision_time.mean_us,
                  result.decision_time.max_us, result.decision_time.decisions);
  return out;
}

namespace {

// The keys every method's JSON starts with.
Json solve_head(const Solve& solve, double lower, double upper, bool exact) {
  Json out;
  out["instance"] = solve.instance;
  out["name"] = solve.problem->name();
  out["method"] = solve.method;
  // With rewards (SPEC §8) the solvers' value is the optimal expected reward.
  out[solve.problem->has_rewards() ? "optimal_expected_reward" : "optimal_success_probability"] =
      exact ? Json(lower) : Json(nullptr);
  out["lower_bound"] = lower;
  out["upper_bound"] = upper;
  out["exact"] = exact;
  return out;
}

Json search_json(const Solve& solve) {
  const SearchSolution& solution = *solve.search;
  Json out = solve_head(solve, solution.lower, solution.upper, solution.exact);
  if (!solution.exact) out["stopped_by"] = solution.stopped_by;
  out["states"] = solution.states;
  out["bounded_successors"] = solution.bounded;
  out["choices_cut"] = solution.choices_cut;
  out["upper_tests"] = solution.tested;
  out["refined_states"] = solution.refined;
  if (solve.timing) out["seconds"] = solve.seconds;
  out["first_choice"] = solution.first_choice;
  out["first_action"] = first_action_of(solve);
  return out;
}

std::string search_text(const Solve& solve, std::string out) {
  const SearchSolution& solution = *solve.search;
  if (!solution.exact) out += fmt::format("search cut                   at {}\n", solution.stopped_by);
  if (solution.first_choice >= 0) {
    out += fmt::format("first choice                 skeleton {} (refine {}){}\n", solution.first_choice,
                       first_action_of(solve), solution.exact ? "" : ", the best lower end's");
  } else {
    out += "first choice                 none (no skeleton can meet the deadline)\n";
  }
  out += fmt::format("states                       {} solved, {} successors valued by their bounds, {} choices cut\n",
                     solution.states, solution.bounded, solution.choices_cut);
  out += fmt::format("upper tests                  {} states expanded, {} with a refined upper bound\n",
                     solution.tested, solution.refined);
  if (solve.timing) out += fmt::format("time                         {:.4f} s\n", solve.seconds);
  return out;
}

}  // namespace

std::string to_json(const Solve& solve) {
  if (solve.search) return dump(search_json(solve));
  const LayeredSolution& solution = solve.solution;
  Json out = solve_head(solve, solution.lower, solution.upper, solution.exact);
  if (solve.memoised) {
    out["states"] = solution.states;
    if (solve.timing) out["seconds"] = solve.seconds;
    out["first_choice"] = solution.first_choice;
    out["first_action"] = first_action_of(solve);
    return dump(out);
  }
  if (solution.frontier_layer >= 0) {
    out["frontier_layer"] = solution.frontier_layer;
    out["stopped_by"] = solution.stopped_by;
  }
  if (solve.tolerance > 0) {
    out["tolerance"] = solve.tolerance;
    out["dropped"] = solution.dropped;
  }
  if (!solution.split_kept.empty()) {
    out["split"] = Json{{"enumerated_skeletons", solution.split_kept},
                        {"bounded_start_upper", solution.split_weak_upper},
                        {"lower_bound", solution.split_lower},
                        {"upper_bound", solution.split_upper},
                        {"states", solution.split_states}};
    if (solution.split_frontier_layer >= 0) {
      out["split"]["frontier_layer"] = solution.split_frontier_layer;
      out["split"]["stopped_by"] = solution.split_stopped_by;
    }
  }
  out["states"] = solution.states;
  if (solve.timing) out["seconds"] = solve.seconds;
  out["first_choice"] = solution.first_choice;
  out["first_action"] = first_action_of(solve);
  out["key_bytes"] = solution.key_bytes;
  if (solve.timing) {
    out["peak_memory_bytes"] = solution.peak_memory_bytes;
    out["peak_disk_bytes"] = solution.peak_disk_bytes;
  }
  if (solve.stats) {
    const auto layers_json = [&](const std::vector<LayerFigures>& of) {
      Json layers = Json::array();
      for (const LayerFigures& layer : of) {
        Json figures{{"layer", layer.layer}, {"states", layer.states}};
        if (solve.timing) {
          figures["forward_seconds"] = layer.forward_seconds;
          figures["backward_seconds"] = layer.backward_seconds;
        }
        layers.push_back(figures);
      }
      return layers;
    };
    if (!solution.layers.empty()) out["layers"] = layers_json(solution.layers);
    if (!solution.split_layers.empty()) out["split"]["layers"] = layers_json(solution.split_layers);
  }
  return dump(out);
}

std::string to_text(const Solve& solve) {
  const LayeredSolution& solution = solve.solution;
  const Problem& problem = *solve.problem;
  const std::string first_action = first_action_of(solve);
  std::string out = fmt::format("instance                     {} ({}), deadline {}, {} skeletons\n", solve.instance,
                                problem.name(), problem.deadline(), problem.skeleton_count());
  const char* objective = problem.has_rewards() ? "optimal expected reward    " : "optimal success probability";
  if (solve.search) {
    const SearchSolution& search = *solve.search;
    if (search.exact) {
      out += fmt::format("{}  {:.6f}\n", objective, search.lower);
    } else {
      out += fmt::format("{}  in [{:.6f}, {:.6f}] (width {:.6f})\n", objective, search.lower, search.upper,
                         search.upper - search.lower);
    }
    return search_text(solve, std::move(out));
  }
  if (solution.exact) {
    out += fmt::format("{}  {:.6f}\n", objective, solution.lower);
  } else {
    out += fmt::format("{}  in [{:.6f}, {:.6f}] (width {:.6f})\n", objective, solution.lower, solution.upper,
                       solution.upper - solution.lower);
  }
  if (solve.memoised) {
    if (solution.first_choice >= 0) {
      out += fmt::format("first choice                 skeleton {} (refine {})\n", solution.first_choice, first_action);
    } else {
      out += "first choice                 none (no skeleton can meet the deadline)\n";
    }
    out += fmt::format("states                       {}\n", solution.states);
    if (solve.timing) out += fmt::format("time                         {:.4f} s\n", solve.seconds);
    return out;
  }
  if (solution.frontier_layer >= 0) out += fmt::format("whole tree cut               {}\n", solution.stopped_by);
  if (solve.tolerance > 0) {
    out += fmt::format("tolerance                    {} ({} outcomes dropped a group)\n", solve.tolerance,
                       solution.dropped);
  }
  if (!solution.split_kept.empty()) {
    out += fmt::format(
        "split                        skeletons {} enumerated ({} states), the others bounded ({:.6f} at "
        "most alone): [{:.6f}, {:.6f}]\n",
        fmt::join(solution.split_kept, ","), solution.split_states, solution.split_weak_upper, solution.split_lower,
        solution.split_upper);
  }
  if (solution.first_choice >= 0) {
    out += fmt::format("first choice                 skeleton {} (refine {}){}\n", solution.first_choice, first_action,
                       solution.exact ? "" : ", the lower bound's policy");
  } else {
    out += "first choice                 none (no skeleton can meet the deadline)\n";
  }
  out += fmt::format("states                       {} in {} layers, {} bytes per state\n", solution.states,
                     solution.layers.size() + solution.split_layers.size(), solution.key_bytes);
  if (solve.timing) {
    out += fmt::format("peak memory, disk            {:.1f} MiB, {:.1f} MiB\n",
                       static_cast<double>(solution.peak_memory_bytes) / 1048576.0,
                       static_cast<double>(solution.peak_disk_bytes) / 1048576.0);
    out += fmt::format("time                         {:.4f} s\n", solve.seconds);
  }
  if (!solve.stats) return out;
  const auto print_layers = [&](const std::vector<LayerFigures>& layers, const char* title) {
    if (layers.empty()) return;
    out += fmt::format("\n{}\n", title);
    if (!solve.timing) {
      out += "| layer | states |\n|------:|-------:|\n";
      for (const LayerFigures& layer : layers) out += fmt::format("| {} | {} |\n", layer.layer, layer.states);
      return;
    }
    out += "| layer | states | forward s | backward s |\n|------:|-------:|----------:|-----------:|\n";
    for (const LayerFigures& layer : layers) {
      out += fmt::format("| {} | {} | {:.3f} | {:.3f} |\n", layer.layer, layer.states, layer.forward_seconds,
                         layer.backward_seconds);
    }
  };
  print_layers(solution.layers, "whole tree");
  print_layers(solution.split_layers, "split (the enumerated subtree; flagged copies one layer on included)");
  return out;
}

std::string policy_lines(const Solve& solve) {
  std::string lines;
  for (const PolicyEntry& entry : solve.solution.policy) {
    Json line = state_object(entry.state, solve.problem->skeleton_count());
    if (solve.problem->has_backtracking()) {
      // The execution each blamable refined action would restore (SPEC §7), by its id.
      Json restore = Json::object();
      for (int a = 0; a < solve.problem->action_count(); ++a) {
        const int slot = solve.problem->culprit_slot(a);
        if (slot >= 0) restore[solve.problem->action(a).id] = entry.state.restore[static_cast<std::size_t>(slot)];
      }
      line["restore"] = std::move(restore);
    }
    if (solve.problem->is_timed()) {
      // Chains or expiry (SPEC §9): each chain's state by name, and the static execution before
      // each refined timed action, by its id.
      // (The joint state numbers the first chain's state fastest, as Mdp::joint_chain_state.)
      Json chains = Json::object();
      int joint = entry.state.chains;
      for (const ExogenousChain& chain : solve.problem->chains()) {
        chains[chain.name] = chain.states[static_cast<std::size_t>(joint % chain.state_count())];
        joint /= chain.state_count();
      }
      if (!chains.empty()) line["chains"] = std::move(chains);
      Json before = Json::object();
      for (int a = 0; a < solve.problem->action_count(); ++a) {
        const int slot = solve.problem->timed_slot(a);
        if (slot >= 0) before[solve.problem->action(a).id] = entry.state.restore[static_cast<std::size_t>(slot)];
      }
      line["before"] = std::move(before);
    }
    line["choice"] = entry.choice;
    line["lower_bound"] = entry.lower;
    line["upper_bound"] = entry.upper;
    lines += line.dump() + "\n";
  }
  return lines;
}

std::string to_json(const Table& table) {
  Json out;
  out["episodes"] = table.episodes;
  out["seed"] = table.seed;
  out["solvers"] = table.solvers;
  out["rows"] = Json::array();
  for (const TableRow& row : table.rows) {
    Json line;
    line["instance"] = row.source;
    line["name"] = row.name;
    // Only rows acting while planning (SPEC §10) say so, so that plan-first tables stay as they were.
    if (row.acting == Acting::concurrent) line["acting"] = acting_name(row.acting);
    Json cells = Json::object();
    for (std::size_t s = 0; s < table.solvers.size(); ++s) {
      const TableCell& cell = row.cells[s];
      Json entry;
      entry["success_rate"] = cell.sampled.success_rate;
      entry["ci95"] = cell.sampled.ci95;
      if (row.rewards) {
        entry["mean_reward"] = cell.sampled.mean_reward;
        entry["reward_ci95"] = cell.sampled.reward_ci95;
      }
      entry["decision_time_us"] = {{"median", cell.sampled.decision_time.median_us},
                                   {"p99", cell.sampled.decision_time.p99_us},
                                   {"mean", cell.sampled.decision_time.mean_us}};
      if (cell.exact) {
        if (cell.exact->value) {
          entry[row.rewards ? "exact_expected_reward" : "exact_success_probability"] = *cell.exact->value;
        }
        entry["exact"] = exact_object(*cell.exact);
      }
      cells[table.solvers[s]] = entry;
    }
    line["solvers"] = cells;
    if (row.optimum) {
      if (row.optimum->value) {
        line[row.rewards ? "optimal_expected_reward" : "optimal_success_probability"] = *row.optimum->value;
      }
      line["optimal_states"] = row.optimum->states;
      line["optimum"] = exact_object(*row.optimum);
    }
    out["rows"].push_back(line);
  }
  return dump(out);
}

std::string to_markdown(const Table& table, const ParameterSpelling& spelling) {
  const std::string cap = spell_parameter(spelling, "max-states");
  std::vector<std::string> header{"instance"};
  for (const std::string& solver : table.solvers) header.push_back(solver);
  if (table.exact) header.emplace_back("optimum");
  std::vector<std::vector<std::string>> body;
  std::vector<double> latency_sum(table.solvers.size(), 0.0);
  for (const TableRow& row : table.rows) {
    std::vector<std::string> line{row.label};
    for (std::size_t s = 0; s < row.cells.size(); ++s) {
      const TableCell& cell = row.cells[s];
      // A row with rewards shows its mean reward (and expected rewards in parentheses).
      std::string text = row.rewards
                             ? fmt::format("{:.3f} ± {:.3f}", cell.sampled.mean_reward, cell.sampled.reward_ci95)
                             : fmt::format("{:.3f} ± {:.3f}", cell.sampled.success_rate, cell.sampled.ci95);
      if (cell.exact) text += " (" + exact_text(*cell.exact) + ")";
      line.push_back(text);
      latency_sum[s] += cell.sampled.decision_time.mean_us;
    }
    if (table.exact) line.push_back(exact_text(*row.optimum));
    body.push_back(std::move(line));
  }
  std::vector<std::string> latency{"mean decision time (µs)"};
  for (const double sum : latency_sum) {
    latency.push_back(fmt::format("{:.3f}", sum / static_cast<double>(table.rows.size())));
  }
  if (table.exact) latency.emplace_back("");
  body.push_back(std::move(latency));

  const bool any_rewards =
      std::any_of(table.rows.begin(), table.rows.end(), [](const TableRow& row) { return row.rewards; });
  std::string out = fmt::format(
      "Success probability{}: mean ± 95% over {} episodes (seed {}){}.\n\n",
      any_rewards ? " (expected reward in the rows of instances with rewards, SPEC §8)" : "", table.episodes,
      table.seed,
      table.exact
          ? "; exact value in parentheses; optimum = exact expectimax, or a certified [lower, upper] past " + cap
          : std::string());
  out += markdown_table(header, body);
  if (!table.exact) return out;
  out += fmt::format("\nExact parts (states, seconds; 'cap reached': more than {} {} states):\n", cap,
                     table.max_states.empty() ? 0 : table.max_states.front());
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const TableRow& row = table.rows[r];
    std::vector<std::string> parts;
    for (std::size_t s = 0; s < row.cells.size(); ++s) {
      const auto& exact = row.cells[s].exact;
      if (!exact) continue;
      parts.push_back(fmt::format("{} {}{} states, {:.1f} s", table.solvers[s], exact->cap_reached ? "over " : "",
                                  exact->states, exact->seconds));
    }
    parts.push_back(fmt::format("optimum {}{} states{}, {:.1f} s", row.optimum->cap_reached ? "over " : "",
                                row.optimum->states, row.optimum->cap_reached ? " (certified interval)" : "",
                                row.optimum->seconds));
    out += fmt::format("- {}: {}.\n", row.label, fmt::join(parts, "; "));
  }
  return out;
}

std::string to_json(const Training& training) {
  Json out;
  out["instance"] = training.instance;
  out["policy"] = training.policy;
  out["learning_curve"] = training.files.size() > 1 ? training.files[1] : std::string();
  out["episodes"] = training.episodes;
  out["seed"] = training.seed;
  out["acting"] = acting_name(training.problem != nullptr ? training.problem->acting() : Acting::plan_first);
  out["epochs"] = training.epochs;
  out["seconds"] = training.seconds;
  out["exact_success_probability"] = training.exact ? Json(*training.exact) : Json(nullptr);
  if (training.exact_reward) out["exact_expected_reward"] = *training.exact_reward;
  return dump(out);
}

std::string to_text(const Training& training) {
  const char* mode = training.problem->acting() == Acting::concurrent ? ", acting while planning" : "";
  std::string out = fmt::format("trained ppo on {} ({}{}): {} episodes in {} epochs, {:.1f} s\n", training.instance,
                                training.problem->name(), mode, training.episodes, training.epochs, training.seconds);
  if (training.exact) {
    out += fmt::format("exact success probability of the trained policy (greedy): {:.4f}\n", *training.exact);
    if (training.exact_reward)
      out += fmt::format("exact expected reward of the trained policy (greedy):    {:.6f}\n", *training.exact_reward);
  } else {
    out += fmt::format("exact success probability of the trained policy: not computed ({} skeletons; at most {})\n",
                       training.problem->skeleton_count(), kMaxExactSkeletons);
  }
  for (const std::string& file : training.files) out += "wrote " + file + "\n";
  return out;
}

std::string study_csv(const StudyRows& rows, const StudySettings& settings) {
  const AllocatorKind& searcher = allocator_registry().find(settings.searcher);
  // The searcher's iterations per search (its declared counters), 0 for a kind that does not search.
  const auto per_search = [](const AllocatorKind& kind, const MonteCarloResult& result) {
    return iterations_per_search(kind, result.statistics).value_or(0.0);
  };
  std::string csv;
  switch (rows.kind) {
    case StudyKind::compute_time: {
      const AllocatorKind& reference = allocator_registry().find(settings.reference);
      csv =
          "instance,solver,episodes,success_rate,ci95,mean_episode_seconds,median_episode_seconds,"
          "p99_episode_seconds,mean_decision_seconds,iterations_per_search\n";
      for (std::size_t i = 0; i < rows.compute_time.size(); ++i) {
        const ComputeTimeStudy& study = rows.compute_time[i];
        for (const auto& [kind, result] :
             {std::pair{&searcher, &study.searcher}, std::pair{&reference, &study.reference}}) {
          csv += fmt::format(
              "{},{},{},{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g}\n", rows.labels[i], kind->name, result->episodes,
              result->success_rate, result->ci95, result->episode_decision_time.mean_us * 1e-6,
              result->episode_decision_time.median_us * 1e-6, result->episode_decision_time.p99_us * 1e-6,
              result->decision_time.mean_us * 1e-6, per_search(*kind, *result));
        }
      }
      break;
    }
    case StudyKind::equal_time:
      csv =
          "instance,episodes,dp_rerun_decision_seconds,dp_rerun_success_rate,dp_rerun_ci95,mcts_success_rate,"
          "mcts_ci95,mcts_iterations_per_search\n";
      for (std::size_t i = 0; i < rows.equal_time.size(); ++i) {
        const EqualTimeStudy& study = rows.equal_time[i];
        csv += fmt::format("{},{},{:.9g},{},{},{},{},{:.6g}\n", rows.labels[i], settings.episodes,
                           study.reference_decision_seconds, study.reference.success_rate, study.reference.ci95,
                           study.searcher.success_rate, study.searcher.ci95, per_search(searcher, study.searcher));
      }
      break;
    case StudyKind::anytime:
      csv =
          "instance,episodes,log10_multiplier,seconds_per_decision,success_rate,ci95,iterations_per_search,"
          "dp_rerun_decision_seconds,dp_rerun_success_rate,optimum\n";
      for (std::size_t i = 0; i < rows.anytime.size(); ++i) {
        const AnytimeStudy& study = rows.anytime[i];
        for (const AnytimePoint& point : study.points) {
          csv += fmt::format("{},{},{},{:.9g},{},{},{:.6g},{:.9g},{},{}\n", rows.labels[i], settings.episodes,
                             point.log10_multiplier, point.seconds_per_decision, point.searcher.success_rate,
                             point.searcher.ci95, per_search(searcher, point.searcher),
                             study.reference_decision_seconds, study.reference.success_rate, study.optimum);
        }
      }
      break;
  }
  return csv;
}

std::string registry_json(const AllocatorRegistry& registry) {
  Json out = Json::array();
  for (const AllocatorKind& kind : registry.kinds()) {
    Json entry;
    entry["name"] = kind.name;
    entry["summary"] = kind.summary;
    entry["capabilities"] = kind.capabilities.names();
    // null: the kind decides plan-first only (SPEC §10).
    entry["commit_rule"] = kind.acts_while_planning() ? Json(kind.commit_rule) : Json(nullptr);
    entry["parameters"] = Json::array();
    for (const Parameter& parameter : kind.parameters) {
      Json item;
      item["name"] = parameter.name;
      item["type"] = to_string(parameter.type);
      if (!parameter.default_value.empty()) item["default"] = parameter.default_value;
      if (std::isfinite(parameter.minimum)) item["minimum"] = parameter.minimum;
      if (std::isfinite(parameter.maximum)) item["maximum"] = parameter.maximum;
      if (!parameter.choices.empty()) item["choices"] = parameter.choices;
      item["help"] = parameter.help;
      entry["parameters"].push_back(item);
    }
    out.push_back(entry);
  }
  return dump(out);
}

std::string registry_markdown(const AllocatorRegistry& registry, const ParameterSpelling& spelling) {
  std::vector<std::vector<std::string>> kinds;
  for (const AllocatorKind& kind : registry.kinds()) {
    kinds.push_back({"`" + kind.name + "`", fmt::format("{}", fmt::join(kind.capabilities.names(), ", ")), kind.summary,
                     kind.acts_while_planning() ? kind.commit_rule : "plan-first only"});
  }
  std::vector<std::vector<std::string>> parameters;
  for (const Parameter& parameter : registry.parameters()) {
    parameters.push_back({"`" + (spelling ? spelling(parameter.name) : parameter.name) + "`",
                          fmt::format("{}", fmt::join(registry.kinds_with_parameter(parameter.name), ", ")),
                          std::string(to_string(parameter.type)),
                          parameter.default_value.empty() ? "none" : parameter.default_value, parameter.allowed(),
                          parameter.help});
  }
  return markdown_table({"allocator", "capabilities", "what it does", "acting while planning (SPEC §10)"}, kinds) +
         "\n" + markdown_table({"parameter", "of", "type", "default", "allowed", "meaning"}, parameters);
}

namespace {

struct ActionSummary {
  double found_in_time;    // P(planning time <= D)
  double mean_planning;    // E[T | T <= D], steps
  double mean_execution;   // E[X | X <= D], steps
  double execution_never;  // P(X > D)
};

ActionSummary summarise(const Action& action) {
  return ActionSummary{1.0 - action.planning.never(), action.planning.mean_finite(), action.execution.mean_finite(),
                       action.execution.never()};
}

std::string format_mean(double mean) { return std::isfinite(mean) ? fmt::format("{:.2f}", mean) : "-"; }

}  // namespace

std::string fit_markdown(const FitResult& fit) {
  std::vector<std::string> header{"action",   "attempts",     "found",        "cut off",
                                  "P(T ≤ D)", "E[T | T ≤ D]", "E[X | X ≤ D]", "P(X > D)"};
  // A log with backtracks (SPEC §7): their count and the fitted chance of backtracking, too.
  const bool backtracking = fit.problem.has_backtracking();
  if (backtracking) header.insert(header.begin() + 4, {"backtracked", "P(backtrack)"});
  std::vector<std::vector<std::string>> body;
  for (std::size_t a = 0; a < fit.actions.size(); ++a) {
    const ActionFit& counts = fit.actions[a];
    const Action& action = fit.problem.action(static_cast<int>(a));
    const ActionSummary summary = summarise(action);
    std::vector<std::string> row{counts.id,
                                 std::to_string(counts.attempts),
                                 std::to_string(counts.found),
                                 std::to_string(counts.censored),
                                 fmt::format("{:.3f}", summary.found_in_time),
                                 format_mean(summary.mean_planning),
                                 format_mean(summary.mean_execution),
                                 fmt::format("{:.3f}", summary.execution_never)};
    if (backtracking) {
      row.insert(row.begin() + 4,
                 {std::to_string(counts.backtracked), fmt::format("{:.3f}", 1.0 - action.backtrack.never())});
    }
    body.push_back(std::move(row));
  }
  return markdown_table(header, body);
}

std::string fit_json(const FitResult& fit) {
  Json actions = Json::array();
  for (std::size_t a = 0; a < fit.actions.size(); ++a) {
    const ActionFit& counts = fit.actions[a];
    const ActionSummary summary = summarise(fit.problem.action(static_cast<int>(a)));
    Json entry;
    entry["action"] = counts.id;
    entry["attempts"] = counts.attempts;
    entry["found"] = counts.found;
    entry["cut_off"] = counts.censored;
    if (fit.problem.has_backtracking()) {
      const Action& action = fit.problem.action(static_cast<int>(a));
      entry["backtracked"] = counts.backtracked;
      entry["backtrack_probability"] = 1.0 - action.backtrack.never();
      Json culprits = Json::object();
      for (const Culprit& culprit : action.culprits) culprits[culprit.id] = culprit.probability;
      entry["culprits"] = culprits;
    }
    entry["planning_within_deadline"] = summary.found_in_time;
    entry["mean_planning_steps"] = std::isfinite(summary.mean_planning) ? Json(summary.mean_planning) : Json(nullptr);
    entry["mean_execution_steps"] =
        std::isfinite(summary.mean_execution) ? Json(summary.mean_execution) : Json(nullptr);
    entry["execution_never"] = summary.execution_never;
    actions.push_back(entry);
  }
  return dump(actions);
}

std::string histogram_csv(const Problem& problem) {
  std::string csv = "action,distribution,step,probability\n";
  for (const Action& action : problem.actions()) {
    const std::string quoted = csv_field(action.id);
    for (const auto& [kind, distribution] : {std::pair<const char*, const Distribution*>{"planning", &action.planning},
                                             {"execution", &action.execution}}) {
      const auto masses = distribution->masses();
      for (std::size_t t = 0; t < masses.size(); ++t) {
        if (masses[t] > 0) csv += fmt::format("{},{},{},{:.17g}\n", quoted, kind, t, masses[t]);
      }
      csv += fmt::format("{},{},never,{:.17g}\n", quoted, kind, distribution->never());
    }
  }
  return csv;
}

std::string csv_field(std::string_view text) {
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

std::string markdown_table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& body) {
  std::vector<std::size_t> widths(header.size(), 0);
  const auto widen = [&widths](const std::vector<std::string>& line) {
    for (std::size_t i = 0; i < line.size(); ++i) widths[i] = std::max(widths[i], display_width(line[i]));
  };
  widen(header);
  for (const auto& line : body) widen(line);
  const auto render = [&widths](const std::vector<std::string>& line) {
    std::string out = "|";
    for (std::size_t i = 0; i < line.size(); ++i) {
      out += " " + line[i] + std::string(widths[i] - display_width(line[i]), ' ') + " |";
    }
    return out + "\n";
  };
  std::string out = render(header);
  std::string rule = "|";
  for (const std::size_t width : widths) rule += std::string(width + 2, '-') + "|";
  out += rule + "\n";
  for (const auto& line : body) out += render(line);
  return out;
}

}  // namespace ontime::report
