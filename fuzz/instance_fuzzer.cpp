// Fuzzes the instance loader: any input must either load or be rejected with InputError —
// never crash, hang, trip a sanitizer, or throw anything else. A loaded instance must survive
// a write/read round trip unchanged and support the MDP and Eq. (1) tables.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "ontime/mdp/mdp.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/solve/contiguous_success.hpp"
#include "ontime/util/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const ontime::Problem problem = ontime::parse_problem(text, "fuzz-input.json");
    const ontime::Problem copy = ontime::parse_problem(ontime::problem_to_json(problem), "round-trip.json");
    if (copy.action_count() != problem.action_count() || copy.skeleton_count() != problem.skeleton_count() ||
        copy.deadline() != problem.deadline()) {
      __builtin_trap();
    }
    for (int a = 0; a < problem.action_count(); ++a) {
      if (!(copy.action(a).planning == problem.action(a).planning)) __builtin_trap();
    }
    // Chains or expiry (SPEC §9) with backtracking are refused by the MDP (not modelled yet).
    if (problem.is_timed() && problem.has_backtracking()) return 0;
    const ontime::Mdp mdp(problem);
    if (problem.is_timed()) {
      // The observations of a first step (refinement and chains) sum to 1.
      double total = 0;
      mdp.for_each_observation(mdp.start(), 0,
                               [&](double probability, const ontime::Observation&) { total += probability; });
      if (!(total > 1 - 1e-6 && total < 1 + 1e-6)) __builtin_trap();
      return 0;  // Eq. (1) below does not model them yet
    }
    if (problem.deadline() <= 200) {  // keeps each input fast; larger deadlines add nothing new here
      const ontime::ContiguousSuccessTable table(mdp, ontime::Aggregation::sum);
      for (int k = 0; k < problem.skeleton_count(); ++k) {
        const double value = table.success_probability(mdp.start(), k);
        if (!(value >= 0.0)) __builtin_trap();
      }
    }
  } catch (const ontime::InputError&) {
    // Rejected with a message: the expected outcome for bad input.
  }
  return 0;
}
