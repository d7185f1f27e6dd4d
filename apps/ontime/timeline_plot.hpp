#pragma once
// The timeline picture of a live episode (`run --live --timeline`, `tamp --picture`): its CSV
// (the domains report's timeline_csv) drawn by python/plot_timeline.py.

#include <filesystem>
#include <string>

#include "ontime/model/problem.hpp"
#include "ontime/run/episode_runner.hpp"

namespace ontime::cli {

// Draws the episode's timeline (its CSV already written to `data`) into `png`.
void plot_timeline(const Problem& problem, const EpisodeResult& shown, const std::filesystem::path& data,
                   const std::filesystem::path& png, const std::string& title);

}  // namespace ontime::cli
