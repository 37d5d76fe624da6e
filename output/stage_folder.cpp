#include "output/stage_folder.h"

#include <filesystem>

#include "core/error.h"
#include "core/json_reader.h"
#include "geometry/mesh_io.h"
#include "output/result_files.h"
#include "output/result_writer.h"
#include "vision/dataset.h"

namespace subflow::output {

namespace fs = std::filesystem;

namespace {

constexpr geometry::PlyFormat kExact = geometry::PlyFormat::kBinaryLittleEndianDouble;

std::string ReportPath(const std::string& folder) { return (fs::path(folder) / "report.json").string(); }

// A mesh of the folder, without the manifold check (the stage that wrote it had it).
geometry::TriangleMesh ReadStageMesh(const fs::path& path) {
  if (!fs::exists(path)) ThrowError(path.string(), "", "missing (expected a file of the stage folder)");
  geometry::MeshReadOptions options;
  options.require_manifold = false;
  return geometry::ReadMesh(path.string(), options);
}

}  // namespace

void WriteStageFolder(const std::string& folder, const StageRecord& record,
                      const std::vector<std::vector<geometry::Positions>>* all_levels) {
  const solver::StageState& state = record.state;
  state.Check(folder);
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) ThrowError(folder, "", "cannot create the stage folder: " + error.message());
  fs::remove(ReportPath(folder), error);  // unfinished from here until the new report
  if (error) ThrowError(ReportPath(folder), "", "cannot remove: " + error.message());

  const geometry::LoopHierarchy& hierarchy = state.Hierarchy();
  WriteHullFiles(folder, state.base_mesh, state.first_frame, state.hulls, kExact);
  if (all_levels) {
    WriteControlFiles(folder, hierarchy, state.first_frame, *all_levels, kExact);
    std::vector<geometry::Positions> surfaces;
    for (int i = 0; i < state.frame_count(); ++i) surfaces.push_back(state.Surface(i));
    WriteResultMeshes(folder, state.first_frame, hierarchy.LevelFaces(hierarchy.finest_level()), surfaces);
  } else {
    WriteFinestControlFiles(folder, hierarchy, state.first_frame, state.control, kExact);
  }

  nlohmann::json report = record.report;
  report["stage_layout_version"] = kStageLayoutVersion;
  report["frames"] = {{"first", state.first_frame}, {"count", state.frame_count()}};
  report["reference_frame"] = state.reference_frame;
  report["levels"] = hierarchy.finest_level();
  report["evidence"] = vision::ToString(state.evidence);
  report["image_scales"] = state.image_scales;
  WriteJsonFile(ReportPath(folder), report);
}

bool StageFolderComplete(const std::string& folder) { return fs::is_regular_file(ReportPath(folder)); }

StageRecord ReadStageFolder(const std::string& folder, const std::string& expected_stage) {
  const std::string report_path = ReportPath(folder);
  if (!fs::is_directory(folder)) ThrowError(folder, "", "not a directory (expected a stage folder)");
  if (!StageFolderComplete(folder))
    ThrowError(report_path, "", "missing: the stage that wrote this folder did not finish");
  StageRecord record;
  record.report = ReadJsonFile(report_path, "a stage report (docs/stages.md)");
  const JsonReader reader(report_path);
  const nlohmann::json& report = record.report;
  const long long version = reader.Integer(reader.Required(report, "stage_layout_version", ""),
                                           "stage_layout_version", 0, 1 << 20);
  if (version != kStageLayoutVersion)
    reader.Fail("stage_layout_version", "expected " + std::to_string(kStageLayoutVersion) + ", found " +
                                            std::to_string(version) + " (written by another subflow version)");
  const std::string stage = reader.String(reader.Required(report, "stage", ""), "stage");
  if (!expected_stage.empty() && stage != expected_stage)
    reader.Fail("stage", "expected \"" + expected_stage + "\", found \"" + stage + "\"");
  const nlohmann::json& frames = reader.Required(report, "frames", "");
  const int first = static_cast<int>(reader.Integer(reader.Required(frames, "first", "frames"), "frames.first", 0,
                                                    1 << 30));
  const int count = static_cast<int>(reader.Integer(reader.Required(frames, "count", "frames"), "frames.count", 1,
                                                    1 << 30));
  const int levels = static_cast<int>(reader.Integer(reader.Required(report, "levels", ""), "levels", 0, 6));

  solver::StageState& state = record.state;
  state.first_frame = first;
  state.reference_frame = static_cast<int>(
      reader.Integer(reader.Required(report, "reference_frame", ""), "reference_frame", first, first + count - 1));
  state.evidence = vision::ParseEvidenceSource(reader.String(reader.Required(report, "evidence", ""), "evidence"),
                                               report_path + ": evidence");
  state.image_scales = reader.Numbers(reader.Required(report, "image_scales", ""), -1, "image_scales");
  for (std::size_t k = 0; k < state.image_scales.size(); ++k)
    if (!(state.image_scales[k] > 0 && state.image_scales[k] <= 1))
      reader.Fail("image_scales[" + std::to_string(k) + "]", "expected a scale in (0, 1]");
  const fs::path root(folder);
  state.base_mesh = ReadStageMesh(root / "base_mesh.ply");
  state.hierarchy = std::make_shared<const geometry::LoopHierarchy>(
      state.base_mesh.F, state.base_mesh.vertex_count(), levels, (root / "base_mesh.ply").string());
  for (int frame = first; frame < first + count; ++frame) {
    state.hulls.push_back(ReadStageMesh(root / "hull" / (vision::FrameName(frame) + ".ply")));
    state.control.push_back(ReadStageMesh(ControlFilePath(folder, frame, levels)).V);
  }
  state.Check(folder);
  return record;
}

}  // namespace subflow::output
