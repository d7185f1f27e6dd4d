// `ontime generate-world --rows R --cols C --seed S -o FILE`: writes a generated navigation world
// (an office building of R x C rooms, navigation_generator.hpp) as a world file that `collect`,
// `map` and `run` read with --world. Same options, same seed: the same file.

#include <fmt/format.h>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/domains/navigation_generator.hpp"
#include "ontime/util/atomic_file.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_generate_world_command(CLI::App& app) {
  struct Options {
    domains::BuildingOptions building;
    std::string output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command =
      app.add_subcommand("generate-world", "Write a generated navigation world: a building of rows x cols rooms");
  command->add_option("-o,--output", options->output, "World file to write (JSON, docs/domains.md)")->required();
  add_number_option(*command, "--rows", options->building.rows, "Rooms along y", 1, domains::kMaxBuildingSide);
  add_number_option(*command, "--cols", options->building.cols, "Rooms along x", 1, domains::kMaxBuildingSide);
  add_number_option(*command, "--room-size", options->building.room_size, "Side of every (square) room in metres",
                    domains::kMinBuildingRoomSize, domains::kMaxBuildingRoomSize);
  add_number_option(*command, "--door-density", options->building.door_density,
                    "Share of neighbouring rooms joined by a door (at least a spanning tree)", 0.0, 1.0);
  add_number_option(*command, "--narrow-doors", options->building.narrow_door_share,
                    "Share of doors that are narrow (0.76-0.86 m; the others 1.0-1.2 m)", 0.0, 1.0);
  add_number_option(*command, "--seed", options->building.seed, "Seed of every random choice");
  command->add_option("--name", options->building.name, "World name (default: building-ROWSxCOLS)");
  command->callback([options] {
    if (options->building.rows * options->building.cols < 2) throw UsageError("a building needs at least two rooms");
    check_outputs({{"--output", options->output}}, {});
    const std::string text = domains::generate_navigation_world_text(options->building);
    write_file_atomically(options->output, text);
    const domains::NavigationWorld world = domains::parse_navigation_world(text, options->output);
    fmt::print("Wrote {}: {} rooms, {} doors, {} pieces of furniture; start in {}, goal {}.\n", options->output,
               world.rooms.size(), world.doors.size(), world.obstacles.size(), world.start_room, world.goal_room);
  });
}

}  // namespace ontime::cli
