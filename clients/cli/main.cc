// driftlab: command-line client. Builds the command line from the registered commands
// (commands.h; one file per command) and runs the one given.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "driftlab/spec_error.h"

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
    // --help and --version print and exit 0; a wrong command line is bad input like a bad job,
    // reported on one line (CLI11's own text spans two).
    if (e.get_exit_code() == 0) return app.exit(e);
    std::fprintf(stderr, "error: %s (see driftlab --help)\n",
                 driftlab::MessageText(e.what(), driftlab::kMaxMessageTextBytes).c_str());
    return driftlab::cli::kExitBadJob;
  }
  const auto subcommands = app.get_subcommands();
  const CLI::App* given = subcommands.front();
  for (size_t i = 0; i < registry.size(); ++i) {
    if (given->get_name() == registry[i].name) return runners[i]();
  }
  return driftlab::cli::kExitFailure;  // unreachable: CLI11 accepts registered names only
}
