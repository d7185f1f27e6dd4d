#include "cluster_job.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ontime/util/error.hpp"

#if ONTIME_WITH_MPI
#include <mpi.h>
#endif

namespace ontime::cli {
namespace {

// A positive integer from the environment, or 0.
long environment_number(const char* name) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return 0;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  return *end == '\0' && value > 0 ? value : 0;
}

void print_line(const char* message) noexcept {
  if (message != nullptr) std::fprintf(stderr, "%s\n", message);
}

bool launched_by_mpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr ||
         std::getenv("PMI_RANK") != nullptr;
}

#if ONTIME_WITH_MPI

// The code of the rank that failed before the gate, once this rank learnt of it there.
int peer_failure = 0;

// Thrown on the ranks that reach the gate whole when another rank failed before it.
class PeerFailed : public std::runtime_error {
 public:
  explicit PeerFailed(int code) : std::runtime_error("rank failed with exit code " + std::to_string(code)) {}
};

class MpiRanks final : public Ranks {
 public:
  MpiRanks() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  int rank() const noexcept override { return rank_; }
  int size() const noexcept override { return size_; }

  // Every rank's exit code so far (0: healthy); each rank calls it once, with the first exchange
  // of results or when it leaves the job, whichever comes first.
  std::vector<int> gate(int code) const {
    std::vector<int> codes(static_cast<std::size_t>(size_));
    MPI_Allgather(&code, 1, MPI_INT, codes.data(), 1, MPI_INT, MPI_COMM_WORLD);
    gate_passed_ = true;
    return codes;
  }
  bool gate_passed() const noexcept { return gate_passed_; }

  // The first exchange meets the gate: a rank that failed before it stops every rank.
  void pass_gate() const {
    if (gate_passed_) return;
    for (const int code : gate(0)) {
      if (code != 0) {
        peer_failure = code;
        throw PeerFailed(code);
      }
    }
  }

