// `ontime generate-world --rows R --cols C --seed S -o FILE`: writes a generated navigation world
// (an office building of R x C rooms, navigation_generator.hpp) as a world file that `collect`,
// `map` and `run` read with --world. Same options, same seed: the same file. The file and the
// summary are domains::write_generated_world's and the domains report's.

#include <fmt/format.h>

#include "common.hpp"
#include "number_options.hpp"
#include "ontime/domains/navigation_generator.hpp"
#include "ontime/domains/report.hpp"
#include "output_paths.hpp"

namespace ontime::cli {

void add_generate_world_command(CLI::App& app) {
  struct Options {
    domains::BuildingOptions building;
    std::string output;
    bool json = false;
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
  auto& b = options->building;
  add_number_option(*command, "--narrow-min", b.narrow_width_min, "Narrowest narrow door (m)",
                    domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth);
  add_number_option(*command, "--narrow-max", b.narrow_width_max, "Widest narrow door (m)",
                    domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth);
  add_number_option(*command, "--wide-min", b.wide_width_min, "Narrowest other door (m)",
                    domains::kMinBuildingDoorWidth, domains::kMaxBuildingDoorWidth);
  add_number_option(*command, "--wide-max", b.wide_width_max, "Widest other door (m)", domains::kMinBuildingDoorWidth,
                    domains::kMaxBuildingDoorWidth);
  add_number_option(*command, "--empty-rooms", b.empty_room_share, "Share of rooms left empty", 0.0, 1.0);
  add_number_option(*command, "--cluttered-rooms", b.cluttered_room_share,
                    "Share of rooms cluttered with boxes (the rest are furnished against the walls)", 0.0, 1.0);
  add_number_option(*command, "--min-boxes", b.min_boxes, "Fewest boxes in a cluttered room", 0,
                    domains::kMaxBuildingBoxes);
  add_number_option(*command, "--max-boxes", b.max_boxes, "Most boxes in a cluttered room", 0,
                    domains::kMaxBuildingBoxes);
  add_number_option(*command, "--skeletons", b.skeletons,
                    "Skeletons written into the world: its task planner's shortest room paths from the start to "
                    "the goal room (0: none)",
                    0, domains::kMaxBuildingSkeletons);
  add_number_option(*command, "--seed", options->building.seed, "Seed of every random choice");
  command->add_option("--name", options->building.name, "World name (default: building-ROWSxCOLS)");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options] {
    check_outputs({{"--output", options->output}}, {});
    const domains::GeneratedWorld world = domains::write_generated_world(options->building, options->output);
    fmt::print("{}", options->json ? domains::report::to_json(world) + "\n" : domains::report::to_text(world));
  });
}

}  // namespace ontime::cli
