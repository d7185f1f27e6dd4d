// `ontime generate-world --rows R --cols C --seed S -o FILE`: writes a generated navigation world
// (an office building of R x C rooms, navigation_generator.hpp) as a world file that `collect`,
// `map` and `run` read with --world; with `--domain manipulation`, a generated kitchen (a table
// scene with its goal and skeletons, manipulation_generator.hpp). Same options, same seed: the
// same file. The files and the summaries are domains::write_generated_world's and
// domains::write_generated_kitchen's and the domains report's; this only parses the options.

#include <fmt/format.h>

#include "common.hpp"
#include "memory_limits.hpp"
#include "number_options.hpp"
#include "ontime/domains/manipulation_generator.hpp"
#include "ontime/domains/navigation_generator.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/util/error.hpp"
#include "output_paths.hpp"

namespace ontime::cli {
namespace {

// The options of one domain's generator, refused with the other's.
const std::vector<std::string> kBuildingFlags{
    "--rows",     "--cols",     "--room-size",   "--door-density",    "--narrow-doors", "--narrow-min", "--narrow-max",
    "--wide-min", "--wide-max", "--empty-rooms", "--cluttered-rooms", "--min-boxes",    "--max-boxes",  "--skeletons"};
const std::vector<std::string> kKitchenFlags{"--tables",      "--regions",     "--region-min",  "--region-max",
                                             "--targets",     "--min-objects", "--max-objects", "--min-clutter",
                                             "--max-clutter", "--classes"};

void refuse_others(const CLI::App& command, const std::vector<std::string>& flags, const std::string& domain) {
  for (const std::string& flag : flags) {
    if (command.count(flag) > 0) {
      throw UsageError(flag + " is an option of the " + (domain == "navigation" ? "manipulation" : "navigation") +
                       " generator, not of --domain " + domain);
    }
  }
}

}  // namespace

void add_generate_world_command(CLI::App& app) {
  struct Options {
    std::string domain = "navigation";
    domains::BuildingOptions building;
    domains::KitchenOptions kitchen;
    std::uint64_t seed = 1;
    std::string name;
    std::string output;
    bool json = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand(
      "generate-world",
      "Write a generated world: a navigation building of rows x cols rooms, or (--domain manipulation) a kitchen "
      "table scene with its goal and skeletons");
  command->add_option("-o,--output", options->output, "World file to write (JSON, docs/domains.md)")->required();
  command->add_option("--domain", options->domain, "Domain of the world: navigation or manipulation")
      ->check(CLI::IsMember({"navigation", "manipulation"}))
      ->capture_default_str();
  auto& b = options->building;
  add_number_option(*command, "--rows", b.rows, "Rooms along y", 1, domains::kMaxBuildingSide);
  add_number_option(*command, "--cols", b.cols, "Rooms along x", 1, domains::kMaxBuildingSide);
  add_number_option(*command, "--room-size", b.room_size, "Side of every (square) room in metres",
                    domains::kMinBuildingRoomSize, domains::kMaxBuildingRoomSize);
  add_number_option(*command, "--door-density", b.door_density,
                    "Share of neighbouring rooms joined by a door (at least a spanning tree)", 0.0, 1.0);
  add_number_option(*command, "--narrow-doors", b.narrow_door_share,
                    "Share of doors that are narrow (0.76-0.86 m; the others 1.0-1.2 m)", 0.0, 1.0);
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
                    "navigation: skeletons written into the world, its task planner's shortest room paths from the "
                    "start to the goal room (0: none)",
                    0, domains::kMaxBuildingSkeletons);
  auto& k = options->kitchen;
  add_number_option(*command, "--tables", k.tables, "manipulation: tables along the back wall", 1,
                    domains::kMaxKitchenTables);
  add_number_option(*command, "--regions", k.regions, "manipulation: placement regions on the tables", 1,
                    domains::kMaxKitchenRegions);
  add_number_option(*command, "--region-min", k.region_min, "manipulation: shortest side of a region (m)",
                    domains::kMinKitchenRegionSide, domains::kMaxKitchenRegionSide);
  add_number_option(*command, "--region-max", k.region_max, "manipulation: longest side of a region (m)",
                    domains::kMinKitchenRegionSide, domains::kMaxKitchenRegionSide);
  add_number_option(*command, "--targets", k.targets, "manipulation: objects the goal brings to a region", 1,
                    domains::kMaxKitchenTargets);
  add_number_option(*command, "--min-objects", k.min_objects, "manipulation: fewest objects, targets included", 1,
                    domains::kMaxKitchenObjects);
  add_number_option(*command, "--max-objects", k.max_objects, "manipulation: most objects, targets included", 1,
                    domains::kMaxKitchenObjects);
  add_number_option(*command, "--min-clutter", k.min_clutter, "manipulation: fewest neighbours close to a target", 0,
                    domains::kMaxKitchenClutter);
  add_number_option(*command, "--max-clutter", k.max_clutter, "manipulation: most neighbours close to a target", 0,
                    domains::kMaxKitchenClutter);
  command->add_option("--classes", k.classes, "manipulation: object classes drawn, comma-separated (cup, box, bottle)")
      ->delimiter(',')
      ->capture_default_str();
  add_number_option(*command, "--seed", options->seed, "Seed of every random choice");
  command->add_option("--name", options->name, "World name (default: building-ROWSxCOLS, or kitchen)");
  command->add_flag("--json", options->json, "Print JSON");
  command->callback([options, command] {
    check_outputs({{"--output", options->output}}, {});
    if (options->domain == "manipulation") {
      refuse_others(*command, kBuildingFlags, options->domain);
      options->kitchen.name = options->name;
      const domains::GeneratedKitchen world =
          domains::write_generated_kitchen(options->kitchen, options->seed, options->output, flag_spelling());
      fmt::print("{}", options->json ? domains::report::to_json(world) + "\n" : domains::report::to_text(world));
      return;
    }
    refuse_others(*command, kKitchenFlags, options->domain);
    options->building.seed = options->seed;
    options->building.name = options->name;
    const domains::GeneratedWorld world = domains::write_generated_world(options->building, options->output);
    fmt::print("{}", options->json ? domains::report::to_json(world) + "\n" : domains::report::to_text(world));
  });
}

}  // namespace ontime::cli
