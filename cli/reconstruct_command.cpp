// `subflow reconstruct DATASET --out DIR`: the product's main job, start to finish —
// shape initialization → motion initialization → stereo refinement (unless --no-refine)
// → rigid / non-rigid split. Writes the OUTPUT.md layout (meshes/<frame>.ply with vx vy vz
// and report.json) and beside it: rigid_vx.., nonrigid_vx.., motion_energy and
// nonrigid_energy vertex properties in the same PLY files, obj/<frame>.obj, hull/,
// base_mesh.ply and control/<frame>/level_<i>.ply (the final control hierarchy).
#include <memory>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "cli/reconstruct_report.h"
#include "cli/report_json.h"
#include "output/result_files.h"
#include "cli/stage_options.h"
#include "core/stopwatch.h"
#include "solver/reconstruction.h"
#include "output/result_writer.h"
#include "vision/dataset.h"

namespace subflow::cli {
namespace {

struct ReconstructArguments {
  std::string dataset;
  std::string out;
  bool overwrite = false;
  bool no_refine = false;
  std::string evidence = "auto";
  solver::ReconstructionOptions options;
};

// Per-frame vertex properties of the flow analysis (rigid and non-rigid flow, energies).
std::map<std::string, std::vector<Eigen::VectorXd>> FlowProperties(const solver::FlowAnalysis& flow) {
  std::map<std::string, std::vector<Eigen::VectorXd>> properties;
  const char* axes[3] = {"x", "y", "z"};
  for (std::size_t f = 0; f < flow.flow.size(); ++f) {
    for (int axis = 0; axis < 3; ++axis) {
      properties[std::string("rigid_v") + axes[axis]].push_back(flow.rigid_flow[f].col(axis));
      properties[std::string("nonrigid_v") + axes[axis]].push_back(flow.non_rigid_flow[f].col(axis));
    }
    properties["motion_energy"].push_back(flow.motion_energy);
    properties["nonrigid_energy"].push_back(flow.non_rigid_energy);
  }
  return properties;
}

void RunReconstruct(const ReconstructArguments& arguments) {
  const Stopwatch start;
  solver::ReconstructionOptions options = arguments.options;
  options.shape.silhouettes.source = vision::ParseEvidenceSource(arguments.evidence, "--evidence");
  options.refine = !arguments.no_refine;
  options.Check();
  const vision::Dataset dataset(arguments.dataset);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);

  ProgressBar progress;
  const solver::ReconstructionResult result = solver::Reconstruct(dataset, options, &progress);
  const geometry::LoopHierarchy& hierarchy = result.hierarchy();
  const int finest = hierarchy.finest_level();
  const int frames = static_cast<int>(result.control.size());

  const Stopwatch write_start;
  std::vector<geometry::Positions> surfaces;
  std::vector<std::vector<geometry::Positions>> levels;
  for (int i = 0; i < frames; ++i) {
    surfaces.push_back(result.Surface(i));
    levels.push_back(result.split.trajectory[i].SynthesizeLevels(hierarchy, finest));
  }
  const solver::FlowAnalysis flow = solver::AnalyzeFlow(surfaces, result.split.rigid);
  output::WriteResultMeshes(arguments.out, result.first_frame, hierarchy.LevelFaces(finest), surfaces,
                            FlowProperties(flow));
  output::WriteObjSequence(arguments.out, result.first_frame, hierarchy.LevelFaces(finest), surfaces);
  output::WriteHullFiles(arguments.out, result.shape);
  output::WriteControlFiles(arguments.out, hierarchy, result.first_frame, levels);
  const double write_seconds =
write_start.Seconds();

  nlohmann::json report = ShapeInitReport(dataset, options.shape, result.shape);
  report["command"] = arguments.no_refine ? "reconstruct --no-refine" : "reconstruct";
  report["output"] = arguments.out;
  report["motion_init"] = MotionInitJson(options.motion, result.motion, result.first_frame);
  if (result.retrack) report["retrack"] = MotionInitJson(options.motion, *result.retrack, result.first_frame);
  if (result.refinement) report["refinement"] = RefinementJson(options.refinement, *result.refinement, result.first_frame);
  report["rigid_motion"] = RigidMotionJson(result.split.rigid, result.first_frame);
  double mean_flow = 0, mean_non_rigid = 0;
  for (int i = 0; i + 1 < frames; ++i) {
    mean_flow += solver::FlowMagnitudes(flow.flow[i]).mean() / (frames - 1);
    mean_non_rigid += solver::FlowMagnitudes(flow.non_rigid_flow[i]).mean() / (frames - 1);
  }
  report["flow"] = {{"mean_flow_per_step", mean_flow},
                    {"mean_non_rigid_flow_per_step", mean_non_rigid},
                    {"output_vertices", surfaces.front().rows()},
                    {"output_faces", hierarchy.FaceCount(finest)}};
  const double total = start.Seconds();
  report["timings_seconds"] = {{"shape_init", result.shape_seconds},
                               {"motion_init", result.motion_seconds},
                               {"refinement", result.refinement_seconds},
                               {"retrack", result.retrack_seconds},
                               {"rigid_split", result.split.seconds},
                               {"writing", write_seconds},
                               {"total", total}};
  report["total_seconds"] = total;
  output::WriteJsonFile((std::filesystem::path(arguments.out) / "report.json").string(), report);

  spdlog::info("reconstruct: {} frames, {} vertices per frame, mean flow {:.4g} per step "
               "(non-rigid {:.4g}); shape {:.1f} s, motion {:.1f} s, refinement {:.1f} s, retrack {:.1f} s, "
               "total {:.1f} s",
               frames, surfaces.front().rows(), mean_flow, mean_non_rigid, result.shape_seconds,
               result.motion_seconds, result.refinement_seconds, result.retrack_seconds, total);
}

}  // namespace

Command AddReconstructCommand(CLI::App& app) {
  auto arguments = std::make_shared<ReconstructArguments>();
  CLI::App* sub = app.add_subcommand(
      "reconstruct", "Multi-view video → time-varying Loop subdivision surface with scene flow "
                     "(shape init, motion init, spatio-temporal stereo, rigid/non-rigid split)");
  AddDatasetAndOutput(sub, &arguments->dataset, &arguments->out, &arguments->overwrite);
  sub->add_flag("--no-refine", arguments->no_refine,
                "Stop after motion initialization (no spatio-temporal stereo refinement)");
  sub->add_flag("!--no-retrack", arguments->options.retrack,
                "Keep the first motion pass (do not re-estimate trajectories on the refined shapes)");
  sub->add_option("--retrack-weight", arguments->options.retrack_weight,
                  "Blend of the second motion pass towards each frame's refined surface (0..1)")
      ->capture_default_str();
  AddShapeInitOptions(sub, &arguments->options.shape, &arguments->evidence);
  AddMotionInitOptions(sub, &arguments->options.motion);
  AddRefinementOptions(sub, &arguments->options.refinement);
  return {sub, [arguments] { RunReconstruct(*arguments); }};
}

}  // namespace subflow::cli
