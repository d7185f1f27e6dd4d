#pragma once
// `solve_layered`: the optimal success probability V* of the start state, layer by layer,
// within memory and disk caps, on threads and over ranks; a certified interval around it
// where a cap stops the enumeration.
//
// Every step adds one to CT, so the states reachable from the start fall into layers (layer t:
// the states with CT = t) and a state's successors all lie in the next layer. The forward pass
// builds layer t + 1 from layer t, holding only those two in memory, and writes each layer it
// leaves to a scratch file; the backward pass reads the layers back, last to first, and values
// each state from the next layer's values, holding two layers' values. States are keys of as few
// 64-bit words as the instance allows (per skeleton, bit fields just wide enough for its refined
// count and for PT and ET up to D + 1; skeletons whose group can no longer succeed blanked, as
// the memoised solver does), and CT is the layer, not part of the key.
//
// Guarantees. Each state's value is computed by one thread from the same choices and outcomes,
// summed in the same order, as OptimalSolver (optimal.hpp) does, with the same tie rule: the
// value and the first choice are those of the memoised solver to the bit, whatever the thread
// or rank count. When a cap (states, memory, disk) or the stop condition ends the forward pass
// at layer T, the states of layer T get certified bounds instead of values (ValueBounds,
// value_bounds.hpp: the best commit policy's value below, the clairvoyant relaxation above),
// and the backward pass carries both: `lower` is then the exact value of a real policy (the
// backed-up choices up to layer T, the committed skeleton after), `upper` an admissible bound,
// and lower <= V* <= upper.
//
// Ranks: states are owned by the rank their key hashes to; each rank expands and values its
// own, sends the successors it finds to their owners (all_to_all) and, going back, asks their
// owners for their values. Every rank returns the same solution.
//
// Cost: time linear in the reachable states times their outcomes; memory about two layers'
// hash tables (each state costs its key plus 16 bytes of values, in a table at most 7/8 full);
// disk the keys of every layer but the last. Caps are checked as tables grow; a cap ends the
// forward pass cleanly with the layer reached, never by running out of memory.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "ontime/mdp.hpp"
#include "ontime/ranks.hpp"

namespace ontime {

struct LayerFigures {
  int layer = 0;                // CT of its states
  std::uint64_t states = 0;     // over all ranks
  double forward_seconds = 0;   // building its successors (0 for the last)
  double backward_seconds = 0;  // valuing its states (0 until the backward pass reaches it)
  bool backward = false;        // reported by the backward pass
};

struct LayeredSolveOptions {
  unsigned threads = 0;                // per rank; 0: one per hardware thread
  std::uint64_t max_states = 0;        // states enumerated, over all ranks; 0: no cap
  std::uint64_t max_memory_bytes = 0;  // tables held by one rank; 0: no cap
  std::uint64_t max_disk_bytes = 0;    // scratch files of one rank; 0: no cap
  // Where the layers' scratch files go (a private directory is made inside, and removed at the
  // end); empty: the system's temporary directory.
  std::filesystem::path scratch_directory;
  // The optimal (or, when bounded, the lower-bound policy's) choice in every state of the first
  // `policy_layers` layers is returned in LayeredSolution::policy.
  int policy_layers = 0;
  const Ranks* ranks = nullptr;
  // Checked as the forward pass goes: once it returns true the pass ends as at a cap.
  std::function<bool()> stop;
  // Called on every rank after each layer of each pass, with the layer's figures so far.
  std::function<void(const LayerFigures&)> on_layer;
};

struct PolicyEntry {
  State state;
  int choice = -1;  // -1: no useful choice (nothing can succeed any more)
  double lower = 0;
  double upper = 0;
};

struct LayeredSolution {
  double lower = 0;  // V* when exact
  double upper = 0;  // equal to lower when exact
  bool exact = true;
  int first_choice = -1;    // the optimal first choice (bounded: the lower-bound policy's), -1 if none
  int frontier_layer = -1;  // bounded: the layer whose states got bounds; -1 when exact
  std::string stopped_by;   // bounded: the cap or stop that ended the forward pass
  std::vector<LayerFigures> layers;
  std::uint64_t states = 0;             // over all layers and ranks
  std::size_t key_bytes = 0;            // bytes per state in the tables' keys and on disk
  std::uint64_t peak_memory_bytes = 0;  // the most table memory one rank held (largest over ranks)
  std::uint64_t peak_disk_bytes = 0;    // the most scratch one rank held (largest over ranks)
  std::vector<PolicyEntry> policy;      // the first policy_layers layers, by layer then key
};

// Solves from mdp.start(). Throws UsageError for more than kMaxExactSkeletons skeletons,
// ResourceLimitError when a scratch file cannot be written or read back.
LayeredSolution solve_layered(const Mdp& mdp, const LayeredSolveOptions& options = {});

}  // namespace ontime
