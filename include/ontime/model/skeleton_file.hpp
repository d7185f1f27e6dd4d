#pragma once
// Reading the plan skeletons of a task on their own, without distributions: the `skeletons`
// member of a JSON object. Instance files (SPEC §5) and domain world files have one, and so
// may a file that holds nothing else: {"skeletons": [["a", "b"], ["a", "c"]]}. Other members
// are ignored. The rules of SPEC §1 on skeletons are checked while reading (non-empty, at
// most Problem::kMaxSkeletons skeletons of at most 255 ids, no id twice in one skeleton, no skeleton twice,
// sharing along a common prefix); a violation raises InputError with the file, the JSON path
// (`skeletons[1][2]`) and the rule.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace ontime {

struct SkeletonList {
  std::string source;                               // the file it was read from, for messages
  std::vector<std::vector<std::string>> skeletons;  // action ids, skeleton by skeleton
};

// Throws InputError.
SkeletonList load_skeleton_file(const std::filesystem::path& path);
SkeletonList parse_skeleton_file(std::string_view text, std::string_view source);

}  // namespace ontime
