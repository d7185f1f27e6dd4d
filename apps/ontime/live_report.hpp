#pragma once
// What the commands that run live episodes (`run --live`, `tamp`) report about them: the charges
// of an episode, its timeline as JSON and as the CSV that python/plot_timeline.py draws.

#include <filesystem>
#include <string>

#include "common.hpp"
#include "ontime/model/problem.hpp"
#include "ontime/run/episode_runner.hpp"

namespace ontime::cli {

const char* status_name(Status status);

// The charges of a live episode (prefix "") or their means over a run ("mean_").
void add_charges(Json& out, const LiveTotals& totals, const std::string& prefix);

// A live episode: its status, charges and timeline.
Json live_json(const EpisodeResult& result);

// One row per step of the episode: what the timeline picture draws.
std::string timeline_csv(const Problem& problem, const EpisodeResult& result);

// Draws the episode's timeline (its CSV already written to `data`) into `png`.
void plot_timeline(const Problem& problem, const EpisodeResult& shown, const std::filesystem::path& data,
                   const std::filesystem::path& png, const std::string& title);

}  // namespace ontime::cli
