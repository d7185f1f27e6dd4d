#include "ontime/solve/concurrent_search.hpp"

#include <absl/container/flat_hash_map.h>
#include <absl/hash/hash.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "ontime/solve/concurrent_solver.hpp"
#include "ontime/solve/concurrent_value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime {

using Interval = ConcurrentValueBounds::Interval;
using Move = ConcurrentMdp::Move;

struct ConcurrentSearch::Impl {
  const ConcurrentMdp* mdp;
  std::uint64_t max_states;
  ConcurrentValueBounds heuristic;
  absl::flat_hash_map<ConcurrentState, Interval> table;
  // Scratch of one backup: the successors of the move to descend by, with probability times gap.
  std::vector<std::pair<double, ConcurrentState>> descent;
  std::vector<ConcurrentState> path;
  SplitMix64 generator{1};

  Impl(const ConcurrentMdp& model, std::uint64_t cap) : mdp(&model), max_states(cap), heuristic(model) {}

  // The key of `state` in the table: the exact solver's (ConcurrentMdp::merge_backlogs where the
  // model merges backlogs), so that trials walk the states the exact pass expands.
  ConcurrentState key_of(const ConcurrentState& state) const {
    ConcurrentState key = state;
    mdp->merge_backlogs(key);
    return key;
  }

  // The interval of `state`: exact when terminal, else the table's, else the heuristic's (kept).
  Interval interval(const ConcurrentState& given) {
    if (!mdp->any_live(given)) return {};
    if (mdp->certain_success(given)) return {1.0, 1.0};
    const ConcurrentState state = key_of(given);
    if (const auto found = table.find(state); found != table.end()) return found->second;
    Interval bounds = heuristic.bounds(state);
    if (bounds.lower < bounds.upper) {
      bounds.lower = std::max(0.0, bounds.lower - kBoundSlack);
      bounds.upper += kBoundSlack;
    }
    table.emplace(state, bounds);
    return bounds;
  }

  struct Backup {
    Interval interval;     // the state's interval after the backup (kept no looser than before)
    double lower_max = 0;  // max_m Q_lo(m)
    double upper_max = 0;  // max_m Q_hi(m)
    Move best_lower;       // the move of the largest Q_lo (the tie rule of the exact solver)
    double best_lower_value = -1.0;
  };

  // Backs `state` (not terminal) up from its successors; fills `descent` with the successors of the
  // move of the largest Q_hi (ties: the first).
  Backup back_up(const ConcurrentState& state) {
    const Interval before = interval(state);
    Backup result;
    double best_upper = -1.0;
    std::vector<std::pair<double, ConcurrentState>> successors;
    for (const Move& move : mdp->useful_moves(state)) {
      Interval q;
      successors.clear();
      if (move.is_start()) {
        // One outcome, or with an execution drawn from a chain when it starts, one per execution
        // time (SPEC §9); an outcome that ends the episode is worth its reward.
        mdp->for_each_start_outcome(state, move.start,
                                    [&](double probability, const ConcurrentMdp::StartOutcome& outcome) {
                                      if (outcome.ends) {
                                        q.lower += probability * outcome.reward;
                                        q.upper += probability * outcome.reward;
                                        return;
                                      }
                                      const Interval v = interval(outcome.next);
                                      q.lower += probability * v.lower;
                                      q.upper += probability * v.upper;
                                      successors.emplace_back(probability * (v.upper - v.lower), key_of(outcome.next));
                                    });
      } else {
        mdp->for_each_step_outcome(state, move.refine, [&](double probability, const ConcurrentState& next) {
          const Interval v = interval(next);
          q.lower += probability * v.lower;
          q.upper += probability * v.upper;
          successors.emplace_back(probability * (v.upper - v.lower), key_of(next));
        });
      }
      if (q.upper > best_upper) {
        best_upper = q.upper;
        descent.swap(successors);
      }
      if (q.lower > result.best_lower_value + ConcurrentSolver::kTieTolerance) {
        result.best_lower_value = q.lower;
        result.best_lower = move;
      }
      result.lower_max = std::max(result.lower_max, q.lower);
    }
    result.upper_max = std::max(best_upper, 0.0);
    Interval kept{std::max(before.lower, result.lower_max), std::min(before.upper, result.upper_max)};
    if (result.lower_max >= result.upper_max) {
      kept = {result.upper_max, result.upper_max};  // closed: its moves' ends met
    } else if (kept.lower > kept.upper) {
      kept.lower = kept.upper;  // rounding only
    }
    table[key_of(state)] = kept;
    result.interval = kept;
    return result;
  }

