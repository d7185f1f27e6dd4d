#pragma once
// `mcts`: Monte Carlo tree search with UCT over decision and chance nodes (SPEC §3, paper §V-A).
//
// Computes, before every step, an estimate of Q(s, c) — the success probability of choosing c
// in the current state s and continuing well — by repeated simulation from the model, and
// returns the choice simulated most often (ties: lowest skeleton index).
//
// The tree alternates decision nodes (MDP states; one child per useful choice: skeletons that
// share their next action are one choice, and choices on skeletons that can no longer succeed
// are left out, as in `optimal`) and chance nodes (the outcomes of SPEC §2: "not yet", or
// "refined, execution takes x steps", each with its model probability). An iteration selects
// by UCT, Q + C sqrt(ln N(s) / N(s, c)) with C = 0.5 by default, samples outcomes from the
// model, adds one decision node, finishes the episode with a rollout policy (uniformly random
// useful choices by default, or any stationary allocator such as dp-rerun) and backs up the
// success (1) or failure (0).
//
// Backups: `mean` (the default, the paper's) keeps Q as the mean reward of the iterations
// through the edge. `bellman` keeps it as the model's expectation over the outcomes met so far
// (partial Bellman backups, DP-UCT: Keller and Helmert 2013): Q(s, c) = sum_o P(o) v(o) /
// sum_o P(o) over the outcomes o of c reached at least once, v(o) being 1 for success, 0 for
// failure and V of the child otherwise, and V(s) = max_c Q(s, c) over the choices tried (the
// leaf value until the node is expanded). The chance nodes then weigh outcomes by their
// probabilities instead of by how often the samples happened to fall on them, and a choice whose
// first rollouts failed recovers as soon as its subtree's values do. A new node's leaf value is a
// rollout's reward, or (`leaf_bounds`) a bound of ValueBounds on V* there: the clairvoyant upper
// bound makes every unexplored subtree look as good as it could be, so UCT goes where the bound
// says success may still be found (bounded search in the manner of bounded RTDP), and needs no
// rollout; the commit bound is a pessimistic start. On the paper's instance 1 the mean with random
// rollouts settles on a1_1 (Q* = 0.920) because a2_1's first rollouts fail; bellman with upper
// leaves picks a2_1 (Q* = 0.942) in every seed tried (docs/experiments.md).
//
// With chains or expiry (SPEC §9) an outcome is a refinement outcome and a step of the chains
// (Mdp::for_each_observation), so the tree branches on the chains too, waiting is a choice, and a
// success is worth its plan's expected reward over the chains' paths. Upper-bound leaves are the
// relaxation of value_bounds.hpp (chain-dependent executions 0, no expiry); the commit bound
// does not value chains and is refused there (exit 2), as are rollout policies that do not take
// chains.
//
// It sees only the MDP state: the search samples from the model's distributions, never from
// the hidden outcomes of the episode it decides for. After each observed transition the
// matching subtree becomes the new root (tree reuse).
//
// Guarantees: UCT's choice converges to an optimal one as iterations grow (Kocsis and
// Szepesvári 2006); for a finite budget it is an estimate. Same seed and an iteration budget:
// same decisions.
// Cost: per iteration O(depth * K) in the tree plus O(D * K) for the rollout (bellman: plus
// O(depth * (outcomes + K)) for the backup; with bound leaves no rollout but O(K) lookups);
// memory a few tens of bytes per decision node, chance node and outcome (bellman: 8 more per
// node and per chance node), bounded by `max_tree_bytes`: a search that would exceed
// it stops with its best answer so far. The bounds' tables are built once per factory.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/concurrent_allocator.hpp"
#include "ontime/allocators/decision_budget.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/solve/concurrent_value_bounds.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/random.hpp"
#include "ontime/util/statistics.hpp"

