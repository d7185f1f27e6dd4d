#include "ontime/domains/collection_journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "ontime/domains/collection.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "ontime/util/json_input.hpp"

namespace ontime::domains {
namespace {

using Json = nlohmann::ordered_json;

// FNV-1a (64 bits) of the world file, to notice that it changed between two runs. Written here
// (a few lines) because std::hash gives no guarantee to stay the same across builds.
std::string fingerprint(std::string_view text) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

Json settings(const Domain& domain, const CollectionOptions& options, std::string_view world_text) {
  Json actions = Json::array();
  for (const TreeAction& node : collection_actions(domain, options)) actions.push_back(node.action);
  Json line;
  line["ontime_collection_journal"] = 1;
  line["domain"] = domain.name();
  line["world_fnv1a"] = fingerprint(world_text);
  line["trials"] = options.trials;
  line["seed"] = options.seed;
  line["effort"] = std::string(effort_unit_name(options.effort.unit));
  line["checks_per_second"] = options.effort.checks_per_second;
  line["step_seconds"] = options.step_seconds;
  line["budget_steps"] = options.budget_steps;
  // Only when set, so that the checkpoints of skeleton-tree collections stay as they were.
  if (options.every_action) line["every_action"] = true;
  line["actions"] = actions;
  return line;
}

void write_all(int descriptor, const std::string& text, const std::filesystem::path& path) {
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(descriptor, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw_file_error(path, "cannot write the checkpoint", n < 0 ? errno : EIO);
    written += static_cast<std::size_t>(n);
  }
}

// Reads the trials of one journal file into `finished` (those not already there from another
// rank's file: the same trial gives the same record whichever rank ran it) and returns how many
// of its bytes are whole lines.
std::size_t read_part(const std::filesystem::path& path, const Json& expected, const CollectionOptions& options,
                      std::vector<JournalTrial>& finished, std::set<std::pair<std::size_t, std::uint64_t>>& known) {
  const std::string source = path.string();
  const std::string text = ontime::read_input_file(path, "collection journal");
  std::set<std::pair<std::size_t, std::uint64_t>> seen;  // in this file
  std::size_t start = 0, number = 0, keep = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) break;  // a last line cut short: dropped
    ++number;
    const std::string place = "line " + std::to_string(number);
    const std::string_view line(text.data() + start, end - start);
    Json value;
    try {
      value = ontime::detail::parse_json_strict<Json>(line, source);
    } catch (const InputError& bad) {
      throw InputError(source, place, bad.rule());
    }
    if (number == 1) {
      for (const auto& [key, wanted] : expected.items()) {
        if (!value.is_object() || !value.contains(key) || value[key] != wanted) {
          throw InputError(source, place,
                           "the checkpoint of another collection ('" + key + "' is " +
                               (value.is_object() && value.contains(key) ? ontime::detail::quote_json(value[key])
                                                                         : std::string("missing")) +
                               " there, " + ontime::detail::quote_json(wanted) + " here); delete it to start over");
        }
      }
    } else {
      if (!value.is_object() || !value.contains("action") || !value["action"].is_number_unsigned() ||
          value["action"].get<std::size_t>() >= expected["actions"].size() || !value.contains("record") ||
          !value["record"].is_object()) {
        throw InputError(source, place, "a trial needs 'action' (an index into the actions of line 1) and 'record'");
      }
      JournalTrial trial;
      trial.action = value["action"].get<std::size_t>();
      const std::vector<RefinementAttempt> records =
          parse_planner_log(value["record"].dump() + "\n", source + " " + place);
      trial.attempt = records.front();
      if (trial.attempt.action != expected["actions"][trial.action].get<std::string>() || !trial.attempt.trial ||
          *trial.attempt.trial >= options.trials || !seen.emplace(trial.action, *trial.attempt.trial).second) {
        throw InputError(source, place, "a trial that does not belong to this collection or is there twice");
      }
      if (value.contains("end")) {
        if (!value["end"].is_array()) throw InputError(source, place, "'end' must be an array of numbers");
        Configuration configuration;
        for (const Json& number_value : value["end"]) {
          if (!number_value.is_number()) throw InputError(source, place, "'end' must be an array of numbers");
          configuration.push_back(number_value.get<double>());
        }
        trial.end = std::move(configuration);
      }
      if (known.emplace(trial.action, *trial.attempt.trial).second) finished.push_back(std::move(trial));
    }
    start = end + 1;
    keep = start;
  }
  return keep;
}

}  // namespace

