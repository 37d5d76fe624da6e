// `subflow hull DATASET --out DIR`: shape initialization (method §4.1) alone.
// Writes DIR/hull/<frame>.ply (visual hulls), DIR/base_mesh.ply (T0),
// DIR/control/<frame>/level_<i>.ply (fitted control meshes), DIR/meshes/<frame>.ply (the
// limit surface on one connectivity, OUTPUT.md layout) and DIR/report.json.
#include <chrono>
#include <filesystem>
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "cli/report_json.h"
#include "output/result_files.h"
#include "cli/stage_options.h"
#include "geometry/mesh_io.h"
#include "output/result_writer.h"
#include "solver/shape/shape_init.h"
#include "vision/dataset.h"

namespace subflow::cli {
namespace {

namespace fs = std::filesystem;

struct HullArguments {
  std::string dataset;
  std::string out;
  bool overwrite = false;
  std::string evidence = "auto";
  solver::ShapeInitOptions options;
};

void RunHull(const HullArguments& arguments) {
  const auto start = std::chrono::steady_clock::now();
  solver::ShapeInitOptions options = arguments.options;
  options.silhouettes.source = vision::ParseEvidenceSource(arguments.evidence, "--evidence");
  options.Check();
  const vision::Dataset dataset(arguments.dataset);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);

  ProgressBar progress;
  const solver::ShapeInitResult result = solver::InitializeShape(dataset, options, &progress);
  const geometry::LoopHierarchy& hierarchy = *result.hierarchy;
  const int finest = hierarchy.finest_level();

  const fs::path out(arguments.out);
  output::WriteHullFiles(arguments.out, result);
  std::vector<geometry::Positions> limit_surfaces;
  std::vector<std::vector<geometry::Positions>> control;
  for (const solver::FrameShapeInit& frame : result.frames) {
    control.push_back(frame.control);
    limit_surfaces.push_back(hierarchy.LimitPositions(finest) * frame.control[finest]);
  }
  output::WriteControlFiles(arguments.out, hierarchy, result.frames.front().frame, control);
  output::WriteResultMeshes(arguments.out, result.frames.front().frame, hierarchy.LevelFaces(finest),
                            limit_surfaces);

  nlohmann::json report = ShapeInitReport(dataset, options, result);
  report["command"] = "hull";
  report["output"] = arguments.out;
  report["total_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  output::WriteJsonFile((out / "report.json").string(), report);

  double iou_sum = 0;
  for (const auto& frame : result.frames) iou_sum += frame.carving.mean_silhouette_iou;
  spdlog::info("hull: {} frames, base mesh {} faces, finest level {} faces, mean silhouette IoU {:.4f}, {:.1f} s",
               result.frames.size(), result.base_mesh.face_count(), hierarchy.FaceCount(finest),
               iou_sum / result.frames.size(), report["total_seconds"].get<double>());
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
