// `ontime map --domain NAME`: a picture of the domain's world with one refined motion per
// skeleton (none when the world has no skeletons). The drawing primitives are written first as
// JSON beside the PNG.

#include <fmt/format.h>

#include <filesystem>

#include "common.hpp"
#include "data_paths.hpp"
#include "number_options.hpp"
#include "ontime/domains/collection.hpp"
#include "ontime/domains/registry.hpp"
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
    const domains::Domain& domain = *loaded.domain;
    domains::CollectionOptions settings;
    settings.step_seconds = loaded.defaults.collection.step_seconds;
    settings.budget_steps = loaded.defaults.collection.deadline;
    settings.effort.checks_per_second = loaded.defaults.collection.checks_per_second;
    const std::filesystem::path png = options->output.empty() ? std::filesystem::path(options->domain + "-map.png")
                                                              : std::filesystem::path(options->output);
    std::filesystem::path data = png;
    data.replace_extension(".json");
    check_outputs({{"--output", png}, {"--output (drawing)", data}}, {world});

    const domains::Scene scene = domain.scene();
    Json drawing;
    // A world without skeletons (a generated building) is drawn without motions.
    const auto& skeletons = domain.skeletons();
    drawing["title"] = skeletons.empty()
                           ? scene.title
                           : fmt::format("{}: one refined motion per skeleton (seed {})", scene.title, options->seed);
    drawing["polygons"] = Json::array();
    for (const domains::ScenePolygon& polygon : scene.polygons) {
      drawing["polygons"].push_back({{"kind", polygon.kind},
                                     {"label", polygon.label},
                                     {"view", polygon.view},
                                     {"points", points_json(polygon.points)}});
    }
    drawing["paths"] = Json::array();
    for (std::size_t k = 0; k < skeletons.size(); ++k) {
      const auto motions = domains::refine_skeleton(domain, skeletons[k], stream_seed(options->seed, k), settings);
      std::vector<std::array<double, 2>> points;
      for (const auto& motion : motions) {
        const auto trace = domain.trace(motion);
        points.insert(points.end(), trace.begin() + (points.empty() ? 0 : 1), trace.end());
      }
      const std::vector<domains::Configuration>& last = motions.back();
      drawing["paths"].push_back({{"label", fmt::format("σ{}: {}", k + 1, domain.describe(skeletons[k]))},
                                  {"points", points_json(points)},
                                  {"end", points_json(domain.outline(last.back()))}});
    }
    write_file_atomically(data, drawing.dump(1) + "\n");
    run_python_script("plot_map.py", png, [&](const std::string& figure) {
      return std::vector<std::string>{"--data", data.string(), "--output", figure};
    });
    fmt::print("Wrote {} (data: {}).\n", png.string(), data.string());
  });
}

}  // namespace ontime::cli
