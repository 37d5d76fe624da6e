// `subflow eval DATASET RESULT`: scores a reconstruction (../shared/OUTPUT.md) against the
// dataset's ground truth (vision/evaluation.h); prints a table, optionally writes JSON.
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "geometry/error.h"
#include "vision/evaluation.h"

namespace subflow::cli {
namespace {

struct EvalSettings {
  std::string dataset, result, json_path;
  vision::EvaluationOptions options;
};

void RunEval(const EvalSettings& settings) {
  ProgressBar progress;
  const vision::EvaluationReport report =
      vision::EvaluateReconstruction(settings.dataset, settings.result, settings.options, &progress);
  std::cout << report.Table();
  std::cout.flush();
  if (!settings.json_path.empty()) {
    const std::string temporary = settings.json_path + ".tmp";
    {
      std::ofstream file(temporary);
      if (!file) ThrowError(settings.json_path, "", "cannot write");
      file << report.Json() << "\n";
      if (!file) ThrowError(settings.json_path, "", "cannot write");
    }
    if (std::rename(temporary.c_str(), settings.json_path.c_str()) != 0)
      ThrowError(settings.json_path, "", "cannot write (rename failed)");
  }
}

}  // namespace

Command AddEvalCommand(CLI::App& app) {
  auto settings = std::make_shared<EvalSettings>();
  CLI::App* command = app.add_subcommand(
      "eval", "Score a reconstruction against ground truth: accuracy, completeness, Chamfer, Hausdorff, "
              "scene-flow end-point error");
  command->add_option("dataset", settings->dataset, "Dataset directory (with groundtruth/mesh/)")->required();
  command->add_option("result", settings->result, "Result directory (with meshes/)")->required();
  command->add_option("--json", settings->json_path, "Also write the figures to this JSON file");
  command->add_option("--threshold", settings->options.threshold,
                      "Completeness distance (world units); 0 = 1 % of the true bounding-box diagonal")
      ->capture_default_str();
  command->add_option("--samples", settings->options.samples, "Area-weighted samples per surface and frame")
      ->capture_default_str();
  return {command, [settings] { RunEval(*settings); }};
}

}  // namespace subflow::cli
