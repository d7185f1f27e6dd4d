#include "ontime/model/instance_io.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "model/chain_fields.hpp"
#include "model/skeleton_list.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime {
namespace {

using Json = nlohmann::ordered_json;

// Any time of up to Distribution::kMaxStep steps is then a finite number of seconds, with
// room to spare (planner logs written from the instance never hold an infinity).
constexpr double kMaxStepSeconds = 1e300;

std::string format_number(double value) {
  std::ostringstream out;
  out.precision(12);
  out << value;
  return out.str();
}

class InstanceReader {
 public:
  explicit InstanceReader(std::string source) : source_(std::move(source)) {}

  Problem read(std::string_view text) {
    const Json root = detail::parse_json_strict<Json>(text, source_);
    if (!root.is_object())
      fail("top level", "an instance must be a JSON object (got " + detail::describe_json_type(root) + ")");
    check_keys(
        root, "",
        {"name", "description", "deadline", "step_seconds", "acting", "chains", "actions", "skeletons", "rewards"});

    std::string name = std::filesystem::path(source_).stem().string();
    if (root.contains("name")) name = string_at(root["name"], "name");
    std::string description;
    if (root.contains("description")) description = string_at(root["description"], "description");

    if (!root.contains("deadline")) fail("top level", "missing required key 'deadline'");
    const Json& deadline_json = root["deadline"];
    // A whole number, written `4` or `4.0` (as Python writes floats); the value as written in messages.
    const bool whole =
        deadline_json.is_number_integer() ||
        (deadline_json.is_number_float() && std::trunc(deadline_json.get<double>()) == deadline_json.get<double>());
    if (!whole) fail("deadline", "must be a whole number of steps (got " + detail::quote_json(deadline_json) + ")");
    const std::optional<std::int64_t> deadline = detail::json_whole_number(deadline_json, 1, Problem::kMaxDeadline);
    if (!deadline) {
      fail("deadline", "must be between 1 and " + std::to_string(Problem::kMaxDeadline) + " steps (got " +
                           detail::quote_json(deadline_json) + ")");
    }

    double step_seconds = 1.0;
    if (root.contains("step_seconds")) {
      const Json& value = root["step_seconds"];
      if (!value.is_number()) fail("step_seconds", "must be a number (got " + detail::describe_json_type(value) + ")");
      step_seconds = value.get<double>();
      if (!(std::isfinite(step_seconds) && step_seconds > 0 && step_seconds <= kMaxStepSeconds)) {
        fail("step_seconds",
             "must be a positive number of seconds, at most 1e300 so that times in seconds stay finite (got " +
                 detail::quote_json(value) + ")");
      }
    }

    Acting acting = Acting::plan_first;
    if (root.contains("acting")) {
      const Json& value = root["acting"];
      if (!value.is_string()) {
        fail("acting", "must be \"plan-first\" or \"concurrent\" (got " + detail::describe_json_type(value) + ")");
      }
      const std::optional<Acting> parsed = parse_acting(value.get_ref<const std::string&>());
      if (!parsed) fail("acting", "must be \"plan-first\" or \"concurrent\" (got " + value.dump() + ")");
      acting = *parsed;
    }

    std::vector<ExogenousChain> chains;
    if (root.contains("chains")) chains = read_chains(root["chains"]);
    std::vector<Action> actions = read_actions(root, chains);
    std::vector<std::vector<int>> skeletons = read_skeletons(root, actions);
    std::vector<SkeletonReward> rewards;
    if (root.contains("rewards")) rewards = read_rewards(root["rewards"], skeletons.size());
    try {
      return Problem(std::move(name), static_cast<Steps>(*deadline), step_seconds, std::move(actions),
                     std::move(skeletons), std::move(description), std::move(rewards), std::move(chains))
          .with_acting(acting);
    } catch (const ChainRuleError& error) {
      // Chains are checked as they are read; what is left are the actions' references to them.
      fail(error.action().empty() ? detail::json_member("chains", error.chain())
                                  : detail::json_member(detail::json_member("actions", error.action()), error.field()),
           error.rule());
    } catch (const RewardError& error) {
      fail(detail::json_index("rewards", static_cast<std::size_t>(error.skeleton())), error.rule());
    } catch (const BacktrackingError& error) {
      // The backtracking rules need the skeletons (a culprit must come before the action on its
      // path): checked by the Problem, placed here.
      const std::string action = detail::json_member("actions", error.action());
      fail(error.culprit().empty() ? action
                                   : detail::json_member(detail::json_member(action, "culprits"), error.culprit()),
           error.rule());
    } catch (const std::invalid_argument& error) {
      fail("top level", error.what());  // every rule is checked above with its place; kept as a guard
    }
  }

