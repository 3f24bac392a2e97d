// driftlab: command-line client. Builds the command line from the registered commands
// (commands.h; one file per command) and runs the one given.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"

namespace driftlab::cli {

std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

}  // namespace driftlab::cli

int main(int argc, char** argv) {
  using driftlab::cli::CommandRegistry;
  CLI::App app{"driftlab: inertial navigation error analysis"};
  app.set_version_flag("--version", std::string("driftlab ") + DRIFTLAB_VERSION);
  app.require_subcommand(1);

  auto& registry = CommandRegistry();
  std::sort(registry.begin(), registry.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<std::function<int()>> runners;
  runners.reserve(registry.size());
  for (const auto& entry : registry) runners.push_back(entry.add(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    // --help and --version exit 0; a wrong command line is bad input like a bad job.
    return status == 0 ? driftlab::cli::kExitOk : driftlab::cli::kExitBadJob;
  }
  const auto subcommands = app.get_subcommands();
  const CLI::App* given = subcommands.front();
  for (size_t i = 0; i < registry.size(); ++i) {
    if (given->get_name() == registry[i].name) return runners[i]();
  }
  return driftlab::cli::kExitFailure;  // unreachable: CLI11 accepts registered names only
}