namespace ontime {

enum class MctsBackup { mean, bellman };

// The counters of an mcts search, in either form (plan-first or acting while planning).
struct MctsCounters {
  std::uint64_t searches = 0;       // decisions that ran a search
  std::uint64_t iterations = 0;     // search iterations over all searches
  std::size_t peak_tree_nodes = 0;  // largest tree held (decision + chance nodes)
  std::size_t peak_tree_bytes = 0;  // its memory, capacity included
  std::uint64_t memory_stops = 0;   // searches ended early by the memory cap

  // One search: `iterate()` (false: the memory cap stopped it) until `budget` is exhausted, then
  // the tree's size by `nodes()` and `bytes()`.
  template <class Iterate, class Nodes, class Bytes>
  void search(const DecisionBudget& budget, Iterate&& iterate, Nodes&& nodes, Bytes&& bytes) {
    ++searches;
    const BudgetMonitor monitor(budget);
    std::uint64_t done = 0;
    while (!monitor.exhausted(done)) {
      if (!iterate()) {
        ++memory_stops;
        break;
      }
      ++done;
    }
    iterations += done;
    peak_tree_nodes = std::max(peak_tree_nodes, nodes());
    peak_tree_bytes = std::max(peak_tree_bytes, bytes());
  }
  // Adds the counters to `statistics` (peaks merged by their maximum).
  void add_to(Statistics& statistics) const;
};

struct MctsOptions {
  double exploration = 0.5;  // C of UCT
  MctsBackup backup = MctsBackup::mean;
  // Bellman backups: a new node's V from these bounds (ValueBounds; null: a rollout's reward):
  // the clairvoyant upper bound when `optimistic_leaves`, else the commit bound below.
  std::shared_ptr<const ValueBounds> leaf_bounds;
  bool optimistic_leaves = true;
  DecisionBudget budget = DecisionBudget::iterations(10'000);  // default per decision
  std::size_t max_tree_bytes = std::size_t{1} << 30;           // 1 GiB
  bool reuse_tree = true;
  // Rollout policy: nullptr for uniformly random useful choices, else a factory of a
  // stationary allocator (its choices must depend on the state alone).
  AllocatorFactory rollout;
};

class MctsAllocator final : public Allocator {
 public:
  // The Mdp must outlive the allocator. Throws UsageError for a non-stationary rollout
  // policy or a negative exploration constant.
  MctsAllocator(const Mdp& mdp, MctsOptions options);

  std::string_view name() const noexcept override { return "mcts"; }
  void begin_episode(std::uint64_t seed) override;
  int choose(const State& state) override;
  int choose(const State& state, const DecisionBudget& budget) override;
  void observe(const State& before, int choice, const State& after, Status status) override;
  bool is_stationary() const noexcept override { return false; }
  // searches, iterations, memory_stops (summed); peak_tree_nodes, peak_tree_bytes (largest).
  void collect_statistics(Statistics& statistics) const override;

  // Visits and estimated success of each root choice after the last search, for inspection.
  struct RootChoice {
    int skeleton;
    std::uint32_t visits;
    double value;
  };
  // One entry per choice at the root of the last search, in tree order; empty before any search.
  std::vector<RootChoice> root_choices() const;
  // The decision and chance nodes the tree holds now.
  std::size_t tree_nodes() const noexcept { return nodes_.size() + edges_.size(); }
  // The bytes the tree's storage holds now (capacities, not sizes): what `max_tree_bytes` caps.
  std::size_t tree_bytes() const noexcept;

 private:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;

  // An outcome's `child` once a terminal outcome has been reached (bellman backups count it).
  static constexpr std::uint32_t kReached = 0xFFFFFFFEU;

  struct DecisionNode {
    std::uint32_t first_edge = kNone;  // kNone until expanded
    std::uint32_t visits = 0;
    std::uint16_t edge_count = 0;
  };
  struct Edge {                           // a chance node: one choice in a decision node
    std::uint32_t first_outcome = kNone;  // kNone until first taken
    std::uint32_t visits = 0;
    std::uint32_t successes = 0;
    std::uint16_t outcome_count = 0;
    std::uint16_t choice = 0;  // skeleton index (Problem::kMaxSkeletons fits)
  };
  struct Outcome {
    double probability;
    Observation observation;
    std::uint32_t child = kNone;  // decision node, kNone until reached (kReached: a terminal one)
    Status status;
  };

