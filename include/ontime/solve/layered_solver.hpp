#pragma once
// `solve_layered`: the optimal success probability V* of the start state, layer by layer,
// within memory and disk caps, on threads and over ranks; a certified interval around it
// where a cap, a tolerance or a split makes it cheaper (docs/theory.md has the proofs).
//
// Every step adds one to CT, so the states reachable from the start fall into layers (layer t:
// the states with CT = t) and a state's successors all lie in the next layer. The forward pass
// builds layer t + 1 from layer t: it generates each state's outcomes, finds every successor's
// place in the next layer (threads own shards of it by a hash of the key, ranks own parts of
// it the same way) and writes, per outcome, that place (or success, failure) to a scratch file;
// each layer's keys go to a scratch file too. The backward pass reads the layers back, last to
// first, and values each state from the places its outcomes point to, with no search: memory
// holds one layer's keys and two layers' values. States are keys of as few 64-bit words as the
// instance allows (per skeleton, bit fields just wide enough for its refined count and for PT
// and ET up to D + 1; skeletons whose group can no longer succeed blanked, as the memoised
// solver does); CT is the layer, not part of the key. A successor differs from its state in the
// chosen group and in groups whose time ran out, so its key is the state's key with those
// fields rewritten.
//
// Guarantees. Each state's value is computed by one thread from the same choices and outcomes,
// summed in the same order, as OptimalSolver (optimal.hpp) does, with the same tie rule: the
// value and the first choice are those of the memoised solver to the bit, whatever the thread
// or rank count. Three things trade exactness for reach, each with a certified interval
// [lower, upper] around V* (lower is the exact value of a real policy):
//  - a cap (states, memory, disk) or the stop condition ends the forward pass at layer T: the
//    states of layer T get ValueBounds (commit policy below, clairvoyant relaxation above);
//  - `tolerance` > 0: a group whose clairvoyant chance alone is below it is dropped from the
//    successor (fewer states); the policy never returns to it (lower) and the upper end adds
//    what it could at most bring in parallel, 1 - (1 - U)(1 - G);
//  - `split`: only the strongest root subtree is enumerated; the others are bounded by their
//    clairvoyant chance alone, and the upper end lets a step on them come at any state at the
//    price of one step of delay for the enumerated part (a flagged copy of each state, one
//    layer on), which keeps the bound near the optimum when the others are weak.
//
// Backtracking (SPEC §7): keys also hold the restore value of every action some action may
// blame, nothing is blanked, and the outcomes are the MDP's own (Mdp::for_each_outcome), so the
// value is still the memoised solver's to the bit. A cap's frontier gets ValueBounds under
// backtracking, whose lower end is at most (not exactly) the commit policy's value, so the
// interval's lower end is at most that of a real policy. A tolerance or `split == always` is a
// UsageError there (their bound counts every give-up as a success and would drop nothing), and
// `fallback` never splits.
//
// Chains and expiry (SPEC §9): keys also hold the chains' joint state and the static execution
// before each timed action, nothing is blanked (a step may wait for a chain), the outcomes are
// the MDP's own and a success is worth its plan's expected reward over the chains' paths (each
// thread keeps a table per plan, as the memoised solver does), so the value is again the
// memoised solver's to the bit. A cap's frontier gets ValueBounds, whose lower end is 0 there
// (the commit tables do not value chains) and whose upper end is the clairvoyant relaxation with
// every chain-dependent execution 0. A tolerance or `split == always` is a UsageError, as with
// rewards (SPEC §8), and `fallback` never splits.
//
// Ranks: states are owned by the rank their key hashes to; each rank expands its own, sends the
// successors it finds to their owners (all_to_all, chunk by chunk) and learns their places; going
// back, it asks the owners for those places' values. Every rank returns the same solution.
//
// Cost: time linear in the reachable states times their outcomes, with one hash-table insertion
// per outcome (forward) and none backward; memory one layer's keys and the next layer's shard
// tables (each state its key, a 4-byte place and the table's slack) forward, one layer's keys
// and 16 bytes of values for two layers backward; disk every layer's keys and 4 bytes per
// outcome. Caps are checked as the tables grow; a cap ends the forward pass cleanly with the
// layer reached, never by running out of memory.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "ontime/mdp/mdp.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime {

struct LayerFigures {
  int layer = 0;                // CT of its states
  std::uint64_t states = 0;     // over all ranks
  double forward_seconds = 0;   // building its successors (0 for the last)
  double backward_seconds = 0;  // valuing its states (0 until the backward pass reaches it)
  bool backward = false;        // reported by the backward pass
};