std::filesystem::path CollectionJournal::part_path(const std::filesystem::path& path, int rank) {
  if (rank == 0) return path;
  return std::filesystem::path(path.string() + kRankSuffix + std::to_string(rank));
}

std::vector<std::filesystem::path> CollectionJournal::parts(const std::filesystem::path& path) {
  std::vector<std::filesystem::path> found;
  std::error_code error;
  if (std::filesystem::exists(path, error)) found.push_back(path);
  const std::filesystem::path folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  const std::string prefix = path.filename().string() + kRankSuffix;
  std::vector<std::pair<int, std::filesystem::path>> ranked;
  for (std::filesystem::directory_iterator entry(folder, error), last; !error && entry != last;
       entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos || digits[0] == '0') continue;
    ranked.emplace_back(std::stoi(digits), part_path(path, std::stoi(digits)));
  }
  std::sort(ranked.begin(), ranked.end());
  for (auto& [rank, part] : ranked) found.push_back(std::move(part));
  return found;
}

CollectionJournal::CollectionJournal(std::filesystem::path path, const Domain& domain, const CollectionOptions& options,
                                     std::string_view world_text, bool resume, const Ranks* ranks)
    : path_(std::move(path)), ranks_(ranks) {
  const Json expected = settings(domain, options, world_text);
  const std::vector<std::filesystem::path> existing = parts(path_);
  if (!existing.empty() && !resume) {
    throw UsageError(existing.front().string() +
                     ": the checkpoint of an unfinished collection is there; resume the collection or delete it");
  }
  const std::filesystem::path own = part_path(path_, ranks == nullptr ? 0 : ranks->rank());
  std::size_t keep = 0;  // bytes of this rank's file to keep (whole lines)
  std::set<std::pair<std::size_t, std::uint64_t>> known;
  for (const std::filesystem::path& part : existing) {
    const std::size_t whole = read_part(part, expected, options, finished_, known);
    if (part == own) keep = whole;
  }
  // Every rank has read every file before any rank creates its own.
  if (split_over_ranks(ranks)) ranks->all_gather({});
  own_ = own;
  const std::string source = own_.string();
  descriptor_ = ::open(own_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (descriptor_ < 0) throw_file_error(own_, "cannot open the checkpoint", errno);
  if (::ftruncate(descriptor_, static_cast<off_t>(keep)) != 0 || ::lseek(descriptor_, 0, SEEK_END) < 0) {
    throw_file_error(own_, "cannot prepare the checkpoint", errno);
  }
  if (keep == 0) write_all(descriptor_, expected.dump() + "\n", own_);
}

CollectionJournal::~CollectionJournal() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

void CollectionJournal::record(const JournalTrial& trial) {
  Json line;
  line["action"] = trial.action;
  line["record"] = Json::parse(planner_log_line(trial.attempt));
  if (trial.end) line["end"] = *trial.end;
  const std::string text = line.dump() + "\n";
  const std::lock_guard lock(mutex_);
  write_all(descriptor_, text, own_);
}

void CollectionJournal::remove() {
  {
    const std::lock_guard lock(mutex_);
    if (descriptor_ >= 0) ::close(descriptor_);
    descriptor_ = -1;
  }
  // Every rank has closed its file (its last trial was exchanged) before rank 0 deletes them all.
  if (split_over_ranks(ranks_)) ranks_->all_gather({});
  if (!is_root_rank(ranks_)) return;
  for (const std::filesystem::path& part : parts(path_)) std::filesystem::remove(part);
}

}  // namespace ontime::domains
