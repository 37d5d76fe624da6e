#include "cli/commands.h"

#include <filesystem>
#include <iostream>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/interrupt.h"

namespace subflow::cli {
namespace {

nlohmann::json& Invocation() {
  static nlohmann::json arguments = nlohmann::json::object();
  return arguments;
}

}  // namespace

nlohmann::json ArgumentsJson(const CLI::App& command) {
  nlohmann::json arguments = nlohmann::json::object();
  for (const CLI::Option* option : command.get_options()) {
    if (option == command.get_help_ptr()) continue;
    const std::string name =
        option->get_lnames().empty() ? option->get_name(true) : "--" + option->get_lnames().front();
    if (option->get_expected_max() == 0 || option->get_type_size_max() == 0) {  // a switch
      arguments[name] = option->count() > 0;
      continue;
    }
    const std::vector<std::string>& given = option->results();
    if (given.empty())
      arguments[name] = option->get_default_str().empty() ? nlohmann::json() : nlohmann::json(option->get_default_str());
    else if (given.size() == 1)
      arguments[name] = given.front();
    else
      arguments[name] = given;
  }
  return arguments;
}

const nlohmann::json& InvocationArguments() { return Invocation(); }

int RunSelected(const std::vector<Command>& commands, bool verbose) {
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  InstallInterruptHandlers();
  for (const Command& command : commands) {
    if (!command.subcommand->parsed()) continue;
    const std::string name = command.subcommand->get_name();
    Invocation() = ArgumentsJson(*command.subcommand);
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
    } catch (const std::filesystem::filesystem_error& e) {
      // The file system refused a path (a link loop, a name too long, no permission):
      // the user's input, not a bug. Said as every error is: the path, then the reason.
      std::cerr << "subflow " << name << ": error: " << e.path1().string()
                << (e.path2().empty() ? "" : " → " + e.path2().string()) << ": " << e.code().message() << "\n";
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
