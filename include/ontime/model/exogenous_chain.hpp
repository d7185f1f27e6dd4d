#pragma once
// An exogenous process: a finite Markov chain that advances one step per time step whatever the
// robot does (a queue's length, a door that opens and closes, a person who may leave a room).
// Its states are named; row i of its transition matrix is the distribution of the next state
// when the chain is in state i; `start` is the state observed at time 0.
//
// The chain file is the JSON of chain_to_json (format "ontime-chain", version 1):
//   {"format": "ontime-chain", "version": 1, "name": "queue", "states": ["0", "1", "2"],
//    "start": "0", "transitions": [[0.8, 0.2, 0], [0.25, 0.55, 0.2], [0, 0.25, 0.75]]}
// `ontime fit-chain` (learn/chain_fitting.hpp) fits one from observed states. A chain is valid
// when it has at least one state, its state names are distinct and non-empty, its start is one
// of them, and its matrix is square over them with finite entries >= 0 whose rows sum to 1
// (within kChainRowTolerance).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ontime {

struct ExogenousChain {
  std::string name;
  std::vector<std::string> states;
  int start = 0;  // index into states
  std::vector<std::vector<double>> transitions;

  // The number of states of the chain.
  int state_count() const noexcept { return static_cast<int>(states.size()); }
  // The index of the state named `state`, or -1.
  int state_index(std::string_view state) const noexcept;
};

// How far a row's sum may lie from 1: far above the rounding of a row written with 17
// significant digits, far below any probability a user means.
inline constexpr double kChainRowTolerance = 1e-9;
// At most this many states (a chain joins the state of the exact solvers).
inline constexpr int kMaxChainStates = 4096;

// The first rule a chain breaks: where (a JSON path of its file: `states[2]`,
// `transitions[1][0]`) and which rule; nothing when it is valid.
struct ChainFault {
  std::string place;
  std::string rule;
};
// The first rule `chain` breaks, or nullopt when it is valid.
std::optional<ChainFault> find_chain_fault(const ExogenousChain& chain);

// Reads a chain file; InputError naming the file, the place and the rule (another format or
// version, a missing or unknown key, a broken rule above).
ExogenousChain parse_chain(std::string_view text, std::string_view source);
ExogenousChain load_chain(const std::filesystem::path& path);

// The chain file's text (entries with 17 significant digits: it reads back bit for bit).
// Throws UsageError for an invalid chain.
std::string chain_to_json(const ExogenousChain& chain);
void save_chain(const ExogenousChain& chain, const std::filesystem::path& path);

// The distribution of the chain's state `steps` steps after it is in state `from`: a vector over
// chain.states. Summed in a fixed order (row by row, state by state), so that it is the same on
// every machine. O(steps * n^2). Throws UsageError for an invalid chain or `from`, or steps < 0;
// Cancelled once `stop` (checked every 4096 steps) returns true, so that a caller can stop a long one.
std::vector<double> chain_distribution(const ExogenousChain& chain, int from, std::int64_t steps,
                                       const std::function<bool()>& stop = {});

// One step of a distribution over the chain's states: next[j] = sum_i now[i] * transitions[i][j], in
// that fixed order (rows of states with no mass skipped). Both spans have one entry per state (not
// checked); no allocation.
void advance_chain_distribution(const ExogenousChain& chain, std::span<const double> now, std::span<double> next);

}  // namespace ontime