 private:
  [[noreturn]] void fail(const std::string& place, const std::string& rule) const {
    throw InputError(source_, place, rule);
  }

  void check_keys(const Json& object, const std::string& path, std::initializer_list<std::string_view> allowed) const {
    detail::check_known_keys(object, path, allowed, source_);
  }

  std::string string_at(const Json& value, const std::string& path) const {
    if (!value.is_string()) fail(path, "must be a string (got " + detail::describe_json_type(value) + ")");
    return value.get<std::string>();
  }

  std::vector<Action> read_actions(const Json& root, const std::vector<ExogenousChain>& chains) const {
    if (!root.contains("actions")) fail("top level", "missing required key 'actions'");
    const Json& actions_json = root["actions"];
    if (!actions_json.is_object()) {
      fail("actions", "must be an object mapping action ids to distributions (got " +
                          detail::describe_json_type(actions_json) + ")");
    }
    if (actions_json.empty()) fail("actions", "at least one action is needed");
    std::vector<Action> actions;
    for (const auto& [id, value] : actions_json.items()) {
      const std::string path = detail::json_member("actions", id);
      if (id.empty()) fail(path, "action ids must be non-empty");
      if (!value.is_object())
        fail(path, "an action must be an object with 'planning' and 'execution' (got " +
                       detail::describe_json_type(value) + ")");
      check_keys(value, path, {"planning", "execution", "backtrack", "culprits", "expires"});
      for (const char* required : {"planning", "execution"}) {
        if (!value.contains(required)) fail(path, std::string("missing required key '") + required + "'");
      }
      Action action;
      action.id = id;
      action.planning = read_distribution(value["planning"], detail::json_member(path, "planning"), 1, "planning");
      const std::string execution_path = detail::json_member(path, "execution");
      if (value["execution"].is_object() && value["execution"].contains("chain")) {
        read_execution_by_state(value["execution"], execution_path, chains, action);
      } else {
        action.execution = read_distribution(value["execution"], execution_path, 0, "execution");
      }
      if (value.contains("expires")) read_expiry(value["expires"], detail::json_member(path, "expires"), action);
      if (value.contains("backtrack")) {
        action.backtrack =
            read_distribution(value["backtrack"], detail::json_member(path, "backtrack"), 1, "backtrack");
      }
      if (value.contains("culprits"))
        action.culprits = read_culprits(value["culprits"], detail::json_member(path, "culprits"));
      actions.push_back(std::move(action));
    }
    return actions;
  }

  // {"NAME": {"states": [...], "start": "...", "transitions": [[...], ...]}, ...} (SPEC §9).
  std::vector<ExogenousChain> read_chains(const Json& value) const {
    if (!value.is_object()) {
      fail("chains", "must be an object mapping chain names to chains (got " + detail::describe_json_type(value) + ")");
    }
    std::vector<ExogenousChain> chains;
    for (const auto& [name, chain] : value.items()) {
      const std::string path = detail::json_member("chains", name);
      if (name.empty()) fail(path, "a chain's name is not empty");
      if (!chain.is_object()) {
        fail(path, "a chain is an object with 'states', 'start' and 'transitions' (got " +
                       detail::describe_json_type(chain) + ")");
      }
      check_keys(chain, path, {"states", "start", "transitions"});
      chains.push_back(detail::read_chain_fields(chain, path, name, source_));
    }
    return chains;
  }

