#include "ontime/solve/search_solver.hpp"

#include <absl/container/flat_hash_map.h>
#include <pthread.h>

#include <algorithm>
#include <climits>
#include <cstddef>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "solve/expectimax.hpp"

namespace ontime {
namespace {

// ValueBounds' ends are computed by other sums than the exact values, so each is widened by this
// much before it settles a comparison: far above their rounding (a few ulps of 1), far below any
// gap worth pruning on.
constexpr double kBoundSlack = 1e-12;
// States between two checks of the stop condition.
constexpr std::size_t kStopCheckInterval = 4096;
// An upper test asks each successor for this much more than its share of the excess, so that
// one round usually suffices.
constexpr double kShareMargin = 1.1;

// The search's stack: a base, and per step of the deadline (a level of solve and one of an upper
// test, under 0.5 KiB together in a release build, measured at D = 4,096) room for the sanitizers'
// larger frames.
constexpr std::size_t kStackBase = std::size_t{1} << 20;
constexpr std::size_t kStackPerStep = std::size_t{4} << 10;

// Unwinds the search at a cap or a stop; the memo keeps what was solved.
struct CutShort {
  std::string why;
};

template <class Policy>
class BranchAndBound {
 public:
  using Compact = typename Policy::Compact;
  using Key = std::remove_cvref_t<decltype(std::declval<const Policy&>().key(std::declval<const Compact&>()))>;
  using Hash = std::conditional_t<std::is_same_v<Key, Compact>, detail::CompactStateHash, detail::PackedStateHash>;

  BranchAndBound(const Mdp& mdp, Policy policy, const ValueBounds& bounds, const SearchSolveOptions& options)
      : mdp_(&mdp), policy_(std::move(policy)), bounds_(&bounds), options_(&options) {}

  SearchSolution run() {
    const Compact start =
        detail::compact<Compact>(mdp_->start(), mdp_->skeleton_count(), mdp_->problem().culprit_slot_count());
    SearchSolution out;
    try {
      const detail::ExpectimaxEntry entry = solve(start, policy_.key(start));
      out.lower = out.upper = entry.value;
      out.first_choice = entry.choice;
    } catch (const CutShort& cut) {
      out = cut_short(start, cut.why);
    }
    out.states = memo_.size();
    out.bounded = bounded_;
    out.tested = tested_;
    out.refined = refined_.size();
    out.choices_cut = choices_cut_;
    return out;
  }

 private:
  struct Item {
    double probability;
    Status status;
    Compact next;
    Key key;  // of `next`, when running
    // When running: the interval around V*(next) last looked up (lo < 0: not yet), and whether
    // it is the exact value.
    double lo = -1.0, hi = 1.0;
    bool exact = false;
  };
  // One choice of a state on the search's path: its outcomes items_[begin, end) and the interval
  // around its value (lo == hi once solved).
  struct Choice {
    int choice;
    std::size_t begin, end;
    double lo = 0, hi = 0;
    bool exact = false;
    bool tested = false;  // an upper test against the best so far was tried
  };
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  detail::ExpectimaxEntry solve(const Compact& state, const Key& key) {
    if (const auto found = memo_.find(key); found != memo_.end()) return found->second;
    const std::size_t item_begin = items_.size();
    const std::size_t choice_begin = choices_.size();
    expand(state);
    const std::size_t choice_end = choices_.size();
    for (std::size_t c = choice_begin; c < choice_end; ++c) bound(c);

    std::size_t best = kNone;
    double threshold = 0.0;
    for (std::size_t next = pick(choice_begin, choice_end, best, threshold); next != kNone;
         next = pick(choice_begin, choice_end, best, threshold)) {
      if (threshold <= 1.0 && !choices_[next].exact && !choices_[next].tested && choices_[next].lo <= threshold) {
        // The best so far is exact and this choice's interval straddles it: first try to show,
        // by bounds refined below it, that it cannot pass.
        prove_below(next, threshold);
        continue;
      }
      solve_choice(next);
    }
    detail::ExpectimaxEntry entry{0.0, -1};
    if (best != kNone) entry = {choices_[best].lo, choices_[best].choice};
    for (std::size_t c = choice_begin; c < choice_end; ++c) {
      if (!choices_[c].exact) ++choices_cut_;
    }
    items_.resize(item_begin);
    choices_.resize(choice_begin);

    if (options_->max_states != 0 && memo_.size() >= options_->max_states) {
      throw CutShort{"the cap of " + std::to_string(options_->max_states) + " states"};
    }
    if (options_->stop && (memo_.size() & (kStopCheckInterval - 1)) == 0 && options_->stop()) {
      throw CutShort{"the stop condition"};
    }
    memo_.emplace(key, entry);
    return entry;
  }

