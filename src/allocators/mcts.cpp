#include "ontime/allocators/mcts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

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

// The index in [first, first + count) of the edge of the most visits (ties: the first).
template <class Edge>
std::uint32_t most_visited(const std::vector<Edge>& edges, std::uint32_t first, std::uint32_t count) {
  std::uint32_t best = first;
  for (std::uint32_t e = first + 1; e < first + count; ++e) {
    if (edges[e].visits > edges[best].visits) best = e;
  }
  return best;
}

// UCT's choice among the edges [first, first + count) of a node visited `visits` times: an edge
// never visited first (the first such), else the largest estimate(e) + C sqrt(ln visits / n_e).
template <class Edge, class Estimate>
std::uint32_t uct_edge(const std::vector<Edge>& edges, std::uint32_t first, std::uint32_t count, std::uint32_t visits,
                       double exploration, Estimate&& estimate) {
  const double log_visits = portable_log(static_cast<double>(std::max<std::uint32_t>(visits, 1)));
  std::uint32_t best = first;
  double best_score = -1.0;
  for (std::uint32_t e = first; e < first + count; ++e) {
    if (edges[e].visits == 0) return e;  // every choice once first, lowest index first
    const double score = estimate(e) + exploration * std::sqrt(log_visits / static_cast<double>(edges[e].visits));
    if (score > best_score) {
      best_score = score;
      best = e;
    }
  }
  return best;
}

}  // namespace

void MctsCounters::add_to(Statistics& statistics) const {
  statistics.add(kSearchesCounter, static_cast<double>(searches));
  statistics.add(kIterationsCounter, static_cast<double>(iterations));
  statistics.add("memory_stops", static_cast<double>(memory_stops));
  statistics.add("peak_tree_nodes", static_cast<double>(peak_tree_nodes), Statistics::Merge::max);
  statistics.add("peak_tree_bytes", static_cast<double>(peak_tree_bytes), Statistics::Merge::max);
}

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
  return uct_edge(edges_, node.first_edge, node.edge_count, node.visits, options_.exploration,
                  [&](std::uint32_t e) { return estimate(e); });
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

  counters_.search(
      budget.is_set() ? budget : options_.budget, [&] { return iterate(); }, [&] { return tree_nodes(); },
      [&] { return tree_bytes(); });
  const DecisionNode& root = nodes_[0];
  if (root.first_edge == kNone) return choices[0];
  return edges_[most_visited(edges_, root.first_edge, root.edge_count)].choice;
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

void MctsAllocator::collect_statistics(Statistics& statistics) const { counters_.add_to(statistics); }

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

ConcurrentMctsAllocator::ConcurrentMctsAllocator(const ConcurrentMdp& mdp, ConcurrentMctsOptions options)
    : mdp_(&mdp), options_(std::move(options)) {
  if (!(options_.exploration >= 0.0) || !std::isfinite(options_.exploration)) {
    throw UsageError("the exploration constant of mcts must be a finite number >= 0");
  }
  if (options_.leaf != MctsLeaf::rollout) {
    if (options_.backup != MctsBackup::bellman) {
      throw UsageError("mcts: leaf values from bounds need bellman backups (a mean counts rewards 0 or 1)");
    }
    bounds_ = std::make_unique<ConcurrentValueBounds>(mdp);
  }
  if (options_.rollout) {
    rollout_policy_ = options_.rollout();
    if (!rollout_policy_->is_stationary()) {
      throw UsageError("the rollout policy of mcts must choose by the state alone; '" +
                       std::string(rollout_policy_->name()) + "' does not");
    }
  }
  const Problem& problem = mdp.problem();
  const std::size_t words =
      3 + 2 * static_cast<std::size_t>(problem.skeleton_count()) + static_cast<std::size_t>(problem.action_count());
  state_bytes_ = (words * 2 + 15) / 16 * 16 + 16;  // rounded up to the heap's 16 bytes, plus its header
}

void ConcurrentMctsAllocator::begin_episode(std::uint64_t seed) {
  generator_ = SplitMix64(seed);
  has_tree_ = false;
  if (rollout_policy_) rollout_policy_->begin_episode(seed);
}

std::size_t ConcurrentMctsAllocator::tree_bytes() const noexcept {
  return nodes_.capacity() * sizeof(Node) + nodes_.size() * state_bytes_ + edges_.capacity() * sizeof(Edge) +
         outcomes_.capacity() * sizeof(Outcome);
}