  // {"chain": "NAME", "by_state": {"STATE": DIST, ...}}: the execution time by the chain's state
  // when the execution starts (SPEC §9). Which states the chain has is the Problem's to check.
  void read_execution_by_state(const Json& value, const std::string& path, const std::vector<ExogenousChain>& chains,
                               Action& action) const {
    check_keys(value, path, {"chain", "by_state"});
    if (!value["chain"].is_string()) {
      fail(detail::json_member(path, "chain"),
           "must be a chain's name (got " + detail::quote_json(value["chain"]) + ")");
    }
    action.execution_chain = value["chain"].get<std::string>();
    if (!value.contains("by_state")) fail(path, "missing required key 'by_state'");
    const Json& states = value["by_state"];
    const std::string states_path = detail::json_member(path, "by_state");
    if (!states.is_object()) {
      fail(states_path, "must be an object mapping the chain's states to distributions (got " +
                            detail::describe_json_type(states) + ")");
    }
    const ExogenousChain* chain = nullptr;
    for (const ExogenousChain& declared : chains) {
      if (declared.name == action.execution_chain) chain = &declared;
    }
    if (chain == nullptr) {
      fail(detail::json_member(path, "chain"), "no chain named '" + action.execution_chain + "' is declared");
    }
    for (const auto& [state, distribution] : states.items()) {
      if (chain->state_index(state) < 0) {
        fail(detail::json_member(states_path, state), "the chain '" + chain->name + "' has no such state");
      }
    }
    // In the chain's order of states.
    for (const std::string& state : chain->states) {
      if (!states.contains(state)) fail(states_path, "missing the chain's state '" + state + "'");
      action.execution_by_state.push_back(
          read_distribution(states[state], detail::json_member(states_path, state), 0, "execution"));
    }
  }

  // {"after": STEP, "chain": "NAME", "states": ["STATE", ...]}, each part optional but not all.
  void read_expiry(const Json& value, const std::string& path, Action& action) const {
    if (!value.is_object()) {
      fail(path, "must be an object with 'after' and/or 'chain' and 'states' (got " +
                     detail::describe_json_type(value) + ")");
    }
    check_keys(value, path, {"after", "chain", "states"});
    if (value.empty()) fail(path, "needs 'after', or 'chain' and 'states'");
    if (value.contains("after")) {
      const std::optional<std::int64_t> after = detail::json_whole_number(value["after"], 0, Problem::kMaxDeadline);
      if (!after) {
        fail(detail::json_member(path, "after"), "must be a whole number of steps between 0 and " +
                                                     std::to_string(Problem::kMaxDeadline) + " (got " +
                                                     detail::quote_json(value["after"]) + ")");
      }
      action.start_by = static_cast<Steps>(*after);
    }
    if (value.contains("chain") != value.contains("states")) {
      fail(path, "'chain' and 'states' come together");
    }
    if (value.contains("chain")) {
      if (!value["chain"].is_string()) {
        fail(detail::json_member(path, "chain"),
             "must be a chain's name (got " + detail::quote_json(value["chain"]) + ")");
      }
      action.blocking_chain = value["chain"].get<std::string>();
      const Json& states = value["states"];
      if (!states.is_array()) {
        fail(detail::json_member(path, "states"),
             "must be an array of the chain's state names (got " + detail::describe_json_type(states) + ")");
      }
      for (std::size_t i = 0; i < states.size(); ++i) {
        if (!states[i].is_string()) {
          fail(detail::json_index(detail::json_member(path, "states"), i),
               "a state's name is a string (got " + detail::quote_json(states[i]) + ")");
        }
        action.blocking_states.push_back(states[i].get<std::string>());
      }
    }
  }

  // [reward, ...], one per skeleton in the order of "skeletons" (SPEC §8): a number (the value at
  // any finish) or {"value": v, "per_step": c}. The rules on the numbers are the Problem's.
  std::vector<SkeletonReward> read_rewards(const Json& value, std::size_t skeleton_count) const {
    if (!value.is_array()) {
      fail("rewards", "must be an array with one reward per skeleton (got " + detail::describe_json_type(value) + ")");
    }
    if (value.size() != skeleton_count) {
      fail("rewards", "has " + std::to_string(value.size()) + " entries for " + std::to_string(skeleton_count) +
                          " skeletons: one reward per skeleton is needed");
    }
    std::vector<SkeletonReward> rewards;
    for (std::size_t k = 0; k < value.size(); ++k) {
      const Json& entry = value[k];
      const std::string place = detail::json_index("rewards", k);
      const auto number = [&](const Json& json, const std::string& at) {
        if (!json.is_number()) fail(at, "must be a number (got " + detail::describe_json_type(json) + ")");
        return json.get<double>();
      };
      SkeletonReward reward;
      if (entry.is_object()) {
        check_keys(entry, place, {"value", "per_step"});
        if (!entry.contains("value")) fail(place, "missing required key 'value'");
        reward.value = number(entry["value"], detail::json_member(place, "value"));
        if (entry.contains("per_step"))
          reward.per_step = number(entry["per_step"], detail::json_member(place, "per_step"));
      } else if (entry.is_number()) {
        reward.value = entry.get<double>();
      } else {
        fail(place, "a reward is a number or an object {\"value\": ..., \"per_step\": ...} (got " +
                        detail::describe_json_type(entry) + ")");
      }
      rewards.push_back(reward);
    }
    return rewards;
  }