  // Pushes every useful choice of `state` and its outcomes (in the MDP's order) on the stacks.
  void expand(const Compact& state) {
    choice_list_.clear();
    policy_.choices(state, choice_list_);
    for (const int choice : choice_list_) {
      Choice entry{choice, items_.size(), 0};
      mdp_->for_each_outcome(state, choice, [&](double probability, Status status, const Compact& next) {
        items_.push_back(Item{probability, status, next, status == Status::running ? policy_.key(next) : Key{}});
      });
      entry.end = items_.size();
      choices_.push_back(entry);
    }
  }

  // Looks up the interval around V*(next) of running item i: the exact value where the memo has
  // it; else the upper test's refined bound or ValueBounds' upper end, and (with `lower`)
  // ValueBounds' lower end, each widened by kBoundSlack.
  void look_up(Item& item, bool lower) {
    if (const auto found = memo_.find(item.key); found != memo_.end()) {
      item.lo = item.hi = found->second.value;
      item.exact = true;
      return;
    }
    ++bounded_;
    item.hi = upper_of(item.next, item.key);
    if (lower && item.lo < 0.0) item.lo = std::max(0.0, bounds_->lower(item.next) - kBoundSlack);
  }

  // Choice c's interval from its items' (`lower`: both ends, else the upper end only). Summed in
  // the exact value's order, so that each end is on its side of the exact sum after rounding too.
  void sum_up(std::size_t c, bool lower) {
    double lo = 0.0;
    double hi = 0.0;
    for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
      const Item& item = items_[i];
      if (item.status == Status::success) {
        lo += item.probability;
        hi += item.probability;
      } else if (item.status == Status::running) {
        if (lower) lo += item.probability * item.lo;
        hi += item.probability * item.hi;
      }
    }
    if (lower) choices_[c].lo = lo;
    choices_[c].hi = hi;
  }

  // Looks up choice c's successors and sums its interval.
  void bound(std::size_t c, bool lower = true) {
    for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
      if (items_[i].status == Status::running && !items_[i].exact) look_up(items_[i], lower);
    }
    sum_up(c, lower);
  }

  // An upper bound on V*(next): refined by an upper test where one ran, else ValueBounds'.
  double upper_of(const Compact& next, const Key& key) const {
    if (const auto found = refined_.find(key); found != refined_.end()) return found->second.upper;
    return std::min(1.0, bounds_->upper(next) + kBoundSlack);
  }

  // Tries to bring choice c's upper end to `threshold` or below by upper tests of its running
  // successors: each is asked for a share of the excess in proportion to its gap (probability
  // times the width of its interval); its upper end is then summed again.
  void prove_below(std::size_t c, double threshold) {
    choices_[c].tested = true;
    const std::size_t begin = choices_[c].begin;
    const std::size_t end = choices_[c].end;
    const double excess = choices_[c].hi - threshold;
    if (excess <= 0.0) return;
    double gaps = 0.0;
    for (std::size_t i = begin; i < end; ++i) {
      Item& item = items_[i];
      if (item.status != Status::running || item.exact) continue;
      if (item.lo < 0.0) item.lo = std::max(0.0, bounds_->lower(item.next) - kBoundSlack);
      gaps += item.probability * (item.hi - item.lo);
    }
    if (gaps <= excess) return;  // even every successor at its lower end would leave it above
    for (std::size_t i = begin; i < end; ++i) {
      if (items_[i].status != Status::running || items_[i].exact) continue;
      const Compact next = items_[i].next;  // copies: the test may move the items
      const Key key = items_[i].key;
      const double upper = items_[i].hi;
      const double gap = upper - items_[i].lo;
      if (gap <= 0.0) continue;
      const double tested = test(next, key, upper - kShareMargin * excess * gap / gaps);
      items_[i].hi = std::min(upper, tested);
    }
    sum_up(c, false);
  }

