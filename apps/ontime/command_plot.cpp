// `ontime plot INSTANCE`: every action's planning and execution PMF as a histogram (the
// paper's Appendix C), "never" as a bar of its own, in one PNG. The plotted numbers are
// written first, as CSV beside the PNG, so they survive a missing plotting stack.

#include <fmt/format.h>

#include <filesystem>

#include "common.hpp"
#include "ontime/model/instance_io.hpp"
#include "ontime/report/report.hpp"
#include "ontime/util/atomic_file.hpp"
#include "output_paths.hpp"
#include "python_runner.hpp"

namespace ontime::cli {
namespace {

// action,distribution,step,probability: one row per step with positive mass, then "never".
std::string histogram_csv(const Problem& problem) {
  std::string csv = "action,distribution,step,probability\n";
  for (const Action& action : problem.actions()) {
    const std::string quoted = report::csv_field(action.id);
    for (const auto& [kind, distribution] : {std::pair<const char*, const Distribution*>{"planning", &action.planning},
                                             {"execution", &action.execution}}) {
      const auto masses = distribution->masses();
      for (std::size_t t = 0; t < masses.size(); ++t) {
        if (masses[t] > 0) csv += fmt::format("{},{},{},{:.17g}\n", quoted, kind, t, masses[t]);
      }
      csv += fmt::format("{},{},never,{:.17g}\n", quoted, kind, distribution->never());
    }
  }
  return csv;
}

}  // namespace

void add_plot_command(CLI::App& app) {
  struct Options {
    std::string instance;
    std::string output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* command = app.add_subcommand("plot", "Histograms of every action's planning and execution PMF (PNG)");
  command->add_option("INSTANCE", options->instance, "Instance file (JSON, SPEC §5)")->required();
  command->add_option("-o,--output", options->output,
                      "PNG to write (default: INSTANCE's stem + '-histograms.png' in the current directory); "
                      "the plotted data goes beside it as .csv");
  command->callback([options] {
    const Problem problem = load_problem(options->instance);
    std::filesystem::path png =
        options->output.empty()
            ? std::filesystem::path(std::filesystem::path(options->instance).stem().string() + "-histograms.png")
            : std::filesystem::path(options->output);
    std::filesystem::path csv = png;
    csv.replace_extension(".csv");
    check_outputs({{"--output", png}, {"--output (plotted data)", csv}}, {options->instance});
    write_file_atomically(csv, histogram_csv(problem));
    // The name is shortened here already: a command-line argument is limited to 128 KiB.
    const std::string title = fmt::format("{}: deadline {} steps of {} s", shortened_label(problem.name(), 200),
                                          problem.deadline(), problem.step_seconds());
    run_python_script("plot_histograms.py", png, [&](const std::string& drawing) {
      return std::vector<std::string>{"--data",  csv.string(), "--output",   drawing,
                                      "--title", title,        "--deadline", std::to_string(problem.deadline())};
    });
    fmt::print("Wrote {} (data: {}).\n", png.string(), csv.string());
  });
}

}  // namespace ontime::cli
