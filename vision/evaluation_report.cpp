// vision/evaluation.h on files: listing and reading the frame meshes, and the report's
// table and JSON.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <regex>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_status.h"
#include "geometry/mesh_io.h"
#include "vision/dataset.h"
#include "vision/evaluation.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

std::string FrameFileName(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.ply", frame);
  return name;
}

void SurfaceAndFlowJson(const SurfaceScores& surface, const FlowScores& flow, nlohmann::json* json) {
  (*json)["accuracy"] = surface.accuracy;
  (*json)["completeness"] = surface.completeness;
  (*json)["chamfer"] = surface.chamfer;
  (*json)["hausdorff"] = surface.hausdorff;
  (*json)["mean_result_to_truth"] = surface.mean_result_to_truth;
  (*json)["mean_truth_to_result"] = surface.mean_truth_to_result;
  if (flow.evaluated) {
    (*json)["flow"] = {{"epe_mean", flow.epe_mean},
                       {"epe_median", flow.epe_median},
                       {"true_motion_mean", flow.true_motion_mean},
                       {"epe_relative", flow.epe_relative},
                       {"epe_normal_mean", flow.epe_normal_mean},
                       {"epe_tangential_mean", flow.epe_tangential_mean}};
  } else {
    (*json)["flow"] = nullptr;
  }
}

nlohmann::json ScoresJson(const FrameScores& scores) {
  nlohmann::json json;
  if (scores.frame >= 0) json["frame"] = scores.frame;
  SurfaceAndFlowJson(scores.surface, scores.flow, &json);
  if (scores.observed.evaluated) {
    nlohmann::json observed;
    SurfaceAndFlowJson(scores.observed.surface, scores.observed.flow, &observed);
    observed["observed_fraction"] = scores.observed.observed_fraction;
    observed["pixel_footprint"] = scores.observed.pixel_footprint;
    observed["accuracy_px"] = scores.observed.accuracy_px;
    json["observed"] = observed;
  }
  return json;
}

std::string ObservedLine(const std::string& label, const FrameScores& s) {
  const ObservedScores& o = s.observed;
  char line[256];
  std::snprintf(line, sizeof(line), "%-8s %11.4g %8.3f %8.4f %11.4g %11.4g %8.4f %11.4g", label.c_str(),
                o.surface.accuracy, o.accuracy_px, o.surface.completeness, o.surface.chamfer, o.surface.hausdorff,
                o.observed_fraction, o.pixel_footprint);
  std::string text = line;
  if (o.flow.evaluated) {
    std::snprintf(line, sizeof(line), " %11.4g %11.4g %8.4f", o.flow.epe_mean, o.flow.true_motion_mean,
                  o.flow.epe_relative);
  } else {
    std::snprintf(line, sizeof(line), " %11s %11s %8s", "-", "-", "-");
  }
  return text + line + "\n";
}

std::string ScoresLine(const std::string& label, const FrameScores& s) {
  char line[256];
  std::snprintf(line, sizeof(line), "%-8s %11.4g %8.4f %11.4g %11.4g", label.c_str(), s.surface.accuracy,
                s.surface.completeness, s.surface.chamfer, s.surface.hausdorff);
  std::string text = line;
  if (s.flow.evaluated) {
    std::snprintf(line, sizeof(line), " %11.4g %11.4g %11.4g %8.4f %11.4g %11.4g", s.flow.epe_mean,
                  s.flow.epe_median, s.flow.true_motion_mean, s.flow.epe_relative, s.flow.epe_normal_mean,
                  s.flow.epe_tangential_mean);
  } else {
    std::snprintf(line, sizeof(line), " %11s %11s %11s %8s %11s %11s", "-", "-", "-", "-", "-", "-");
  }
  return text + line + "\n";
}

}  // namespace

std::vector<std::string> ListFrameMeshes(const std::string& directory, int* first_frame) {
  std::error_code error;
  if (!fs::is_directory(directory, error))
    ThrowError(directory, "", "missing (expected a directory of <frame>.ply meshes, 000000.ply …)");
  const std::regex frame_pattern("^([0-9]{6})\\.ply$");
  std::vector<int> frames;
  for (const auto& entry : fs::directory_iterator(directory)) {
    std::smatch match;
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, match, frame_pattern)) frames.push_back(std::stoi(match[1]));
  }
  if (frames.empty()) ThrowError(directory, "", "no frame meshes (expected 000000.ply, 000001.ply, …)");
  std::sort(frames.begin(), frames.end());
  const int first = first_frame ? frames.front() : 0;
  if (first_frame) *first_frame = first;
  std::vector<std::string> paths;
  for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
    const int f = first + i;
    if (frames[i] != f)
      ThrowError((fs::path(directory) / FrameFileName(f)).string(), "frame " + std::to_string(f),
                 "missing (frames must be contiguous from " + FrameFileName(first) + "; found up to " +
                     FrameFileName(frames.back()) + ")");
    paths.push_back((fs::path(directory) / FrameFileName(f)).string());
  }
  return paths;
}

