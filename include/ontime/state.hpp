#pragma once
// The MDP state of SPEC §2 in a compact, fixed-size, trivially copyable form.
//
// 82 bytes for up to Problem::kMaxSkeletons skeletons; unused slots stay zero so that the
// whole object can be compared and hashed as raw bytes.

#include <array>
#include <cstddef>
#include <cstdint>

#include "ontime/problem.hpp"

namespace ontime {

struct State {
  std::uint16_t time = 0;                                      // CT: steps used
  std::array<std::uint8_t, Problem::kMaxSkeletons> refined{};  // l_k: actions refined
  std::array<std::uint16_t, Problem::kMaxSkeletons> spent{};   // PT_k: steps on action l_k
  // ET_k: execution steps of the refined actions, saturated at deadline + 1 (any larger
  // value is equally too slow, and saturation keeps equivalent states equal).
  std::array<std::uint16_t, Problem::kMaxSkeletons> execution{};

  friend bool operator==(const State&, const State&) = default;
};

static_assert(sizeof(State) == 2 + 16 + 32 + 32, "State must have no padding: it is packed and compared as bytes");

enum class Status : std::uint8_t { running, success, failure };

}  // namespace ontime
