#pragma once
// The checkpoint of a collection (collection.hpp): every finished trial is appended to a journal
// file, so that an interrupted collection (SIGINT, a crash, a power cut) loses at most the trials
// in progress and can resume where it stopped, with the same result as an uninterrupted run.
//
// A trial of an action starts where a successful refinement of the action before it ended, so
// the journal keeps, besides the trial's log record, the configuration its refinement ended in.
// Its first line states everything the results depend on (domain, world file contents, trials,
// seed, effort unit and rate, step, cut-off, the actions collected); resuming with
// other settings is refused. The journal is JSON Lines, one line per trial written with one
// write(2) call, doubles in round-trip precision:
//
//   {"ontime_collection_journal": 1, "domain": ..., "world_fnv1a": ..., "trials": ..., ...}
//   {"action": 3, "record": {planner log record}, "end": [configuration]}
//
// A last line cut short (by a crash during the write) is dropped on resuming; any other bad line
// is an InputError naming the file, the line and the rule.
//
// A collection split over MPI ranks keeps one journal file per rank, each complete with its
// settings line: rank 0 the file at `path`, rank r > 0 `path.rank-r`. Every rank reads them all
// on resuming, so a collection resumes under any number of ranks (or one process) from what any
// rank finished.

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/model/planner_log.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime::domains {

struct CollectionOptions;

struct JournalTrial {
  std::size_t action = 0;  // index in collection_actions(domain, options)
  RefinementAttempt attempt;
  std::optional<Configuration> end;  // where a successful refinement ended
};

class CollectionJournal {
 public:
  // Opens the journal for a collection of `domain` with `options`, whose world file holds
  // `world_text`:
  //  - no file at `path`: creates it with the settings line;
  //  - a file and `resume`: reads its trials (checking its settings are these: InputError
  //    otherwise) and appends after them;
  //  - a file and not `resume`: UsageError, so that the work it holds is not lost by accident.
  //  With `ranks`, every rank makes this call: each reads every rank's file (parts()) and
  //  writes its own (part_path()).
  CollectionJournal(std::filesystem::path path, const Domain& domain, const CollectionOptions& options,
                    std::string_view world_text, bool resume, const Ranks* ranks = nullptr);

  // The file rank `rank` writes for the journal at `path`.
  static std::filesystem::path part_path(const std::filesystem::path& path, int rank);
  // The journal files there are for `path`: its own, then those of ranks 1, 2, ... that exist.
  static std::vector<std::filesystem::path> parts(const std::filesystem::path& path);
  ~CollectionJournal();
  CollectionJournal(const CollectionJournal&) = delete;
  CollectionJournal& operator=(const CollectionJournal&) = delete;

  // The journal's path, as given (with ranks, rank r writes part_path(path(), r)).
  const std::filesystem::path& path() const noexcept { return path_; }
  // The trials read when the journal was opened.
  const std::vector<JournalTrial>& finished() const noexcept { return finished_; }

  // Appends a finished trial (thread-safe). Throws as write_file_atomically does (util/atomic_file.hpp)
  // when the write fails.
  void record(const JournalTrial& trial);

  // Closes and deletes the files, once the collection's outputs are written (with ranks: every
  // rank calls it, after rank 0 has written them; rank 0 deletes every rank's file).
  void remove();

 private:
  static constexpr const char* kRankSuffix = ".rank-";
  std::filesystem::path path_;
  std::filesystem::path own_;  // this rank's file
  const Ranks* ranks_ = nullptr;
  std::vector<JournalTrial> finished_;
  int descriptor_ = -1;
  std::mutex mutex_;
};

}  // namespace ontime::domains
