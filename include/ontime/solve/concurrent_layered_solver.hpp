#pragma once
// `solve_concurrent_layered`: V* of the acting-while-planning MDP (SPEC §10) from its start, level
// by level on threads, within caps on states, memory and disk; a certified interval around V* where
// a cap or the stop condition cuts it (`ontime solve --act concurrent --method layered`).
//
// Levels. A step adds one to CT and leaves the executed prefix E as it is; a start adds one
// action to E and takes no time. So every move raises CT + |E| (E's depth,
// ConcurrentMdp::executed_depth) by exactly one: the states reachable from the start fall into
// levels, and a state's successors all lie in the next level, as the plan-first layered solver's
// layers do (layered_solver.hpp), starts making levels of their own within a step. The forward
// pass builds level n + 1 from level n: on threads, each state's moves (ConcurrentMdp::useful_moves)
// and their outcomes in the MDP's order (move_value's walk); then, in the level's order, each
// successor that is not settled (settled_value) is found or placed in the next level's table and
// its place recorded. The backward pass values the levels from the last to the first, each state
// from the places its outcomes point to, with no search.
//
// States are the memoised solver's keys (ConcurrentMdp::merge_backlogs where the model merges
// backlogs, the state itself otherwise), each expanded as a state of the MDP, as the memoised
// solver expands them: a key has the value and the moves of every state with that key
// (docs/theory.md, "Backlogs").
//
// Guarantees. Each state's value is computed by one thread with the memoised solver's arithmetic
// (ConcurrentSolver): the same moves, their outcomes summed in the same order from the same
// successors' values, the same tie rule (the first move within ConcurrentSolver::kTieTolerance of
// the largest value, that move's value). Both solvers value the same keys, so the value and the
// first move are the memoised solver's to the bit, and the states enumerated are its states,
// whatever the thread count; with backtracking (SPEC §7), rewards (§8), chains and expiry (§9) too.
//
// A cut (a cap on states, memory or disk, or the stop condition, checked as the next level grows;
// never before level 1, so that the start's move is chosen) ends the forward pass at level T: T's
// states get ConcurrentValueBounds' interval (widened by ConcurrentSearch::kBoundSlack against
// rounding unless its ends meet), and the backward pass carries intervals up, a state's lower end
// that of the move the tie rule picks by lower ends and its upper end the largest of its moves'
// upper ends: lower <= V* <= upper.
//
// Each level, once its outcomes' places are written, goes to a scratch file with them (the
// plan-first layered solver's scratch directory: removed at the end, stale ones of dead processes
// removed first, on a signal too when asked) and comes back for the backward pass.
//
// Cost: time linear in the reachable states times their outcomes (the outcomes generated on every
// thread, one hash-table lookup per successor not settled, in the level's order); memory one
// level's states (2 (4 + 2K + A) bytes each) and its outcomes' places (4 bytes per outcome not
// settled) while the next level's table (its keys, twice where backlogs merge, and a slot each) is
// built; disk every level's states and places. Caps are checked as the table grows, between chunks
// of a few ten thousand states.

#include "ontime/mdp/concurrent_mdp.hpp"
#include "ontime/solve/concurrent_search.hpp"
#include "ontime/solve/layered_solver.hpp"

namespace ontime {

// The optimum from mdp.start(), with the plan-first layered solver's options: threads, max_states
// (the states enumerated), max_memory_bytes, max_disk_bytes, scratch_directory, on_stale_scratch,
// remove_scratch_on_signal, stop and on_layer (LayerFigures::layer: the level CT + |E|). Throws
// UsageError for what it does not take (a tolerance, SplitMode::always, policy layers, more than
// one rank); ResourceLimitError when a scratch file cannot be written or read back, or a level has
// more states than a 32-bit place can name. The solution's `solved` counts the states enumerated.
ConcurrentSolution solve_concurrent_layered(const ConcurrentMdp& mdp, const LayeredSolveOptions& options);

}  // namespace ontime
