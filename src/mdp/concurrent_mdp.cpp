#include "ontime/mdp/concurrent_mdp.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

namespace ontime {
ConcurrentMdp::ConcurrentMdp(const Problem& problem, HopelessSkeletons hopeless)
    : problem_(std::make_unique<const Problem>(problem.with_acting(Acting::plan_first))),
      mdp_(*problem_),
      deadline_(problem.deadline()),
      skeleton_count_(problem.skeleton_count()),
      action_count_(problem.action_count()),
      backtracking_(problem.has_backtracking()),
      keeps_hopeless_(backtracking_ || hopeless == HopelessSkeletons::kept),
      culprit_(static_cast<std::size_t>(problem.action_count()), 0),
      timed_(problem.is_timed()) {
  for (int a = 0; a < action_count_; ++a) {
    for (const Problem::CulpritIndex& culprit : problem_->culprits(a)) {
      if (culprit.probability > 0) culprit_[static_cast<std::size_t>(culprit.action)] = 1;
    }
  }
  const auto deadline = static_cast<std::size_t>(deadline_);
  next_finish_.assign(static_cast<std::size_t>(action_count_) * (deadline + 1), kNever);
  fastest_execution_.assign(static_cast<std::size_t>(action_count_), kNever);
  for (int a = 0; a < action_count_; ++a) {
    const auto row = static_cast<std::size_t>(a) * (deadline + 1);
    // Planning steps past D cannot finish within the deadline: only steps up to D count.
    Steps next_positive = kNever;
    for (Steps pt = deadline_; pt >= 0; --pt) {
      next_finish_[row + static_cast<std::size_t>(pt)] = next_positive == kNever ? kNever : next_positive - pt;
      if (pt >= 1 && problem_->action(a).planning.pmf(pt) > 0) next_positive = pt;
    }
    Steps& fastest = fastest_execution_[static_cast<std::size_t>(a)];
    if (problem_->execution_chain(a) >= 0) {
      // Drawn when it starts, from the chain's state then: the fastest over every state.
      for (const Distribution& drawn : problem_->action(a).execution_by_state) {
        for (Steps x = 0; x <= deadline_ && x < fastest; ++x) {
          if (drawn.pmf(x) > 0) fastest = x;
        }
      }
      continue;
    }
    for (const Mdp::ExecutionOutcome& outcome : mdp_.execution_outcomes(a)) {
      if (outcome.steps <= deadline_ && outcome.probability > 0) fastest = std::min(fastest, outcome.steps);
    }
  }
}

ConcurrentMdp::~ConcurrentMdp() = default;

ConcurrentState ConcurrentMdp::start() const {
  ConcurrentState state(
      kHeader + 2 * static_cast<std::size_t>(skeleton_count_) + static_cast<std::size_t>(action_count_), 0);
  for (int a = 0; a < action_count_; ++a) execution_word(state, a) = kUnknown;
  state[3] = mdp_.start().chains;
  canonicalise(state);
  return state;
}

bool ConcurrentMdp::any_live(const ConcurrentState& state) const noexcept {
  for (int k = 0; k < skeleton_count_; ++k) {
    // Unless hopeless skeletons are kept, a live skeleton can finish (canonicalise drops the others).
    if (is_live(state, k) && (!keeps_hopeless_ || can_finish(state, k))) return true;
  }
  return false;
}

int ConcurrentMdp::executed_depth(const ConcurrentState& state) const noexcept {
  const int last = executed(state);
  return last < 0 ? 0 : problem_->position(last) + 1;
}

std::int64_t ConcurrentMdp::robot_free(const ConcurrentState& state, int k) const noexcept {
  std::int64_t free = std::int64_t{time(state)} + robot_left(state);
  for (int j = executed_depth(state); j < refined(state, k); ++j)
    free += known_execution(state, problem_->action_at(k, j));
  return free;
}

bool ConcurrentMdp::through_executed(const ConcurrentState& state, int k) const noexcept {
  const int last = executed(state);
  if (last < 0) return true;
  const auto members = problem_->members(last);
  return std::binary_search(members.begin(), members.end(), k);
}

std::int64_t ConcurrentMdp::earliest_finish(const ConcurrentState& state, int k) const noexcept {
  const auto stride = static_cast<std::size_t>(deadline_) + 1;
  const int length = problem_->skeleton_length(k);
  const int refined_count = refined(state, k);
  std::int64_t robot_free = std::int64_t{time(state)} + robot_left(state);
  std::int64_t planned = time(state);  // the planner, on k alone
  // With backtracking: at or below a culprit, so that a give-up may discard the motion (a culprit
  // executed too: SPEC §10 discards what was refined below it and not started).
  bool discardable = false;
  for (int j = 0; backtracking_ && j < executed_depth(state); ++j) {
    discardable = discardable || culprit_[static_cast<std::size_t>(problem_->action_at(k, j))] != 0;
  }
  const auto planning_from = [&](int action, Steps pt) {
    return pt > deadline_ ? kNever
                          : next_finish_[static_cast<std::size_t>(action) * stride + static_cast<std::size_t>(pt)];
  };
  for (int j = executed_depth(state); j < length; ++j) {
    const int action = problem_->action_at(k, j);
    const Steps fastest = fastest_execution_[static_cast<std::size_t>(action)];
    discardable = discardable || (backtracking_ && culprit_[static_cast<std::size_t>(action)] != 0);
    if (j < refined_count) {
      // Refined: it can start as soon as the robot is free (found again, no sooner than now).
      if (!before_expiry(action, robot_free)) return Mdp::kUnreachableNeed;
      if (!discardable) {
        robot_free += known_execution(state, action);
      } else if (fastest == kNever) {
        return Mdp::kUnreachableNeed;
      } else {
        robot_free += std::min<std::int64_t>(known_execution(state, action), fastest);
      }
      continue;
    }
    Steps planning = planning_from(action, j == refined_count ? spent(state, k) : 0);
    // With backtracking the attempt may give up (or be discarded) and start again from 0.
    if (backtracking_ && j == refined_count) planning = std::min(planning, planning_from(action, 0));
    if (planning == kNever || fastest == kNever) return Mdp::kUnreachableNeed;
    planned += planning;
    robot_free = std::max(robot_free, planned);
    if (!before_expiry(action, robot_free)) return Mdp::kUnreachableNeed;
    robot_free += fastest;
  }
  return robot_free;
}

void ConcurrentMdp::canonicalise(ConcurrentState& state) const {
  const int depth = executed_depth(state);
  for (int k = 0; k < skeleton_count_; ++k) {
    if (!is_live(state, k)) continue;
    // With backtracking a skeleton that cannot finish now may again (class comment): it is kept,
    // as every one is where HopelessSkeletons::kept asks for it.
    if (!through_executed(state, k) || problem_->skeleton_length(k) <= depth ||
        (!keeps_hopeless_ && earliest_finish(state, k) > deadline_)) {
      refined_word(state, k) = kDropped;
      spent_word(state, k) = 0;
    }
  }
  for (int a = 0; a < action_count_; ++a) {
    if (execution(state, a) == kUnknown) continue;
    const int position = problem_->position(a);
    bool runs = false;
    if (position >= depth) {
      for (const int k : problem_->members(a)) {
        if (is_live(state, k) && position < refined(state, k)) {
          runs = true;
          break;
        }
      }
    }
    if (!runs) execution_word(state, a) = kUnknown;
  }
}

std::vector<int> ConcurrentMdp::startable(const ConcurrentState& state) const {
  std::vector<int> children;
  if (robot_left(state) > 0) return children;
  const int depth = executed_depth(state);
  for (int k = 0; k < skeleton_count_; ++k) {
    if (!is_live(state, k) || refined(state, k) <= depth) continue;
    const int child = problem_->action_at(k, depth);
    if (timed_ && !may_start_now(state, child)) continue;
    if (std::find(children.begin(), children.end(), child) == children.end()) children.push_back(child);
  }
  std::sort(children.begin(), children.end());
  return children;
}

int ConcurrentMdp::forced_start(const ConcurrentState& state) const noexcept {
  if (backtracking_ || timed_ || robot_left(state) > 0) return -1;
  const int depth = executed_depth(state);
  int child = -1;
  for (int k = 0; k < skeleton_count_; ++k) {
    if (!is_live(state, k)) continue;
    if (refined(state, k) <= depth) return -1;  // a live skeleton whose next execution is not refined yet
    const int next = problem_->action_at(k, depth);
    if (child >= 0 && next != child) return -1;
    child = next;
  }
  return child;
}

std::vector<ConcurrentMdp::Move> ConcurrentMdp::useful_moves(const ConcurrentState& state) const {
  std::vector<Move> moves;
  if (!any_live(state)) return moves;
  if (const int forced = forced_start(state); forced >= 0) {
    moves.push_back({forced, kWait});
    return moves;
  }
  if (time(state) < deadline_) {
    const ChoiceList choices = refine_choices(state);
    for (const int choice : choices) moves.push_back({-1, choice});
    // With backtracking an attempt may discard motions: an idle planner is a move of its own.
    if (choices.empty() || backtracking_) moves.push_back({-1, kWait});
  }
  for (const int action : startable(state)) moves.push_back({action, kWait});
  return moves;
}

bool ConcurrentMdp::may_start_now(const ConcurrentState& state, int action) const noexcept {
  const Action& model = problem_->action(action);
  if (model.start_by != kNever && time(state) > model.start_by) return false;
  const int blocking = problem_->blocking_chain(action);
  return blocking < 0 || !problem_->blocks(action, mdp_.chain_state(chains(state), blocking));
}

ConcurrentMdp::StartOutcome ConcurrentMdp::start_action(const ConcurrentState& state, int action, Steps drawn) const {
  const std::vector<int> children = startable(state);
  if (!std::binary_search(children.begin(), children.end(), action)) {
    if (timed_ && action >= 0 && action < action_count_ && !may_start_now(state, action)) {
      throw UsageError("action " + problem_->action(action).id +
                       " cannot be started now: it expires (SPEC §9), past its step `after` or while its chain is in a "
                       "blocking state");
    }
    throw UsageError("action " + std::to_string(action) +
                     " cannot be started now: the robot starts a refined action just after what it has executed, "
                     "on a skeleton that can still finish, and only while it is idle");
  }
  StartOutcome outcome;
  std::uint16_t steps = execution(state, action);
  if (steps == kDrawnAtStart) {
    if (drawn < 0) {
      throw UsageError("action " + problem_->action(action).id +
                       ": its execution depends on a chain's state when it starts (SPEC §9); give the time drawn");
    }
    steps = static_cast<std::uint16_t>(std::min<Steps>(drawn, deadline_ + 1));
  }
  const std::int64_t finish = std::int64_t{time(state)} + steps;
  const int position = problem_->position(action);
  for (const int k : problem_->members(action)) {
    if (is_live(state, k) && problem_->skeleton_length(k) == position + 1) {
      // The last action of k: its execution ends the episode (SPEC §10).
      outcome.ends = true;
      if (finish <= deadline_) {
        outcome.reward = problem_->has_rewards() ? problem_->reward_at(k, static_cast<Steps>(finish)) : 1.0;
      }
      return outcome;
    }
  }
  outcome.next = state;
  outcome.next[1] = steps;
  outcome.next[2] = static_cast<std::uint16_t>(action + 1);
  canonicalise(outcome.next);
  return outcome;
}

ChoiceList ConcurrentMdp::refine_choices(const ConcurrentState& state) const {
  // One choice per next action, marked as met in a scratch array (per thread, sized once), so
  // that a wide problem costs O(K), not O(K^2).
  thread_local std::vector<std::uint8_t> met;
  met.assign(static_cast<std::size_t>(action_count_), 0);
  ChoiceList choices;
  for (int k = 0; k < skeleton_count_; ++k) {
    if (!is_live(state, k) || refined(state, k) >= problem_->skeleton_length(k)) continue;
    const auto action = static_cast<std::size_t>(problem_->action_at(k, refined(state, k)));
    if (met[action] != 0) continue;
    met[action] = 1;
    choices.push_back(k);
  }
  return choices;
}

ConcurrentState ConcurrentMdp::step(const ConcurrentState& state, int choice, const Observation& observation) const {
  return step(state, choice, observation,
              ClockReading{.time = time(state) + 1, .robot_left = std::max<Steps>(0, robot_left(state) - 1)});
}

namespace {

std::uint16_t clock_word(Steps value, Steps deadline) {
  return static_cast<std::uint16_t>(std::clamp<Steps>(value, 0, deadline + 1));
}

}  // namespace

std::uint16_t ConcurrentMdp::checked_chains(int joint) const {
  if (joint < 0 || joint >= mdp_.joint_chain_states()) {
    throw UsageError("the chains' joint state " + std::to_string(joint) + " is not one of the " +
                     std::to_string(mdp_.joint_chain_states()) + " states of this problem's chains");
  }
  return static_cast<std::uint16_t>(joint);
}

ConcurrentState ConcurrentMdp::on_clock(const ConcurrentState& state, const ClockReading& clock) const {
  ConcurrentState next = state;
  next[0] = clock_word(std::max(time(state), clock.time), deadline_);
  next[1] = clock_word(clock.robot_left, deadline_);
  if (clock.chains >= 0 && mdp_.has_chains()) next[3] = checked_chains(clock.chains);
  canonicalise(next);
  return next;
}

ConcurrentState ConcurrentMdp::step(const ConcurrentState& state, int choice, const Observation& observation,
                                    const ClockReading& clock) const {
  if (time(state) >= deadline_) {
    throw UsageError("no step is left at the deadline (step " + std::to_string(deadline_) + ")");
  }
  ConcurrentState next = state;
  next[0] = clock_word(std::max(time(state), clock.time), deadline_);
  next[1] = clock_word(clock.robot_left, deadline_);
  // The chains move whatever the step does (SPEC §9).
  if (mdp_.has_chains()) next[3] = checked_chains(observation.chains);
  if (choice == kWait) {
    if (observation.refined || observation.is_backtrack()) {
      throw UsageError("a motion cannot be found, nor an attempt give up, in a step in which the planner idles");
    }
    canonicalise(next);
    return next;
  }
  if (choice < 0 || choice >= skeleton_count_ || !is_live(state, choice) ||
      refined(state, choice) >= problem_->skeleton_length(choice)) {
    reject_choice(choice);
  }
  const int action = problem_->action_at(choice, refined(state, choice));
  if (observation.is_backtrack()) {
    const auto culprits = problem_->culprits(action);
    if (std::none_of(culprits.begin(), culprits.end(),
                     [&](const Problem::CulpritIndex& culprit) { return culprit.action == observation.culprit; })) {
      throw UsageError("action " + problem_->action(action).id + " cannot blame action " +
                       problem_->action(observation.culprit).id + ": not one of its culprits (SPEC §7)");
    }
    give_up(next, state, action, observation.culprit);
    canonicalise(next);
    return next;
  }
  if (observation.refined) {
    const Steps saturated = std::min<Steps>(observation.execution, deadline_ + 1);
    // An execution that depends on a chain is drawn when it starts (SPEC §9): what the world
    // reported for it is not used.
    execution_word(next, action) =
        problem_->execution_chain(action) >= 0 ? kDrawnAtStart : static_cast<std::uint16_t>(saturated);
  }
  // The live skeletons whose next action is `action` share the step (SPEC §1).
  for (const int m : problem_->members(action)) {
    if (!is_live(state, m) || refined(state, m) >= problem_->skeleton_length(m) ||
        problem_->action_at(m, refined(state, m)) != action) {
      continue;
    }
    if (observation.refined) {
      ++refined_word(next, m);
      spent_word(next, m) = 0;
    } else {
      spent_word(next, m) = clock_word(spent(state, m) + 1 + clock.extra_effort, deadline_);
    }
  }
  canonicalise(next);
  return next;
}

ConcurrentState ConcurrentMdp::state_of(Steps time, Steps robot_left, int executed, std::span<const Steps> execution,
                                        std::span<const Steps> effort, std::uint16_t chains) const {
  ConcurrentState state = start();
  state[0] = clock_word(time, deadline_);
  state[1] = clock_word(robot_left, deadline_);
  state[2] = static_cast<std::uint16_t>(executed + 1);
  if (mdp_.has_chains()) state[3] = checked_chains(chains);
  for (int a = 0; a < action_count_; ++a) {
    const Steps known = execution[static_cast<std::size_t>(a)];
    // An execution a chain draws when the action starts is not known before (SPEC §9).
    execution_word(state, a) = known < 0                           ? kUnknown
                               : problem_->execution_chain(a) >= 0 ? kDrawnAtStart
                                                                   : clock_word(known, deadline_);
  }
  for (int k = 0; k < skeleton_count_; ++k) {
    int refined = 0;
    while (refined < problem_->skeleton_length(k) &&
           execution[static_cast<std::size_t>(problem_->action_at(k, refined))] >= 0) {
      ++refined;
    }
    refined_word(state, k) = static_cast<std::uint16_t>(refined);
    spent_word(state, k) =
        refined < problem_->skeleton_length(k)
            ? clock_word(effort[static_cast<std::size_t>(problem_->action_at(k, refined))], deadline_)
            : std::uint16_t{0};
  }
  canonicalise(state);
  return state;
}

ConcurrentState ConcurrentMdp::canonical(const ConcurrentState& state) const {
  ConcurrentState seen = state;
  canonicalise(seen);
  return seen;
}

ConcurrentState ConcurrentMdp::devoted_to(const ConcurrentState& state, int k) const {
  ConcurrentState devoted = state;
  for (int j = 0; j < skeleton_count_; ++j) {
    // A skeleton whose path is a prefix of k's (k runs through its last action) is kept.
    const std::span<const int> along = problem_->members(problem_->skeleton(j).back());
    if (j == k || std::binary_search(along.begin(), along.end(), k)) continue;
    refined_word(devoted, j) = kDropped;
    spent_word(devoted, j) = 0;
  }
  canonicalise(devoted);
  return devoted;
}

ConcurrentState ConcurrentMdp::execution_finished(const ConcurrentState& state) const {
  ConcurrentState next = state;
  next[1] = 0;
  canonicalise(next);
  return next;
}

int ConcurrentMdp::complete_plan(const ConcurrentState& state) const noexcept {
  for (int k = 0; k < skeleton_count_; ++k) {
    // Unless hopeless skeletons are kept, a live skeleton refined in full ends by D (its earliest finish).
    if (is_live(state, k) && refined(state, k) == problem_->skeleton_length(k) &&
        (!keeps_hopeless_ || robot_free(state, k) <= deadline_)) {
      return k;
    }
  }
  return -1;
}

ConcurrentMdp::Move ConcurrentMdp::run_complete_plan(const ConcurrentState& state) const {
  const int k = complete_plan(state);
  if (k < 0 || robot_left(state) > 0) return {};
  const int next = problem_->action_at(k, executed_depth(state));
  // With expiry its chain may block it now (SPEC §9): the planner idles until it may start.
  if (timed_ && !may_start_now(state, next)) return {};
  return {next, kWait};
}

bool ConcurrentMdp::certain_success(const ConcurrentState& state) const noexcept {
  return !problem_->has_rewards() && !timed_ && complete_plan(state) >= 0;
}

void ConcurrentMdp::give_up(ConcurrentState& next, const ConcurrentState& state, int action, int culprit) const {
  const int depth = executed_depth(state);
  const int position = problem_->position(culprit);
  if (position < depth) {
    // The culprit's motion is executed (or executing): it cannot be given up. What was refined
    // below it and not started is discarded as SPEC §7 says (every live skeleton goes back to E,
    // its effort lost), and the action that gave up is blocked with the skeletons through it.
    for (int m = 0; m < skeleton_count_; ++m) {
      if (!is_live(state, m)) continue;
      const bool through_blocked =
          std::binary_search(problem_->members(action).begin(), problem_->members(action).end(), m);
      refined_word(next, m) = through_blocked ? kDropped : static_cast<std::uint16_t>(depth);
      spent_word(next, m) = 0;
    }
    return;
  }
  // SPEC §7: every skeleton through the culprit that refined it goes back to it; canonicalise
  // forgets the executions of the culprit and of what was refined below it.
  for (const int m : problem_->members(culprit)) {
    if (is_live(state, m) && refined(state, m) > position) {
      refined_word(next, m) = static_cast<std::uint16_t>(position);
      spent_word(next, m) = 0;
    }
  }
}

void ConcurrentMdp::reject_choice(int choice) {
  throw UsageError("skeleton " + std::to_string(choice) +
                   " cannot be refined in this state: it is dropped (not through what the robot executed, or unable "
                   "to finish by the deadline) or has nothing left to refine");
}

void ConcurrentMdp::merge_backlogs(ConcurrentState& key) const {
  if (!merges_backlogs()) return;
  const int depth = executed_depth(key);
  int live = 0;
  for (int k = 0; k < skeleton_count_; ++k) live += is_live(key, k) ? 1 : 0;
  const auto runs_alone = [&](int action, int k) {
    for (const int m : problem_->members(action)) {
      if (m != k && is_live(key, m)) return false;
    }
    return true;
  };
  for (int k = 0; k < skeleton_count_; ++k) {
    if (!is_live(key, k)) continue;
    const int refined_count = refined(key, k);
    // The first position after E from which every action of k is k's alone.
    int first = problem_->skeleton_length(k);
    while (first > depth && runs_alone(problem_->action_at(k, first - 1), k)) --first;
    if (first >= refined_count) continue;
    const bool into_robot = live == 1 && robot_left(key) > 0;
    std::uint32_t backlog = into_robot ? key[1] : 0;
    for (int j = first; j < refined_count; ++j) {
      std::uint16_t& word = execution_word(key, problem_->action_at(k, j));
      backlog += word;
      word = 0;
    }
    // A live skeleton's backlog ends by D (canonicalise drops it otherwise): the sum fits a word.
    const auto merged = static_cast<std::uint16_t>(std::min<std::uint32_t>(backlog, deadline_ + 1U));
    (into_robot ? key[1] : execution_word(key, problem_->action_at(k, first))) = merged;
  }
}

}  // namespace ontime
