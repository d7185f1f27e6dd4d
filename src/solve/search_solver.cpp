#include "ontime/solve/search_solver.hpp"

#include <absl/container/flat_hash_map.h>
#include <fmt/format.h>
#include <pthread.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstddef>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "ontime/solve/optimal_solver.hpp"
#include "ontime/solve/value_bounds.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"
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
// A trial ends where its choice's outcomes hold less than this fraction of the start's gap, in
// probability times gap (bounded RTDP's tau); the trials end when the start's gap is below
// kTrialsDone.
constexpr double kTrialRatio = 32.0;
constexpr double kTrialsDone = SearchSolveOptions::kFinestGap;
// The trials' draws until clear(seed) gives others.
constexpr std::uint64_t kDefaultTrialSeed = 1;

// The search's stack: a base, and per step of the deadline (a level of solve and one of an upper
// test, under 0.5 KiB together in a release build, measured at D = 4,096) room for the sanitizers'
// larger frames.
constexpr std::size_t kStackBase = std::size_t{1} << 20;
constexpr std::size_t kStackPerStep = std::size_t{4} << 10;
// Searches whose deadline needs at most this much run on the caller's stack (D <= 64).
constexpr std::size_t kInlineStack = std::size_t{256} << 10;

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

  BranchAndBound(const Mdp& mdp, Policy policy, const ValueBounds& bounds, std::uint64_t max_states)
      : mdp_(&mdp), policy_(std::move(policy)), bounds_(&bounds), max_states_(max_states) {}

  // Searches from `from` until its value is exact, the cap is reached or `stop(work)` returns
  // true (checked after every `check_interval` units of work: a state solved or expanded by an
  // upper test, counted from this call's start). What was solved and refined is kept.
  SearchSolution run(const State& from, const std::function<bool(std::uint64_t)>& stop, std::uint64_t check_interval) {
    const auto start = detail::compact<Compact>(from, mdp_->skeleton_count(), detail::recorded_slots(mdp_->problem()));
    stop_ = &stop;
    check_interval_ = check_interval;
    work_start_ = work_;
    SearchSolution out;
    try {
      const detail::ExpectimaxEntry entry = solve(start, policy_.key(start));
      out.lower = out.upper = entry.value;
      out.first_choice = entry.choice;
    } catch (const CutShort& cut) {
      out = cut_short(start, cut.why);
    }
    stop_ = nullptr;
    return with_counters(out);
  }

  // Trials from `from` (bounded RTDP, McMahan, Likhachev and Gordon 2005) until `stop(work)`
  // returns true (checked after every `check_interval` states expanded), the cap is reached or
  // from's interval is narrower than kTrialsDone. Each trial walks down from `from`: at every
  // state it takes the choice of the largest upper end and draws one of its outcomes in
  // proportion to probability times gap, and ends where the choice's outcomes hold less than
  // 1/kTrialRatio of from's gap in all; the states walked are then backed up deepest first, both ends (a state's lower
  // end is its best choice's lower end less kTieTolerance, which keeps it at most the exact
  // solver's value whatever choice its tie rule takes). The bounds are kept, so a search after
  // them starts from them. Returns from's interval and the choice of the best lower end.
  SearchSolution trials(const State& from, const std::function<bool(std::uint64_t)>& stop, std::uint64_t check_interval,
                        double gap) {
    const auto start = detail::compact<Compact>(from, mdp_->skeleton_count(), detail::recorded_slots(mdp_->problem()));
    const Key key = policy_.key(start);
    work_start_ = work_;
    trials_end_.clear();
    while (trial(start, key, stop, check_interval, std::max(gap, kTrialsDone))) {
    }
    SearchSolution out;
    if (const auto found = table_.find(key); found != table_.end() && found->second.exact) {
      out.lower = out.upper = found->second.value;
      out.first_choice = found->second.choice;
    } else {
      out = cut_short(start, trials_end_);
    }
    return with_counters(out);
  }

  // Forgets every state solved or refined; the trials draw from `seed` on.
  void clear(std::uint64_t seed) {
    table_.clear();
    lower_.clear();
    solved_ = 0;
    generator_ = SplitMix64(seed);
  }
  // Records held, what the cap counts: a state solved or refined is one, a lower end kept by the
  // trials another (a smaller one: counting it whole keeps the memory estimate an upper bound).
  std::uint64_t size() const noexcept { return table_.size() + lower_.size(); }

 private:
  // `out` with the cumulative counters.
  SearchSolution with_counters(SearchSolution out) const {
    out.states = solved_;
    out.bounded = bounded_;
    out.tested = tested_;
    out.refined = table_.size() - solved_;
    out.choices_cut = choices_cut_;
    return out;
  }

  struct Item {
    // Sets every field but `key` one by one: value-initialising the whole item first (136 bytes
    // with 16 skeleton slots) costs a block fill per outcome.
    Item(double p, Status s, const Compact& n) : probability(p), status(s), next(n) {}

    double probability;
    Status status;
    Compact next;
    Key key;  // of `next`, when running, from the first look-up on (most outcomes are never looked up)
    // When running: the interval around V*(next) last looked up (lo < 0: not yet), and whether
    // it is the exact value.
    double lo = -1.0, hi = 1.0;
    bool exact = false;
  };
  // One choice of a state on the search's path: its outcomes items_[begin, end) and the interval
  // around its value (lo == hi once solved).
  struct Choice {
    int choice = -1;
    std::size_t begin = 0, end = 0;
    double lo = 0, hi = 0;
    bool exact = false;
    bool tested = false;  // an upper test against the best so far was tried
  };
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  // A state on a trial's path: its key and its choices choices_[choice_begin, choice_end), whose
  // outcomes start at items_[item_begin].
  struct TrialLevel {
    Compact state;
    Key key;
    std::size_t item_begin = 0, choice_begin = 0, choice_end = 0;
  };

  // (solve, solve_choice, prove_below and test recurse one level per step of CT, at most D deep:
  // solve_search gives deep deadlines a stack of their own. An explicit stack would hold the same
  // frames with far less clear code.)
  // NOLINTNEXTLINE(misc-no-recursion)
  detail::ExpectimaxEntry solve(const Compact& state, const Key& key) {
    if (const auto found = table_.find(key); found != table_.end() && found->second.exact) {
      return {found->second.value, found->second.choice};
    }
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
    // (erase, not resize: an Item has no default.)
    items_.erase(items_.begin() + static_cast<std::ptrdiff_t>(item_begin), items_.end());
    choices_.resize(choice_begin);

    check_cap();
    table_.insert_or_assign(key, Entry{entry.value, -1.0F, static_cast<std::int16_t>(entry.choice), true});
    ++solved_;
    count_work();
    return entry;
  }

  // One trial (see trials()); false when the trials should end.
  // Sets trials_end_ to what ended them.
  bool trial(const Compact& start, const Key& start_key, const std::function<bool(std::uint64_t)>& stop,
             std::uint64_t check_interval, double gap) {
    path_.clear();
    Compact state = start;
    Key key = start_key;
    double start_gap = -1.0;
    bool go_on = true;
    for (;;) {
      if (const auto found = table_.find(key); found != table_.end() && found->second.exact) {
        go_on = !path_.empty();  // the start solved: nothing left to narrow
        break;
      }
      if (max_states_ != 0 && size() >= max_states_ && !table_.contains(key)) {
        trials_end_ = "the cap of " + std::to_string(max_states_) + " states";
        go_on = false;
        break;
      }
      TrialLevel level{state, key, items_.size(), choices_.size(), 0};
      expand(state);
      level.choice_end = choices_.size();
      path_.push_back(level);
      const auto [lo, hi] = back_up(path_.back());
      ++work_;
      const std::uint64_t done = work_ - work_start_;
      if (stop && (done == 1 || done % check_interval == 0) && stop(done)) {
        trials_end_ = "the stop condition";
        go_on = false;
      }
      if (start_gap < 0.0) {
        start_gap = hi - lo;
        if (start_gap <= gap) {
          trials_end_ = "the gap";
          go_on = false;
        }
      }
      if (!go_on) break;
      // The choice of the largest upper end (the lowest index on ties), then one of its outcomes
      // drawn in proportion to probability times gap. (Always the largest would walk the same
      // path again and again where the backups no longer move its bounds.)
      std::size_t choice = kNone;
      for (std::size_t c = path_.back().choice_begin; c < path_.back().choice_end; ++c) {
        if (choice == kNone || choices_[c].hi > choices_[choice].hi) choice = c;
      }
      double mass = 0.0;
      for (std::size_t i = choices_[choice].begin; i < choices_[choice].end; ++i) {
        const Item& item = items_[i];
        if (item.status == Status::running && !item.exact) mass += item.probability * std::max(0.0, item.hi - item.lo);
      }
      if (mass <= start_gap / kTrialRatio) break;
      double draw = uniform01(generator_) * mass;
      std::size_t next = kNone;
      for (std::size_t i = choices_[choice].begin; i < choices_[choice].end; ++i) {
        const Item& item = items_[i];
        if (item.status != Status::running || item.exact) continue;
        const double weight = item.probability * std::max(0.0, item.hi - item.lo);
        if (weight <= 0.0) continue;
        next = i;
        draw -= weight;
        if (draw < 0.0) break;
      }
      if (next == kNone) break;
      state = items_[next].next;
      key = items_[next].key;
    }
    // Deepest first; the deepest level was just backed up.
    for (std::size_t level = path_.size(); level-- > 1;) {
      (void)back_up(path_[level - 1]);
    }
    if (!path_.empty()) {
      items_.erase(items_.begin() + static_cast<std::ptrdiff_t>(path_.front().item_begin), items_.end());
      choices_.resize(path_.front().choice_begin);
    }
    return go_on;
  }

  // Bounds a trial level's choices from what the table and the trials hold, and keeps the
  // state's interval: its upper end in the table (as an upper test does), its lower end in
  // lower_. A state without choices is solved (0, as solve() would find).
  std::pair<double, double> back_up(const TrialLevel& level) {
    const Key& key = level.key;
    if (level.choice_begin == level.choice_end) {
      table_.insert_or_assign(key, Entry{0.0, -1.0F, -1, true});
      ++solved_;
      return {0.0, 0.0};
    }
    double lo = 0.0;
    double hi = 0.0;
    for (std::size_t c = level.choice_begin; c < level.choice_end; ++c) {
      key_and_prefetch(c);
      for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
        Item& item = items_[i];
        if (item.status != Status::running || item.exact) continue;
        look_up(item, true);
      }
      sum_up(c, true);
      lo = std::max(lo, choices_[c].lo);
      hi = std::max(hi, choices_[c].hi);
    }
    lo = std::max(0.0, lo - OptimalSolver::kTieTolerance);
    // Never above what was known: the state's own bounds can be tighter than one step of
    // lookahead over its successors' (the clairvoyant bound of a state is not the largest of its
    // choices' sums of their successors' bounds).
    Entry& entry = table_.try_emplace(key, Entry{static_upper(level.state), -1.0F, -1, false}).first->second;
    if (!entry.exact) entry.value = std::min(entry.value, hi);
    double& held = lower_.try_emplace(key, std::max(0.0, bounds_->lower(level.state) - kBoundSlack)).first->second;
    held = std::max(held, lo);
    return {held, entry.exact ? entry.value : std::min(entry.value, 1.0)};
  }

  // Throws CutShort when the cap's records are held (what memory holds).
  void check_cap() const {
    if (max_states_ != 0 && size() >= max_states_) {
      throw CutShort{"the cap of " + std::to_string(max_states_) + " states"};
    }
  }

  // One unit of work done: throws CutShort when the stop condition says so.
  void count_work() {
    ++work_;
    const std::uint64_t done = work_ - work_start_;
    if (stop_ != nullptr && *stop_ && (done == 1 || done % check_interval_ == 0) && (*stop_)(done)) {
      throw CutShort{"the stop condition"};
    }
  }

  // Pushes every useful choice of `state` and its outcomes (in the MDP's order) on the stacks.
  void expand(const Compact& state) {
    choice_list_.clear();
    policy_.choices(state, choice_list_);
    for (const int choice : choice_list_) {
      Choice entry{choice, items_.size(), 0};
      mdp_->for_each_outcome(state, choice, [&](double probability, Status status, const Compact& next) {
        // Written in place: an Item built aside and copied in costs a store-forwarding stall on
        // every outcome (the copy reads back words of the temporary just written in parts).
        items_.emplace_back(probability, status, next);
      });
      entry.end = items_.size();
      choices_.push_back(entry);
    }
  }

  // Looks up the interval around V*(next) of running item i: the exact value where the memo has
  // it; else the upper test's refined bound or ValueBounds' upper end, and (with `lower`)
  // ValueBounds' lower end, each widened by kBoundSlack.
  void look_up(Item& item, bool lower) {
    const auto found = table_.find(item.key);
    if (found != table_.end() && found->second.exact) {
      item.lo = item.hi = found->second.value;
      item.exact = true;
      return;
    }
    ++bounded_;
    item.hi = found != table_.end() ? found->second.value : static_upper(item.next);
    if (!lower) return;
    if (item.lo < 0.0) item.lo = std::max(0.0, bounds_->lower(item.next) - kBoundSlack);
    if (!lower_.empty()) {
      if (const auto held = lower_.find(item.key); held != lower_.end()) item.lo = std::max(item.lo, held->second);
    }
  }

  // Choice c's interval from its items' (`lower`: both ends, else the upper end only). Summed in
  // the exact value's order, so that each end is on its side of the exact sum after rounding too.
  void sum_up(std::size_t c, bool lower) {
    double lo = 0.0;
    double hi = 0.0;
    for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
      const Item& item = items_[i];
      if (item.status == Status::success) {
        const double reward = item.probability * success_reward(item.next, choices_[c].choice);
        lo += reward;
        hi += reward;
      } else if (item.status == Status::running) {
        if (lower) lo += item.probability * item.lo;
        hi += item.probability * item.hi;
      }
    }
    if (lower) choices_[c].lo = lo;
    choices_[c].hi = hi;
  }

  // Choice c's upper end from ValueBounds alone (no probe of the table, whose entries are never
  // above it): sets choices_[c].hi and the running items' hi, and returns the sum.
  double static_sum(std::size_t c) {
    for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
      if (items_[i].status == Status::running) items_[i].hi = static_upper(items_[i].next);
    }
    sum_up(c, false);
    return choices_[c].hi;
  }

  // Packs the keys of choice c's running successors and prefetches their places in the table.
  void key_and_prefetch(std::size_t c) {
    for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
      Item& item = items_[i];
      if (item.status != Status::running || item.exact) continue;
      item.key = policy_.key(item.next);
      table_.prefetch(item.key);
    }
  }

  // Looks up choice c's successors and sums its interval. The table is far larger than the
  // caches: every lookup is prefetched first.
  void bound(std::size_t c, bool lower = true) {
    key_and_prefetch(c);
    for (std::size_t i = choices_[c].begin; i < choices_[c].end; ++i) {
      if (items_[i].status == Status::running && !items_[i].exact) look_up(items_[i], lower);
    }
    sum_up(c, lower);
  }

  // R of a success (SPEC §8); with chains or expiry (SPEC §9) from the plans' tables, as the
  // memoised solver takes it.
  double success_reward(const Compact& state, int choice) {
    if constexpr (kHoldsChains<Compact>) {
      if (mdp_->is_timed()) return plans_.reward(*mdp_, state, choice);
    }
    return mdp_->success_reward(state, choice);
  }

  // ValueBounds' upper bound on V*(next), widened by kBoundSlack.
  double static_upper(const Compact& next) const {
    return std::min(mdp_->problem().max_reward(), bounds_->upper(next) + kBoundSlack);
  }

  // Tries to bring choice c's upper end to `threshold` or below by upper tests of its running
  // successors: each is asked for a share of the excess in proportion to its gap (probability
  // times the width of its interval); its upper end is then summed again.
  void prove_below(std::size_t c, double threshold) {  // NOLINT(misc-no-recursion): see solve
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
  // state's bound is kept (table_).
  double test(const Compact& state, const Key& key, double target) {  // NOLINT(misc-no-recursion): see solve
    const auto found = table_.find(key);
    if (found != table_.end() && found->second.exact) return found->second.value;
    const double known = found != table_.end() ? found->second.value : static_upper(state);
    if (known <= target || target < 0.0) return known;
    if (found != table_.end() && target <= found->second.failed_at) return known;
    const bool held = found != table_.end();
    const std::size_t item_begin = items_.size();
    const std::size_t choice_begin = choices_.size();
    expand(state);
    const std::size_t choice_end = choices_.size();
    double result = 0.0;
    bool failed = false;
    for (std::size_t c = choice_begin; c < choice_end; ++c) {
      // A choice that ValueBounds alone keeps at or below the target needs no look-up.
      if (static_sum(c) <= target) {
        result = std::max(result, choices_[c].hi);
        continue;
      }
      bound(c, false);
      if (!failed && choices_[c].hi > target) {
        prove_below(c, target);
        failed = choices_[c].hi > target;
      }
      result = std::max(result, choices_[c].hi);
    }
    ++tested_;
    items_.erase(items_.begin() + static_cast<std::ptrdiff_t>(item_begin), items_.end());
    choices_.resize(choice_begin);
    result = std::min(result, known);
    if (!held) check_cap();
    // (Looked up again: the recursion may have moved the table's slots.)
    Entry& refined = table_.try_emplace(key, Entry{1.0, -1.0F, -1, false}).first->second;
    refined.value = result;
    if (result > target) {
      // Rounded up, so that a test to the same target is not run again.
      auto missed = static_cast<float>(target);
      if (static_cast<double>(missed) < target) missed = std::nextafter(missed, 2.0F);
      refined.failed_at = std::max(refined.failed_at, missed);
    }
    count_work();
    return result;
  }

  // Solves choice c exactly: the memoised solver's sum, in its order.
  void solve_choice(std::size_t c) {  // NOLINT(misc-no-recursion): see solve
    double value = 0.0;
    const std::size_t begin = choices_[c].begin;
    const std::size_t end = choices_[c].end;
    for (std::size_t i = begin; i < end; ++i) {
      const double probability = items_[i].probability;
      if (items_[i].status == Status::success) {
        value += probability * success_reward(items_[i].next, choices_[c].choice);
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
  // answer, kNone when there is no choice). `threshold` (at most 1): the target of an upper test
  // the choice should get first, where one may settle it without solving it. The verdicts come
  // from the replay on intervals alone (docs/theory.md, "Branch and bound"); the targets only
  // steer the work.
  std::size_t pick(std::size_t begin, std::size_t end, std::size_t& best, double& threshold) const {
    best = kNone;
    threshold = 2.0;
    if (begin == end) return kNone;
    bool any_exact = false;
    std::size_t first = begin;
    for (std::size_t c = begin; c < end; ++c) {
      any_exact = any_exact || choices_[c].exact;
      if (choices_[c].lo > choices_[first].lo) first = c;
    }
    if (!any_exact) return first;  // the largest lower end
    // A choice whose lower end passes every earlier choice's upper end by more than the tolerance
    // is the record at its place, whatever the earlier comparisons decide: the replay starts at
    // the last such choice (the earlier ones need not be settled among themselves).
    std::size_t from = begin;
    double earlier_hi = -1.0;
    std::size_t best_exact = kNone;  // the exact choice of the largest value (the first on ties)
    for (std::size_t c = begin; c < end; ++c) {
      if (choices_[c].exact && (best_exact == kNone || choices_[c].lo > choices_[best_exact].lo)) best_exact = c;
      if (choices_[c].lo > earlier_hi + OptimalSolver::kTieTolerance) from = c;
      earlier_hi = std::max(earlier_hi, choices_[c].hi);
    }
    // The exact solver's replay: the best so far starts below every value.
    double best_lo = -1.0;
    double best_hi = -1.0;
    std::size_t record = kNone;
    for (std::size_t c = from; c < end; ++c) {
      const Choice& choice = choices_[c];
      if (choice.lo > best_hi + OptimalSolver::kTieTolerance) {
        record = c;
        best_lo = choice.lo;
        best_hi = choice.hi;
      } else if (choice.hi > best_lo + OptimalSolver::kTieTolerance) {
        // Unsettled (both cannot be exact here). Against an exact record, test the choice.
        if (choices_[record].exact) {
          threshold = best_lo + OptimalSolver::kTieTolerance;
          return c;
        }
        // Else first test the two against the best exact choice: one before it that stays below
        // its value by more than the tolerance cannot be the record there or after it; one after
        // it that stays at or below its value never passes a record (the record there is at least
        // that value less the tolerance).
        if (best_exact != kNone) {
          for (const std::size_t x : {record, c}) {
            if (choices_[x].exact || choices_[x].tested) continue;
            const double target =
                x < best_exact ? choices_[best_exact].lo - 2.0 * OptimalSolver::kTieTolerance : choices_[best_exact].lo;
            if (choices_[x].lo <= target) {
              threshold = target;
              return x;
            }
          }
        }
        // Else solve the more promising of the two not solved.
        if (choice.exact) return record;
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
  std::uint64_t max_states_;
  const std::function<bool(std::uint64_t)>* stop_ = nullptr;
  std::uint64_t check_interval_ = 1;
  std::uint64_t work_ = 0, work_start_ = 0;
  std::vector<Item> items_;
  std::vector<Choice> choices_;
  std::vector<int> choice_list_;
  std::vector<TrialLevel> path_;
  std::string trials_end_;
  SplitMix64 generator_{kDefaultTrialSeed};
  // Lower ends backed up by trials (certified: at most the exact solver's value of the state).
  absl::flat_hash_map<Key, double, Hash> lower_;
  // One table for the states solved (exact) and those whose upper bound an upper test refined
  // (value: that bound), so that a successor costs one probe. failed_at: the highest target a
  // test of the state missed; a test to that target or below is not run again (it would most
  // likely miss again; where the bounds below have moved since, the exact solve that follows a
  // miss is only slower). A float: it only steers the search.
  struct Entry {
    double value;
    float failed_at;
    std::int16_t choice;
    bool exact;
  };
  absl::flat_hash_map<Key, Entry, Hash> table_;
  std::uint64_t solved_ = 0;
  std::uint64_t tested_ = 0;
  std::uint64_t bounded_ = 0;
  std::uint64_t choices_cut_ = 0;
  detail::PlanValues plans_;  // with chains or expiry: the successes' rewards
};

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
  pthread_t thread{};
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

using Engine = std::variant<BranchAndBound<detail::OptimalPolicy<2>>, BranchAndBound<detail::OptimalPolicy<4>>,
                            BranchAndBound<detail::OptimalPolicy<0>>, BranchAndBound<detail::OptimalBacktrackPolicy>,
                            BranchAndBound<detail::OptimalTimedPolicy>>;

Engine make_engine(const Mdp& mdp, const ValueBounds& bounds, std::uint64_t max_states) {
  if (mdp.is_timed()) {
    return BranchAndBound<detail::OptimalTimedPolicy>(mdp, detail::OptimalTimedPolicy(mdp), bounds, max_states);
  }
  if (mdp.has_backtracking()) {
    return BranchAndBound<detail::OptimalBacktrackPolicy>(mdp, detail::OptimalBacktrackPolicy(mdp), bounds, max_states);
  }
  switch (detail::packed_words(mdp)) {
    case 2:
      return BranchAndBound<detail::OptimalPolicy<2>>(mdp, detail::OptimalPolicy<2>(mdp), bounds, max_states);
    case 4:
      return BranchAndBound<detail::OptimalPolicy<4>>(mdp, detail::OptimalPolicy<4>(mdp), bounds, max_states);
    default:
      return BranchAndBound<detail::OptimalPolicy<0>>(mdp, detail::OptimalPolicy<0>(mdp), bounds, max_states);
  }
}

}  // namespace

struct BranchAndBoundSearch::Impl {
  Impl(const Mdp& mdp, std::uint64_t max_states)
      : bounds(mdp), engine(make_engine(mdp, bounds, max_states)), deadline(mdp.deadline()) {}
  ValueBounds bounds;
  Engine engine;
  Steps deadline;

  SearchSolution run(const State& from, const std::function<bool(std::uint64_t)>& stop, std::uint64_t check_interval) {
    SearchSolution solution;
    const auto work = [&] {
      solution = std::visit([&](auto& search) { return search.run(from, stop, check_interval); }, engine);
    };
    // Shallow searches run on the caller's stack; deeper ones on a stack of their own.
    const std::size_t stack = static_cast<std::size_t>(deadline) * kStackPerStep;
    if (stack <= kInlineStack) {
      work();
    } else {
      run_on_own_stack(kStackBase + stack, work);
    }
    return solution;
  }
};

BranchAndBoundSearch::BranchAndBoundSearch(const Mdp& mdp, std::uint64_t max_states) {
  detail::require_exact_size(mdp, "search");
  impl_ = std::make_unique<Impl>(mdp, max_states);
}
BranchAndBoundSearch::~BranchAndBoundSearch() = default;
BranchAndBoundSearch::BranchAndBoundSearch(BranchAndBoundSearch&&) noexcept = default;
BranchAndBoundSearch& BranchAndBoundSearch::operator=(BranchAndBoundSearch&&) noexcept = default;

SearchSolution BranchAndBoundSearch::search(const State& from, const std::function<bool(std::uint64_t)>& stop,
                                            std::uint64_t check_interval) {
  return impl_->run(from, stop, std::max<std::uint64_t>(check_interval, 1));
}

SearchSolution BranchAndBoundSearch::trials(const State& from, const std::function<bool(std::uint64_t)>& stop,
                                            std::uint64_t check_interval, double gap) {
  // (Trials walk down a path without recursion: the caller's stack suffices.)
  return std::visit(
      [&](auto& search) { return search.trials(from, stop, std::max<std::uint64_t>(check_interval, 1), gap); },
      impl_->engine);
}

void BranchAndBoundSearch::clear(std::uint64_t seed) {
  std::visit([seed](auto& search) { search.clear(seed); }, impl_->engine);
}

// (std::visit throws only for a valueless variant, which the engine, never reassigned, cannot be.)
// NOLINTNEXTLINE(bugprone-exception-escape)
std::uint64_t BranchAndBoundSearch::size() const noexcept {
  return std::visit([](const auto& search) { return search.size(); }, impl_->engine);
}

SearchSolution solve_search(const Mdp& mdp, const SearchSolveOptions& options) {
  if (!(options.gap == 0.0 || (options.gap >= SearchSolveOptions::kFinestGap && options.gap <= 1.0))) {
    throw UsageError("gap: 0 for the exact search, or between " + fmt::format("{:g}", SearchSolveOptions::kFinestGap) +
                     " (the finest interval the trials certify) and 1 (got " + fmt::format("{:g}", options.gap) + ")");
  }
  BranchAndBoundSearch search(mdp, options.max_states);
  std::function<bool(std::uint64_t)> stop;
  if (options.stop) stop = [&options](std::uint64_t) { return options.stop(); };
  if (options.gap > 0.0) return search.trials(mdp.start(), stop, kStopCheckInterval, options.gap);
  return search.search(mdp.start(), stop, kStopCheckInterval);
}

}  // namespace ontime