  // The successors' summed probability times gap.
  double descent_mass() const {
    double mass = 0.0;
    for (const auto& [weight, next] : descent) mass += weight;
    return mass;
  }

  // A successor of `descent` drawn in proportion to probability times gap (`mass`, their sum), or
  // null when none has a gap.
  ConcurrentState* drawn(double mass) {
    if (!(mass > 0.0)) return nullptr;
    double draw = uniform01(generator) * mass;
    ConcurrentState* chosen = nullptr;
    for (auto& [weight, next] : descent) {
      if (!(weight > 0.0)) continue;
      chosen = &next;
      draw -= weight;
      if (draw < 0.0) break;
    }
    return chosen;
  }
};

ConcurrentSearch::ConcurrentSearch(const ConcurrentMdp& mdp, std::uint64_t max_states)
    : impl_(std::make_unique<Impl>(mdp, max_states)) {}

ConcurrentSearch::~ConcurrentSearch() = default;

Interval ConcurrentSearch::interval(const ConcurrentState& state) { return impl_->interval(state); }

void ConcurrentSearch::clear(std::uint64_t seed) {
  impl_->table.clear();
  impl_->generator = SplitMix64(seed);
}

std::uint64_t ConcurrentSearch::size() const noexcept { return impl_->table.size(); }

ConcurrentSearchResult ConcurrentSearch::search(const ConcurrentState& from,
                                                const std::function<bool(std::uint64_t work)>& stop) {
  Impl& impl = *impl_;
  const ConcurrentMdp& mdp = *impl.mdp;
  ConcurrentSearchResult result;
  if (!mdp.any_live(from)) return result;
  if (mdp.certain_success(from)) {
    result.move = mdp.run_complete_plan(from);
    result.lower = result.upper = 1.0;
    result.exact = true;
    return result;
  }
  const auto stopped = [&] {
    return (stop && stop(result.work)) || (impl.max_states > 0 && impl.table.size() >= impl.max_states);
  };
  for (;;) {
    // From's own interval may have closed on its bounds alone (one eligible skeleton): the move is
    // known to be optimal only once its lower end reaches every move's upper end.
    const Impl::Backup root = impl.back_up(from);
    ++result.work;
    result.move = root.best_lower;
    result.lower = root.best_lower_value;
    result.upper = std::min(root.interval.upper, root.upper_max);
    result.exact = root.lower_max >= root.upper_max;
    if (result.exact || stopped()) break;
    const double start_gap = root.interval.upper - root.interval.lower;
    const ConcurrentState* next = impl.drawn(impl.descent_mass());
    if (next == nullptr) break;  // closed but for rounding
    impl.path.assign(1, *next);
    for (;;) {
      const Impl::Backup backup = impl.back_up(impl.path.back());
      ++result.work;
      if (backup.interval.lower >= backup.interval.upper || stopped()) break;
      const double mass = impl.descent_mass();
      if (mass <= start_gap / kTrialRatio) break;
      next = impl.drawn(mass);
      if (next == nullptr) break;
      impl.path.push_back(*next);
    }
    // The path's last state was just backed up; the others again, deepest first (from's at the
    // top of the loop).
    for (std::size_t i = impl.path.size() - 1; i-- > 0;) {
      impl.back_up(impl.path[i]);
      ++result.work;
    }
  }
  return result;
}