  // {"ACTION ID": probability, ...}: the actions an attempt that backtracks blames (SPEC §7).
  std::vector<Culprit> read_culprits(const Json& value, const std::string& path) const {
    if (!value.is_object()) {
      fail(path, "must be an object mapping earlier action ids to probabilities (got " +
                     detail::describe_json_type(value) + ")");
    }
    std::vector<Culprit> culprits;
    for (const auto& [id, probability] : value.items()) {
      culprits.push_back({id, read_probability(probability, detail::json_member(path, id))});
    }
    return culprits;
  }

  Steps read_step(const std::string& key, const std::string& path, Steps first, const char* kind) const {
    // Canonical decimal: "0", or up to nine digits without a leading zero.
    const bool digits = !key.empty() && key.size() <= 9 &&
                        std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits || (key.size() > 1 && key[0] == '0')) {
      fail(path, std::string("keys must be whole numbers of steps, written without sign or leading zeros (got '") +
                     key + "')");
    }
    const long step = std::stol(key);
    if (step < first) {
      fail(path, std::string(kind) + " steps start at " + std::to_string(first) + " (got " + key + ")");
    }
    if (step > Distribution::kMaxStep) {
      fail(path, "steps above " + std::to_string(Distribution::kMaxStep) + " are not supported (got " + key + ")");
    }
    return static_cast<Steps>(step);
  }

  double read_probability(const Json& value, const std::string& path) const {
    if (!value.is_number())
      fail(path, "a probability must be a number (got " + detail::describe_json_type(value) + ")");
    const double probability = value.get<double>();
    if (!(probability >= 0.0 && probability <= 1.0 + Distribution::kSumTolerance)) {
      fail(path, "a probability must be within [0, 1] (got " + detail::quote_json(value) + ")");
    }
    return std::min(probability, 1.0);
  }

  Distribution read_distribution(const Json& value, const std::string& path, Steps first, const char* kind) const {
    if (!value.is_object()) {
      fail(path, "a distribution must be an object {\"pmf\": {...}} or {\"cdf\": {...}} (got " +
                     detail::describe_json_type(value) + ")");
    }
    check_keys(value, path, {"pmf", "cdf"});
    const bool has_pmf = value.contains("pmf");
    const bool has_cdf = value.contains("cdf");
    if (has_pmf == has_cdf) fail(path, "a distribution needs exactly one of 'pmf' or 'cdf'");
    const char* form = has_pmf ? "pmf" : "cdf";
    const std::string table_path = detail::json_member(path, form);
    const Json& table = value[form];
    if (!table.is_object()) {
      fail(table_path,
           "must be an object mapping steps to probabilities (got " + detail::describe_json_type(table) + ")");
    }
    std::map<Steps, std::pair<double, std::string>> entries;  // numeric order
    for (const auto& [key, probability] : table.items()) {
      const std::string entry_path = detail::json_member(table_path, key);
      const Steps step = read_step(key, entry_path, first, kind);
      entries.emplace(step, std::make_pair(read_probability(probability, entry_path), entry_path));
    }
    const std::size_t size = entries.empty() ? 0 : static_cast<std::size_t>(entries.rbegin()->first) + 1;
    std::vector<double> masses(size, 0.0);
    if (has_pmf) {
      double total = 0;
      for (const auto& [step, entry] : entries) {
        masses[static_cast<std::size_t>(step)] = entry.first;
        total += entry.first;
      }
      if (total > 1.0 + Distribution::kSumTolerance) {
        fail(table_path, "probabilities sum to " + format_number(total) + ", above 1");
      }
    } else {
      double previous = 0;
      Steps previous_step = -1;
      for (const auto& [step, entry] : entries) {
        if (entry.first < previous) {
          fail(entry.second, "a CDF must not decrease (" + format_number(entry.first) + " here, after " +
                                 format_number(previous) + " at step " + std::to_string(previous_step) + ")");
        }
        masses[static_cast<std::size_t>(step)] = entry.first - previous;
        previous = entry.first;
        previous_step = step;
      }
    }
    try {
      return Distribution::from_pmf(std::move(masses));
    } catch (const std::invalid_argument& error) {
      fail(table_path, error.what());
    }
  }

