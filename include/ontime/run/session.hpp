#pragma once
// An online session: the API a caller's own motion planner drives.
//
//   ontime::Session session(mdp, allocator);
//   while (session.status() == ontime::Status::running) {
//     const auto decision = session.choose();        // which skeleton, which action
//     // ... spend one step of real planning effort on decision.action ...
//     if (found) session.report_refined(execution_steps);
//     else       session.report_not_yet();
//   }
//   if (session.status() == ontime::Status::success) execute(session.solution());
//
// The session keeps the MDP state, asks the allocator before every step, and reports
// success (with the skeleton to execute) or failure: the deadline passed, or no skeleton can
// still meet it, so that no more effort is wasted.
//
// Every episode of the library steps through a session: one place computes a step (the action
// to refine, the world's answer or an idle step, the transition, the end of the episode). A
// session made without an allocator takes the caller's choices instead (decide(), checked as
// choose() checks an allocator's): a learner's environment, or a policy of the caller's own.
// carry_out(world) carries out the step just decided against a World (world.hpp): one step of
// effort on its action, or an idle step that never reaches the world (a skeleton with nothing
// left to refine), then its report. The episode runner (episode_runner.hpp) drives allocators
// this way, ppo training (ppo_training.hpp) and the Python environment (ontime.env) their
// learners' choices.
//
// A live session (constructed with a Clock) runs on seconds instead of abstract steps. The
// deadline is D * step_seconds after the session began, and everything the clock sees counts
// against it: the allocator's decision time, the planner's call (a slice of step_seconds, and
// any overrun beyond it), the caller's time between a report and the next decision, and time
// reported with charge_outside(). The MDP state the allocator sees is derived from the seconds
// gone, so every allocator stays valid:
//   CT   = ceil(elapsed / step_seconds)   (a step that overran by more than a slice counts as more)
//   PT_k += max(1, floor(planning seconds / step_seconds)) for an unsuccessful call
//   ET_k += ceil(execution seconds / step_seconds) for a found motion
// (with a tolerance of 1e-9 slices against rounding); an idle step (a skeleton with nothing left
// to refine) holds at least its slice, as in the model. Success needs the refined skeleton's
// execution seconds to fit in the seconds left; failure comes when CT reaches D or no skeleton
// can still succeed. An anytime allocator called without a budget gets decision_share of a
// slice (at most the seconds left). With a manual clock advanced by exactly one slice per call
// and no time elsewhere, a live session makes exactly the MDP's transitions.
//
// Cost: a step of a session that is not live allocates nothing (the state before a transition
// is kept in a reused buffer, and only when an allocator observes it or the clock needs it), but
// for a backtrack, which records the attempts it ends (ActionAttempt::ended). The
// live overhead per step is a few clock reads and one timeline entry (reserved up front).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ontime/allocators/allocator.hpp"
#include "ontime/allocators/decision_budget.hpp"
#include "ontime/mdp/mdp.hpp"
#include "ontime/run/clock.hpp"
#include "ontime/run/live_ledger.hpp"
#include "ontime/run/world.hpp"
#include "ontime/util/error.hpp"

namespace ontime {

struct Decision {
  int skeleton = -1;  // the allocator's (or the caller's) choice
  int action = -1;    // the action to refine now, or -1: the step is spent idle
};

// An attempt of an action that ended before its episode did (backtracking, SPEC §7): after
// `effort` steps, with a motion that a backtrack later discarded (found: a backtrack blamed the
// action or one before it), by giving up and blaming an earlier action itself (backtracked), or
// with neither when a backtrack discarded it (cut off after `effort` steps).
struct EndedAttempt {
  Steps effort = 0;
  bool found = false;
  bool backtracked = false;
  friend bool operator==(const EndedAttempt&, const EndedAttempt&) = default;
};

// What a session saw of one action: its current attempt, the steps of effort its refinement got
// (a live session counts each planner call as the slices it charged to the action, as PT_k does,
// at least one) and whether that refinement found a motion, and the attempts a backtrack ended
// before it. An action never picked has effort 0. Without backtracking an action is refined once
// in an episode, so this is one attempt: found after `effort` steps, or cut off after `effort`
// steps without a motion when the session ended. With backtracking (SPEC §7) an attempt also ends
// when it backtracks, or when a backtrack blames the action or one before it on its path: it then
// joins `ended` (in the order they ended) and a new attempt starts with effort 0
// (online_belief.hpp learns from them all).
struct ActionAttempt {
  ActionAttempt() = default;
  // The current attempt, `effort_steps` steps long, found or not, after the attempts `earlier`. (A
  // constructor rather than an aggregate, so that attempts without backtracking name just these two.)
  ActionAttempt(Steps effort_steps, bool found_motion, std::vector<EndedAttempt> earlier = {})
      : effort(effort_steps), found(found_motion), ended(std::move(earlier)) {}

