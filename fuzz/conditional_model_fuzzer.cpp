// Fuzzes the conditional time model reader (all kinds: pooled, hazard, boosted with its XGBoost
// boosters): any input must either load or be rejected with InputError — never crash, hang, trip
// a sanitizer, or throw anything else (XGBoost reads a booster only once it follows the rules of
// learn/booster_check.hpp). A loaded model must predict the laws of features of zeros and write a
// file that reads back to the same text.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/learn/conditional_model.hpp"
#include "ontime/util/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::unique_ptr<ontime::ConditionalTimeModel> model;
  try {
    model = ontime::parse_conditional_model(text, "fuzz-model.json");
  } catch (const ontime::InputError&) {
    return 0;  // rejected with a message: the expected outcome for bad input
  }
  const std::vector<double> zeros(model->feature_count(), 0.0);
  static_cast<void>(model->predict(zeros));
  const std::string written = model->to_json();
  if (ontime::parse_conditional_model(written, "round-trip.json")->to_json() != written) __builtin_trap();
  return 0;
}
