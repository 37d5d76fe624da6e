// `subflow hull DATASET --out DIR`: shape initialization (method §4.1) alone; writes the
// files of output/shape_writer.h.
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "cli/stage_options.h"
#include "core/stopwatch.h"
#include "output/result_writer.h"
#include "output/shape_writer.h"
#include "solver/shape/shape_init.h"
#include "vision/dataset.h"

namespace subflow::cli {
namespace {

struct HullArguments {
  std::string dataset;
  std::string out;
  bool overwrite = false;
  std::string evidence = "auto";
  solver::ShapeInitOptions options;
};

void RunHull(const HullArguments& arguments) {
  const Stopwatch start;
  solver::ShapeInitOptions options = arguments.options;
  options.silhouettes.source = vision::ParseEvidenceSource(arguments.evidence, "--evidence");
  options.Check();
  const vision::Dataset dataset(arguments.dataset);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  ProgressBar progress;
  const solver::ShapeInitResult result = solver::InitializeShape(dataset, options, &progress);
  output::WriteShapeResult({"hull", arguments.out, arguments.overwrite}, dataset, options, result, start);
  spdlog::info("{}", result.BriefReport());
}

}  // namespace

Command AddHullCommand(CLI::App& app) {
  auto arguments = std::make_shared<HullArguments>();
  CLI::App* sub = app.add_subcommand(
      "hull", "Shape initialization (method §4.1): visual hull per frame, base mesh, and a "
              "subdivision surface fitted to every frame on one connectivity");
  AddDatasetAndOutput(sub, &arguments->dataset, &arguments->out, &arguments->overwrite);
  AddShapeInitOptions(sub, &arguments->options, &arguments->evidence);
  return {sub, [arguments] { RunHull(*arguments); }};
}

}  // namespace subflow::cli
