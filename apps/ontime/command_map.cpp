// `ontime map --domain NAME`: a picture of the domain's world with one refined motion per
// skeleton (none when the world has no skeletons). The drawing primitives are written first as
// JSON beside the PNG. The drawing is domains::map_drawing (drawing.hpp), its JSON the domains
// report's.

#include <fmt/format.h>

#include <filesystem>
#include <vector>

#include "common.hpp"
#include "data_paths.hpp"
#include "number_options.hpp"
#include "ontime/domains/drawing.hpp"
#include "ontime/domains/registry.hpp"
#include "ontime/domains/report.hpp"
#include "ontime/util/atomic_file.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"

namespace ontime::cli {

void add_map_command(CLI::App& app) {
  struct Options {
    std::string domain;
    std::string world;
    std::string output;
    std::uint64_t seed = 1;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("map", "Draw a domain's world with one refined motion per skeleton (PNG)");
  command->add_option("--domain", options->domain, "Domain")->required();
  command->add_option("--world", options->world, "World file (default: data/domains/DOMAIN.json)");
  add_number_option(*command, "--seed", options->seed, "Seed of the refinements drawn");
  command->add_option(
      "-o,--output", options->output,
      "PNG to write (default: DOMAIN-map.png in the current directory); the drawing goes beside it as .json");
  command->callback([options] {
    const std::filesystem::path world =
        options->world.empty() ? default_world_file(options->domain) : std::filesystem::path(options->world);
    const domains::LoadedDomain loaded = domains::load_domain(options->domain, world);
    const std::filesystem::path png = options->output.empty() ? std::filesystem::path(options->domain + "-map.png")
                                                              : std::filesystem::path(options->output);
    std::filesystem::path data = png;
    data.replace_extension(".json");
    check_outputs({{"--output", png}, {"--output (drawing)", data}}, {world});
    const domains::MapDrawing drawing = domains::map_drawing(*loaded.domain, loaded.defaults, options->seed);
    write_file_atomically(data, domains::report::to_json(drawing) + "\n");
    run_python_script("plot_map.py", png, [&](const std::string& figure) {
      return std::vector<std::string>{"--data", data.string(), "--output", figure};
    });
    fmt::print("Wrote {} (data: {}).\n", png.string(), data.string());
  });
}

}  // namespace ontime::cli
