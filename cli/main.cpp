// subflow: multi-view video → time-varying Loop subdivision surface with scene flow.
// Each subcommand lives in its own file and registers itself through cli/commands.h.
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "core/memory.h"

int main(int argc, char** argv) {
  subflow::KeepFreedMemoryForReuse();
  CLI::App app{"subflow " SUBFLOW_VERSION
               " — spatio-temporal stereo with multi-resolution Loop subdivision surfaces"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("subflow ") + SUBFLOW_VERSION);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Log debug messages");
  std::vector<subflow::cli::Command> commands;
  for (auto add_command : subflow::cli::AllCommands()) commands.push_back(add_command(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return subflow::cli::RunSelected(commands, verbose);
}
