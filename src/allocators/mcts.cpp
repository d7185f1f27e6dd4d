#include "ontime/allocators/mcts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "allocators/detail/anytime_budget.hpp"
#include "ontime/allocators/allocator_registry.hpp"
#include "ontime/util/error.hpp"
#include "util/portable_math.hpp"

namespace ontime {
namespace {

// Capacity a std::vector grows to when it must hold `needed` elements (libstdc++ doubles).
std::size_t grown_capacity(std::size_t capacity, std::size_t needed) noexcept {
  return needed <= capacity ? capacity : std::max(needed, 2 * capacity);
}

}  // namespace

MctsAllocator::MctsAllocator(const Mdp& mdp, MctsOptions options)
    : mdp_(&mdp),
      options_(std::move(options)),
      // With chains or expiry a completed plan is worth its expected reward over the chains' paths
      // while it executes (SPEC §9), which may be below 1 even without rewards.
      rewards_(mdp.problem().has_rewards() || mdp.is_timed()) {
  if (!(options_.exploration >= 0.0) || !std::isfinite(options_.exploration)) {
    throw UsageError("the exploration constant of mcts must be a finite number >= 0");
  }
  if (options_.leaf_bounds && options_.backup != MctsBackup::bellman) {
    throw UsageError("mcts: leaf values from bounds need bellman backups (a mean counts rewards 0 or 1)");
  }
  if (mdp.has_chains()) {
    // A chance node holds every refinement outcome times every step of the chains (SPEC §9), and
    // counts them in 16 bits.
    std::size_t refinement = 0;
    for (int action = 0; action < mdp.problem().action_count(); ++action) {
      refinement =
          std::max(refinement, mdp.execution_outcomes(action).size() + 1 + mdp.problem().culprits(action).size());
    }
    std::size_t steps = 0;
    for (int joint = 0; joint < mdp.joint_chain_states(); ++joint) {
      steps = std::max(steps, mdp.chain_steps(static_cast<std::uint16_t>(joint)).size());
    }
    if (refinement * steps > std::numeric_limits<std::uint16_t>::max()) {
      throw UsageError("mcts: a step may have " + std::to_string(refinement * steps) +
                       " outcomes (refinement outcomes times steps of the chains); its chance nodes hold at most " +
                       std::to_string(std::numeric_limits<std::uint16_t>::max()));
    }
  }
  if (options_.rollout) {
    rollout_policy_ = options_.rollout();
    if (!rollout_policy_->is_stationary()) {
      throw UsageError("the rollout policy of mcts must choose by the state alone; '" +
                       std::string(rollout_policy_->name()) + "' does not");
    }
  }
}

void MctsAllocator::begin_episode(std::uint64_t seed) {
  generator_ = SplitMix64(seed);
  has_tree_ = false;
  if (rollout_policy_) rollout_policy_->begin_episode(seed);
}

std::size_t MctsAllocator::tree_bytes() const noexcept {
  return nodes_.capacity() * sizeof(DecisionNode) + edges_.capacity() * sizeof(Edge) +
         outcomes_.capacity() * sizeof(Outcome) +
         (node_values_.capacity() + edge_values_.capacity() + edge_returns_.capacity() + outcome_rewards_.capacity()) *
             sizeof(double);
}

bool MctsAllocator::would_exceed_memory(std::size_t nodes, std::size_t edges, std::size_t outcomes) const {
  const std::size_t projected = grown_capacity(nodes_.capacity(), nodes_.size() + nodes) * sizeof(DecisionNode) +
                                grown_capacity(edges_.capacity(), edges_.size() + edges) * sizeof(Edge) +
                                grown_capacity(outcomes_.capacity(), outcomes_.size() + outcomes) * sizeof(Outcome);
  const std::size_t values = bellman() ? (grown_capacity(node_values_.capacity(), node_values_.size() + nodes) +
                                          grown_capacity(edge_values_.capacity(), edge_values_.size() + edges)) *
                                             sizeof(double)
                                       : 0;
  const std::size_t returns = rewards_
                                  ? (grown_capacity(edge_returns_.capacity(), edge_returns_.size() + edges) +
                                     grown_capacity(outcome_rewards_.capacity(), outcome_rewards_.size() + outcomes)) *
                                        sizeof(double)
                                  : 0;
  return projected + values + returns > options_.max_tree_bytes;
}

void MctsAllocator::reset(const State& root) {
  nodes_.clear();
  edges_.clear();
  outcomes_.clear();
  node_values_.clear();
  edge_values_.clear();
  edge_returns_.clear();
  outcome_rewards_.clear();
  nodes_.emplace_back();
  if (bellman()) node_values_.push_back(0.0);
  root_state_ = root;
  has_tree_ = true;
}

std::uint32_t MctsAllocator::add_node() {
  nodes_.emplace_back();
  if (bellman()) node_values_.push_back(0.0);
  return static_cast<std::uint32_t>(nodes_.size() - 1);
}

bool MctsAllocator::expand(std::uint32_t node, const State& state) {
  const ChoiceList choices = mdp_->useful_choices(state);
  if (would_exceed_memory(0, choices.size(), 0)) return false;
  nodes_[node].first_edge = static_cast<std::uint32_t>(edges_.size());
  nodes_[node].edge_count = static_cast<std::uint16_t>(choices.size());
  for (const int choice : choices) {
    Edge edge;
    edge.choice = static_cast<std::uint16_t>(choice);
    edges_.push_back(edge);
  }
  if (bellman()) edge_values_.resize(edges_.size(), 0.0);
  if (rewards_) edge_returns_.resize(edges_.size(), 0.0);
  return true;
}

bool MctsAllocator::expand_outcomes(std::uint32_t edge, const State& state) {
  const int choice = edges_[edge].choice;
  std::size_t count = 0;
  mdp_->for_each_observation(state, choice, [&](double, const Observation&) { ++count; });
  if (would_exceed_memory(0, 0, count)) return false;
  edges_[edge].first_outcome = static_cast<std::uint32_t>(outcomes_.size());
  edges_[edge].outcome_count = static_cast<std::uint16_t>(count);
  mdp_->for_each_observation(state, choice, [&](double probability, const Observation& observation) {
    State next = state;
    const Status status = mdp_->apply(next, choice, observation);
    outcomes_.push_back(Outcome{probability, observation, kNone, status});
    if (rewards_) outcome_rewards_.push_back(status == Status::success ? mdp_->success_reward(next, choice) : 0.0);
  });
  return true;
}

std::uint32_t MctsAllocator::select_edge(const DecisionNode& node) const {
  const double log_visits = portable_log(static_cast<double>(std::max<std::uint32_t>(node.visits, 1)));
  std::uint32_t best = node.first_edge;
  double best_score = -1.0;
  for (std::uint32_t e = node.first_edge; e < node.first_edge + node.edge_count; ++e) {
    const Edge& edge = edges_[e];
    if (edge.visits == 0) return e;  // every choice once first, lowest index first
    const double visits = edge.visits;
    const double score = estimate(e) + options_.exploration * std::sqrt(log_visits / visits);
    if (score > best_score) {
      best_score = score;
      best = e;
    }
  }
  return best;
}

double MctsAllocator::rollout(State& state) {
  for (;;) {
    int choice = -1;
    if (rollout_policy_) {
      choice = rollout_policy_->choose(state);
    } else {
      const ChoiceList choices = mdp_->useful_choices(state);
      if (choices.empty()) return 0.0;
      choice = choices[static_cast<std::size_t>(generator_() % choices.size())];
    }
    const Observation observation = mdp_->sample_observation(state, choice, generator_);
    const Status status = mdp_->apply(state, choice, observation);
    if (status == Status::success) return mdp_->success_reward(state, choice);
    if (status == Status::failure) return 0.0;
  }
}

bool MctsAllocator::iterate() {
  path_.clear();
  // One scratch state, assigned rather than copied: a wide problem's state then reuses its
  // heap arrays from iteration to iteration.
  State& state = scratch_state_;
  state = root_state_;
  std::uint32_t node = 0;
  double reward = 0.0;
  for (;;) {
    if (nodes_[node].first_edge == kNone && !expand(node, state)) return false;
    if (nodes_[node].edge_count == 0) break;  // no skeleton can succeed: reward 0
    const std::uint32_t e = select_edge(nodes_[node]);
    if (edges_[e].first_outcome == kNone && !expand_outcomes(e, state)) return false;
    path_.push_back(node);
    path_.push_back(e);

    const Edge& edge = edges_[e];
    const std::uint32_t first = edge.first_outcome;
    const std::uint32_t picked =
        first + static_cast<std::uint32_t>(sample_index(
                    edge.outcome_count, [&](std::size_t o) { return outcomes_[first + o].probability; }, generator_));
    const Outcome& outcome = outcomes_[picked];
    if (outcome.status != Status::running) {
      reward = outcome.status != Status::success ? 0.0 : rewards_ ? outcome_rewards_[picked] : 1.0;
      outcomes_[picked].child = kReached;
      break;
    }
    mdp_->apply(state, edge.choice, outcome.observation);
    if (outcome.child == kNone) {
      if (would_exceed_memory(1, 0, 0)) return false;
      const std::uint32_t child = add_node();
      outcomes_[picked].child = child;
      nodes_[child].visits = 1;
      if (bellman()) {
        node_values_[child] = leaf_value(state);
      } else {
        reward = rollout(state);
      }
      break;
    }
    node = outcome.child;
  }
  for (std::size_t i = 0; i < path_.size(); i += 2) {
    ++nodes_[path_[i]].visits;
    Edge& edge = edges_[path_[i + 1]];
    ++edge.visits;
    edge.successes += reward > 0.5 ? 1U : 0U;
    if (rewards_) edge_returns_[path_[i + 1]] += reward;
  }
  if (bellman()) back_up_bellman();
  return true;
}

double MctsAllocator::leaf_value(State& state) {
  if (!options_.leaf_bounds) return rollout(state);
  return options_.optimistic_leaves ? options_.leaf_bounds->upper(state) : options_.leaf_bounds->lower(state);
}

void MctsAllocator::back_up_bellman() {
  // Deepest first: each edge's Q from its reached outcomes, then its node's V from its edges.
  for (std::size_t i = path_.size(); i >= 2; i -= 2) {
    const Edge& edge = edges_[path_[i - 1]];
    double weight = 0.0, sum = 0.0;
    for (std::uint32_t o = edge.first_outcome; o < edge.first_outcome + edge.outcome_count; ++o) {
      const Outcome& outcome = outcomes_[o];
      if (outcome.child == kNone) continue;
      weight += outcome.probability;
      if (outcome.status == Status::success) {
        sum += outcome.probability * (rewards_ ? outcome_rewards_[o] : 1.0);
      } else if (outcome.status == Status::running) {
        sum += outcome.probability * node_values_[outcome.child];
      }
    }
    edge_values_[path_[i - 1]] = weight > 0.0 ? sum / weight : 0.0;
    const DecisionNode& node = nodes_[path_[i - 2]];
    double best = 0.0;
    for (std::uint32_t e = node.first_edge; e < node.first_edge + node.edge_count; ++e) {
      if (edges_[e].visits > 0) best = std::max(best, edge_values_[e]);
    }
    node_values_[path_[i - 2]] = best;
  }
}

int MctsAllocator::choose(const State& state) { return choose(state, options_.budget); }

int MctsAllocator::choose(const State& state, const DecisionBudget& budget) {
  if (!has_tree_ || !(state == root_state_)) reset(state);
  const ChoiceList choices = mdp_->useful_choices(state);
  if (choices.empty()) return mdp_->first_with_work_left(state);
  if (choices.size() == 1) return choices[0];

  ++counters_.searches;
  const BudgetMonitor monitor(budget.is_set() ? budget : options_.budget);
  std::uint64_t iterations = 0;
  while (!monitor.exhausted(iterations)) {
    if (!iterate()) {
      ++counters_.memory_stops;
      break;
    }
    ++iterations;
  }
  counters_.iterations += iterations;
  counters_.peak_tree_nodes = std::max(counters_.peak_tree_nodes, tree_nodes());
  counters_.peak_tree_bytes = std::max(counters_.peak_tree_bytes, tree_bytes());

  const DecisionNode& root = nodes_[0];
  if (root.first_edge == kNone) return choices[0];
  std::uint32_t best = root.first_edge;
  for (std::uint32_t e = root.first_edge + 1; e < root.first_edge + root.edge_count; ++e) {
    if (edges_[e].visits > edges_[best].visits) best = e;
  }
  return edges_[best].choice;
}

void MctsAllocator::observe(const State& before, int choice, const State& after, Status status) {
  const bool reusable = options_.reuse_tree && has_tree_ && status == Status::running && before == root_state_ &&
                        nodes_[0].first_edge != kNone;
  has_tree_ = false;
  if (!reusable) return;
  const int action = mdp_->next_action(before, choice);
  if (action < 0) return;
  const int group = mdp_->problem().members(action).front();
  const DecisionNode& root = nodes_[0];
  for (std::uint32_t e = root.first_edge; e < root.first_edge + root.edge_count; ++e) {
    const Edge& edge = edges_[e];
    if (edge.choice != group || edge.first_outcome == kNone) continue;
    for (std::uint32_t o = edge.first_outcome; o < edge.first_outcome + edge.outcome_count; ++o) {
      State next = before;
      mdp_->apply(next, choice, outcomes_[o].observation);
      if (next == after && outcomes_[o].child < kReached) {
        reroot(outcomes_[o].child);
        root_state_ = after;
        has_tree_ = true;
        return;
      }
    }
    return;
  }
}

void MctsAllocator::reroot(std::uint32_t new_root) {
  // Copies the subtree under new_root into fresh arrays (depth first), so that memory held
  // stays proportional to the tree in use.
  std::vector<DecisionNode> nodes;
  std::vector<Edge> edges;
  std::vector<Outcome> outcomes;
  std::vector<double> node_values, edge_values, edge_returns, outcome_rewards;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pending{{new_root, 0}};
  nodes.push_back(nodes_[new_root]);
  if (bellman()) node_values.push_back(node_values_[new_root]);
  while (!pending.empty()) {
    const auto [old_index, new_index] = pending.back();
    pending.pop_back();
    const DecisionNode old_node = nodes_[old_index];
    if (old_node.first_edge == kNone) continue;
    nodes[new_index].first_edge = static_cast<std::uint32_t>(edges.size());
    for (std::uint32_t e = old_node.first_edge; e < old_node.first_edge + old_node.edge_count; ++e) {
      Edge edge = edges_[e];
      if (edge.first_outcome != kNone) {
        const auto first = static_cast<std::uint32_t>(outcomes.size());
        for (std::uint32_t o = edge.first_outcome; o < edge.first_outcome + edge.outcome_count; ++o) {
          Outcome outcome = outcomes_[o];
          if (outcome.child < kReached) {
            const auto child = static_cast<std::uint32_t>(nodes.size());
            nodes.push_back(nodes_[outcome.child]);
            if (bellman()) node_values.push_back(node_values_[outcome.child]);
            pending.emplace_back(outcome.child, child);
            outcome.child = child;
          }
          outcomes.push_back(outcome);
          if (rewards_) outcome_rewards.push_back(outcome_rewards_[o]);
        }
        edge.first_outcome = first;
      }
      edges.push_back(edge);
      if (bellman()) edge_values.push_back(edge_values_[e]);
      if (rewards_) edge_returns.push_back(edge_returns_[e]);
    }
  }
  nodes_ = std::move(nodes);
  edges_ = std::move(edges);
  outcomes_ = std::move(outcomes);
  node_values_ = std::move(node_values);
  edge_values_ = std::move(edge_values);
  edge_returns_ = std::move(edge_returns);
  outcome_rewards_ = std::move(outcome_rewards);
}

void MctsAllocator::collect_statistics(Statistics& statistics) const {
  statistics.add(kSearchesCounter, static_cast<double>(counters_.searches));
  statistics.add(kIterationsCounter, static_cast<double>(counters_.iterations));
  statistics.add("memory_stops", static_cast<double>(counters_.memory_stops));
  statistics.add("peak_tree_nodes", static_cast<double>(counters_.peak_tree_nodes), Statistics::Merge::max);
  statistics.add("peak_tree_bytes", static_cast<double>(counters_.peak_tree_bytes), Statistics::Merge::max);
}

std::vector<MctsAllocator::RootChoice> MctsAllocator::root_choices() const {
  std::vector<RootChoice> result;
  if (!has_tree_ || nodes_.empty() || nodes_[0].first_edge == kNone) return result;
  const DecisionNode& root = nodes_[0];
  for (std::uint32_t e = root.first_edge; e < root.first_edge + root.edge_count; ++e) {
    const Edge& edge = edges_[e];
    result.push_back({edge.choice, edge.visits, estimate(e)});
  }
  return result;
}

AllocatorKind mcts_kind() {
  return {
      .name = "mcts",
      .summary = "Monte Carlo tree search (UCT with chance nodes) sampling the model before every step",
      .capabilities = {Capability::randomised, Capability::anytime, Capability::chains},
      .parameters = {Parameter::integer("iterations", 10'000, 1, Parameter::kNoLimit,
                                        "search iterations per decision (no limit when only time-budget is given)"),
                     Parameter::real("time-budget", 0, 0, Parameter::kNoLimit,
                                     "seconds per decision, 0: none (with iterations, whichever ends first)"),
                     Parameter::real("exploration", 0.5, 0, Parameter::kNoLimit, "exploration constant C of UCT"),
                     Parameter::choice("backup", "mean", {"mean", "bellman"},
                                       "Q of a choice: the mean reward through it (the paper's), or the model's "
                                       "expectation over the outcomes reached, V the best Q (DP-UCT)"),
                     Parameter::choice("leaf", "rollout", {"rollout", "upper", "lower"},
                                       "bellman: a new node's value, a rollout's reward or the clairvoyant (upper) or "
                                       "commit (lower) bound on the optimum there"),
                     Parameter::text("rollout", "random",
                                     "rollout policy: 'random' or a stationary allocator (e.g. dp-rerun)"),
                     Parameter::integer("max-tree-mib", 1024, 1, 1 << 24,
                                        "memory cap of the search tree in MiB; a search stops there with its best "
                                        "answer")},
      .make = [](const Mdp& mdp, const ParameterReader& parameters) -> AllocatorFactory {
        MctsOptions options;
        options.exploration = parameters.real("exploration");
        options.backup = parameters.text("backup") == "bellman" ? MctsBackup::bellman : MctsBackup::mean;
        const std::string leaf = parameters.text("leaf");
        if (leaf != "rollout") {
          if (options.backup != MctsBackup::bellman) {
            throw UsageError("parameter 'leaf': '" + leaf + "' needs backup 'bellman' (a mean counts rewards 0 or 1)");
          }
          if (leaf == "lower" && mdp.is_timed()) {
            throw UsageError(
                "parameter 'leaf': the commit bound does not value exogenous chains or expiry (SPEC §9); use "
                "'upper' or 'rollout'");
          }
          options.leaf_bounds = std::make_shared<const ValueBounds>(mdp);  // ResourceLimitError past its cap
          options.optimistic_leaves = leaf == "upper";
        }
        options.budget = detail::default_budget(parameters);
        options.max_tree_bytes = static_cast<std::size_t>(parameters.integer("max-tree-mib")) << 20;
        const std::string rollout = parameters.text("rollout");
        if (rollout != "random") {
          if (!allocator_registry().find(rollout).capabilities.has(Capability::stationary)) {
            throw UsageError("parameter 'rollout': the rollout policy of mcts must choose by the state alone; '" +
                             rollout + "' does not");
          }
          options.rollout = allocator_registry().make_factory(rollout, mdp, parameters.values());
        }
        MctsAllocator probe(mdp, options);  // checks the options once, before any episode
        return [model = &mdp, options] { return std::make_unique<MctsAllocator>(*model, options); };
      },
      .needs = {.decision_budget = detail::given_budget,
                .memory = {.parameter = "max-tree-mib",
                           .bytes =
                               [](const Problem&, const ParameterReader& parameters) {
                                 return static_cast<double>(parameters.integer("max-tree-mib")) * 1024.0 * 1024.0;
                               },
                           .per_allocator = true},
                .counters = {{kSearchesCounter, "decisions that ran a search"},
                             {kIterationsCounter, "search iterations, summed over the searches"},
                             {"memory_stops", "searches stopped by the tree's memory cap"},
                             {"peak_tree_nodes", "the most nodes a tree held"},
                             {"peak_tree_bytes", "the most bytes a tree held"}}}};
}

}  // namespace ontime
