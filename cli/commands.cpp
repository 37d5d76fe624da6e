#include "cli/commands.h"

#include <iostream>

#include <spdlog/spdlog.h>

#include "core/error.h"

namespace subflow::cli {

int RunSelected(const std::vector<Command>& commands, bool verbose) {
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  for (const Command& command : commands) {
    if (!command.subcommand->parsed()) continue;
    const std::string name = command.subcommand->get_name();
    try {
      command.run();
      return 0;
    } catch (const subflow::Error& e) {
      std::cerr << "subflow " << name << ": error: " << e.what() << "\n";
      return 1;
    } catch (const std::exception& e) {
      std::cerr << "subflow " << name << ": internal error: " << e.what() << "\n";
      return 2;
    }
  }
  std::cerr << "subflow: no subcommand given (see --help)\n";
  return 1;
}

}  // namespace subflow::cli