  Steps effort = 0;
  bool found = false;
  std::vector<EndedAttempt> ended;  // empty without backtracking
  friend bool operator==(const ActionAttempt&, const ActionAttempt&) = default;
};

class Session {
 public:
  // Makes the allocator of a session whose skeletons change: called with the first Mdp and
  // again with every new one (e.g. [&](const Mdp& mdp) { return make_allocator_factory(name,
  // mdp, values)(); }). An empty maker: the caller decides every step (decide()).
  using AllocatorMaker = std::function<std::unique_ptr<Allocator>(const Mdp&)>;

  // Calls allocator.begin_episode(seed). The Mdp and the allocator must outlive the session.
  Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed = 0);
  // A live session on `clock` (which must outlive it); its deadline starts now. Throws
  // UsageError for a decision share outside (0, 1e6].
  Session(const Mdp& mdp, Allocator& allocator, std::uint64_t seed, const Clock& clock, LiveOptions options = {});
  // A session without an allocator: the caller decides every step (decide()). The Mdp must
  // outlive it. `seed` draws the simulated chains (SPEC §9) when the steps are carried out in a
  // World (carry_out): a learner's environment passes each episode's own.
  explicit Session(const Mdp& mdp, std::uint64_t seed = 0);
  // The same live on `clock` (which must outlive it); its deadline starts now. Throws UsageError
  // for a decision share outside (0, 1e6].
  Session(const Mdp& mdp, const Clock& clock, LiveOptions options = {});
  // A session that owns its problem and its allocator, so that skeletons can arrive and leave
  // while it runs (add_skeleton, retire_skeleton); live on `clock` unless it is null.
  Session(Problem problem, AllocatorMaker make_allocator, std::uint64_t seed, const Clock* clock = nullptr,
          LiveOptions options = {});

  Session(Session&&) noexcept = default;
  Session& operator=(Session&&) noexcept = default;
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  ~Session() = default;

  // Asks the allocator for the next step. Throws std::logic_error when the session is over
  // or a decision is still waiting for its report; UsageError when the allocator returns a
  // skeleton index out of range. A live session first brings its state up to the clock: when
  // the deadline passed (or no skeleton can succeed any more) while the caller was away, the
  // session ends as a failure and the decision has skeleton -1.
  Decision choose();
  // The same within `budget` (an anytime allocator's budget for this decision; unset: its own).
  // Both throw std::logic_error for a session without an allocator (use decide()).
  Decision choose(const DecisionBudget& budget);
  // The caller's choice of the next step: skeleton `skeleton`, in a session without an allocator.
  // Checked as choose() checks an allocator's: std::logic_error when the session is over, a
  // decision is still waiting for its report, or the session has an allocator (it decides);
  // UsageError for a skeleton index out of range. A live session first brings its state up to
  // the clock, as choose() does (skeleton -1 when it ended meanwhile).
  Decision decide(int skeleton);

  // Carries out the step just decided in `world`: one step of effort on its action,
  // world.step(action, effort already spent on it), reported as report() does; an idle step (no
  // action left to refine) is reported as not yet without asking the world. With exogenous
  // chains (SPEC §9) the session simulates them, drawn from its seed: their step joins the
  // world's answer, and a completed plan's execution is drawn in them (not in a live session:
  // UsageError). Returns the status after the step. Throws std::logic_error without a pending
  // decision, and what the world or report() throws.
  Status carry_out(World& world);

