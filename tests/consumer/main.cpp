// Solves an instance with the installed library and prints the optimum.
#include <iostream>

#include <ontime/ontime.hpp>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const ontime::Problem problem = ontime::load_problem(argv[1]);
  const ontime::Mdp mdp(problem);
  ontime::OptimalSolver solver(mdp);
  std::cout << "optimum " << solver.solve(mdp.start()) << "\n";
  return 0;
}
