// Solves an instance with the installed library, and runs a trained-policy round trip through
// the public PPO handle (no Eigen in sight), then prints the optimum.
#include <iostream>
#include <memory>
#include <ontime/ontime.hpp>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const ontime::Problem problem = ontime::load_problem(argv[1]);
  const ontime::Mdp mdp(problem);
  ontime::OptimalSolver solver(mdp);
  ontime::PpoHyperparameters small;
  small.steps_per_epoch = 100;
  const auto policy = std::make_shared<const ontime::PpoPolicy>(
      ontime::parse_ppo_policy(ontime::ppo_policy_to_json(ontime::train_ppo(mdp, 10, 1, small).policy), "policy"));
  ontime::PpoAllocator allocator(mdp, policy);
  if (allocator.choose(mdp.start()) < 0) return 1;
  std::cout << "optimum " << solver.solve(mdp.start()) << "\n";
  return 0;
}