  // An upper test: a bound u >= V*(state), refined by expanding the state (and, recursively, its
  // successors) until u <= target or the expansion shows it cannot get there. Each expanded
  // state's bound is kept (refined_).
  double test(const Compact& state, const Key& key, double target) {
    if (const auto found = memo_.find(key); found != memo_.end()) return found->second.value;
    const double known = upper_of(state, key);
    if (known <= target || target < 0.0) return known;
    const auto tried = refined_.find(key);
    if (tried != refined_.end() && target <= tried->second.failed_at) return known;
    const std::size_t item_begin = items_.size();
    const std::size_t choice_begin = choices_.size();
    expand(state);
    const std::size_t choice_end = choices_.size();
    double result = 0.0;
    bool failed = false;
    for (std::size_t c = choice_begin; c < choice_end; ++c) {
      bound(c, false);
      if (!failed && choices_[c].hi > target) {
        prove_below(c, target);
        failed = choices_[c].hi > target;
      }
      result = std::max(result, choices_[c].hi);
    }
    ++tested_;
    items_.resize(item_begin);
    choices_.resize(choice_begin);
    result = std::min(result, known);
    Refined& refined = refined_[key];
    refined.upper = result;
    if (result > target) refined.failed_at = std::max(refined.failed_at, target);
    return result;
  }

  // Solves choice c exactly: the memoised solver's sum, in its order.
  void solve_choice(std::size_t c) {
    double value = 0.0;
    const std::size_t begin = choices_[c].begin;
    const std::size_t end = choices_[c].end;
    for (std::size_t i = begin; i < end; ++i) {
      const double probability = items_[i].probability;
      if (items_[i].status == Status::success) {
        value += probability;
      } else if (items_[i].status == Status::running) {
        // Copies: the recursion may move the items.
        const Compact next = items_[i].next;
        const Key key = items_[i].key;
        value += probability * solve(next, key).value;
      }
    }
    choices_[c].lo = value;
    choices_[c].hi = value;
    choices_[c].exact = true;
  }

  // The next choice to solve, or kNone when the tie rule's verdict is settled (then `best` is the
  // answer, kNone when there is no choice). `threshold`: what the choice must not pass to be
  // settled against the best so far when that is exact (else above 1).
  std::size_t pick(std::size_t begin, std::size_t end, std::size_t& best, double& threshold) const {
    best = kNone;
    threshold = 2.0;
    if (begin == end) return kNone;
    bool any_exact = false;
    std::size_t widest = begin;
    for (std::size_t c = begin; c < end; ++c) {
      any_exact = any_exact || choices_[c].exact;
      if (choices_[c].lo > choices_[widest].lo) widest = c;
    }
    if (!any_exact) return widest;
    // The exact solver's replay: the best so far starts below every value.
    double best_lo = -1.0;
    double best_hi = -1.0;
    std::size_t record = kNone;
    for (std::size_t c = begin; c < end; ++c) {
      const Choice& choice = choices_[c];
      if (choice.lo > best_hi + OptimalSolver::kTieTolerance) {
        record = c;
        best_lo = choice.lo;
        best_hi = choice.hi;
      } else if (choice.hi > best_lo + OptimalSolver::kTieTolerance) {
        // Unsettled (both cannot be exact here): solve the more promising of the two not solved.
        if (choice.exact) return record;
        if (choices_[record].exact) {
          threshold = best_lo + OptimalSolver::kTieTolerance;
          return c;
        }
        return choices_[record].hi >= choice.hi ? record : c;
      }
    }
    if (!choices_[record].exact) return record;
    best = record;
    return kNone;
  }