  // Reports the outcome of the step just decided. Throws std::logic_error without a
  // pending decision, and UsageError for a refinement reported on an idle step or a negative
  // execution time.
  Status report_not_yet();
  Status report_refined(Steps execution_steps);
  Status report(const Observation& observation);
  // A live session's report of a found motion with its execution time in seconds (the steps
  // form converts steps to seconds at step_seconds each). Throws UsageError for a negative or
  // non-finite time; infinity means the motion cannot be executed.
  Status report_refined_seconds(double execution_seconds);
  // The same with exogenous chains (SPEC §9): `chains` is their joint state after the step
  // (Mdp::joint_chain_state). Each report brings the chains' state now, and steps the clock
  // moved on between reports keep the state last reported. (Carried out in a world instead,
  // carry_out, a live session simulates the chains along the clock: one step of their path per
  // step of CT, however many a report charges.) A completed plan's static part must fit in
  // seconds (the execution reported for an action that depends on a chain is not used: it is
  // drawn when the action starts); the plan is then worth its expected reward from the state at
  // the report (reward()).
  Status report_refined_seconds(double execution_seconds, std::uint16_t chains);

  // Live sessions: time the clock did not see but the deadline must (e.g. spent on another
  // clock), added to the seconds gone. Throws UsageError for a negative or non-finite time,
  // std::logic_error for a session without a clock.
  void charge_outside(double seconds);

  // Sessions that own their problem: a skeleton arrives. `action_ids` lists its actions in
  // order; `new_actions` brings those the problem does not know yet, with their distributions;
  // `reward` is what succeeding with it is worth (SPEC §8; 1 by default).
  // Known actions are shared, so SPEC §1's prefix rule applies. What was learnt carries over:
  // the new skeleton starts with the leading actions already refined (their execution times
  // too) and the effort already spent on its next action. The allocator is made anew for the
  // new problem and decides from the current state (a search starts a new tree, the exact
  // solver solves from here within its cap). Returns the skeleton's index. Throws UsageError for
  // a broken rule or an allocator that cannot take the new problem (the session is then
  // unchanged), std::logic_error while a decision awaits its report, after the end, or for a
  // session that does not own its problem.
  int add_skeleton(const std::vector<std::string>& action_ids, std::vector<Action> new_actions = {},
                   SkeletonReward reward = {});
  // Sessions that own their problem: skeleton k leaves (e.g. the task planner found it
  // infeasible); later skeletons move down by one index. The last one leaving ends the session
  // as a failure. Same errors as add_skeleton.
  void retire_skeleton(int k);
  // Sessions that own their problem: every action takes the distributions of the action of
  // `beliefs` with the same id or, failing that, the same action_base_id (problem.hpp: a node
  // "move(A,B)#2" takes the belief's "move(A,B)"), e.g. an online belief's posterior means
  // (online_belief.hpp); the skeletons, the state and what was refined stay. The allocator is made
  // anew for the revised problem and decides from the current state, as after add_skeleton (so a
  // search or the exact solver plans with the new distributions). An action still in progress
  // keeps the effort spent on it, and the revised distribution is conditioned on it as any is.
  // Throws UsageError for an action `beliefs` lacks, or another deadline or step; the same
  // std::logic_error as add_skeleton. The session is unchanged when it throws.
  void revise_distributions(const Problem& beliefs);
  // Sessions that own their problem: while more skeletons are expected (a task planner is still
  // searching), the session does not end when no skeleton found so far can still succeed; the
  // caller adds one (can_succeed() tells when it must) or says no more will come, which ends
  // such a session as a failure. The deadline ends it either way. Throws std::logic_error for a
  // session that does not own its problem.
  void expect_more_skeletons(bool expected);
  // Whether some skeleton can still succeed from the current state.
  bool can_succeed() const { return mdp_->any_can_succeed(state_); }

