// `ontime fit-chain LOG... --kind markov|birth-death -o CHAIN`: an exogenous chain (a queue, a
// door) fitted to a log of observed states (learn/chain_fitting.hpp), written as a chain file.

#include <fmt/format.h>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/learn/chain_fitting.hpp"
#include "ontime/model/exogenous_chain.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_fit_chain_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> logs;
    std::string kind = "markov";
    std::string output;
    std::vector<std::string> states;
    ChainFitOptions fit;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "fit-chain", "Fit an exogenous chain (a queue's length, a door's state) to a log of observed states");
  command->add_option("logs", options->logs, "Observation logs (JSON lines: sequence, step, state)")->required();
  command->add_option("--kind", options->kind, "markov (every transition free) or birth-death (a queue)")
      ->capture_default_str();
  command->add_option("-o,--output", options->output, "Chain file to write")->required();
  command->add_option("--name", options->fit.name, "The chain's name")->capture_default_str();
  add_number_option(*command, "--prior", options->fit.prior,
                    "markov: pseudo-transitions added to every entry (0: plain maximum likelihood)", 0.0, 1e12);
  command->add_option("--states", options->states, "markov: the states, in this order (default: those observed)")
      ->delimiter(',');
  add_number_option(*command, "--capacity", options->fit.capacity,
                    "birth-death: the queue's capacity (0: the longest queue observed)", std::int64_t{0},
                    std::int64_t{kMaxChainStates - 1});
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    options->fit.kind = chain_kind(options->kind);
    options->fit.states = options->states;
    std::vector<std::filesystem::path> inputs(options->logs.begin(), options->logs.end());
    check_outputs({{"--output", options->output}}, inputs);
    std::vector<ChainRun> runs;
    for (const std::string& log : options->logs) {
      std::vector<ChainRun> read = load_chain_observations(log);
      runs.insert(runs.end(), std::make_move_iterator(read.begin()), std::make_move_iterator(read.end()));
    }
    const ChainFit fit = fit_chain(runs, options->fit);
    save_chain(fit.chain, options->output);
    const ExogenousChain& chain = fit.chain;
    if (options->json) {
      Json out;
      out["chain"] = options->output;
      out["kind"] = std::string(chain_kind_name(options->fit.kind));
      out["name"] = chain.name;
      out["states"] = chain.states;
      out["start"] = chain.states[static_cast<std::size_t>(chain.start)];
      out["transitions_counted"] = fit.transitions;
      out["runs"] = fit.runs;
      out["log_likelihood"] = fit.log_likelihood;
      if (options->fit.kind == ChainKind::birth_death) {
        out["arrival"] = fit.arrival;
        out["service"] = fit.service;
      }
      out["transitions"] = chain.transitions;
      print_json(out);
      return;
    }
    fmt::print(
        "Fitted a {} chain '{}' of {} states to {} transitions in {} runs (log-likelihood {:.6g}), starting in "
        "'{}': wrote {}.\n",
        chain_kind_name(options->fit.kind), chain.name, chain.state_count(), fit.transitions, fit.runs,
        fit.log_likelihood, chain.states[static_cast<std::size_t>(chain.start)], options->output);
    if (options->fit.kind == ChainKind::birth_death) {
      fmt::print(
          "Per step: a customer arrives with probability {:.6g} (not when full), one is served with "
          "probability {:.6g} (not when empty).\n",
          fit.arrival, fit.service);
    }
    // The matrix itself for chains small enough to read.
    constexpr int kPrintedStates = 12;
    if (chain.state_count() <= kPrintedStates) {
      std::size_t width = 4;
      for (const std::string& state : chain.states) width = std::max(width, state.size());
      fmt::print("{:>{}}", "", width);
      for (const std::string& state : chain.states) fmt::print(" {:>8}", state);
      fmt::print("\n");
      for (int i = 0; i < chain.state_count(); ++i) {
        fmt::print("{:>{}}", chain.states[static_cast<std::size_t>(i)], width);
        for (const double p : chain.transitions[static_cast<std::size_t>(i)]) fmt::print(" {:8.4f}", p);
        fmt::print("\n");
      }
    }
  });
}

}  // namespace ontime::cli
