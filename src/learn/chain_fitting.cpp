#include "ontime/learn/chain_fitting.hpp"

#include <nlopt.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <unordered_set>

#include "ontime/util/error.hpp"
#include "ontime/util/input_file.hpp"
#include "ontime/util/json_input.hpp"
#include "util/portable_math.hpp"

namespace ontime {
namespace {

using ObservationJson = nlohmann::ordered_json;

// A state's name that is a whole number written plainly ("0", "17"; not "017", "+3", "1.0").
bool is_whole_number(const std::string& name) {
  if (name.empty() || name.size() > 18) return false;
  if (name.size() > 1 && name[0] == '0') return false;
  return std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string run_place(const ChainRun& run, std::size_t t) {
  return "sequence '" + run.sequence + "', step " + std::to_string(run.first_step + static_cast<std::int64_t>(t));
}

// One line of the observation log.
struct ObservedState {
  std::string sequence;
  std::int64_t step = 0;
  std::string state;
};

ObservedState read_observation(const ObservationJson& record, const std::string& source, std::size_t line) {
  const std::string place = "line " + std::to_string(line);
  const auto fail = [&](const std::string& key, const std::string& rule) {
    throw InputError(source, key.empty() ? place : place + ": " + key, rule);
  };
  if (!record.is_object()) fail("", "a record must be a JSON object (got " + detail::describe_json_type(record) + ")");
  for (const auto& [key, value] : record.items()) {
    if (key != "sequence" && key != "step" && key != "state") {
      fail(key, "unknown key (expected 'sequence', 'step', 'state')");
    }
  }
  ObservedState observation;
  if (record.contains("sequence")) {
    if (!record["sequence"].is_string()) {
      fail("sequence", "must be a string naming the sequence (got " + detail::quote_json(record["sequence"]) + ")");
    }
    observation.sequence = record["sequence"].get<std::string>();
  }
  if (!record.contains("step")) fail("", "missing required key 'step'");
  const std::optional<std::int64_t> step =
      detail::json_whole_number(record["step"], 0, std::numeric_limits<std::int64_t>::max() / 2);
  if (!step) fail("step", "must be a whole number of steps >= 0 (got " + detail::quote_json(record["step"]) + ")");
  observation.step = *step;
  if (!record.contains("state")) fail("", "missing required key 'state'");
  const ObservationJson& state = record["state"];
  if (state.is_string()) {
    if (state.get<std::string>().empty()) fail("state", "a state's name is not empty");
    observation.state = state.get<std::string>();
  } else {
    const std::optional<std::int64_t> number =
        detail::json_whole_number(state, 0, std::numeric_limits<std::int64_t>::max());
    if (!number) fail("state", "must be a state's name or a whole number >= 0 (got " + detail::quote_json(state) + ")");
    observation.state = std::to_string(*number);
  }
  return observation;
}

// x * log(p), 0 when x is 0.
double weighted_log(double count, double probability) { return count > 0 ? count * portable_log(probability) : 0.0; }

// log(1 + e^x) without overflow.
double log_one_plus_exp(double x) { return std::max(x, 0.0) + portable_log1p(portable_exp(-std::abs(x))); }

// The birth-death counts: stays at 0, in between and at the capacity; moves up and down.
struct QueueCounts {
  double stay_empty = 0, stay_between = 0, stay_full = 0, up = 0, down = 0;
  double total() const { return stay_empty + stay_between + stay_full + up + down; }
};

// log(1 + e^u + e^v), without overflow.
double log_one_plus(double u, double v) {
  const double m = std::max({0.0, u, v});
  return m + portable_log(portable_exp(-m) + portable_exp(u - m) + portable_exp(v - m));
}

// The negative log-likelihood over the total count, in (u, v) with arrival = e^u / (1 + e^u +
// e^v) and service = e^v / (1 + e^u + e^v): both free of bounds, their sum below 1.
double queue_objective(unsigned n, const double* x, double* gradient, void* data) {
  const auto& c = *static_cast<const QueueCounts*>(data);
  (void)n;
  const double u = x[0];
  const double v = x[1];
  const double total = c.total();
  const double l = log_one_plus(u, v);
  const double value =
      -c.up * u - c.down * v - c.stay_empty * log_one_plus_exp(v) - c.stay_full * log_one_plus_exp(u) + total * l;
  if (gradient != nullptr) {
    gradient[0] = (-c.up - c.stay_full * portable_logistic(u) + total * portable_exp(u - l)) / total;
    gradient[1] = (-c.down - c.stay_empty * portable_logistic(v) + total * portable_exp(v - l)) / total;
  }
  return value / total;
}

// The maximum-likelihood arrival and service probabilities.
std::array<double, 2> fit_queue(const QueueCounts& c) {
  const double up = c.up, down = c.down;
  if (up == 0 && down == 0) return {0.0, 0.0};
  if (up == 0) return {0.0, down / (down + c.stay_between + c.stay_full)};
  if (down == 0) return {up / (up + c.stay_empty + c.stay_between), 0.0};
  if (c.stay_full == 0) {
    // Then the likelihood factors in a = arrival and b = service / (1 - arrival).
    const double arrival = up / (up + c.stay_empty + down + c.stay_between);
    return {arrival, (1 - arrival) * down / (down + c.stay_between)};
  }
  if (c.stay_empty == 0) {
    // The same with the roles of arrival and service exchanged.
    const double service = down / (down + c.stay_full + up + c.stay_between);
    return {(1 - service) * up / (up + c.stay_between), service};
  }
  const double total = c.total();
  const double arrival0 = (up + 0.5) / (total + 1.5);
  const double service0 = (down + 0.5) / (total + 1.5);
  const double rest0 = 1 - arrival0 - service0;
  std::array<double, 2> x{portable_log(arrival0 / rest0), portable_log(service0 / rest0)};
  QueueCounts counts = c;
  nlopt_opt optimiser = nlopt_create(NLOPT_LD_LBFGS, 2);
  nlopt_set_min_objective(optimiser, queue_objective, &counts);
  nlopt_set_ftol_rel(optimiser, 1e-15);
  nlopt_set_xtol_rel(optimiser, 1e-12);
  nlopt_set_maxeval(optimiser, 2000);
  double minimum = 0.0;
  const nlopt_result result = nlopt_optimize(optimiser, x.data(), &minimum);
  nlopt_destroy(optimiser);
  if (result < 0)
    throw std::runtime_error("fit-chain: the optimiser failed (nlopt code " + std::to_string(result) + ")");
  const double l = log_one_plus(x[0], x[1]);
  return {portable_exp(x[0] - l), portable_exp(x[1] - l)};
}

// The index of the state each run's sequence was first observed in, counted; the most frequent
// (ties: the lowest index).
int most_frequent_first(std::span<const ChainRun> runs, const std::vector<int>& first_state_of_run, int states) {
  std::vector<std::uint64_t> firsts(static_cast<std::size_t>(states), 0);
  std::unordered_set<std::string> seen;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    if (seen.insert(runs[r].sequence).second) ++firsts[static_cast<std::size_t>(first_state_of_run[r])];
  }
  return static_cast<int>(std::max_element(firsts.begin(), firsts.end()) - firsts.begin());
}

void check_options(const ChainFitOptions& options) {
  if (options.name.empty()) throw UsageError("fit-chain: the chain's name is not empty");
  if (!(std::isfinite(options.prior) && options.prior >= 0)) {
    throw UsageError("fit-chain: the prior is a finite number of pseudo-transitions >= 0 (got " +
                     std::to_string(options.prior) + ")");
  }
  if (options.capacity < 0 || options.capacity >= kMaxChainStates) {
    throw UsageError("fit-chain: the capacity is between 0 (the longest queue observed) and " +
                     std::to_string(kMaxChainStates - 1) + " (got " + std::to_string(options.capacity) + ")");
  }
  std::unordered_set<std::string_view> listed;
  for (const std::string& state : options.states) {
    if (state.empty()) throw UsageError("fit-chain: a state's name is not empty");
    if (!listed.insert(state).second) throw UsageError("fit-chain: state '" + state + "' is listed twice");
  }
  if (options.kind == ChainKind::birth_death && !options.states.empty()) {
    throw UsageError("fit-chain: a birth-death chain's states are 0 ... capacity (give the capacity, not states)");
  }
  if (options.kind == ChainKind::markov && options.capacity != 0) {
    throw UsageError("fit-chain: the capacity is a birth-death chain's (a markov chain takes its states)");
  }
}

ChainFit fit_birth_death(std::span<const ChainRun> runs, const ChainFitOptions& options) {
  std::int64_t longest = 0;
  for (const ChainRun& run : runs) {
    for (std::size_t t = 0; t < run.states.size(); ++t) {
      if (!is_whole_number(run.states[t])) {
        throw InputError(
            run.source, run_place(run, t),
            "a birth-death chain's state is a queue's length, a whole number (got '" + run.states[t] + "')");
      }
      longest = std::max<std::int64_t>(longest, std::stoll(run.states[t]));
    }
  }
  const std::int64_t capacity = options.capacity > 0 ? options.capacity : longest;
  if (capacity >= kMaxChainStates) {
    throw UsageError("fit-chain: a queue of " + std::to_string(capacity) + " is longer than a chain holds (" +
                     std::to_string(kMaxChainStates - 1) + ")");
  }
  QueueCounts counts;
  ChainFit fit;
  std::vector<int> first_state(runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const ChainRun& run = runs[r];
    first_state[r] = static_cast<int>(std::stoll(run.states.front()));
    for (std::size_t t = 0; t < run.states.size(); ++t) {
      const std::int64_t now = std::stoll(run.states[t]);
      if (now > capacity) {
        throw InputError(run.source, run_place(run, t),
                         "a queue of " + run.states[t] + " is above the capacity of " + std::to_string(capacity));
      }
      if (t == 0) continue;
      const std::int64_t before = std::stoll(run.states[t - 1]);
      ++fit.transitions;
      if (now == before) {
        (now == 0 ? counts.stay_empty : now == capacity ? counts.stay_full : counts.stay_between) += 1;
      } else if (now == before + 1) {
        counts.up += 1;
      } else if (now == before - 1) {
        counts.down += 1;
      } else {
        throw InputError(run.source, run_place(run, t),
                         "the queue goes from " + run.states[t - 1] + " to " + run.states[t] +
                             " in one step; a birth-death chain moves by at most one per step");
      }
    }
  }
  if (fit.transitions == 0)
    throw UsageError("fit-chain: no two observations of a sequence one step apart: nothing to fit");
  const auto n = static_cast<std::size_t>(capacity + 1);
  const auto [arrival, service] = fit_queue(counts);
  ExogenousChain& chain = fit.chain;
  chain.name = options.name;
  for (std::size_t i = 0; i < n; ++i) chain.states.push_back(std::to_string(i));
  chain.transitions.assign(n, std::vector<double>(n, 0.0));
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double>& row = chain.transitions[i];
    const double in = i + 1 < n ? arrival : 0.0;
    const double out = i > 0 ? service : 0.0;
    if (i + 1 < n) row[i + 1] = in;
    if (i > 0) row[i - 1] = out;
    row[i] = 1.0 - in - out;
  }
  chain.start = most_frequent_first(runs, first_state, static_cast<int>(n));
  fit.runs = runs.size();
  fit.arrival = arrival;
  fit.service = service;
  fit.log_likelihood = weighted_log(counts.up, arrival) + weighted_log(counts.down, service) +
                       weighted_log(counts.stay_empty, 1 - arrival) + weighted_log(counts.stay_full, 1 - service) +
                       weighted_log(counts.stay_between, 1 - arrival - service);
  return fit;
}

ChainFit fit_markov(std::span<const ChainRun> runs, const ChainFitOptions& options) {
  std::vector<std::string> states = options.states;
  if (states.empty()) {
    std::unordered_set<std::string> seen;
    for (const ChainRun& run : runs) {
      for (const std::string& state : run.states) {
        if (seen.insert(state).second) states.push_back(state);
      }
    }
    const bool numeric = std::all_of(states.begin(), states.end(), is_whole_number);
    std::sort(states.begin(), states.end(), [numeric](const std::string& a, const std::string& b) {
      return numeric && a.size() != b.size() ? a.size() < b.size() : a < b;
    });
  }
  if (states.size() > static_cast<std::size_t>(kMaxChainStates)) {
    throw UsageError("fit-chain: " + std::to_string(states.size()) + " states, more than a chain holds (" +
                     std::to_string(kMaxChainStates) + ")");
  }
  std::map<std::string, int, std::less<>> index;
  for (std::size_t i = 0; i < states.size(); ++i) index.emplace(states[i], static_cast<int>(i));
  const std::size_t n = states.size();
  std::vector<std::vector<double>> counts(n, std::vector<double>(n, 0.0));
  ChainFit fit;
  std::vector<int> first_state(runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const ChainRun& run = runs[r];
    int before = -1;
    for (std::size_t t = 0; t < run.states.size(); ++t) {
      const auto found = index.find(run.states[t]);
      if (found == index.end()) {
        throw InputError(run.source, run_place(run, t), "state '" + run.states[t] + "' is not among the states listed");
      }
      if (t == 0) first_state[r] = found->second;
      if (before >= 0) {
        counts[static_cast<std::size_t>(before)][static_cast<std::size_t>(found->second)] += 1;
        ++fit.transitions;
      }
      before = found->second;
    }
  }
  if (fit.transitions == 0)
    throw UsageError("fit-chain: no two observations of a sequence one step apart: nothing to fit");
  ExogenousChain& chain = fit.chain;
  chain.name = options.name;
  chain.states = states;
  chain.transitions.assign(n, std::vector<double>(n, 0.0));
  for (std::size_t i = 0; i < n; ++i) {
    double leaving = 0.0;
    for (const double count : counts[i]) leaving += count;
    if (leaving == 0 && options.prior == 0) {
      throw UsageError("fit-chain: state '" + states[i] +
                       "' is never seen followed by another, so it has no row: give a prior > 0 (--prior), leave it "
                       "out, or fit a birth-death chain");
    }
    const double denominator = leaving + static_cast<double>(n) * options.prior;
    for (std::size_t j = 0; j < n; ++j) {
      chain.transitions[i][j] = (counts[i][j] + options.prior) / denominator;
      fit.log_likelihood += weighted_log(counts[i][j], chain.transitions[i][j]);
    }
  }
  chain.start = most_frequent_first(runs, first_state, static_cast<int>(n));
  fit.runs = runs.size();
  return fit;
}

}  // namespace