  // Where the episode stands: running, then success or failure once it has ended.
  Status status() const noexcept { return status_; }
  // The current MDP state (for a live session, derived from the seconds gone).
  const State& state() const noexcept { return state_; }
  // The MDP the session steps through.
  const Mdp& mdp() const noexcept { return *mdp_; }
  // The MDP's problem.
  const Problem& problem() const noexcept { return mdp_->problem(); }
  // The skeleton to execute after success, -1 before.
  int solution() const noexcept { return solution_; }
  // What the episode earned (SPEC §8): after a success, the solution's reward at its finish (the
  // state's CT plus the solution's ET; 1 without rewards), else 0.
  // On the robot's clock, the finish is the plan's end in seconds over the step (a real number).
  // With chains or expiry (SPEC §9): after carry_out, what the plan's execution drawn in the
  // simulated chains earned (a plan that cannot be carried out ends the session in failure);
  // after the caller's report, the plan's expected reward from the reported chains' state.
  double reward() const;
  // Steps of effort spent so far (CT).
  Steps steps_used() const noexcept { return state_.time; }
  // What the session saw of each action of problem() so far, by action index.
  const std::vector<ActionAttempt>& attempts() const noexcept { return attempts_; }
  // The same, moved out (the episode runner's result takes it when the session is done).
  std::vector<ActionAttempt> take_attempts() noexcept { return std::move(attempts_); }

  // Whether the session runs on a Clock's seconds (made with one) rather than on steps.
  bool is_live() const noexcept { return live_.is_live(); }
  // Whether an allocator decides (choose()) rather than the caller (decide()).
  bool has_allocator() const noexcept { return allocator_ != nullptr; }
  // Live sessions: D * step_seconds, the seconds gone (frozen when the session ended), the
  // steps so far, and what was charged.
  double step_seconds() const noexcept;
  double deadline_seconds() const noexcept;
  double elapsed_seconds() const;
  // One entry per step; its skeleton index is the one at the time of the step.
  const std::vector<LiveStep>& timeline() const noexcept { return live_.timeline(); }
  // After a live success, the plan's execution: its actions back to back from the success on.
  const std::vector<LiveExecution>& executions() const noexcept { return live_.executions(); }
  LiveTotals totals() const;
  // Live sessions: the same planner calls judged by the model's step clock (one step per call,
  // steps of execution, nothing charged for thinking or overruns): success or failure once that
  // clock decided, running when the live session ended before it did. With chains or expiry
  // (SPEC §9) its success is a plan completed in time: the plan's execution in the chains is
  // drawn for the live session only.
  Status model_status() const noexcept { return model_status_; }

 private:
  [[noreturn]] static void throw_without_decision();
  Status carry_out_timed(World& world);
  // A live session carried out in a world (SPEC §9): the simulated chains' joint state at step t.
  // Their path is drawn step by step from exogenous_ as far as it is needed, so that the clock may
  // move several steps between two reports and the chains still move once per step.
  std::uint16_t simulated_chains_at(Steps t);
  // The live half (src/run/live_session.cpp).
  void start_live(const Clock& clock, LiveOptions options);
  // choose(), decide() and report() on the clock, once what every session checks and records is
  // done; record_live_decision keeps a decision made at `begin` on the timeline.
  Decision choose_live(const DecisionBudget& budget);
  Decision decide_live(int skeleton);
  Decision record_live_decision(int choice, double begin, Steps steps_before);
  // A live success: the plan's actions executed back to back from `elapsed` seconds on.
  void record_plan_execution(int skeleton, double elapsed);
  Status report_live(int choice, int action, const Observation& observation, double execution_seconds);
  Status report(const Observation& observation, double execution_seconds);
  void end_if_out_of_time();
  // A backtrack of the action `backtracking` blaming `culprit` (SPEC §7): the attempts of the
  // culprit and of every action below it end (attempts_[a].ended), and theirs start anew.
  void end_attempts_below(int culprit, int backtracking);
  // No skeleton can succeed and none is expected to come.
  bool out_of_skeletons() const;
  // Replaces the problem (add_skeleton, retire_skeleton, revise_distributions: the same actions, in
  // the same order, and maybe more) and carries the state over.
  void change_skeletons(Problem next);
  State carried_over(const State& old, const Problem& next) const;

