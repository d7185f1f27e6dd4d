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
  Policy policy;  // set: the policy's value, not the optimum
};

ConcurrentSolver::ConcurrentSolver(const ConcurrentMdp& mdp, std::size_t max_states)
    : mdp_(&mdp), impl_(std::make_unique<Impl>()) {
  impl_->max_states = max_states;
}

ConcurrentSolver::ConcurrentSolver(const ConcurrentMdp& mdp, Policy policy, std::size_t max_states)
    : ConcurrentSolver(mdp, max_states) {
  impl_->policy = std::move(policy);
}

ConcurrentSolver::~ConcurrentSolver() = default;

void ConcurrentSolver::set_stop(std::function<bool()> stop) { impl_->stop = std::move(stop); }

std::size_t ConcurrentSolver::states() const noexcept { return impl_->memo.size(); }

double ConcurrentSolver::max_bytes(const Problem& problem, std::size_t max_states) {
  const double words = 3.0 + 2.0 * problem.skeleton_count() + problem.action_count();
  // A state's words on the heap: rounded up to the allocator's 16 bytes, plus its 16-byte header.
  const double heap = std::ceil(words * 2.0 / 16.0) * 16.0 + 16.0;
  const double slot = sizeof(ConcurrentState) + sizeof(Impl::Entry) + 1.0;
  // abseil's table keeps at most 7/8 of its power-of-two capacity full; while it grows it holds
  // both tables. The stack holds at most one state per state solved, words included.
  const double capacity = std::exp2(std::ceil(std::log2(std::max(16.0, static_cast<double>(max_states) * 8.0 / 7.0))));
  return capacity * slot * 1.5 + static_cast<double>(max_states) * (2.0 * heap + sizeof(ConcurrentState));
}

namespace {

// The value of a state that needs no search: 0 when no skeleton can finish any more; for the
// optimum, 1 when one is refined in full without rewards (ConcurrentMdp::certain_success).
std::optional<double> terminal_value(const ConcurrentMdp& mdp, const ConcurrentState& state, bool optimum) {
  if (!mdp.any_live(state)) return 0.0;
  if (optimum && mdp.certain_success(state)) return 1.0;
  return std::nullopt;
}

}  // namespace

double ConcurrentSolver::solve(const ConcurrentState& root) {
  const ConcurrentMdp& mdp = *mdp_;
  const bool optimum = !impl_->policy;
  if (const std::optional<double> value = terminal_value(mdp, root, optimum)) return *value;
  auto& memo = impl_->memo;
  // A successor's value when it is known (terminal or memoised); otherwise it is queued.
  std::vector<ConcurrentState> missing;
  const auto known = [&](const ConcurrentState& next) -> std::optional<double> {
    if (const std::optional<double> value = terminal_value(mdp, next, optimum)) return value;
    if (const auto found = memo.find(next); found != memo.end()) return found->second.value;
    missing.push_back(next);
    return std::nullopt;
  };

  std::vector<ConcurrentState> stack{root};
  std::size_t visits = 0;
  while (!stack.empty()) {
    if (memo.contains(stack.back())) {
      stack.pop_back();
      continue;
    }
    if (++visits % 4096 == 0 && impl_->stop && impl_->stop()) throw Cancelled("solve stopped");
    const ConcurrentState state = stack.back();
    missing.clear();
    double best = -1.0;
    Move best_move;
    const auto consider = [&](double value, Move move) {
      if (value > best + kTieTolerance) {
        best = value;
        best_move = move;
      }
    };
    const auto step_value = [&](int refine) {
      double q = 0.0;
      bool complete = true;
      mdp.for_each_step_outcome(state, refine, [&](double probability, const ConcurrentState& next) {
        if (const std::optional<double> value = known(next)) {
          q += probability * *value;
        } else {
          complete = false;
        }
      });
      if (complete) consider(q, Move{-1, refine});
    };
    const auto start_value = [&](int action) {
      const ConcurrentMdp::StartOutcome outcome = mdp.start_action(state, action);
      if (outcome.ends) {
        consider(outcome.reward, Move{action, ConcurrentMdp::kWait});
      } else if (const std::optional<double> value = known(outcome.next)) {
        consider(*value, Move{action, ConcurrentMdp::kWait});
      }
    };
    if (!optimum) {
      const Move move = impl_->policy(state);
      if (move.is_start()) {
        start_value(move.start);
      } else if (ConcurrentMdp::time(state) < mdp.deadline()) {
        step_value(move.refine);
      } else {
        consider(0.0, move);  // no step is left at the deadline
      }
    } else {
      const int forced = mdp.forced_start(state);
      if (forced < 0 && ConcurrentMdp::time(state) < mdp.deadline()) {
        const ChoiceList choices = mdp.refine_choices(state);
        if (choices.empty()) step_value(ConcurrentMdp::kWait);
        for (const int choice : choices) step_value(choice);
        // With backtracking an attempt may discard motions: an idle planner is a move of its own.
        if (!choices.empty() && mdp.has_backtracking()) step_value(ConcurrentMdp::kWait);
      }
      for (const int action : mdp.startable(state)) {
        if (forced < 0 || action == forced) start_value(action);
      }
    }
    if (!missing.empty()) {
      for (ConcurrentState& next : missing) stack.push_back(std::move(next));
      continue;
    }
    if (memo.size() >= impl_->max_states) {
      throw ResourceLimitError("the acting-while-planning solver reached its cap of " +
                               std::to_string(impl_->max_states) + " states");
    }
    // A live state always has a move (docs/theory.md); 0 is kept as a guard.
    memo.emplace(state, Impl::Entry{best < 0 ? 0.0 : best, best_move});
    stack.pop_back();
  }
  return memo.at(root).value;
}

std::optional<ConcurrentSolver::Move> ConcurrentSolver::best_move(const ConcurrentState& state) const {
  const auto found = impl_->memo.find(state);
  if (found == impl_->memo.end()) return std::nullopt;
  return found->second.move;
}

}  // namespace ontime
