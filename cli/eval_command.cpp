// `subflow eval DATASET RESULT`: scores a reconstruction (../shared/OUTPUT.md) against the
// dataset's ground truth (vision/evaluation.h); prints a table, optionally writes JSON.
#include <iostream>
#include <memory>
#include <string>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "core/error.h"
#include "geometry/mesh_io.h"
#include "output/overwrite_guard.h"
#include "output/result_writer.h"
#include "solver/rigid/rigid_motion.h"
#include "vision/dataset.h"
#include "vision/evaluation.h"
#include "vision/evaluation_maps.h"

namespace subflow::cli {
namespace {

struct EvalSettings {
  std::string dataset, result, json_path;
  std::string error_maps;  // --error-maps DIR: per-vertex error maps (vision/evaluation_maps.h)
  bool overwrite = false;
  vision::EvaluationOptions options;
  bool hull = false;  // score RESULT/hull/ (visual hulls) instead of RESULT/meshes/
};

Eigen::Matrix3d CayleyRotation(const Eigen::Vector3d& w) {
  Eigen::Matrix3d W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  return (I - 0.5 * W).inverse() * (I + 0.5 * W);
}

double RotationAngleDegrees(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
}

// The rigid motion of every frame step fitted to the true vertices (the ground truth keeps
// its connectivity) and to the result's vertices and their motion (vx vy vz), and the
// angle between the two rotations: how well the rigid part of the motion is recovered.
// Empty when the ground truth changes its vertex count.
nlohmann::json RigidComparison(const std::string& dataset_directory, const std::string& result_directory) {
  namespace fs = std::filesystem;
  int first = 0;
  const std::vector<std::string> result_paths =
      vision::ListFrameMeshes((fs::path(result_directory) / "meshes").string(), &first);
  const std::vector<std::string> truth_paths =
      vision::ListFrameMeshes((fs::path(dataset_directory) / "groundtruth" / "mesh").string());
  geometry::MeshReadOptions read_options;
  read_options.require_manifold = false;
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t i = 0; i + 1 < result_paths.size(); ++i) {
    const geometry::TriangleMesh t0 = geometry::ReadMesh(truth_paths.at(first + i), read_options);
    const geometry::TriangleMesh t1 = geometry::ReadMesh(truth_paths.at(first + i + 1), read_options);
    if (t0.V.rows() != t1.V.rows()) return nlohmann::json::array();
    geometry::VertexProperties properties;
    const geometry::TriangleMesh r0 = geometry::ReadMesh(result_paths[i], read_options, &properties);
    if (!properties.values.count("vx")) return nlohmann::json::array();
    geometry::Positions motion(r0.V.rows(), 3);
    motion.col(0) = properties.values.at("vx");
    motion.col(1) = properties.values.at("vy");
    motion.col(2) = properties.values.at("vz");
    const solver::RigidMotion truth = solver::FitRigidMotion((t0.V + t1.V) / 2.0, t1.V - t0.V);
    const solver::RigidMotion result = solver::FitRigidMotion(r0.V + motion / 2.0, motion);
    const Eigen::Matrix3d Rt = CayleyRotation(truth.omega), Rr = CayleyRotation(result.omega);
    steps.push_back({{"frame", first + static_cast<int>(i)},
                     {"true_rotation_degrees", RotationAngleDegrees(Rt)},
                     {"rotation_degrees", RotationAngleDegrees(Rr)},
                     {"rotation_error_degrees", RotationAngleDegrees(Rr * Rt.transpose())},
                     {"true_non_rigid_rms", truth.rms_residual},
                     {"non_rigid_rms", result.rms_residual}});
  }
  return steps;
}

// Writes DIR/result and DIR/truth, each a result folder (meshes/<frame>.ply with the vertex
// properties error (signed distance), distance (|error|) and views, and report.json naming
// the dataset) that `subflow render --colour-by distance` pictures.
void WriteErrorMaps(const EvalSettings& settings, const vision::EvaluationReport& report) {
  namespace fs = std::filesystem;
  const std::string surfaces = settings.hull ? "hull" : "meshes";
  int first = 0;
  const std::vector<std::string> result_paths =
      vision::ListFrameMeshes((fs::path(settings.result) / surfaces).string(), &first);
  const std::vector<std::string> truth_paths =
      vision::ListFrameMeshes((fs::path(settings.dataset) / "groundtruth" / "mesh").string());
  const fs::path cameras_path = fs::path(settings.dataset) / "cameras.json";
  const std::vector<vision::Camera> cameras =
      fs::exists(cameras_path) ? vision::ReadCamerasJson(cameras_path.string()) : std::vector<vision::Camera>();
  geometry::MeshReadOptions read_options;
  read_options.require_manifold = false;
  for (const char* side : {"result", "truth"}) fs::create_directories(fs::path(settings.error_maps) / side / "meshes");
  auto write = [&](const char* side, int frame, const geometry::TriangleMesh& mesh, const vision::SurfaceErrorMap& map) {
    geometry::VertexProperties properties;
    properties.names = {"error", "distance", "views"};
    properties.values["error"] = map.error;
    properties.values["distance"] = map.error.cwiseAbs();
    properties.values["views"] = map.views.cast<double>();
    geometry::WriteMesh((fs::path(settings.error_maps) / side / "meshes" / (vision::FrameName(frame) + ".ply")).string(),
                        mesh, &properties);
  };
  for (std::size_t i = 0; i < result_paths.size(); ++i) {
    const int frame = first + static_cast<int>(i);
    const geometry::TriangleMesh truth = geometry::ReadMesh(truth_paths.at(frame), read_options);
    const geometry::TriangleMesh result = geometry::ReadMesh(result_paths[i], read_options);
    const vision::FrameErrorMaps maps = vision::ComputeErrorMaps(truth, result, cameras, report.visibility_tolerance);
    write("result", frame, result, maps.result);
    write("truth", frame, truth, maps.truth);
  }
  for (const char* side : {"result", "truth"})
    output::WriteJsonFile((fs::path(settings.error_maps) / side / "report.json").string(),
                          {{"command", "eval --error-maps"},
                           {"side", side},
                           {"result", settings.result},
                           {"surfaces", surfaces},
                           {"dataset", {{"directory", fs::absolute(settings.dataset).string()}}},
                           {"visibility_tolerance", report.visibility_tolerance}});
}

void RunEval(const EvalSettings& settings) {
  if (!settings.json_path.empty()) output::CheckOutputFile(settings.json_path, settings.overwrite, "--json");
  if (!settings.error_maps.empty()) {
    output::PrepareOutputDirectory(settings.error_maps, settings.overwrite);
    for (const char* side : {"result", "truth"}) std::filesystem::remove_all(std::filesystem::path(settings.error_maps) / side);
  }
  ProgressBar progress;
  const vision::EvaluationReport report =
      vision::EvaluateReconstruction(settings.dataset, settings.result, settings.options, &progress,
                                     settings.hull ? "hull" : "meshes");
  std::cout << report.Table();
  const nlohmann::json rigid =
      settings.hull ? nlohmann::json::array() : RigidComparison(settings.dataset, settings.result);
  if (!rigid.empty()) {
    double worst = 0.0, sum = 0.0;
    for (const auto& step : rigid) {
      worst = std::max(worst, step["rotation_error_degrees"].get<double>());
      sum += step["rotation_error_degrees"].get<double>();
    }
    std::printf("rigid motion per step: rotation error mean %.4f deg, max %.4f deg (%zu steps)\n",
                sum / rigid.size(), worst, rigid.size());
  }
  std::cout.flush();
  if (!settings.json_path.empty()) {
    nlohmann::json json = nlohmann::json::parse(report.Json());
    json["rigid_motion"] = rigid;
    json["command"] = "eval";
    json["arguments"] = InvocationArguments();
    output::WriteJsonFile(settings.json_path, json);
  }
  if (!settings.error_maps.empty()) WriteErrorMaps(settings, report);
}

}  // namespace