std::vector<ChainRun> parse_chain_observations(std::string_view text, std::string_view source) {
  const std::string name(source);
  std::vector<ChainRun> runs;
  // Per sequence: its last step and the run that holds it.
  std::map<std::string, std::pair<std::int64_t, std::size_t>, std::less<>> last;
  detail::for_each_json_line<ObservationJson>(text, name, [&](const ObservationJson& record, std::size_t line) {
    ObservedState observation = read_observation(record, name, line);
    const auto found = last.find(observation.sequence);
    if (found != last.end() && observation.step <= found->second.first) {
      throw InputError(name, "line " + std::to_string(line) + ": step",
                       "must be after the sequence's previous step, " + std::to_string(found->second.first) + " (got " +
                           std::to_string(observation.step) + ")");
    }
    if (found != last.end() && observation.step == found->second.first + 1) {
      runs[found->second.second].states.push_back(std::move(observation.state));
      found->second.first = observation.step;
      return;
    }
    runs.push_back(ChainRun{name, observation.sequence, observation.step, {std::move(observation.state)}});
    last.insert_or_assign(observation.sequence, std::make_pair(observation.step, runs.size() - 1));
  });
  if (runs.empty()) throw InputError(name, "file", "the log holds no observations (one JSON object per line)");
  return runs;
}

std::vector<ChainRun> load_chain_observations(const std::filesystem::path& path) {
  return parse_chain_observations(read_input_file(path, "observation log"), path.string());
}

ChainKind chain_kind(std::string_view name) {
  if (name == "markov") return ChainKind::markov;
  if (name == "birth-death") return ChainKind::birth_death;
  const std::vector<std::string> known{"markov", "birth-death"};
  throw unknown_name_error("chain kind", name, known);
}

std::string_view chain_kind_name(ChainKind kind) noexcept {
  return kind == ChainKind::birth_death ? "birth-death" : "markov";
}

ChainFit fit_chain(std::span<const ChainRun> runs, const ChainFitOptions& options) {
  check_options(options);
  for (const ChainRun& run : runs) {
    if (run.states.empty()) throw UsageError("fit-chain: " + run.source + ": a run holds at least one state");
    for (const std::string& state : run.states) {
      if (state.empty()) throw UsageError("fit-chain: " + run.source + ": a state's name is not empty");
    }
  }
  return options.kind == ChainKind::birth_death ? fit_birth_death(runs, options) : fit_markov(runs, options);
}

}  // namespace ontime
