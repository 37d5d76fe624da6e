#include "cli/commands.h"

#include <iostream>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/interrupt.h"

namespace subflow::cli {

int RunSelected(const std::vector<Command>& commands, bool verbose) {
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  InstallInterruptHandlers();
  for (const Command& command : commands) {
    if (!command.subcommand->parsed()) continue;
    const std::string name = command.subcommand->get_name();
    try {
      command.run();
      return 0;
    } catch (const Interrupted& e) {
      // Temporaries are gone (unwinding destroyed their AtomicFiles); files already
      // committed are complete, and the missing report.json marks the output unfinished.
      std::cerr << "\nsubflow " << name << ": interrupted: " << e.what()
                << "; the output is incomplete (no report.json written)\n";
      return 128 + e.signal_number();
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
