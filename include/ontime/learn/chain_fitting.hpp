#pragma once
// Fitting an exogenous chain (model/exogenous_chain.hpp) to observed states: a queue's length
// read once per step, a door seen open or closed. Maximum likelihood from the transitions seen
// between consecutive steps:
//
// - markov: every transition probability free, P(i -> j) = (n_ij + prior) / (n_i + n prior),
//   n_ij the transitions seen from i to j (a Dirichlet prior of `prior` pseudo-transitions per
//   entry; 0: the plain maximum likelihood). A state never seen followed by another has no row
//   unless prior > 0. O(transitions + n^2).
// - birth-death: a queue of capacity N (states "0" ... "N"). Each step one customer arrives with
//   probability `arrival` (not when full), or one is served with probability `service` (not
//   when empty), or nothing happens: at most one change per step, so a queue read once per step
//   must not move by more than one. Two parameters for the whole queue, so a short log fits it
//   where the markov kind would leave rows empty. Closed form where the counts allow it (no stay
//   at 0 or none at N observed), else NLopt's L-BFGS on a smooth reparametrisation of the two
//   (the likelihood is concave in them: one maximum). O(transitions).
//
// The log of observations (JSON lines, one per observation):
//   {"sequence": "monday", "step": 17, "state": 3}
// `state`: a name (string) or a whole number >= 0 (named by its decimal digits); `sequence`
// (optional, default ""): observations of one sequence are in increasing `step` order; records
// of several sequences may interleave. Transitions are counted between observations of the same
// sequence one step apart; a gap ends a run. The fitted chain starts in the state most often
// observed first in a sequence (ties: the lowest index).

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/model/exogenous_chain.hpp"

namespace ontime {

// States observed at consecutive steps: states[t] at step first_step + t. `source` names where
// it came from (a file, or `sequences[2]` when given in code) for messages.
struct ChainRun {
  std::string source;
  std::string sequence;
  std::int64_t first_step = 0;
  std::vector<std::string> states;
};

// The runs of a log of observations (above), in the order of their first observation. Throws
// InputError naming the file, the line and the rule (a step not after the sequence's previous
// one, a state that is neither a name nor a whole number, an unknown key; a log without records).
std::vector<ChainRun> parse_chain_observations(std::string_view text, std::string_view source);
std::vector<ChainRun> load_chain_observations(const std::filesystem::path& path);

enum class ChainKind { markov, birth_death };
// "markov" / "birth-death"; UsageError naming the kinds for another name.
ChainKind chain_kind(std::string_view name);
std::string_view chain_kind_name(ChainKind kind) noexcept;

struct ChainFitOptions {
  ChainKind kind = ChainKind::markov;
  std::string name = "chain";
  double prior = 0.0;  // markov: pseudo-transitions per entry, >= 0
  // markov: the chain's states in this order (every observed state among them); empty: the
  // states observed, in numeric order when all are whole numbers, else in name order.
  std::vector<std::string> states;
  // birth-death: the queue's capacity N; 0: the longest queue observed.
  std::int64_t capacity = 0;
};

struct ChainFit {
  ExogenousChain chain;
  std::uint64_t transitions = 0;  // counted (pairs of consecutive steps)
  std::uint64_t runs = 0;
  double log_likelihood = 0.0;  // of the transitions counted, under the fitted chain
  // birth-death: the fitted probabilities per step (markov: 0).
  double arrival = 0.0;
  double service = 0.0;
};

// Fits a chain to the runs. Throws UsageError for bad options (a negative or non-finite prior,
// capacity out of range, states listed twice), InputError naming a run's source and step for
// observations the kind cannot explain (birth-death: a state that is not a whole number, a move
// by more than one, a queue above the capacity; markov: a state not among `states`), and
// UsageError when no transition was observed or (markov, prior 0) a state has no row.
ChainFit fit_chain(std::span<const ChainRun> runs, const ChainFitOptions& options);

}  // namespace ontime
