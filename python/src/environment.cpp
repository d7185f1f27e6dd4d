// The stepping cores of ontime.env.EffortAllocationEnv: one simulated episode at a time in a hidden
// sampled world (the simulator's HiddenWorld, seeded as the episode runner seeds it). Plan-first
// (SPEC §2), each episode is a Session whose choices the caller makes (Session::decide), carried
// out against the world as the episode runner carries out its allocators' (Session::carry_out),
// observed as the normalised MDP state the ppo allocator sees. Acting while planning (SPEC §10),
// each episode is a ConcurrentSession whose moves the caller makes (ConcurrentSession::decide; a
// step carried out in the world as the runner's concurrent episodes carry theirs out), an action
// being one output of the concurrent ppo actor (ppo_move_output) and the observation its features
// (concurrent_normalised_state). Written in C++ so that a step costs a few microseconds from Python;
// the Gymnasium-style API around it is pure Python (env.py).

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/run/concurrent_session.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime::python {

namespace {

// Which episode comes next: episode e after the seed was last set lives in the hidden world of
// stream_seed(seed, e), as episode e of the episode runner does.
class EpisodeSeeds {
 public:
  explicit EpisodeSeeds(std::uint64_t seed) : seed_(seed) {}
  // The next episode's seed; a seed given restarts the count.
  std::uint64_t next(std::optional<Seed> seed) {
    if (seed) {
      seed_ = *seed;
      episode_ = 0;
    }
    return stream_seed(seed_, episode_++);
  }

 private:
  std::uint64_t seed_;
  std::uint64_t episode_ = 0;
};

// A mask of `size` entries, 1 at the `marked` ones, 0 elsewhere.
template <class Marked>
py::array_t<std::int8_t> mask_of(int size, const Marked& marked) {
  py::array_t<std::int8_t> mask(size);
  auto view = mask.mutable_unchecked<1>();
  for (int i = 0; i < size; ++i) view(i) = 0;
  for (const int i : marked) view(i) = 1;
  return mask;
}

// Checks a step: the episode running, and `action` in [0, count) (else UsageError naming the
// parameter, `what` the actions are and `layout`, their meaning).
int checked_action(Status status, std::int64_t action, int count, const char* what, const char* layout = "") {
  if (status != Status::running) throw UsageError("the episode is over: call reset() before step()");
  if (action < 0 || action >= count) {
    throw UsageError("parameter 'action': " + std::to_string(action) + " is not " + what + " in [0, " +
                     std::to_string(count) + ")" + layout);
  }
  return static_cast<int>(action);
}

class EnvironmentCore {
 public:
  EnvironmentCore(std::shared_ptr<MdpHandle> mdp, std::uint64_t seed)
      : mdp_(std::move(mdp)),
        world_(*mdp_->problem, 0),
        seeds_(seed),
        features_(static_cast<std::size_t>(
            feature_count(mdp_->mdp.skeleton_count(), chain_feature_count(mdp_->mdp.problem())))),
        start_(mdp_->mdp.start()) {}

  int skeleton_count() const { return mdp_->mdp.skeleton_count(); }
  int feature_size() const { return static_cast<int>(features_); }

  // Episode e after the seed was last set is episode e of the episode runner: its hidden world
  // drawn from stream_seed(seed, e), its session (the simulated chains, SPEC §9) seeded with
  // stream_seed(that, 1) (run_episode).
  py::array_t<float> reset(std::optional<Seed> seed) {
    const std::uint64_t episode_seed = seeds_.next(seed);
    world_.begin_episode(episode_seed);
    session_seed_ = stream_seed(episode_seed, 1);
    session_.emplace(mdp_->mdp, session_seed_);
    return observation();
  }

  py::tuple step(Number<std::int64_t, "action"> action) {
    const int k = checked_action(status(), action, skeleton_count(), "a skeleton index");
    session_->decide(k);
    const Status status = session_->carry_out(world_);
    const double reward = session_->reward();
    return py::make_tuple(observation(), reward, status != Status::running, false);
  }

  py::array_t<std::int8_t> action_mask() const {
    return mask_of(skeleton_count(),
                   status() == Status::running ? mdp_->mdp.useful_choices(session_->state()) : ChoiceList{});
  }

  StateView state() const { return {current_state(), skeleton_count(), mdp_->problem}; }
  // No episode yet: step() needs a reset() first.
  Status status() const { return session_ ? session_->status() : Status::failure; }
  std::shared_ptr<MdpHandle> mdp() const { return mdp_; }
  std::uint64_t session_seed() const { return session_seed_; }

 private:
  const State& current_state() const { return session_ ? session_->state() : start_; }

  py::array_t<float> observation() const {
    py::array_t<float> out(static_cast<py::ssize_t>(features_));
    normalised_state(mdp_->mdp, current_state(), std::span<float>(out.mutable_data(), features_));
    return out;
  }

  std::shared_ptr<MdpHandle> mdp_;
  HiddenWorld world_;
  EpisodeSeeds seeds_;
  std::uint64_t session_seed_ = 0;
  std::size_t features_;
  State start_;                     // the state before the first reset()
  std::optional<Session> session_;  // the episode since the last reset()
};

// The hidden world, with what its last step revealed (for the step's info).
class RevealingWorld final : public World {
 public:
  explicit RevealingWorld(const Problem& problem) : world_(problem, 0) {}
  void begin_episode(std::uint64_t seed) override { world_.begin_episode(seed); }
  Observation step(int action, Steps spent) override {
    revealed_ = world_.step(action, spent);
    return *revealed_;
  }
  // What the last step revealed; nullopt before the first step since forget().
  const std::optional<Observation>& revealed() const noexcept { return revealed_; }
  void forget() noexcept { revealed_.reset(); }

 private:
  HiddenWorld world_;
  std::optional<Observation> revealed_;
};

// Acting while planning (SPEC §10): actions are the concurrent ppo actor's outputs, 2 K + 1 of them.
class ConcurrentEnvironmentCore {
 public:
  ConcurrentEnvironmentCore(std::shared_ptr<const Problem> problem, std::uint64_t seed)
      : problem_(std::move(problem)),
        mdp_(std::make_unique<ConcurrentMdp>(*problem_)),
        world_(mdp_->problem()),  // as the runner's hidden worlds (run_monte_carlo)
        seeds_(seed),
        features_(static_cast<std::size_t>(
            concurrent_feature_count(mdp_->skeleton_count(), concurrent_chain_feature_count(mdp_->problem())))),
        start_(mdp_->start()) {}

  int skeleton_count() const { return mdp_->skeleton_count(); }
  int action_count() const { return concurrent_move_count(skeleton_count()); }
  int feature_size() const { return static_cast<int>(features_); }

  // Episode e after the seed was last set is episode e of the concurrent episode runner: its hidden
  // world drawn from stream_seed(seed, e), its session (the simulated chains, SPEC §9) seeded with
  // stream_seed(that, 1) (run_concurrent_episode).
  py::array_t<float> reset(std::optional<Seed> seed) {
    const std::uint64_t episode_seed = seeds_.next(seed);
    world_.begin_episode(episode_seed);
    world_.forget();
    session_seed_ = stream_seed(episode_seed, 1);
    session_.emplace(*mdp_, session_seed_);
    refresh_moves();
    return observation();
  }

  // One move: the start or step that output `action` stands for, among the state's useful moves.
  // Returns (observation, reward, terminated, truncated, found, execution_steps, culprit): for a
  // planner step on an action, whether its motion was found, if so its execution steps, and if the
  // attempt gave up (SPEC §7) the id of the action it blamed; None where there is nothing to say.
  py::tuple step(Number<std::int64_t, "action"> action) {
    const int output = checked_action(status(), action, action_count(), "a move",
                                      " (k: a step on skeleton k, K + k: start skeleton k's next action, 2 K: the "
                                      "planner idles)");
    const auto chosen = std::find(outputs_.begin(), outputs_.end(), output);
    if (chosen == outputs_.end()) {
      throw UsageError("parameter 'action': move " + std::to_string(output) +
                       " is masked out: only the state's useful moves (the exact solver's, "
                       "ConcurrentMdp::useful_moves; info['action_mask']) may be played");
    }
    const ConcurrentMdp::Move& move = moves_[static_cast<std::size_t>(chosen - outputs_.begin())];
    world_.forget();
    // As the runner's concurrent episodes: a start is carried out at once, a step in the world.
    if (!session_->decide(move).is_start() && session_->status() == Status::running) session_->carry_out(world_);
    py::object found = py::none();
    py::object execution = py::none();
    py::object culprit = py::none();
    if (const std::optional<Observation>& revealed = world_.revealed()) {
      found = py::bool_(revealed->refined);
      if (revealed->refined) execution = py::int_(revealed->execution);
      if (revealed->is_backtrack()) culprit = py::str(problem_->action(revealed->culprit).id);
    }
    refresh_moves();
    return py::make_tuple(observation(), session_->reward(), session_->status() != Status::running, false, found,
                          execution, culprit);
  }

  py::array_t<std::int8_t> action_mask() const { return mask_of(action_count(), outputs_); }

  // The output that stands for a move of a ConcurrentSession in the current state: `start` an
  // action's id, or a step on skeleton `skeleton` (None: the planner idles).
  int action_of(const py::object& start, const py::object& skeleton) const {
    if (status() != Status::running) throw UsageError("the episode is over: no move has an action");
    ConcurrentMdp::Move move;
    if (!start.is_none()) {
      if (!skeleton.is_none()) throw UsageError("parameter 'move': a start or a step, not both");
      if (!py::isinstance<py::str>(start)) {
        throw UsageError("parameter 'move': its 'start' must be an action's id (str) or None (got " +
                         std::string(py::repr(start)) + ")");
      }
      move.start = problem_->find_action(start.cast<std::string>());
      if (move.start < 0) throw UsageError("parameter 'move': no action '" + start.cast<std::string>() + "'");
    } else if (!skeleton.is_none()) {
      if (!py::isinstance<py::int_>(skeleton) || py::isinstance<py::bool_>(skeleton) ||
          skeleton.attr("__lt__")(0).cast<bool>() || skeleton.attr("__ge__")(skeleton_count()).cast<bool>()) {
        throw UsageError("parameter 'move': its 'skeleton' must be a skeleton index in [0, " +
                         std::to_string(skeleton_count()) + ") or None (got " + std::string(py::repr(skeleton)) + ")");
      }
      move.refine = skeleton.cast<int>();
      // A step on a live skeleton's next action is the step of its group: named by its lowest index.
      const ConcurrentState& state = session_->state();
      const Problem& plan = mdp_->problem();
      const auto next = [&](int k) {
        return ConcurrentMdp::is_live(state, k) && ConcurrentMdp::refined(state, k) < plan.skeleton_length(k)
                   ? plan.action_at(k, ConcurrentMdp::refined(state, k))
                   : -1;
      };
      const int action = next(move.refine);
      for (int k = 0; action >= 0 && k < move.refine; ++k) {
        if (next(k) == action) {
          move.refine = k;
          break;
        }
      }
    }
    const int output = ppo_move_output(*mdp_, session_->state(), move);
    if (output < 0) {
      throw UsageError("parameter 'move': no live skeleton executes action '" + problem_->action(move.start).id +
                       "' next");
    }
    return output;
  }

  // What the current state shows (SPEC §10): CT, r, the actions started, per skeleton whether it is
  // live, l_k and PT_k, and the actions the robot may start now.
  py::dict state() const {
    const ConcurrentState& state = session_ ? session_->state() : start_;
    py::dict out;
    out["time"] = ConcurrentMdp::time(state);
    out["robot_left"] = ConcurrentMdp::robot_left(state);
    std::vector<std::string> ids;
    if (session_) {
      for (const int action : session_->started()) ids.push_back(problem_->action(action).id);
    }
    out["started"] = ids;
    std::vector<bool> live;
    std::vector<int> refined;
    std::vector<Steps> spent;
    for (int k = 0; k < skeleton_count(); ++k) {
      live.push_back(ConcurrentMdp::is_live(state, k));
      refined.push_back(live.back() ? ConcurrentMdp::refined(state, k) : 0);
      spent.push_back(live.back() ? mdp_->spent(state, k) : 0);
    }
    out["live"] = live;
    out["refined"] = refined;
    out["spent"] = spent;
    ids.clear();
    for (const int action : mdp_->startable(state)) ids.push_back(problem_->action(action).id);
    out["startable"] = ids;
    return out;
  }

  // No episode yet: step() needs a reset() first.
  Status status() const { return session_ ? session_->status() : Status::failure; }
  std::uint64_t session_seed() const { return session_seed_; }
  std::shared_ptr<Problem> problem() const { return std::const_pointer_cast<Problem>(problem_); }

 private:
  // The useful moves of the current state and their outputs (none once the episode is over).
  void refresh_moves() {
    moves_.clear();
    outputs_.clear();
    if (session_->status() != Status::running) return;
    moves_ = mdp_->useful_moves(session_->state());
    for (const ConcurrentMdp::Move& move : moves_) outputs_.push_back(ppo_move_output(*mdp_, session_->state(), move));
  }

  py::array_t<float> observation() const {
    py::array_t<float> out(static_cast<py::ssize_t>(features_));
    concurrent_normalised_state(*mdp_, session_ ? session_->state() : start_,
                                std::span<float>(out.mutable_data(), features_));
    return out;
  }

  std::shared_ptr<const Problem> problem_;
  std::unique_ptr<ConcurrentMdp> mdp_;
  RevealingWorld world_;
  EpisodeSeeds seeds_;
  std::uint64_t session_seed_ = 0;
  std::size_t features_;
  ConcurrentState start_;                     // the state before the first reset()
  std::optional<ConcurrentSession> session_;  // the episode since the last reset()
  std::vector<ConcurrentMdp::Move> moves_;    // the useful moves of the current state
  std::vector<int> outputs_;                  // their outputs, in the same order
};

}  // namespace

void bind_environment(py::module_& m) {
  py::class_<EnvironmentCore>(m, "_EnvironmentCore")
      .def_property_readonly("skeleton_count", &EnvironmentCore::skeleton_count)
      .def_property_readonly("feature_size", &EnvironmentCore::feature_size)
      .def("reset", &EnvironmentCore::reset, py::arg("seed") = py::none())
      .def("step", &EnvironmentCore::step, py::arg("action"))
      .def("action_mask", &EnvironmentCore::action_mask)
      .def_property_readonly("state", &EnvironmentCore::state)
      .def_property_readonly("status", &EnvironmentCore::status)
      .def_property_readonly("session_seed", &EnvironmentCore::session_seed)
      .def_property_readonly("mdp", &EnvironmentCore::mdp);
  py::class_<ConcurrentEnvironmentCore>(m, "_ConcurrentEnvironmentCore")
      .def_property_readonly("skeleton_count", &ConcurrentEnvironmentCore::skeleton_count)
      .def_property_readonly("action_count", &ConcurrentEnvironmentCore::action_count)
      .def_property_readonly("feature_size", &ConcurrentEnvironmentCore::feature_size)
      .def("reset", &ConcurrentEnvironmentCore::reset, py::arg("seed") = py::none())
      .def("step", &ConcurrentEnvironmentCore::step, py::arg("action"))
      .def("action_mask", &ConcurrentEnvironmentCore::action_mask)
      .def("action_of", &ConcurrentEnvironmentCore::action_of, py::arg("start"), py::arg("skeleton"))
      .def_property_readonly("state", &ConcurrentEnvironmentCore::state)
      .def_property_readonly("status", &ConcurrentEnvironmentCore::status)
      .def_property_readonly("session_seed", &ConcurrentEnvironmentCore::session_seed)
      .def_property_readonly("problem", &ConcurrentEnvironmentCore::problem);
  // The core of `problem` in acting mode `act` (None: the problem's own): plan-first, its Mdp's
  // (an Mdp given is kept); concurrent, its ConcurrentMdp's.
  m.def(
      "_environment_core",
      [](const py::object& problem, Seed seed, const std::optional<std::string>& act) -> py::object {
        const std::shared_ptr<const Problem> chosen = problem_with_acting(problem, act);
        if (chosen->acting() == Acting::concurrent) {
          return py::cast(std::make_unique<ConcurrentEnvironmentCore>(chosen, seed));
        }
        std::shared_ptr<MdpHandle> mdp;
        if (py::isinstance<MdpHandle>(problem)) mdp = problem.cast<std::shared_ptr<MdpHandle>>();
        if (!mdp || mdp->problem != chosen) mdp = std::make_shared<MdpHandle>(chosen);
        return py::cast(std::make_unique<EnvironmentCore>(std::move(mdp), seed));
      },
      py::arg("problem"), py::arg("seed"), py::arg("act"));
}

}  // namespace ontime::python
