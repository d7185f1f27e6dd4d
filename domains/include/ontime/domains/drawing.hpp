#pragma once
// What the pictures of a domain draw, as data (report.hpp writes it as the JSON the plot scripts
// read): the map of `ontime map` — the world with one refined motion per skeleton
// (python/plot_map.py) — and the map of one TAMP episode (`ontime tamp --picture`,
// python/plot_tamp.py) — the world, every skeleton the task planner found with the planning
// seconds its actions got, and the motions found.
//
// A map costs one refine_skeleton per skeleton of the world (collection.hpp: up to 20 attempts of
// the world's deadline for each action), the same for the same seed; an episode's drawing only
// reads what the episode left in its world.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ontime/domains/domain.hpp"
#include "ontime/domains/planner_world.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/run/episode_runner.hpp"

namespace ontime::domains {

using Polyline = std::vector<std::array<double, 2>>;

// One skeleton of a map: its caption, the motion refined for it (one polyline through all its
// actions) and the robot's outline where the motion ends.
struct MapPath {
  std::string label;
  Polyline points;
  Polyline end;
};

struct MapDrawing {
  std::string title;
  std::vector<ScenePolygon> polygons;
  std::vector<MapPath> paths;  // none for a world without skeletons (a generated building)
};

// The domain's world and, for skeleton k, the motions refine_skeleton finds from stream k of
// `seed` with the world file's step, deadline (as the cut-off) and checker speed. A skeleton that
// cannot be refined has no points and no end, and its label says why.
MapDrawing map_drawing(const Domain& domain, const DomainDefaults& defaults, std::uint64_t seed);

// A skeleton an episode's task planner found: its planning seconds are those of its actions (an
// action shared by a prefix counts for each skeleton that has it); `points` is the domain's
// skeleton_points (empty when it draws none).
struct EpisodeSkeleton {
  int index = 0;
  std::string label;
  double planning_seconds = 0;
  bool executed = false;
  Polyline points;
};

// A motion the episode found, and whether the plan executed it.
struct EpisodeMotion {
  std::string action;
  bool executed = false;
  Polyline points;
};

struct EpisodeDrawing {
  std::string title;
  std::vector<ScenePolygon> polygons;
  std::vector<EpisodeSkeleton> skeletons;
  std::vector<EpisodeMotion> motions;
};

// The episode `shown` (run with its timeline kept, so `shown.problem` is set) in the streaming
// world that ran it, which still holds its refinements.
EpisodeDrawing episode_drawing(const Domain& domain, const PlannerWorld& world, const EpisodeResult& shown,
                               std::string title);

}  // namespace ontime::domains
