#pragma once
// Internal: memoised expectimax over the reachable states of the MDP, without recursion.
//
// V(s) = max over c in choices(s) of  sum_o P(o | s, c) * ([o is success] + [o running] V(o)),
// 0 when there is no choice. `optimal` maximises over every useful choice; exact evaluation
// passes the one choice an allocator makes. Time only grows along a path, so the reachable
// states form a DAG of depth at most D; an explicit stack keeps deep deadlines off the call
// stack, and one item buffer used as a stack avoids allocation per state.

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "ontime/error.hpp"
#include "ontime/mdp.hpp"

namespace ontime::detail {

struct ExpectimaxEntry {
  double value;
  int choice;  // the maximising choice, -1 when there was none
};

// Policy provides:
//   void choices(const State&, std::vector<int>& out) const;  // in increasing preference on ties
//   State key(const State&) const;                            // states with one key share a value
template <class Policy>
class Expectimax {
 public:
  using Memo = std::unordered_map<State, ExpectimaxEntry, StateHash>;

  Expectimax(const Mdp& mdp, Policy policy, std::size_t max_states, double tie_tolerance, std::string what)
      : mdp_(&mdp), policy_(std::move(policy)), max_states_(max_states), tie_tolerance_(tie_tolerance),
        what_(std::move(what)) {}

  const ExpectimaxEntry& solve(const State& start) {
    if (const auto found = memo_.find(policy_.key(start)); found != memo_.end()) return found->second;
    push(start);
    while (!frames_.empty()) {
      const std::size_t top = frames_.size() - 1;
      bool descended = false;
      while (frames_[top].cursor < frames_[top].end) {
        const Item& item = items_[frames_[top].cursor++];
        if (item.status == Status::running && !memo_.contains(policy_.key(item.next))) {
          const State next = item.next;
          push(next);
          descended = true;
          break;
        }
      }
      if (descended) continue;
      finish(top);
    }
    return memo_.at(policy_.key(start));
  }

  const Memo& memo() const noexcept { return memo_; }
  const Policy& policy() const noexcept { return policy_; }

 private:
  struct Item {
    int choice;
    Status status;
    double probability;
    State next;
  };
  struct Frame {
    State key;
    std::size_t begin, end, cursor;
  };

  void push(const State& state) {
    Frame frame{policy_.key(state), items_.size(), 0, items_.size()};
    choices_.clear();
    policy_.choices(state, choices_);
    for (const int choice : choices_) {
      mdp_->for_each_outcome(state, choice, [&](double probability, Status status, const State& next) {
        items_.push_back(Item{choice, status, probability, next});
      });
    }
    frame.end = items_.size();
    frames_.push_back(frame);
  }

  void finish(std::size_t top) {
    const Frame frame = frames_[top];
    ExpectimaxEntry best{0.0, -1};
    double best_value = -1.0;
    for (std::size_t i = frame.begin; i < frame.end;) {
      const int choice = items_[i].choice;
      double value = 0;
      for (; i < frame.end && items_[i].choice == choice; ++i) {
        const Item& item = items_[i];
        if (item.status == Status::success) {
          value += item.probability;
        } else if (item.status == Status::running) {
          value += item.probability * memo_.at(policy_.key(item.next)).value;
        }
      }
      if (value > best_value + tie_tolerance_) {
        best_value = value;
        best = {value, choice};
      }
    }
    if (memo_.size() >= max_states_) {
      throw ResourceLimitError(what_ + ": reached the cap of " + std::to_string(max_states_) +
                               " states before finishing (about " +
                               std::to_string((memo_.size() * kBytesPerState) >> 20) +
                               " MiB held); raise the cap (--max-states) or use an approximate allocator");
    }
    memo_.emplace(frame.key, best);
    items_.resize(frame.begin);
    frames_.pop_back();
  }

 public:
  // Approximate memory per memoised state: key, entry, hash-node overhead.
  static constexpr std::size_t kBytesPerState = sizeof(State) + sizeof(ExpectimaxEntry) + 32;

 private:
  const Mdp* mdp_;
  Policy policy_;
  std::size_t max_states_;
  double tie_tolerance_;
  std::string what_;
  Memo memo_;
  std::vector<Frame> frames_;
  std::vector<Item> items_;
  std::vector<int> choices_;
};

}  // namespace ontime::detail