  std::vector<std::vector<int>> read_skeletons(const Json& root, const std::vector<Action>& actions) const {
    if (!root.contains("skeletons")) fail("top level", "missing required key 'skeletons'");
    std::map<std::string, int> index_of;
    for (std::size_t a = 0; a < actions.size(); ++a) index_of.emplace(actions[a].id, static_cast<int>(a));
    return detail::read_skeleton_list(
        root["skeletons"], source_,
        [&index_of](const std::string& id) -> std::optional<int> {
          const auto known = index_of.find(id);
          if (known == index_of.end()) return std::nullopt;
          return known->second;
        },
        [&actions](int index) { return actions[static_cast<std::size_t>(index)].id; });
  }

  std::string source_;
};

Json distribution_to_json(const Distribution& distribution) {
  Json pmf = Json::object();
  const auto masses = distribution.masses();
  for (std::size_t t = 0; t < masses.size(); ++t) {
    if (masses[t] > 0) pmf[std::to_string(t)] = masses[t];
  }
  return Json{{"pmf", pmf}};
}

}  // namespace

Problem parse_problem(std::string_view text, std::string_view source) {
  return InstanceReader(std::string(source)).read(text);
}

Problem load_problem(const std::filesystem::path& path) {
  return parse_problem(read_input_file(path, "instance"), path.string());
}

std::string problem_to_json(const Problem& problem) {
  Json root = Json::object();
  root["name"] = problem.name();
  if (!problem.description().empty()) root["description"] = problem.description();
  root["deadline"] = problem.deadline();
  root["step_seconds"] = problem.step_seconds();
  // Written only when it is not the default, so that a plan-first instance reads and writes as before.
  if (problem.acting() != Acting::plan_first) root["acting"] = std::string(acting_name(problem.acting()));
  if (problem.has_chains()) {
    Json chains = Json::object();
    for (const ExogenousChain& chain : problem.chains()) {
      chains[chain.name] = Json{{"states", chain.states},
                                {"start", chain.states[static_cast<std::size_t>(chain.start)]},
                                {"transitions", chain.transitions}};
    }
    root["chains"] = chains;
  }
  Json actions = Json::object();
  for (const Action& action : problem.actions()) {
    Json entry{{"planning", distribution_to_json(action.planning)},
               {"execution", distribution_to_json(action.execution)}};
    if (!action.execution_chain.empty()) {
      const int chain = problem.execution_chain(problem.find_action(action.id));
      Json by_state = Json::object();
      const std::vector<std::string>& states = problem.chains()[static_cast<std::size_t>(chain)].states;
      for (std::size_t s = 0; s < states.size(); ++s) {
        by_state[states[s]] = distribution_to_json(action.execution_by_state[s]);
      }
      entry["execution"] = Json{{"chain", action.execution_chain}, {"by_state", by_state}};
    }
    if (action.start_by != kNever || !action.blocking_chain.empty()) {
      Json expires = Json::object();
      if (action.start_by != kNever) expires["after"] = action.start_by;
      if (!action.blocking_chain.empty()) {
        expires["chain"] = action.blocking_chain;
        expires["states"] = action.blocking_states;
      }
      entry["expires"] = expires;
    }
    if (action.backtrack.never() < 1.0) {
      entry["backtrack"] = distribution_to_json(action.backtrack);
      Json culprits = Json::object();
      for (const Culprit& culprit : action.culprits) culprits[culprit.id] = culprit.probability;
      entry["culprits"] = culprits;
    }
    actions[action.id] = entry;
  }
  root["actions"] = actions;
  Json skeletons = Json::array();
  for (int k = 0; k < problem.skeleton_count(); ++k) {
    Json skeleton = Json::array();
    for (const int action : problem.skeleton(k)) skeleton.push_back(problem.action(action).id);
    skeletons.push_back(skeleton);
  }
  root["skeletons"] = skeletons;
  if (problem.has_rewards()) {
    Json rewards = Json::array();
    for (const SkeletonReward& reward : problem.rewards()) {
      if (reward.per_step == 0.0) {
        rewards.push_back(reward.value);
      } else {
        rewards.push_back(Json{{"value", reward.value}, {"per_step", reward.per_step}});
      }
    }
    root["rewards"] = rewards;
  }
  return root.dump(2) + "\n";
}

void save_problem(const Problem& problem, const std::filesystem::path& path) {
  write_file_atomically(path, problem_to_json(problem));
}

}  // namespace ontime
