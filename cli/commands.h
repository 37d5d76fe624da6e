// The registry of subcommands. Each cli/<name>_command.cpp defines one
// `Command Add<Name>Command(CLI::App&)` that adds its subcommand, binds its options and
// returns the action that runs it; AllCommands() lists them.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace subflow::cli {

struct Command {
  CLI::App* subcommand = nullptr;
  std::function<void()> run;  // called after parsing when `subcommand` was given
};

using AddCommandFunction = Command (*)(CLI::App&);

// Every option of `command` as the command line gave it, by its long name (positionals by
// their name): {"IN": "base.ply", "--levels": "2", "--limit": true, "--out": "x.ply"}.
// A value is the text given (a list when given several times or with several values), a
// switch true or false; an option not given records its default as --help shows it, or
// null. Built from CLI11's own record of the parse, so no flag can be left out.
nlohmann::json ArgumentsJson(const CLI::App& command);
// ArgumentsJson of the subcommand being run (set by RunSelected before it runs): every
// command records it in its report as "arguments".
const nlohmann::json& InvocationArguments();

Command AddCheckCommand(CLI::App& app);  // cli/check_command.cpp
Command AddSynthCommand(CLI::App& app);  // cli/synth_command.cpp
Command AddEvalCommand(CLI::App& app);   // cli/eval_command.cpp
Command AddSubdivideCommand(CLI::App& app);  // cli/subdivide_command.cpp
Command AddShapeCommand(CLI::App& app);       // cli/stage_commands.cpp
Command AddHullCommand(CLI::App& app);        // cli/stage_commands.cpp (= shape)
Command AddMotionCommand(CLI::App& app);      // cli/stage_commands.cpp
Command AddRefineCommand(CLI::App& app);      // cli/stage_commands.cpp
Command AddRetrackCommand(CLI::App& app);     // cli/stage_commands.cpp
Command AddSplitCommand(CLI::App& app);       // cli/stage_commands.cpp
Command AddMergeCommand(CLI::App& app);       // cli/stage_commands.cpp
Command AddPlanCommand(CLI::App& app);        // cli/plan_command.cpp
Command AddRunPlanCommand(CLI::App& app);     // cli/plan_command.cpp
Command AddReconstructCommand(CLI::App& app);  // cli/reconstruct_command.cpp
Command AddExportCommand(CLI::App& app);       // cli/export_command.cpp
Command AddImportCommand(CLI::App& app);       // cli/import_command.cpp
Command AddRenderCommand(CLI::App& app);       // cli/render_command.cpp
Command AddViewCommand(CLI::App& app);         // cli/view_command.cpp

inline std::vector<AddCommandFunction> AllCommands() {
  return {
      AddCheckCommand,
      AddSynthCommand,
      AddEvalCommand,
      AddSubdivideCommand,
      AddShapeCommand,
      AddHullCommand,
      AddMotionCommand,
      AddRefineCommand,
      AddRetrackCommand,
      AddSplitCommand,
      AddMergeCommand,
      AddPlanCommand,
      AddRunPlanCommand,
      AddReconstructCommand,
      AddExportCommand,
      AddImportCommand,
      AddRenderCommand,
      AddViewCommand,
  };
}

// Runs the command whose subcommand was parsed. A subflow::Error is printed in one line
// ("subflow <command>: error: ...") and gives exit code 1; success gives 0. SIGINT and
// SIGTERM stop the work at its next progress point (core/interrupt.h): "subflow
// <command>: interrupted: <signal> (finished: <stages>...)", exit code 128 + signal
// (130, 143), no report.json.
int RunSelected(const std::vector<Command>& commands, bool verbose);

}  // namespace subflow::cli
