// `ontime allocators`: every allocator kind of the registry with its summary, capabilities and
// parameters, as tables (Markdown) or JSON. docs/cli.md holds the Markdown output (a test
// checks that it is current).

#include <fmt/format.h>

#include <cmath>

#include "common.hpp"
#include "markdown_table.hpp"

namespace ontime::cli {
namespace {

Json kinds_json() {
  Json out = Json::array();
  for (const AllocatorKind& kind : allocator_registry().kinds()) {
    Json entry;
    entry["name"] = kind.name;
    entry["summary"] = kind.summary;
    entry["capabilities"] = kind.capabilities.names();
    entry["parameters"] = Json::array();
    for (const Parameter& parameter : kind.parameters) {
      Json item;
      item["name"] = parameter.name;
      item["type"] = to_string(parameter.type);
      if (!parameter.default_value.empty()) item["default"] = parameter.default_value;
      if (std::isfinite(parameter.minimum)) item["minimum"] = parameter.minimum;
      if (std::isfinite(parameter.maximum)) item["maximum"] = parameter.maximum;
      if (!parameter.choices.empty()) item["choices"] = parameter.choices;
      item["help"] = parameter.help;
      entry["parameters"].push_back(item);
    }
    out.push_back(entry);
  }
  return out;
}

}  // namespace

std::string allocators_markdown() {
  const AllocatorRegistry& registry = allocator_registry();
  std::vector<std::vector<std::string>> kinds;
  for (const AllocatorKind& kind : registry.kinds()) {
    kinds.push_back(
        {"`" + kind.name + "`", fmt::format("{}", fmt::join(kind.capabilities.names(), ", ")), kind.summary});
  }
  std::vector<std::vector<std::string>> parameters;
  for (const Parameter& parameter : registry.parameters()) {
    parameters.push_back({"`--" + parameter.name + "`",
                          fmt::format("{}", fmt::join(registry.kinds_with_parameter(parameter.name), ", ")),
                          std::string(to_string(parameter.type)),
                          parameter.default_value.empty() ? "none" : parameter.default_value, parameter.allowed(),
                          parameter.help});
  }
  return render_markdown({"allocator", "capabilities", "what it does"}, kinds) + "\n" +
         render_markdown({"parameter", "of", "type", "default", "allowed", "meaning"}, parameters);
}

void add_allocators_command(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  CLI::App* command =
      app.add_subcommand("allocators", "The allocators (--solver NAME) with their capabilities and parameters");
  command->add_flag("--json", *json, "Print JSON");
  command->callback([json] {
    if (*json) {
      print_json(kinds_json());
    } else {
      fmt::print("{}", allocators_markdown());
    }
  });
}

}  // namespace ontime::cli