namespace {

ConcurrentSolution solve_memoised(const ConcurrentMdp& mdp, const ConcurrentSolveOptions& options) {
  ConcurrentSolver solver(mdp, options.max_states > 0 ? options.max_states : ConcurrentSolver::kDefaultMaxStates);
  if (options.stop) solver.set_stop(options.stop);
  ConcurrentSolution solution;
  solution.lower = solution.upper = solver.solve(mdp.start());
  solution.exact = true;
  solution.first = solver.best_move(mdp.start()).value_or(ConcurrentMdp::Move{});
  solution.solved = solver.states();
  return solution;
}

ConcurrentSolution solve_by_search(const ConcurrentMdp& mdp, const ConcurrentSolveOptions& options) {
  ConcurrentSearch search(mdp, options.max_states);
  ConcurrentSolution solution;
  const ConcurrentState start = mdp.start();
  const auto from_records = [&](std::string stopped_by) {
    const ConcurrentSearchResult trials = search.search(start, [](std::uint64_t) { return true; });
    solution.lower = trials.lower;
    solution.upper = trials.upper;
    solution.exact = trials.exact;
    solution.first = trials.move;
    solution.records = search.size();
    if (!trials.exact) solution.stopped_by = std::move(stopped_by);
  };
  if (options.gap > 0) {
    // Trials in rounds of a few thousand backups, until the start's interval is narrow enough.
    constexpr std::uint64_t kRound = 4096;
    bool stopped = false;
    ConcurrentSearchResult trials;
    for (;;) {
      trials = search.search(start, [&](std::uint64_t work) {
        if (work < kRound) return false;
        stopped = options.stop && options.stop();
        return true;
      });
      const bool capped = options.max_states > 0 && search.size() >= options.max_states;
      if (trials.exact || trials.upper - trials.lower <= options.gap || stopped || capped) {
        if (!trials.exact) {
          solution.stopped_by = trials.upper - trials.lower <= options.gap ? "the gap"
                                : stopped                                  ? "the stop condition"
                                                                           : "the state cap";
        }
        break;
      }
    }
    solution.lower = trials.lower;
    solution.upper = trials.upper;
    solution.exact = trials.exact;
    solution.first = trials.move;
    solution.records = search.size();
    return solution;
  }
  // Trials first: they narrow the intervals where the optimum goes, so that the exact pass below
  // solves few moves beyond the optimal ones.
  bool stopped = false;
  search.search(start, [&](std::uint64_t work) {
    if (work % 4096 == 0 && options.stop && options.stop()) stopped = true;
    return stopped;
  });
  if (stopped) {
    from_records("the stop condition");
    return solution;
  }
  ConcurrentSolver solver(mdp, options.max_states > 0 ? options.max_states : ConcurrentSolver::kDefaultMaxStates);
  solver.set_bounds([&](const ConcurrentState& state) {
    if (options.max_states > 0 && search.size() >= options.max_states) {
      throw ResourceLimitError("the search reached its cap of states");
    }
    const Interval bounds = search.interval(state);
    return std::pair<double, double>{bounds.lower, bounds.upper};
  });
  if (options.stop) solver.set_stop(options.stop);
  try {
    solution.lower = solution.upper = solver.solve(start);
  } catch (const ResourceLimitError&) {
    from_records("the state cap");
    return solution;
  } catch (const Cancelled&) {
    from_records("the stop condition");
    return solution;
  }
  solution.exact = true;
  solution.first = solver.best_move(start).value_or(ConcurrentMdp::Move{});
  solution.solved = solver.states();
  solution.records = search.size();
  return solution;
}

}  // namespace

ConcurrentSolution solve_concurrent(const ConcurrentMdp& mdp, const ConcurrentSolveOptions& options) {
  if (options.method == ConcurrentSolveOptions::Method::memoised) return solve_memoised(mdp, options);
  return solve_by_search(mdp, options);
}

}  // namespace ontime