  std::vector<std::string> all_gather(std::string_view bytes) const override {
    pass_gate();
    const auto count = static_cast<std::size_t>(size_);
    const auto own = static_cast<unsigned long long>(bytes.size());
    std::vector<unsigned long long> sizes(count);
    MPI_Allgather(&own, 1, MPI_UNSIGNED_LONG_LONG, sizes.data(), 1, MPI_UNSIGNED_LONG_LONG, MPI_COMM_WORLD);
    std::vector<std::string> parts(count);
    unsigned long long total = 0;
    for (std::size_t r = 0; r < count; ++r) {
      parts[r].resize(sizes[r]);
      total += sizes[r];
    }
    parts[static_cast<std::size_t>(rank_)].assign(bytes);
    constexpr auto kMaxCount = static_cast<unsigned long long>(std::numeric_limits<int>::max());
    if (total <= kMaxCount) {
      // One exchange (MPI counts are ints).
      std::string joined(total, '\0');
      std::vector<int> counts(count), offsets(count);
      int offset = 0;
      for (std::size_t r = 0; r < count; ++r) {
        counts[r] = static_cast<int>(sizes[r]);
        offsets[r] = offset;
        offset += counts[r];
      }
      MPI_Allgatherv(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, joined.data(), counts.data(),
                     offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
      for (std::size_t r = 0; r < count; ++r) {
        parts[r] = joined.substr(static_cast<std::size_t>(offsets[r]), sizes[r]);
      }
      return parts;
    }
    // More than 2 GiB in all: each rank broadcasts its bytes in pieces that fit an int count.
    constexpr std::size_t kPiece = std::size_t{1} << 30;
    for (std::size_t r = 0; r < count; ++r) {
      for (std::size_t begin = 0; begin < parts[r].size(); begin += kPiece) {
        const std::size_t length = std::min(kPiece, parts[r].size() - begin);
        MPI_Bcast(parts[r].data() + begin, static_cast<int>(length), MPI_BYTE, static_cast<int>(r), MPI_COMM_WORLD);
      }
    }
    return parts;
  }

  std::vector<std::string> all_to_all(const std::vector<std::string>& parts) const override {
    pass_gate();
    const auto count = static_cast<std::size_t>(size_);
    std::vector<unsigned long long> sizes(count), incoming(count);
    unsigned long long sent = 0;
    for (std::size_t r = 0; r < count; ++r) sent += sizes[r] = parts.at(r).size();
    MPI_Alltoall(sizes.data(), 1, MPI_UNSIGNED_LONG_LONG, incoming.data(), 1, MPI_UNSIGNED_LONG_LONG, MPI_COMM_WORLD);
    unsigned long long received_total = 0;
    for (const unsigned long long size : incoming) received_total += size;
    // MPI counts are ints: the two totals over all ranks decide, so that all take the same path.
    const unsigned long long largest = std::max(sent, received_total);
    unsigned long long largest_anywhere = 0;
    MPI_Allreduce(&largest, &largest_anywhere, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    if (largest_anywhere > static_cast<unsigned long long>(std::numeric_limits<int>::max())) {
      return Ranks::all_to_all(parts);
    }
    std::string out_bytes, in_bytes(received_total, '\0');
    std::vector<int> out_counts(count), out_offsets(count), in_counts(count), in_offsets(count);
    int out_offset = 0, in_offset = 0;
    for (std::size_t r = 0; r < count; ++r) {
      out_bytes += parts[r];
      out_counts[r] = static_cast<int>(sizes[r]);
      out_offsets[r] = out_offset;
      out_offset += out_counts[r];
      in_counts[r] = static_cast<int>(incoming[r]);
      in_offsets[r] = in_offset;
      in_offset += in_counts[r];
    }
    MPI_Alltoallv(out_bytes.data(), out_counts.data(), out_offsets.data(), MPI_BYTE, in_bytes.data(), in_counts.data(),
                  in_offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
    std::vector<std::string> received(count);
    for (std::size_t r = 0; r < count; ++r) {
      received[r] = in_bytes.substr(static_cast<std::size_t>(in_offsets[r]), incoming[r]);
    }
    return received;
  }

 private:
  int rank_ = 0;
  int size_ = 1;
  mutable bool gate_passed_ = false;
};

std::optional<MpiRanks>& job() {
  static std::optional<MpiRanks> ranks;
  return ranks;
}

#endif

}  // namespace

void join_cluster_job([[maybe_unused]] int& argc, [[maybe_unused]] char**& argv) {
  if (!launched_by_mpi()) {
    // srun without an MPI plugin starts its tasks as unrelated copies, which would each do the
    // whole work and write the same files.
    if (environment_number("SLURM_STEP_NUM_TASKS") > 1 && std::getenv("SLURM_PROCID") != nullptr) {
      throw UsageError("srun started " + std::string(std::getenv("SLURM_STEP_NUM_TASKS")) +
                       " tasks without MPI: launch ontime with 'srun --mpi=pmix' (or as one task)");
    }
    return;
  }
#if ONTIME_WITH_MPI
  int provided = 0;
  // Only the thread that called main() talks to MPI; the worker threads never do.
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  job().emplace();
  if (job()->rank() != 0) {
    // Rank 0 alone prints; the others' standard output goes nowhere.
    if (std::freopen("/dev/null", "w", stdout) == nullptr) std::fclose(stdout);
  }
#else
  const long size = std::max(environment_number("OMPI_COMM_WORLD_SIZE"), environment_number("SLURM_NTASKS"));
  if (size > 1) {
    throw UsageError("this ontime was built without MPI (ONTIME_MPI=OFF): it cannot split its work over " +
                     std::to_string(size) + " ranks; run it as one process, or build it with libopenmpi-dev");
  }
#endif
}

const Ranks* job_ranks() noexcept {
#if ONTIME_WITH_MPI
  if (job()) return &*job();
#endif
  return nullptr;
}

bool is_job_root() noexcept { return is_root_rank(job_ranks()); }

int leave_cluster_job(int code, const char* message) noexcept {
#if ONTIME_WITH_MPI
  if (job()) {
    try {
      const MpiRanks& ranks = *job();
      if (peer_failure != 0) {
        MPI_Finalize();
        return peer_failure;
      }
      if (!ranks.gate_passed()) {
        // Before the first exchange: meet the other ranks at the gate, the lowest failing rank
        // speaks, all leave with a failing rank's code.
        const std::vector<int> codes = ranks.gate(code);
        int first = -1;
        for (std::size_t r = 0; r < codes.size() && first < 0; ++r) {
          if (codes[r] != 0) first = static_cast<int>(r);
        }
        if (first == ranks.rank()) print_line(message);
        MPI_Finalize();
        return code != 0 ? code : (first < 0 ? 0 : codes[static_cast<std::size_t>(first)]);
      }
      if (code == 0) {
        MPI_Finalize();
        return 0;
      }
    } catch (...) {
      // MPI itself failed: fall through and end the job.
    }
    print_line(message);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, code);
    return code;
  }
#endif
  print_line(message);
  return code;
}

}  // namespace ontime::cli