  // The start state's interval from one step of lookahead over the states solved.
  SearchSolution cut_short(const Compact& start, const std::string& why) {
    items_.clear();
    choices_.clear();
    expand(start);
    SearchSolution out;
    out.exact = false;
    out.stopped_by = why;
    out.lower = 0.0;
    out.upper = 0.0;
    for (std::size_t c = 0; c < choices_.size(); ++c) {
      bound(c);
      if (choices_[c].lo > out.lower || out.first_choice < 0) {
        out.lower = std::max(out.lower, choices_[c].lo);
        out.first_choice = choices_[c].choice;
      }
      out.upper = std::max(out.upper, choices_[c].hi);
    }
    out.upper = std::min(out.upper, 1.0);
    return out;
  }

  const Mdp* mdp_;
  Policy policy_;
  const ValueBounds* bounds_;
  const SearchSolveOptions* options_;
  absl::flat_hash_map<Key, detail::ExpectimaxEntry, Hash> memo_;
  std::vector<Item> items_;
  std::vector<Choice> choices_;
  std::vector<int> choice_list_;
  // A state's upper bound as upper tests refined it, and the highest target a test of it missed:
  // a test to that target or below is not run again (it would most likely miss again; when the
  // bounds below have moved since, the exact solve that follows a miss is only slower).
  struct Refined {
    double upper = 1.0;
    double failed_at = -1.0;
  };
  absl::flat_hash_map<Key, Refined, Hash> refined_;
  std::uint64_t tested_ = 0;
  std::uint64_t bounded_ = 0;
  std::uint64_t choices_cut_ = 0;
};

template <class Policy>
SearchSolution run(const Mdp& mdp, Policy policy, const ValueBounds& bounds, const SearchSolveOptions& options) {
  return BranchAndBound<Policy>(mdp, std::move(policy), bounds, options).run();
}

// Runs `work` on a thread of its own whose stack holds `stack_bytes`, and waits for it; rethrows
// what it threw. The search recurses one level per step of the deadline, and the caller's thread
// may have a small stack (a host program's worker, a lowered ulimit): this keeps a deep deadline
// from overflowing it. (std::thread cannot set a stack size; POSIX threads can.)
void run_on_own_stack(std::size_t stack_bytes, const std::function<void()>& work) {
  struct Job {
    const std::function<void()>* work;
    std::exception_ptr error;
  } job{&work, nullptr};
  pthread_attr_t attributes;
  if (pthread_attr_init(&attributes) != 0) throw std::runtime_error("search: cannot set up its thread");
  pthread_attr_setstacksize(&attributes, std::max<std::size_t>(stack_bytes, PTHREAD_STACK_MIN));
  pthread_t thread;
  const int created = pthread_create(
      &thread, &attributes,
      [](void* argument) -> void* {
        Job& running = *static_cast<Job*>(argument);
        try {
          (*running.work)();
        } catch (...) {
          running.error = std::current_exception();
        }
        return nullptr;
      },
      &job);
  pthread_attr_destroy(&attributes);
  if (created != 0)
    throw ResourceLimitError("search: cannot start its thread (" + std::to_string(stack_bytes >> 20) +
                             " MiB of stack)");
  pthread_join(thread, nullptr);
  if (job.error) std::rethrow_exception(job.error);
}

}  // namespace

SearchSolution solve_search(const Mdp& mdp, const SearchSolveOptions& options) {
  detail::require_exact_size(mdp, "search");
  const ValueBounds bounds(mdp);
  SearchSolution solution;
  run_on_own_stack(kStackBase + kStackPerStep * static_cast<std::size_t>(mdp.deadline()), [&] {
    if (mdp.has_backtracking()) {
      solution = run(mdp, detail::OptimalBacktrackPolicy(mdp), bounds, options);
      return;
    }
    switch (detail::packed_words(mdp)) {
      case 2:
        solution = run(mdp, detail::OptimalPolicy<2>(mdp), bounds, options);
        break;
      case 4:
        solution = run(mdp, detail::OptimalPolicy<4>(mdp), bounds, options);
        break;
      default:
        solution = run(mdp, detail::OptimalPolicy<0>(mdp), bounds, options);
    }
  });
  return solution;
}

}  // namespace ontime
