#pragma once
// A domain's real motion planner as the World of episodes (ontime/world.hpp): the episode
// runner's allocator decides, step by step, which action of the domain gets the next step of
// effort, and the domain's refinements — resumed slice by slice, several of them interleaved —
// answer. The instance supplies the allocator's model (fitted from the domain's log); the
// outcomes come from the planner itself, so the success rate measures how well the model
// predicts the domain.
//
// Within an episode an action is refined once, unless refinement backtracks: its refinement
// starts, the first time the allocator picks it, where the refinement of the action before it
// ended (a first action at the domain's initial configuration), and every later pick continues
// it by one step. When a refinement gives up (RefinementStatus::backtrack, docs/spec.md §7), the
// action before it is blamed: that action's motion and those of every action below it in the
// prefix tree are discarded, and the step reports the backtrack; each is refined anew, in a new
// attempt, when next picked. The episode with seed s draws attempt 0 of the a-th action of the
// instance from stream_seed(s, 2a), attempt n > 0 from stream_seed(stream_seed(s, 2a), n) (and
// a fallback start from stream 2a + 1): same seed, same episodes, whatever the thread count (in
// the collision-checks effort unit).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ontime/domains/collection.hpp"
#include "ontime/domains/domain.hpp"
#include "ontime/domains/task_planner.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/world.hpp"

namespace ontime::domains {

struct PlannerWorldOptions {
  EffortSettings effort;
  // Diagnostic: an action after the first starts from the domain's fallback start (drawn from
  // the episode's seed) instead of where the refinement before it ended, which removes the
  // dependence between consecutive refinements that the MDP does not model.
  bool independent_starts = false;
  // Live episodes in the collision-checks unit: charge the allocator's thinking by this model
  // instead of real time (NominalPlanningClock); nothing real is then on the clock.
  std::optional<ThinkingModel> thinking;
};

// The clock of live episodes in the collision-checks unit. Each planner call counts as the
// nominal seconds of its collision checks instead of the real time it took. Without a thinking
// model it is otherwise the steady clock: the allocator's thinking, the task planner's search and
// the caller's time stay real, so a live episode charges them against a planner as slow as the
// model says (a robot's view). With a thinking model nothing real is on it: decisions are charged
// by the model (clock.hpp), so that the same seed gives the same episodes to the last one on any
// machine and under any load (reports).
class NominalPlanningClock final : public Clock {
 public:
  // `thinking`: the model that charges the allocator's decisions; none: they take real time.
  explicit NominalPlanningClock(std::optional<ThinkingModel> thinking = std::nullopt) : thinking_(thinking) {}
  double now() const override { return thinking_ ? modelled_ : steady_.now() + offset_; }
  // A planner call took `real_seconds` and counts as `nominal_seconds`.
  void count_call(double real_seconds, double nominal_seconds) noexcept {
    offset_ += nominal_seconds - real_seconds;
    modelled_ += nominal_seconds;
  }
  // A new episode: the modelled time starts again from 0 (the steady clock cannot).
  void restart() noexcept { modelled_ = 0; }
  const ThinkingModel* thinking_model() const noexcept override { return thinking_ ? &*thinking_ : nullptr; }
  void charge_thinking(std::uint64_t iterations) const override {
    if (thinking_) {
      modelled_ += thinking_->seconds_per_decision + thinking_->seconds_per_iteration * static_cast<double>(iterations);
    }
  }

 private:
  SteadyClock steady_;
  std::optional<ThinkingModel> thinking_;
  double offset_ = 0;
  // The modelled time: planner calls and charged thinking. Mutable: sessions hold clocks as
  // const and charge a decision's thinking through them.
  mutable double modelled_ = 0;
};

// Streaming episodes (episode_runner.hpp, run_streaming_episodes): skeletons come from a task
// planner (task_planner.hpp) as the episode goes, and the distributions of their actions from a
// library, a problem whose actions are the domain's actions (e.g. fitted from a log of every
// move). The episode's actions are the nodes of the prefix tree of the skeletons found so far,
// numbered in the order they appear; a node takes the domain action's id, or, when that id is
// already a node under another prefix, the id followed by "#2", "#3", ... (the same action
// reached another way). Each found skeleton is charged `seconds_per_skeleton` of search besides
// the time the task planner takes on the clock.
struct StreamingWorldOptions {
  const Problem* library = nullptr;  // must outlive the worlds
  TaskPlannerFactory task_planners;
  double seconds_per_skeleton = 0;
};

// Counters: "refinements_started" (interleaved ones included), "refinements_found" (those
// that found a motion) and "backtracks", summed over the episodes since the world was made.
class PlannerWorld final : public World {
 public:
  // The domain and the problem must outlive the world. The problem's action ids must be
  // actions of the domain: step throws std::invalid_argument for one that is not.
  PlannerWorld(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options);
  // A world whose skeletons stream in (see StreamingWorldOptions). Throws std::invalid_argument
  // without a library or a task planner factory, or for a negative search charge.
  PlannerWorld(const Domain& domain, const StreamingWorldOptions& streaming, const PlannerWorldOptions& options);

  void begin_episode(std::uint64_t seed) override;
  Observation step(int action, Steps spent) override;
  void collect_statistics(Statistics& statistics) const override;
  // Live episodes: the nominal planning clock in the collision-checks unit; the steady clock
  // (nullptr) in the wall-clock unit, where planner calls take the time they take.
  const Clock* clock() const noexcept override;
  std::optional<FoundSkeleton> next_skeleton() override;
  // Streaming worlds acting while planning: from now on the task planner's skeletons that do not
  // begin with the domain actions of `executed` are passed over.
  void commit(const std::vector<int>& executed) override;
  // Streaming worlds: the library the distributions of the skeletons found from now on come from
  // (e.g. an online belief's, between two episodes); it must outlive its use and have the
  // library's step. Throws std::invalid_argument for a world that does not stream or another step.
  void set_library(const Problem& library);

  // The episode's actions so far (domain action ids, prefix-tree parents) and their refinements
  // (null for an action never picked), for pictures of the last episode.
  const std::vector<TreeAction>& actions() const noexcept { return actions_; }
  const Refinement* refinement(int action) const;

 private:
  const Domain* domain_;
  double step_seconds_;
  std::vector<TreeAction> actions_;  // by action index: the domain's action id and the parent
  PlannerWorldOptions options_;
  // Streaming worlds only.
  StreamingWorldOptions streaming_;
  std::unique_ptr<TaskPlanner> task_planner_;
  std::vector<std::string> node_ids_;   // by action index: the id in the episode's problem
  std::vector<std::string> committed_;  // the domain actions the robot committed to (commit)
  std::uint64_t seed_ = 0;
  std::vector<std::unique_ptr<Refinement>> refinements_;  // by action, in this episode
  std::vector<std::uint64_t> attempts_;                   // by action: attempts before the current one
  std::uint64_t backtracks_ = 0;
  std::uint64_t started_ = 0;
  std::uint64_t found_ = 0;
  NominalPlanningClock nominal_clock_;

  // Discards the refinements of `culprit` and of every action below it.
  void discard_from(int culprit);
};

// One planner world per thread, for the episode runner; the arguments must outlive the worlds.
WorldFactory planner_worlds(const Domain& domain, const Problem& problem, const PlannerWorldOptions& options);
// One streaming planner world per thread (each with its own task planner).
WorldFactory streaming_planner_worlds(const Domain& domain, const StreamingWorldOptions& streaming,
                                      const PlannerWorldOptions& options);

}  // namespace ontime::domains
