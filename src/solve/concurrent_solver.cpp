#include "ontime/solve/concurrent_solver.hpp"

#include <absl/container/flat_hash_map.h>
#include <absl/hash/hash.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "ontime/util/error.hpp"

namespace ontime {

struct ConcurrentSolver::Impl {
  struct Entry {
    double value;
    Move move;
  };
  absl::flat_hash_map<ConcurrentState, Entry> memo;
  std::size_t max_states = 0;
  std::function<bool()> stop;
  Policy policy;        // set: the policy's value, not the optimum
  Bounds bounds;        // set: branch and bound
  bool merge = false;   // the optimum's memo is keyed by ConcurrentMdp::merge_backlogs
  ConcurrentState key;  // scratch

  // The memo's key of `state`.
  const ConcurrentState& key_of(const ConcurrentMdp& mdp, const ConcurrentState& state) {
    if (!merge) return state;
    key = state;
    mdp.merge_backlogs(key);
    return key;
  }
};

ConcurrentSolver::ConcurrentSolver(const ConcurrentMdp& mdp, std::size_t max_states)
    : mdp_(&mdp), impl_(std::make_unique<Impl>()) {
  impl_->max_states = max_states;
  impl_->merge = mdp.merges_backlogs();
}

ConcurrentSolver::ConcurrentSolver(const ConcurrentMdp& mdp, Policy policy, std::size_t max_states)
    : ConcurrentSolver(mdp, max_states) {
  impl_->policy = std::move(policy);
  impl_->merge = false;
}

ConcurrentSolver::~ConcurrentSolver() = default;

void ConcurrentSolver::set_bounds(Bounds bounds) { impl_->bounds = std::move(bounds); }

void ConcurrentSolver::set_stop(std::function<bool()> stop) { impl_->stop = std::move(stop); }

std::size_t ConcurrentSolver::states() const noexcept { return impl_->memo.size(); }

double ConcurrentSolver::max_bytes(const Problem& problem, std::size_t max_states) {
  const double words = 4.0 + 2.0 * problem.skeleton_count() + problem.action_count();
  // A state's words on the heap: rounded up to the allocator's 16 bytes, plus its 16-byte header.
  const double heap = std::ceil(words * 2.0 / 16.0) * 16.0 + 16.0;
  const double slot = sizeof(ConcurrentState) + sizeof(Impl::Entry) + 1.0;
  // abseil's table keeps at most 7/8 of its power-of-two capacity full; while it grows it holds
  // both tables. The stack holds at most one state per state solved, words included.
  const double capacity = std::exp2(std::ceil(std::log2(std::max(16.0, static_cast<double>(max_states) * 8.0 / 7.0))));
  return capacity * slot * 1.5 + static_cast<double>(max_states) * (2.0 * heap + sizeof(ConcurrentState));
}

std::optional<double> settled_value(const ConcurrentMdp& mdp, const ConcurrentState& state, bool optimum) {
  if (!mdp.any_live(state)) return 0.0;
  if (optimum && mdp.certain_success(state)) return 1.0;
  return std::nullopt;
}

double ConcurrentSolver::solve(const ConcurrentState& root) {
  const ConcurrentMdp& mdp = *mdp_;
  const bool optimum = !impl_->policy;
  if (const std::optional<double> value = settled_value(mdp, root, optimum)) return *value;
  auto& memo = impl_->memo;
  const Bounds& bounds = impl_->bounds;
  // A successor's value when it is known (terminal or memoised).
  const auto known = [&](const ConcurrentState& next) -> std::optional<double> {
    if (const std::optional<double> value = settled_value(mdp, next, optimum)) return value;
    if (const auto found = memo.find(impl_->key_of(mdp, next)); found != memo.end()) return found->second.value;
    return std::nullopt;
  };
  // A move's value Q, summed over its outcomes in the MDP's order from the successors' values, or,
  // while some successor is unknown, an interval around it from their bounds ([0, R] without
  // them); the unknown successors go to `missing` when it is given.
  struct MoveValue {
    Move move;
    double lower = 0;
    double upper = 0;
    bool exact = true;
  };
  const double most = mdp.problem().has_rewards() ? mdp.problem().max_reward() : 1.0;
  const auto add = [&](MoveValue& q, double probability, const ConcurrentState& next,
                       std::vector<ConcurrentState>* missing) {
    if (const std::optional<double> value = known(next)) {
      q.lower += probability * *value;
      q.upper += probability * *value;
      return;
    }
    q.exact = false;
    const std::pair<double, double> interval = bounds ? bounds(next) : std::pair<double, double>{0.0, most};
    q.lower += probability * interval.first;
    q.upper += probability * interval.second;
    if (missing != nullptr) missing->push_back(next);
  };
  const auto value_of = [&](const ConcurrentState& state, Move move, std::vector<ConcurrentState>* missing) {
    MoveValue q{.move = move};
    if (move.is_start()) {
      // One outcome, or one per execution time drawn from a chain when the action starts.
      mdp.for_each_start_outcome(state, move.start,
                                 [&](double probability, const ConcurrentMdp::StartOutcome& outcome) {
                                   if (outcome.ends) {
                                     q.lower += probability * outcome.reward;
                                     q.upper += probability * outcome.reward;
                                   } else {
                                     add(q, probability, outcome.next, missing);
                                   }
                                 });
    } else if (ConcurrentMdp::time(state) < mdp.deadline()) {
      mdp.for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
        add(q, probability, next, missing);
      });
    }  // a policy's step asked for at the deadline ends the episode: worth 0
    return q;
  };

  std::vector<ConcurrentState> stack{root};
  std::vector<MoveValue> values;
  std::size_t visits = 0;
  while (!stack.empty()) {
    if (memo.contains(impl_->key_of(mdp, stack.back()))) {
      stack.pop_back();
      continue;
    }
    if (++visits % 4096 == 0 && impl_->stop && impl_->stop()) throw Cancelled("solve stopped");
    // Where backlogs merge, the key itself is the state expanded (a state of the MDP with the same
    // value and moves): so a key's value does not depend on which of its states was met first, and
    // every solver that expands keys (the search's exact pass, the layered solver) has its bits.
    const ConcurrentState state = impl_->key_of(mdp, stack.back());
    const std::size_t depth = stack.size();
    values.clear();
    if (!optimum) {
      values.push_back(value_of(state, impl_->policy(state), &stack));
    } else if (!bounds) {
      for (const Move& move : mdp.useful_moves(state)) values.push_back(value_of(state, move, &stack));
    } else {
      // Branch and bound: the move of the largest lower end first, exactly; then only the moves
      // whose upper end reaches within the tie tolerance of its value (the others can be neither
      // the best nor tied with it).
      const std::vector<Move> moves = mdp.useful_moves(state);
      for (const Move& move : moves) values.push_back(value_of(state, move, nullptr));
      std::size_t lead = 0;
      for (std::size_t m = 1; m < values.size(); ++m) {
        if (values[m].lower > values[lead].lower) lead = m;
      }
      if (!values.empty() && !values[lead].exact) {
        value_of(state, values[lead].move, &stack);
      } else if (!values.empty()) {
        const double floor = values[lead].lower - kTieTolerance;
        std::size_t kept = 0;
        for (std::size_t m = 0; m < values.size(); ++m) {
          if (values[m].exact) {
            values[kept++] = values[m];
          } else if (values[m].upper >= floor) {
            value_of(state, values[m].move, &stack);
          }
        }
        values.resize(kept);
      }
    }
    if (stack.size() > depth) continue;
    // Ties: the first move in the order of useful_moves whose value is within kTieTolerance of
    // the best.
    double best = -1.0;
    for (const MoveValue& q : values) best = std::max(best, q.lower);
    Move best_move;
    double value = 0.0;
    for (const MoveValue& q : values) {
      if (q.lower >= best - kTieTolerance) {
        best_move = q.move;
        value = q.lower;
        break;
      }
    }
    if (memo.size() >= impl_->max_states) {
      throw ResourceLimitError("the acting-while-planning solver reached its cap of " +
                               std::to_string(impl_->max_states) + " states");
    }
    // A live state always has a move (docs/theory.md); 0 is kept as a guard.
    memo.emplace(impl_->key_of(mdp, state), Impl::Entry{value, best_move});
    stack.pop_back();
  }
  return memo.at(impl_->key_of(mdp, root)).value;
}

std::optional<double> ConcurrentSolver::value(const ConcurrentState& state) const {
  if (const std::optional<double> terminal = settled_value(*mdp_, state, !impl_->policy)) return terminal;
  ConcurrentState key = state;
  if (impl_->merge) mdp_->merge_backlogs(key);
  const auto found = impl_->memo.find(key);
  if (found == impl_->memo.end()) return std::nullopt;
  return found->second.value;
}

std::optional<ConcurrentSolver::Move> ConcurrentSolver::best_move(const ConcurrentState& state) const {
  ConcurrentState key = state;
  if (impl_->merge) mdp_->merge_backlogs(key);
  const auto found = impl_->memo.find(key);
  if (found == impl_->memo.end()) return std::nullopt;
  return found->second.move;
}

}  // namespace ontime