  const Mdp* mdp_;
  Allocator* allocator_;  // null: the caller decides
  State state_;
  // The state before the last transition, for the allocator's observe() and the clock: reused,
  // so that a wide problem's state is not reallocated.
  State before_;
  Status status_ = Status::running;
  int pending_ = -1;         // the skeleton decided, awaiting its report
  int pending_action_ = -1;  // its action (-1: an idle step)
  int solution_ = -1;
  // By action index (every session: one entry updated per step, nothing allocated).
  std::vector<ActionAttempt> attempts_;

  // Live and owning sessions: what every action revealed (by action index; actions are only
  // ever appended): its execution once refined, in steps and seconds, -1 before. Empty otherwise.
  std::vector<Steps> action_execution_steps_;
  std::vector<double> action_execution_seconds_;

  // Sessions that own their problem.
  std::unique_ptr<Problem> owned_problem_;
  std::unique_ptr<Mdp> owned_mdp_;
  std::unique_ptr<Allocator> owned_allocator_;
  AllocatorMaker make_allocator_;
  std::uint64_t seed_ = 0;
  // Chains or expiry (SPEC §9): the simulated chains' draws (carry_out; seeded from seed_ on
  // first use), and the reward of the success.
  SplitMix64 exogenous_{0};
  bool exogenous_seeded_ = false;
  double timed_reward_ = 0;
  // A live session carried out in a world: the simulated chains' path (by step, from the start).
  std::vector<std::uint16_t> chain_path_;
  bool simulated_chains_ = false;
  std::uint64_t changes_ = 0;   // skeleton changes so far: the allocator's seed stream
  bool more_expected_ = false;  // expect_more_skeletons()

  // Live sessions only.
  LiveLedger live_;
  double finish_seconds_ = -1;  // live success: when the plan's execution ends, elapsed seconds
  State model_state_;           // the step clock's state
  Status model_status_ = Status::running;
};

// Sessions whose skeletons change (Session, ConcurrentSession): the allocator `make_allocator` makes
// for `mdp`, null without a maker. Throws UsageError when the maker returns none.
template <class Maker, class AnyMdp>
auto made_allocator(const Maker& make_allocator, const AnyMdp& mdp) -> decltype(make_allocator(mdp)) {
  if (!make_allocator) return nullptr;
  auto allocator = make_allocator(mdp);
  if (!allocator) throw UsageError("the allocator maker returned no allocator");
  return allocator;
}

// Sessions whose skeletons change (Session, ConcurrentSession): `current` with one more skeleton,
// `action_ids` in order, the actions it does not know among `new_actions` (appended in their
// order), worth `reward`. Throws UsageError for an action in neither, or a broken rule of the problem.
Problem with_added_skeleton(const Problem& current, const std::vector<std::string>& action_ids,
                            std::vector<Action> new_actions, SkeletonReward reward = {});
// `current` without skeleton k (its actions stay); nullopt when k is the last skeleton (a problem
// has one at least). Throws UsageError for k out of range.
std::optional<Problem> without_skeleton(const Problem& current, int k);
// `current`'s name, deadline, step, description and chains with these actions, skeletons and rewards.
Problem with_skeletons(const Problem& current, std::vector<Action> actions, std::vector<std::vector<int>> skeletons,
                       std::vector<SkeletonReward> rewards);

// Inline, so that the runner's loop pays for no more than the calls it would make itself.
inline Status Session::carry_out(World& world) {
  if (pending_ < 0) throw_without_decision();
  if (mdp_->is_timed()) return carry_out_timed(world);
  if (pending_action_ < 0) return report_not_yet();  // an idle step: nothing to ask the world
  return report(world.step(pending_action_, state_.spent[static_cast<std::size_t>(pending_)]));
}

}  // namespace ontime