bool ConcurrentMctsAllocator::would_exceed_memory(std::size_t nodes, std::size_t edges, std::size_t outcomes) const {
  const std::size_t projected = grown_capacity(nodes_.capacity(), nodes_.size() + nodes) * sizeof(Node) +
                                (nodes_.size() + nodes) * state_bytes_ +
                                grown_capacity(edges_.capacity(), edges_.size() + edges) * sizeof(Edge) +
                                grown_capacity(outcomes_.capacity(), outcomes_.size() + outcomes) * sizeof(Outcome);
  return projected > options_.max_tree_bytes;
}

void ConcurrentMctsAllocator::reset(const ConcurrentState& root) {
  nodes_.clear();
  edges_.clear();
  outcomes_.clear();
  nodes_.push_back(Node{.state = root});
  has_tree_ = true;
}

bool ConcurrentMctsAllocator::expand(std::uint32_t node) {
  const std::vector<ConcurrentMdp::Move> moves = mdp_->useful_moves(nodes_[node].state);
  if (would_exceed_memory(0, moves.size(), 0)) return false;
  nodes_[node].first_edge = static_cast<std::uint32_t>(edges_.size());
  nodes_[node].edge_count = static_cast<std::uint16_t>(moves.size());
  for (const ConcurrentMdp::Move& move : moves) edges_.push_back(Edge{.move = move});
  return true;
}

bool ConcurrentMctsAllocator::expand_outcomes(std::uint32_t edge, std::uint32_t node) {
  const ConcurrentState& state = nodes_[node].state;
  const ConcurrentMdp::Move move = edges_[edge].move;
  // A state that ends the search: no skeleton can finish (0), or certain success (1).
  const auto ending = [&](const ConcurrentState& next, Outcome& outcome) {
    if (!mdp_->any_live(next)) {
      outcome.ends = true;
    } else if (mdp_->certain_success(next)) {
      outcome.ends = true;
      outcome.reward = 1.0;
    }
  };
  std::vector<Outcome> found;
  if (move.is_start()) {
    // One outcome, or one per execution time a chain draws when the action starts (SPEC §9).
    mdp_->for_each_start_outcome(state, move.start, [&](double probability, const ConcurrentMdp::StartOutcome& start) {
      Outcome outcome{.probability = probability, .ends = start.ends, .reward = start.reward};
      if (!start.ends) ending(start.next, outcome);
      found.push_back(outcome);
    });
  } else {
    mdp_->for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
      Outcome outcome{.probability = probability};
      ending(next, outcome);
      found.push_back(outcome);
    });
  }
  if (would_exceed_memory(0, 0, found.size())) return false;
  edges_[edge].first_outcome = static_cast<std::uint32_t>(outcomes_.size());
  edges_[edge].outcome_count = static_cast<std::uint16_t>(found.size());
  outcomes_.insert(outcomes_.end(), found.begin(), found.end());
  return true;
}

ConcurrentState ConcurrentMctsAllocator::successor(const ConcurrentState& state, const ConcurrentMdp::Move& move,
                                                   std::size_t index) const {
  ConcurrentState result;
  std::size_t seen = 0;
  if (move.is_start()) {
    mdp_->for_each_start_outcome(state, move.start, [&](double, const ConcurrentMdp::StartOutcome& outcome) {
      if (seen++ == index) result = outcome.next;
    });
    return result;
  }
  mdp_->for_each_step_outcome(state, move.refine, [&](double, const ConcurrentState& next) {
    if (seen++ == index) result = next;
  });
  return result;
}

double ConcurrentMctsAllocator::estimate(const Edge& edge) const noexcept {
  if (edge.visits == 0) return 0.0;
  return bellman() ? edge.q : edge.returns / edge.visits;
}

std::uint32_t ConcurrentMctsAllocator::select_edge(const Node& node) const {
  return uct_edge(edges_, node.first_edge, node.edge_count, node.visits, options_.exploration,
                  [&](std::uint32_t e) { return estimate(edges_[e]); });
}

double ConcurrentMctsAllocator::rollout(ConcurrentState state) {
  for (;;) {
    if (!mdp_->any_live(state)) return 0.0;
    if (mdp_->certain_success(state)) return 1.0;
    ConcurrentMdp::Move move;
    if (rollout_policy_) {
      move = rollout_policy_->choose(state);
      if (!move.is_start() && ConcurrentMdp::time(state) >= mdp_->deadline()) return 0.0;
    } else {
      const std::vector<ConcurrentMdp::Move> moves = mdp_->useful_moves(state);
      if (moves.empty()) return 0.0;
      move = moves[static_cast<std::size_t>(generator_() % moves.size())];
    }
    if (move.is_start()) {
      // An execution a chain draws when the action starts: the world's draw (SPEC §9).
      const Steps drawn = mdp_->sample_start_execution(state, move.start, generator_);
      ConcurrentMdp::StartOutcome outcome = mdp_->start_action(state, move.start, drawn);
      if (outcome.ends) return outcome.reward;
      state = std::move(outcome.next);
      continue;
    }
    double u = uniform01(generator_);
    ConcurrentState drawn;
    mdp_->for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
      if (drawn.empty() || u >= 0.0) drawn = next;  // the first outcome whose cumulative mass passes u
      u -= probability;
    });
    state = std::move(drawn);
  }
}