Command AddEvalCommand(CLI::App& app) {
  auto settings = std::make_shared<EvalSettings>();
  CLI::App* command = app.add_subcommand(
      "eval", "Score a reconstruction against ground truth: accuracy, completeness, Chamfer, Hausdorff, "
              "scene-flow end-point error, on the whole and on the observed surface (seen by --min-views cameras)");
  command->add_option("dataset", settings->dataset, "Dataset directory (with groundtruth/mesh/)")->required();
  command->add_option("result", settings->result, "Result directory (with meshes/)")->required();
  command->add_option("--json", settings->json_path,
                      "Also write the figures to this JSON file (an existing file is refused without --overwrite)");
  command->add_flag("--overwrite", settings->overwrite, "Replace the --json file / --error-maps folder if it exists");
  command->add_option("--error-maps", settings->error_maps,
                      "Also write per-vertex error maps to this folder: result/ and truth/, result folders whose "
                      "meshes carry error (signed distance to the other surface), distance and views; "
                      "picture them with `subflow render DIR/truth --colour-by distance`");
  command->add_option("--threshold", settings->options.threshold,
                      "Completeness distance (world units); 0 = 1 % of the true bounding-box diagonal")
      ->capture_default_str();
  command->add_option("--samples", settings->options.samples, "Area-weighted samples per surface and frame")
      ->capture_default_str();
  command->add_option("--min-views", settings->options.min_views,
                      "Observed surface: true surface seen by at least this many cameras (z-buffer visibility)")
      ->capture_default_str();
  command->add_option("--visibility-tolerance", settings->options.visibility_tolerance,
                      "Depth tolerance of the visibility test (world units); 0 = 0.25 % of the true bbox diagonal")
      ->capture_default_str();
  command->add_flag("--hull", settings->hull,
                    "Score RESULT/hull/ (the visual hulls of `subflow hull`) instead of RESULT/meshes/: surfaces only");
  return {command, [settings] { RunEval(*settings); }};
}

}  // namespace subflow::cli
