// Fuzzes the chain readers: the first byte picks a chain file (SPEC §9, "ontime-chain") or an
// observation log (JSON Lines of sequence, step, state); the rest is the text. Any input must
// either load or be rejected with InputError — never crash, hang, trip a sanitizer, or throw
// anything else. A chain read must write a file that reads back to the same chain; observations
// read must fit a markov chain with a prior (every state gets a row) or be refused as a usage
// error (too many states).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/learn/chain_fitting.hpp"
#include "ontime/model/exogenous_chain.hpp"
#include "ontime/util/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      const ontime::ExogenousChain chain = ontime::parse_chain(text, "fuzz-chain.json");
      const std::string written = ontime::chain_to_json(chain);
      if (ontime::chain_to_json(ontime::parse_chain(written, "round-trip.json")) != written) __builtin_trap();
      return 0;
    }
    const std::vector<ontime::ChainRun> runs = ontime::parse_chain_observations(text, "fuzz-log.jsonl");
    ontime::ChainFitOptions options;
    options.prior = 0.5;
    try {
      ontime::fit_chain(runs, options);
    } catch (const ontime::UsageError&) {
      // A log that fits no chain of the options (more states than a chain holds): a usage error.
    }
  } catch (const ontime::InputError&) {
    // Rejected with a message: the expected outcome for bad input.
  }
  return 0;
}
