#pragma once
// The processes one run is split over: the ranks of an MPI job started by `mpirun` or
// `srun --mpi=pmix`, as the library sees them. The library never talks to MPI itself (the core
// does not depend on it): the caller hands it a Ranks, and the library splits its independent
// units (episodes, collection trials) over the ranks, runs its share on its own threads and
// exchanges the results with all_gather, once per batch of units (all_to_all where each rank
// sends each other rank its own part, as the layered exact solver does with the states it finds).
//
// Determinism: every unit draws its randomness from its own seeded stream and results are
// merged in unit order (or by sums of integers and maxima), so a run split over any number of
// ranks gives the numbers of one process, to the byte.
//
// A null `const Ranks*` means one process; so does a Ranks of size 1.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace ontime {

class Ranks {
 public:
  virtual ~Ranks() = default;
  virtual int rank() const noexcept = 0;  // 0 .. size() - 1
  virtual int size() const noexcept = 0;  // at least 1
  // Every rank's `bytes`, in rank order, on every rank. Collective: every rank must call it, in
  // the same order; it returns once all have.
  virtual std::vector<std::string> all_gather(std::string_view bytes) const = 0;
  // Sends parts[r] to rank r (parts has size() entries) and returns what each rank sent to this
  // one, in rank order. Collective, like all_gather. The default gathers every rank's parts on
  // every rank (memory for all of them at once); an MPI implementation exchanges only the parts.
  virtual std::vector<std::string> all_to_all(const std::vector<std::string>& parts) const;
};

// The units of 0 .. count - 1 that rank `rank` of `size` takes: rank, rank + size,
// rank + 2 size, ... Interleaved rather than contiguous, so that every rank gets units from all
// along the list and the ranks' loads stay alike when units differ in cost along it (episodes
// of a long run, the trials of one action after another's).
struct RankUnits {
  std::uint64_t first = 0;
  std::uint64_t stride = 1;
  std::uint64_t count = 0;  // how many units the rank takes
  // The rank's i-th unit (i < count): first + i * stride.
  std::uint64_t unit(std::uint64_t i) const noexcept { return first + i * stride; }
};
// The units of `count` that rank `rank` of `size` (>= 1) takes.
RankUnits rank_units(std::uint64_t count, int rank, int size) noexcept;
// The same for this process's rank of `ranks`; every unit for null (one process).
inline RankUnits rank_units(std::uint64_t count, const Ranks* ranks) noexcept {
  return ranks == nullptr ? RankUnits{0, 1, count} : rank_units(count, ranks->rank(), ranks->size());
}

// True when `ranks` splits work over more than one process.
inline bool split_over_ranks(const Ranks* ranks) noexcept { return ranks != nullptr && ranks->size() > 1; }

// Rank 0 of `ranks` (true for one process): the rank that writes a run's outputs.
inline bool is_root_rank(const Ranks* ranks) noexcept { return ranks == nullptr || ranks->rank() == 0; }

}  // namespace ontime