  void reset(const State& root);
  std::uint32_t add_node();
  bool expand(std::uint32_t node, const State& state);  // false: memory cap
  bool expand_outcomes(std::uint32_t edge, const State& state);
  std::uint32_t select_edge(const DecisionNode& node) const;
  double estimate(std::uint32_t e) const noexcept {
    const Edge& edge = edges_[e];
    if (edge.visits == 0) return 0.0;
    if (bellman()) return edge_values_[e];
    return rewards_ ? edge_returns_[e] / edge.visits : static_cast<double>(edge.successes) / edge.visits;
  }
  bool bellman() const noexcept { return options_.backup == MctsBackup::bellman; }
  double leaf_value(State& state);  // a new node's value (bellman): a rollout's reward or a bound
  void back_up_bellman();
  bool iterate();                // false: memory cap reached
  double rollout(State& state);  // plays on from `state`, changing it
  void reroot(std::uint32_t new_root);
  bool would_exceed_memory(std::size_t nodes, std::size_t edges, std::size_t outcomes) const;

  const Mdp* mdp_;
  MctsOptions options_;
  std::unique_ptr<Allocator> rollout_policy_;
  SplitMix64 generator_{0};
  State root_state_;
  State scratch_state_;  // the state of the current iteration
  bool has_tree_ = false;
  std::vector<DecisionNode> nodes_;  // nodes_[0] is the root
  std::vector<Edge> edges_;
  std::vector<Outcome> outcomes_;
  // Bellman backups only (empty otherwise, so that the mean's tree stays as small): V per
  // decision node (the leaf value until expanded), Q per edge (over the outcomes reached).
  std::vector<double> node_values_;
  std::vector<double> edge_values_;
  // With rewards (SPEC §8) only, beside the edges and outcomes: an edge's sum of rewards (its
  // `successes` counts rewards of 1 without them), and a success outcome's reward (else 0).
  bool rewards_ = false;
  std::vector<double> edge_returns_;
  std::vector<double> outcome_rewards_;
  std::vector<std::uint32_t> path_;  // edges visited by the current iteration
  MctsCounters counters_;
};

// A new node's value under bellman backups in the concurrent form (ConcurrentMctsAllocator).
enum class MctsLeaf { rollout, upper, lower };

struct ConcurrentMctsOptions {
  double exploration = 0.5;  // C of UCT
  MctsBackup backup = MctsBackup::mean;
  // Bellman backups: a new node's V, a rollout's reward or a bound of ConcurrentValueBounds.
  MctsLeaf leaf = MctsLeaf::rollout;
  DecisionBudget budget = DecisionBudget::iterations(10'000);  // per decision
  std::size_t max_tree_bytes = std::size_t{1} << 30;           // 1 GiB
  bool reuse_tree = true;
  // Rollout policy: null for uniformly random useful moves, else a factory of a stationary
  // allocator acting while planning.
  ConcurrentAllocatorFactory rollout;
};

// `mcts` acting while planning (SPEC §10): the same search over the moves of ConcurrentMdp.
//
// A decision node is a state; its edges are the moves the exact solver considers
// (ConcurrentMdp::useful_moves: the forced start alone where there is one, else the step choices
// and the starts); a step's chance node has the outcomes of ConcurrentMdp::for_each_step_outcome
// with their probabilities, a start one outcome. An outcome where no skeleton can finish ends the
// iteration with 0, one that starts a skeleton's last action with its reward, and without rewards
// one with a live skeleton refined in full with 1 (ConcurrentMdp::certain_success, proved). UCT,
// the mean and bellman backups and the leaf values (a rollout's reward, or the upper or lower
// bound of ConcurrentValueBounds) are those of MctsAllocator above; rollouts play uniformly random
// useful moves or a stationary allocator acting while planning. The move returned is the root's
// most simulated (ties: the first in useful_moves' order, the steps before the starts), so the
// commit rule is the search's: the robot starts an action when the search values starting above
// planning on. Without a search: a complete plan without rewards runs at once (certain success),
// a forced start or the only useful move is made.
//
// Tree reuse: the node of the state met at the next decision, when it is a child of the root,
// becomes the new root. Guarantees: as MctsAllocator's (UCT converges; same seed and an iteration
// budget, same moves). Cost per iteration: O(depth * (K + outcomes)) in the tree, a rollout or
// ConcurrentValueBounds' cost at the leaf; memory: a node holds its state's words (4 + 2K + A, two
// bytes each), capped by `max_tree_bytes`.
class ConcurrentMctsAllocator final : public ConcurrentAllocator {
 public:
  // The ConcurrentMdp must outlive the allocator. Throws UsageError for a negative exploration
  // constant, bound leaves without bellman backups or a rollout policy that is not stationary.
  ConcurrentMctsAllocator(const ConcurrentMdp& mdp, ConcurrentMctsOptions options);

