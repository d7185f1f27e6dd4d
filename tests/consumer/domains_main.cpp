// Loads a domain's world file with the installed domains component and prints its skeletons.
#include <iostream>
#include <ontime/domains/registry.hpp>

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  const ontime::domains::LoadedDomain loaded = ontime::domains::load_domain(argv[1], argv[2]);
  std::cout << "skeletons " << loaded.domain->skeletons().size() << "\n";
  return 0;
}
