#pragma once
// The paper's reference instances and published figures (SPEC §6).

#include <array>
#include <filesystem>
#include <string>

#include "ontime/model/problem.hpp"

namespace ontime::testing {

std::filesystem::path source_path(const std::string& relative);
Problem paper_instance(const std::string& name);  // "figure1", "instance1" .. "instance5"
// data/instances/navigation.json (four skeletons of four moves) with its deadline shortened to
// `deadline` steps, named "navigation-<deadline>".
Problem navigation_with_deadline(Steps deadline);

// Table I, 100 runs: mean and 95% half-width per instance (1..5).
struct PublishedCell {
  double mean;
  double half_width;
};
struct PublishedRow {
  PublishedCell mcts, dp, dp_rerun, ppo, round_robin, greedy;
};
extern const std::array<PublishedRow, 5> kTableOne;

}  // namespace ontime::testing