double ConcurrentMctsAllocator::leaf_value(const ConcurrentState& state) {
  switch (options_.leaf) {
    case MctsLeaf::upper:
      return bounds_->upper(state);
    case MctsLeaf::lower:
      return bounds_->lower(state);
    case MctsLeaf::rollout:
      break;
  }
  return rollout(state);
}

bool ConcurrentMctsAllocator::iterate() {
  path_.clear();
  std::uint32_t node = 0;
  double reward = 0.0;
  for (;;) {
    if (nodes_[node].first_edge == kNone && !expand(node)) return false;
    if (nodes_[node].edge_count == 0) break;  // no skeleton can finish: reward 0
    const std::uint32_t e = select_edge(nodes_[node]);
    if (edges_[e].first_outcome == kNone && !expand_outcomes(e, node)) return false;
    path_.push_back(node);
    path_.push_back(e);
    const std::uint32_t first = edges_[e].first_outcome;
    const std::uint32_t picked =
        first +
        static_cast<std::uint32_t>(sample_index(
            edges_[e].outcome_count, [&](std::size_t o) { return outcomes_[first + o].probability; }, generator_));
    outcomes_[picked].reached = true;
    if (outcomes_[picked].ends) {
      reward = outcomes_[picked].reward;
      break;
    }
    if (outcomes_[picked].child == kNone) {
      if (would_exceed_memory(1, 0, 0)) return false;
      ConcurrentState next = successor(nodes_[node].state, edges_[e].move, picked - first);
      const auto child = static_cast<std::uint32_t>(nodes_.size());
      nodes_.push_back(Node{.state = std::move(next), .visits = 1});
      outcomes_[picked].child = child;
      if (bellman()) {
        nodes_[child].value = leaf_value(nodes_[child].state);
      } else {
        reward = rollout(nodes_[child].state);
      }
      break;
    }
    node = outcomes_[picked].child;
  }
  for (std::size_t i = 0; i < path_.size(); i += 2) {
    ++nodes_[path_[i]].visits;
    Edge& edge = edges_[path_[i + 1]];
    ++edge.visits;
    edge.returns += reward;
  }
  if (bellman()) back_up_bellman();
  return true;
}

void ConcurrentMctsAllocator::back_up_bellman() {
  for (std::size_t i = path_.size(); i >= 2; i -= 2) {
    Edge& edge = edges_[path_[i - 1]];
    double weight = 0.0, sum = 0.0;
    for (std::uint32_t o = edge.first_outcome; o < edge.first_outcome + edge.outcome_count; ++o) {
      const Outcome& outcome = outcomes_[o];
      if (!outcome.reached) continue;
      weight += outcome.probability;
      sum += outcome.probability * (outcome.ends ? outcome.reward : nodes_[outcome.child].value);
    }
    edge.q = weight > 0.0 ? sum / weight : 0.0;
    Node& node = nodes_[path_[i - 2]];
    double best = 0.0;
    for (std::uint32_t e = node.first_edge; e < node.first_edge + node.edge_count; ++e) {
      if (edges_[e].visits > 0) best = std::max(best, edges_[e].q);
    }
    node.value = best;
  }
}

