// The stepping core of ontime.env.EffortAllocationEnv: one simulated episode at a time in a hidden
// sampled world (the simulator's HiddenWorld, seeded as the episode runner seeds it), observed as
// the normalised MDP state the ppo allocator sees. Each episode is a Session whose choices the
// caller makes (Session::decide), carried out against the world as the episode runner carries
// out its allocators' (Session::carry_out). Written in C++ so that a step costs a few
// microseconds from Python; the Gymnasium-style API around it is pure Python (env.py).

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>

#include "bindings.hpp"
#include "ontime/allocators/ppo.hpp"
#include "ontime/run/session.hpp"
#include "ontime/run/simulator.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/random.hpp"

namespace ontime::python {

namespace {

class EnvironmentCore {
 public:
  EnvironmentCore(std::shared_ptr<MdpHandle> mdp, std::uint64_t seed)
      : mdp_(std::move(mdp)),
        world_(*mdp_->problem, 0),
        seed_(seed),
        features_(static_cast<std::size_t>(
            feature_count(mdp_->mdp.skeleton_count(), chain_feature_count(mdp_->mdp.problem())))),
        start_(mdp_->mdp.start()) {}

  int skeleton_count() const { return mdp_->mdp.skeleton_count(); }
  int feature_size() const { return static_cast<int>(features_); }

  // Episode e after the seed was last set draws its hidden world from stream_seed(seed, e), as
  // episode e of the episode runner does.
  py::array_t<float> reset(std::optional<Seed> seed) {
    if (seed) {
      seed_ = *seed;
      episode_ = 0;
    }
    const std::uint64_t episode_seed = stream_seed(seed_, episode_++);
    world_.begin_episode(episode_seed);
    session_.emplace(mdp_->mdp, episode_seed);  // (its simulated chains, SPEC §9)
    return observation();
  }

  py::tuple step(Number<std::int64_t, "action"> action) {
    if (status() != Status::running) throw UsageError("the episode is over: call reset() before step()");
    const std::int64_t k = action;
    if (k < 0 || k >= skeleton_count()) {
      throw UsageError("parameter 'action': " + std::to_string(k) + " is not a skeleton index in [0, " +
                       std::to_string(skeleton_count()) + ")");
    }
    session_->decide(static_cast<int>(k));
    const Status status = session_->carry_out(world_);
    const double reward = session_->reward();
    return py::make_tuple(observation(), reward, status != Status::running, false);
  }

  py::array_t<std::int8_t> action_mask() const {
    py::array_t<std::int8_t> mask(skeleton_count());
    auto view = mask.mutable_unchecked<1>();
    for (int k = 0; k < skeleton_count(); ++k) view(k) = 0;
    if (status() == Status::running) {
      for (const int choice : mdp_->mdp.useful_choices(session_->state())) view(choice) = 1;
    }
    return mask;
  }

  StateView state() const { return {current_state(), skeleton_count(), mdp_->problem}; }
  // No episode yet: step() needs a reset() first.
  Status status() const { return session_ ? session_->status() : Status::failure; }
  std::shared_ptr<MdpHandle> mdp() const { return mdp_; }

 private:
  const State& current_state() const { return session_ ? session_->state() : start_; }

  py::array_t<float> observation() const {
    py::array_t<float> out(static_cast<py::ssize_t>(features_));
    normalised_state(mdp_->mdp, current_state(), std::span<float>(out.mutable_data(), features_));
    return out;
  }

  std::shared_ptr<MdpHandle> mdp_;
  HiddenWorld world_;
  std::uint64_t seed_;
  std::uint64_t episode_ = 0;
  std::size_t features_;
  State start_;                     // the state before the first reset()
  std::optional<Session> session_;  // the episode since the last reset()
};

}  // namespace

void bind_environment(py::module_& m) {
  py::class_<EnvironmentCore>(m, "_EnvironmentCore")
      .def(py::init([](const py::object& problem, Seed seed) {
             return std::make_unique<EnvironmentCore>(to_mdp(problem), seed);
           }),
           py::arg("problem"), py::arg("seed"))
      .def_property_readonly("skeleton_count", &EnvironmentCore::skeleton_count)
      .def_property_readonly("feature_size", &EnvironmentCore::feature_size)
      .def("reset", &EnvironmentCore::reset, py::arg("seed") = py::none())
      .def("step", &EnvironmentCore::step, py::arg("action"))
      .def("action_mask", &EnvironmentCore::action_mask)
      .def_property_readonly("state", &EnvironmentCore::state)
      .def_property_readonly("status", &EnvironmentCore::status)
      .def_property_readonly("mdp", &EnvironmentCore::mdp);
}

}  // namespace ontime::python
