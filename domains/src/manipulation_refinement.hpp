#pragma once
// Internal: one refinement of move+pick(O) or move+place(O,R) in the manipulation domain (the
// phases are described in manipulation.hpp).

#include <memory>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/manipulation.hpp"

namespace ontime::domains {

// Throws std::invalid_argument when `start` does not suit the action (a pick with a full hand,
// a place without the object in the hand) or the robot collides there.
std::unique_ptr<Refinement> make_manipulation_refinement(const ManipulationDomain& domain,
                                                         const ManipulationAction& action, const KitchenState& start,
                                                         std::uint64_t seed, const EffortSettings& effort);

}  // namespace ontime::domains
