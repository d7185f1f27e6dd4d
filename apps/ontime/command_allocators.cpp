// `ontime allocators`: every allocator kind of the registry with its summary, capabilities and
// parameters, as tables (Markdown) or JSON (the report module's). docs/cli.md holds the Markdown
// output (a test checks that it is current).

#include <fmt/format.h>

#include "common.hpp"
#include "memory_limits.hpp"
#include "ontime/report/report.hpp"

namespace ontime::cli {

std::string allocators_markdown() { return report::registry_markdown(allocator_registry(), flag_spelling()); }

void add_allocators_command(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  CLI::App* command =
      app.add_subcommand("allocators", "The allocators (--solver NAME) with their capabilities and parameters");
  command->add_flag("--json", *json, "Print JSON");
  command->callback(
      [json] { fmt::print("{}", *json ? report::registry_json(allocator_registry()) + "\n" : allocators_markdown()); });
}

}  // namespace ontime::cli
