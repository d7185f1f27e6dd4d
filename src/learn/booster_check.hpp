#pragma once
// The rules a boosted model's booster text must follow before XGBoost reads it (docs/formats.md,
// "Boosters"). XGBoost's reader trusts its input: an out-of-range child or split index reads out
// of bounds, a cycle of children makes prediction loop forever, a short tree_info or a tree count
// that disagrees crashes, and its JSON parser recurses once per level of nesting. A model file is
// user input, so the booster is checked here first, whole.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace ontime::detail {

// A broken rule of a booster text that is to take `features` features: where within the
// booster's JSON (`learner.gradient_booster.model.trees[2].left_children[5]`) and what; nullopt
// when the text follows every rule.
struct BoosterFault {
  std::string place;
  std::string rule;
};
std::optional<BoosterFault> booster_fault(std::string_view text, std::size_t features);

}  // namespace ontime::detail