  std::string_view name() const noexcept override { return "mcts"; }
  void begin_episode(std::uint64_t seed) override;
  ConcurrentMdp::Move choose(const ConcurrentState& state) override;
  bool is_stationary() const noexcept override { return false; }
  // searches, iterations, memory_stops (summed); peak_tree_nodes, peak_tree_bytes (largest).
  void collect_statistics(Statistics& statistics) const override;

  // The decision and chance nodes the tree holds now.
  std::size_t tree_nodes() const noexcept { return nodes_.size() + edges_.size(); }
  // The bytes the tree holds now (capacities, and the nodes' states): what `max_tree_bytes` caps.
  std::size_t tree_bytes() const noexcept;

 private:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;

  struct Node {
    ConcurrentState state;
    std::uint32_t first_edge = kNone;  // kNone until expanded
    std::uint32_t visits = 0;
    std::uint16_t edge_count = 0;
    double value = 0.0;  // bellman: V (the leaf value until expanded)
  };
  struct Edge {
    ConcurrentMdp::Move move;
    std::uint32_t first_outcome = kNone;  // kNone until first taken
    std::uint32_t visits = 0;
    std::uint16_t outcome_count = 0;
    double returns = 0.0;  // mean: the sum of the rewards through it
    double q = 0.0;        // bellman: Q over the outcomes reached
  };
  struct Outcome {
    double probability = 0.0;
    std::uint32_t child = kNone;  // decision node, kNone until reached (or when it ends)
    bool ends = false;            // the episode ends here, worth `reward`
    bool reached = false;
    double reward = 0.0;
  };

  void reset(const ConcurrentState& root);
  bool reroot_to(const ConcurrentState& state);
  bool expand(std::uint32_t node);
  bool expand_outcomes(std::uint32_t edge, std::uint32_t node);
  std::uint32_t select_edge(const Node& node) const;
  double estimate(const Edge& edge) const noexcept;
  ConcurrentState successor(const ConcurrentState& state, const ConcurrentMdp::Move& move, std::size_t index) const;
  bool iterate();
  double leaf_value(const ConcurrentState& state);
  double rollout(ConcurrentState state);
  void back_up_bellman();
  bool would_exceed_memory(std::size_t nodes, std::size_t edges, std::size_t outcomes) const;
  bool bellman() const noexcept { return options_.backup == MctsBackup::bellman; }

  const ConcurrentMdp* mdp_;
  ConcurrentMctsOptions options_;
  std::unique_ptr<ConcurrentAllocator> rollout_policy_;
  std::unique_ptr<ConcurrentValueBounds> bounds_;  // bound leaves only (one per allocator: its memo)
  std::size_t state_bytes_;                        // a node's state on the heap
  SplitMix64 generator_{0};
  bool has_tree_ = false;
  std::vector<Node> nodes_;  // nodes_[0] is the root
  std::vector<Edge> edges_;
  std::vector<Outcome> outcomes_;
  std::vector<std::uint32_t> path_;  // node, edge, node, edge, ... of the current iteration
  MctsCounters counters_;
};

}  // namespace ontime