// When solve_layered splits the tree (see the header comment): never; only when a cap cut the
// enumeration of the whole tree (then the tighter of the two intervals, per end); or straight away.
enum class SplitMode { never, fallback, always };

struct LayeredSolveOptions {
  unsigned threads = 0;                // per rank; 0: one per hardware thread
  std::uint64_t max_states = 0;        // states enumerated, over all ranks; 0: no cap
  std::uint64_t max_memory_bytes = 0;  // tables held by one rank; 0: no cap
  std::uint64_t max_disk_bytes = 0;    // scratch files of one rank; 0: no cap
  // Where the layers' scratch files go (a private directory is made inside, and removed at the
  // end); empty: the system's temporary directory.
  std::filesystem::path scratch_directory;
  // Scratch directories in that folder left by runs on this host whose process is gone (killed,
  // crashed) are removed before the solve starts (never a live process's): each is reported
  // here with the bytes it held.
  std::function<void(const std::filesystem::path&, std::uint64_t bytes)> on_stale_scratch;
  // Whether SIGINT, SIGTERM and SIGHUP remove the scratch before the process dies of the signal
  // (one line on standard error names each directory; a handler installed before runs after).
  // For programs that end on those signals, such as the ontime tool; off by default, so that a
  // host program's own handlers (Python's) are left alone.
  bool remove_scratch_on_signal = false;
  // The optimal (or, when bounded, the lower-bound policy's) choice in every state of the first
  // `policy_layers` layers is returned in LayeredSolution::policy.
  int policy_layers = 0;
  // Groups whose clairvoyant chance alone is below this are dropped, with their share in the
  // interval; 0: none (exact). In [0, 1].
  double tolerance = 0;
  // Whether to enumerate only the strongest root subtree and bound the others (split_plan).
  // `always` needs at least two root subtrees (UsageError otherwise); `fallback` splits only
  // where it can.
  SplitMode split = SplitMode::never;
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
  int first_choice = -1;      // the optimal first choice (bounded: the lower-bound policy's), -1 if none
  int frontier_layer = -1;    // cut: the layer whose states got bounds; -1 otherwise
  std::string stopped_by;     // cut: the cap or stop that ended the forward pass
  std::uint64_t dropped = 0;  // tolerance: outcomes from which a group was dropped
  // Split (when one ran): the skeletons enumerated (the others are bounded), the bound on the
  // others alone at the start, the split's own interval and states, and its layers.
  std::vector<int> split_kept;
  double split_weak_upper = 0;
  double split_lower = 0, split_upper = 0;
  std::uint64_t split_states = 0;
  int split_frontier_layer = -1;  // the split cut too: its frontier, and why
  std::string split_stopped_by;
  std::vector<LayerFigures> split_layers;
  // The whole tree's enumeration (empty when split straight away).
  std::vector<LayerFigures> layers;
  std::uint64_t states = 0;             // over all layers and ranks, both runs
  std::size_t key_bytes = 0;            // bytes per state in the keys
  std::uint64_t peak_memory_bytes = 0;  // the most table memory one rank held (largest over ranks)
  std::uint64_t peak_disk_bytes = 0;    // the most scratch one rank held (largest over ranks)
  std::vector<PolicyEntry> policy;      // the first policy_layers layers, by layer then key
};

// Which skeletons a split enumerates: those under the root action whose subtree has the largest
// clairvoyant chance alone at the start (the lowest skeleton index on ties). Empty when all
// skeletons share their first action (nothing to split).
std::vector<int> split_plan(const Mdp& mdp);

// Solves from mdp.start(). Throws UsageError for more than kMaxExactSkeletons skeletons, a
// tolerance outside [0, 1] or SplitMode::always with one root subtree; ResourceLimitError when
// a scratch file cannot be written or read back, or a layer has more states than one rank can
// index.
LayeredSolution solve_layered(const Mdp& mdp, const LayeredSolveOptions& options = {});

// Fills in the memory and disk caps that are still 0 with what this machine can give, so that a
// solve stops with a certified interval rather than being killed or filling the disk: 80% of
// the available memory (util/memory.hpp) divided among the ranks, and 90% of the free space where
// the scratch files go. The command line and Python solve with these defaults.
void fill_default_caps(LayeredSolveOptions& options);

}  // namespace ontime