bool ConcurrentMctsAllocator::reroot_to(const ConcurrentState& state) {
  const Node& root = nodes_[0];
  if (root.first_edge == kNone) return false;
  std::uint32_t found = kNone;
  for (std::uint32_t e = root.first_edge; e < root.first_edge + root.edge_count && found == kNone; ++e) {
    const Edge& edge = edges_[e];
    if (edge.first_outcome == kNone) continue;
    for (std::uint32_t o = edge.first_outcome; o < edge.first_outcome + edge.outcome_count; ++o) {
      const std::uint32_t child = outcomes_[o].child;
      if (child != kNone && nodes_[child].state == state) {
        found = child;
        break;
      }
    }
  }
  if (found == kNone) return false;
  // Copies the subtree under `found` into fresh arrays (depth first), so that the memory held
  // stays proportional to the tree in use.
  std::vector<Node> nodes;
  std::vector<Edge> edges;
  std::vector<Outcome> outcomes;
  std::vector<std::uint32_t> pending{0};  // copied nodes whose edges still point into the old arrays
  nodes.push_back(std::move(nodes_[found]));
  while (!pending.empty()) {
    const std::uint32_t new_index = pending.back();
    pending.pop_back();
    const std::uint32_t old_first = nodes[new_index].first_edge;
    const std::uint16_t count = nodes[new_index].edge_count;
    if (old_first == kNone) continue;
    nodes[new_index].first_edge = static_cast<std::uint32_t>(edges.size());
    for (std::uint32_t e = old_first; e < old_first + count; ++e) {
      Edge edge = edges_[e];
      if (edge.first_outcome != kNone) {
        const auto first = static_cast<std::uint32_t>(outcomes.size());
        for (std::uint32_t o = edge.first_outcome; o < edge.first_outcome + edge.outcome_count; ++o) {
          Outcome outcome = outcomes_[o];
          if (outcome.child != kNone) {
            const auto child = static_cast<std::uint32_t>(nodes.size());
            nodes.push_back(std::move(nodes_[outcome.child]));
            pending.push_back(child);
            outcome.child = child;
          }
          outcomes.push_back(outcome);
        }
        edge.first_outcome = first;
      }
      edges.push_back(edge);
    }
  }
  nodes_ = std::move(nodes);
  edges_ = std::move(edges);
  outcomes_ = std::move(outcomes);
  return true;
}

ConcurrentMdp::Move ConcurrentMctsAllocator::choose(const ConcurrentState& state) {
  if (has_tree_ && !(nodes_[0].state == state) && !(options_.reuse_tree && reroot_to(state))) has_tree_ = false;
  if (mdp_->certain_success(state)) return mdp_->run_complete_plan(state);
  const std::vector<ConcurrentMdp::Move> moves = mdp_->useful_moves(state);
  if (moves.empty()) return {};
  if (moves.size() == 1) return moves[0];
  if (!has_tree_) reset(state);

  counters_.search(
      options_.budget, [&] { return iterate(); }, [&] { return tree_nodes(); }, [&] { return tree_bytes(); });
  const Node& root = nodes_[0];
  if (root.first_edge == kNone) return moves[0];
  return edges_[most_visited(edges_, root.first_edge, root.edge_count)].move;
}

void ConcurrentMctsAllocator::collect_statistics(Statistics& statistics) const { counters_.add_to(statistics); }

namespace {

// The backup the parameters ask for; UsageError for bound leaves without bellman backups.
MctsBackup read_backup(const ParameterReader& parameters) {
  const MctsBackup backup = parameters.text("backup") == "bellman" ? MctsBackup::bellman : MctsBackup::mean;
  const std::string leaf = parameters.text("leaf");
  if (leaf != "rollout" && backup != MctsBackup::bellman) {
    throw UsageError("parameter 'leaf': '" + leaf + "' needs backup 'bellman' (a mean counts rewards 0 or 1)");
  }
  return backup;
}

}  // namespace

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
        options.backup = read_backup(parameters);
        const std::string leaf = parameters.text("leaf");
        if (leaf != "rollout") {
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
                             {"peak_tree_bytes", "the most bytes a tree held"}}},
      .commit_rule =
          "the search's: starts an action when the search values starting above planning on (its most "
          "simulated move), weighing that a later give-up blaming a started motion blocks its action",
      .make_concurrent = [](const ConcurrentMdp& mdp, const ParameterReader& parameters) -> ConcurrentAllocatorFactory {
        ConcurrentMctsOptions options;
        options.exploration = parameters.real("exploration");
        options.backup = read_backup(parameters);
        const std::string leaf = parameters.text("leaf");
        if (leaf != "rollout") options.leaf = leaf == "upper" ? MctsLeaf::upper : MctsLeaf::lower;
        options.budget = detail::default_budget(parameters);
        options.max_tree_bytes = static_cast<std::size_t>(parameters.integer("max-tree-mib")) << 20;
        const std::string rollout = parameters.text("rollout");
        if (rollout != "random") {
          const AllocatorKind& kind = allocator_registry().find(rollout);
          if (!kind.capabilities.has(Capability::stationary)) {
            throw UsageError("parameter 'rollout': the rollout policy of mcts must choose by the state alone; '" +
                             rollout + "' does not");
          }
          options.rollout = allocator_registry().make_concurrent_factory(rollout, mdp, parameters.values());
        }
        const ConcurrentMctsAllocator probe(mdp, options);  // checks the options once, before any episode
        return [model = &mdp, options] { return std::make_unique<ConcurrentMctsAllocator>(*model, options); };
      }};
}

}  // namespace ontime