EvaluationReport EvaluateReconstruction(const std::string& dataset_directory,
                                        const std::string& result_directory,
                                        const EvaluationOptions& given_options, Progress* progress,
                                        const std::string& surfaces) {
  given_options.Check();
  if (surfaces != "meshes" && surfaces != "hull")
    ThrowError("eval", "surfaces", "expected meshes or hull, got \"" + surfaces + "\"");
  EvaluationOptions options = given_options;
  if (surfaces == "hull") options.score_flow = false;
  const std::string truth_directory = (fs::path(dataset_directory) / "groundtruth" / "mesh").string();
  const std::string result_meshes = (fs::path(result_directory) / surfaces).string();
  // Without cameras.json (a folder of ground truth only) there is no observed surface.
  const fs::path cameras_path = fs::path(dataset_directory) / "cameras.json";
  const std::vector<Camera> cameras = EntryExists(cameras_path) ? ReadCamerasJson(cameras_path.string())
                                                               : std::vector<Camera>();
  // A result may cover a contiguous part of the sequence (reconstruct --first-frame/--frames).
  int first = 0;
  const std::vector<std::string> all_truth_paths = ListFrameMeshes(truth_directory);
  const std::vector<std::string> result_paths = ListFrameMeshes(result_meshes, &first);
  if (first + result_paths.size() > all_truth_paths.size())
    ThrowError(result_meshes, "frame count",
               "frames " + FrameFileName(first) + "–" + FrameFileName(first + static_cast<int>(result_paths.size()) - 1) +
                   ", but the ground truth (" + truth_directory + ") has " +
                   std::to_string(all_truth_paths.size()) + " frames");
  const std::vector<std::string> truth_paths(all_truth_paths.begin() + first,
                                             all_truth_paths.begin() + first + result_paths.size());
  geometry::MeshReadOptions read_options;
  read_options.require_manifold = false;  // scoring does not need manifold meshes
  auto load_truth = [&](int f) { return geometry::ReadMesh(truth_paths[f], read_options); };
  auto load_result = [&](int f) {
    geometry::VertexProperties properties;
    EvaluationFrame frame;
    frame.mesh = geometry::ReadMesh(result_paths[f], read_options, &properties);
    const bool has_any = properties.values.count("vx") || properties.values.count("vy") ||
                         properties.values.count("vz");
    if (has_any) {
      geometry::Positions motion(frame.mesh.V.rows(), 3);
      const char* names[3] = {"vx", "vy", "vz"};
      for (int k = 0; k < 3; ++k) {
        const auto found = properties.values.find(names[k]);
        if (found == properties.values.end())
          ThrowError(result_paths[f], names[k], "missing (vx, vy, vz must be given together)");
        if (found->second.size() != frame.mesh.V.rows())
          ThrowError(result_paths[f], names[k], "expected one value per vertex");
        motion.col(k) = found->second;
      }
      frame.motion = std::move(motion);
    }
    return frame;
  };
  EvaluationReport report = EvaluateSequence(static_cast<int>(truth_paths.size()), load_truth, load_result,
                                             options, progress, truth_directory, result_meshes, cameras);
  report.surfaces = surfaces;
  for (FrameScores& frame : report.frames) frame.frame += first;
  return report;
}

std::string EvaluationReport::Table() const {
  char header[512];
  std::snprintf(header, sizeof(header), "%-8s %11s %8s %11s %11s %11s %11s %11s %8s %11s %11s\n", "frame",
                ("accuracy" + std::to_string(static_cast<int>(accuracy_percentile))).c_str(), "complete",
                "chamfer", "hausdorff", "epe_mean", "epe_median", "true_mean", "epe_rel", "epe_normal",
                "epe_tangent");
  std::string table = header;
  for (const FrameScores& frame : frames) table += ScoresLine(FrameFileName(frame.frame).substr(0, 6), frame);
  table += ScoresLine("overall", overall);
  char footer[256];
  std::snprintf(footer, sizeof(footer),
                "completeness threshold %.4g; %d samples per surface and frame; flow from %s\n", threshold,
                samples, flow_source.c_str());
  table += footer;
  if (!overall.observed.evaluated) return table + "observed surface: not scored (no cameras)\n";
  std::snprintf(header, sizeof(header),
                "\nobserved surface: seen by >= %d of %d cameras (visibility tolerance %.4g)\n"
                "%-8s %11s %8s %8s %11s %11s %8s %11s %11s %11s %8s\n",
                min_views, camera_count, visibility_tolerance, "frame",
                ("accuracy" + std::to_string(static_cast<int>(accuracy_percentile))).c_str(), "acc_px", "complete",
                "chamfer", "hausdorff", "observed", "px_size", "epe_mean", "true_mean", "epe_rel");
  table += header;
  for (const FrameScores& frame : frames) table += ObservedLine(FrameFileName(frame.frame).substr(0, 6), frame);
  table += ObservedLine("overall", overall);
  return table;
}

std::string EvaluationReport::Json() const {
  nlohmann::json json;
  json["threshold"] = threshold;
  json["samples"] = samples;
  json["accuracy_percentile"] = accuracy_percentile;
  json["flow_source"] = flow_source;
  json["surfaces"] = surfaces;
  json["camera_count"] = camera_count;
  json["min_views"] = min_views;
  json["visibility_tolerance"] = visibility_tolerance;
  json["overall"] = ScoresJson(overall);
  json["frames"] = nlohmann::json::array();
  for (const FrameScores& frame : frames) json["frames"].push_back(ScoresJson(frame));
  return json.dump(2);
}

}  // namespace subflow::vision
