#include "output/stage_folder.h"

#include <algorithm>
#include <filesystem>
#include <functional>

#include <opencv2/imgcodecs.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/file_status.h"
#include "core/json_reader.h"
#include "geometry/mesh_io.h"
#include "output/options_json.h"
#include "output/result_files.h"
#include "output/result_writer.h"
#include "output/stage_frames.h"
#include "vision/dataset.h"

namespace subflow::output {

namespace fs = std::filesystem;

namespace {

constexpr geometry::PlyFormat kExact = geometry::PlyFormat::kBinaryLittleEndianDouble;

std::string ReportPath(const std::string& folder) { return (fs::path(folder) / "report.json").string(); }

// A mesh of the folder, without the manifold check (the stage that wrote it had it).
geometry::TriangleMesh ReadStageMesh(const fs::path& path) {
  if (!EntryExists(path)) ThrowError(path.string(), "", "missing (expected a file of the stage folder)");
  geometry::MeshReadOptions options;
  options.require_manifold = false;
  return geometry::ReadMesh(path.string(), options);
}

// meshes/<frame>.ply: the fitted limit surfaces of the frames first_frame + i, i < count,
// with their motion to the next frame, as WriteResultMeshes writes them, two frames in
// memory at a time rather than the take. control(i): index i's finest control points.
void WriteFittedSurfaces(const std::string& folder, const geometry::LoopHierarchy& hierarchy, int first_frame,
                         int count, const std::function<geometry::Positions(int)>& control) {
  const int finest = hierarchy.finest_level();
  const geometry::Faces& faces = hierarchy.LevelFaces(finest);
  const auto surface_of = [&](int i) { return geometry::Positions(hierarchy.LimitPositions(finest) * control(i)); };
  std::error_code error;
  fs::create_directories(fs::path(folder) / "meshes", error);
  if (error) ThrowError(folder + "/meshes", "", "cannot create the directory: " + error.message());
  geometry::Positions surface = surface_of(0);
  for (int i = 0; i < count; ++i) {
    geometry::Positions next = i + 1 < count ? surface_of(i + 1) : geometry::Positions();
    const geometry::Positions motion = i + 1 < count
                                           ? geometry::Positions(next - surface)
                                           : geometry::Positions(geometry::Positions::Zero(surface.rows(), 3));
    WriteResultMesh(folder, first_frame + i, faces, surface, motion);
    surface = std::move(next);
  }
}

// outlines/<camera index>.png, per camera with an outline (StageState::outlines), and the
// list of their paths relative to the folder ("" for a camera without one); empty when
// the state has none.
nlohmann::json WriteOutlineFiles(const std::string& folder, const std::vector<cv::Mat>& outlines) {
  nlohmann::json paths = nlohmann::json::array();
  if (outlines.empty()) return paths;
  std::error_code error;
  fs::create_directories(fs::path(folder) / "outlines", error);
  if (error) ThrowError(folder + "/outlines", "", "cannot create the directory: " + error.message());
  for (std::size_t k = 0; k < outlines.size(); ++k) {
    if (outlines[k].empty()) {
      paths.push_back("");
      continue;
    }
    const std::string name = "outlines/" + std::to_string(k) + ".png";
    std::vector<uchar> png;
    if (!cv::imencode(".png", outlines[k], png)) ThrowError(folder + "/" + name, "", "cannot encode the outline");
    AtomicFile file((fs::path(folder) / name).string());
    file.stream().write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
    file.Commit();
    paths.push_back(name);
  }
  return paths;
}

// The outlines report.json's "outlines" lists (absent: none), read from their files.
std::vector<cv::Mat> ReadOutlineFiles(const std::string& folder, const nlohmann::json& report,
                                      const JsonReader& reader) {
  std::vector<cv::Mat> outlines;
  if (!report.contains("outlines")) return outlines;
  const nlohmann::json& paths = report["outlines"];
  if (!paths.is_array()) reader.Fail("outlines", "expected an array of file names");
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const std::string field = "outlines[" + std::to_string(k) + "]";
    const std::string name = reader.String(paths[k], field);
    if (name.empty()) {
      outlines.emplace_back();
      continue;
    }
    const fs::path path = fs::path(folder) / name;
    cv::Mat outline = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
    if (outline.empty()) ThrowError(path.string(), "", "missing or unreadable (expected the " + field + " PNG)");
    outlines.push_back(outline);
  }
  return outlines;
}

// Creates `folder` and removes its report.json: unfinished until WriteStageReport.
void BeginStageFolder(const std::string& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) ThrowError(folder, "", "cannot create the stage folder: " + error.message());
  fs::remove(ReportPath(folder), error);
  if (error) ThrowError(ReportPath(folder), "", "cannot remove: " + error.message());
}

// report.json, last: record's report with the layout fields of `state` over `frame_count` frames.
void WriteStageReport(const std::string& folder, const StageRecord& record, int frame_count) {
  const solver::StageState& state = record.state;
  nlohmann::json report = record.report;
  report["stage_layout_version"] = kStageLayoutVersion;
  report["frames"] = {{"first", state.first_frame}, {"count", frame_count}};
  report["reference_frame"] = state.reference_frame;
  // The take's reference frame (shape initialization's), kept through ranges and seeds.
  report["take_reference_frame"] = record.report.value("take_reference_frame", state.reference_frame);
  report["levels"] = state.Hierarchy().finest_level();
  report["evidence"] = vision::ToString(state.evidence);
  report["image_scales"] = state.image_scales;
  const nlohmann::json outlines = WriteOutlineFiles(folder, state.outlines);
  if (outlines.empty())
    report.erase("outlines");
  else
    report["outlines"] = outlines;
  if (state.background_outlines)
    report["background_outlines"] = *state.background_outlines;
  else
    report.erase("background_outlines");
  WriteJsonFile(ReportPath(folder), report);
}

}  // namespace

void WriteStageFolder(const std::string& folder, const StageRecord& record,
                      const std::vector<std::vector<geometry::Positions>>* all_levels) {
  const solver::StageState& state = record.state;
  state.Check(folder);
  BeginStageFolder(folder);
  const geometry::LoopHierarchy& hierarchy = state.Hierarchy();
  WriteHullFiles(folder, state.base_mesh, state.first_frame, state.hulls, kExact);
  if (all_levels) {
    WriteControlFiles(folder, hierarchy, state.first_frame, *all_levels, kExact);
    WriteFittedSurfaces(folder, hierarchy, state.first_frame, state.frame_count(),
                        [&](int i) { return state.control[i]; });
  } else {
    WriteFinestControlFiles(folder, hierarchy, state.first_frame, state.control, kExact);
  }
  WriteStageReport(folder, record, state.frame_count());
}

ShapeStageFolderStore::ShapeStageFolderStore(std::string folder) : folder_(std::move(folder)) {
  BeginStageFolder(folder_);
}

void ShapeStageFolderStore::StoreHull(int frame, const geometry::TriangleMesh& hull) {
  WriteHullFile(folder_, frame, hull, kExact);
}

geometry::TriangleMesh ShapeStageFolderStore::LoadHull(int frame) const { return ReadStageHull(folder_, frame); }

void ShapeStageFolderStore::StoreControl(int frame, const geometry::LoopHierarchy& hierarchy,
                                         const std::vector<geometry::Positions>& levels) {
  WriteFrameControlFiles(folder_, hierarchy, frame, levels, kExact);
  ++frames_fitted_;
}

void FinishShapeStageFolder(const std::string& folder, const StageRecord& record, int frame_count) {
  const solver::StageState& state = record.state;
  geometry::WriteMesh((fs::path(folder) / "base_mesh.ply").string(), state.base_mesh, nullptr, kExact);
  WriteFittedSurfaces(folder, state.Hierarchy(), state.first_frame, frame_count,
                      [&](int i) { return ReadStageControl(folder, state.first_frame + i, state.Hierarchy()); });
  WriteStageReport(folder, record, frame_count);
}

bool StageFolderComplete(const std::string& folder) { return IsFile(ReportPath(folder)); }

StageRecord ReadStageFolderHead(const std::string& folder, const std::string& expected_stage, int first_wanted,
                                int count_wanted, int* frame_count) {
  const std::string report_path = ReportPath(folder);
  if (!IsDirectory(folder)) ThrowError(folder, "", "not a directory (expected a stage folder)");
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
  int first = static_cast<int>(reader.Integer(reader.Required(frames, "first", "frames"), "frames.first", 0,
                                                    1 << 30));
  int count = static_cast<int>(reader.Integer(reader.Required(frames, "count", "frames"), "frames.count", 1,
                                                    1 << 30));
  const int levels = static_cast<int>(reader.Integer(reader.Required(report, "levels", ""), "levels", 0, 6));

  const int reference = static_cast<int>(
      reader.Integer(reader.Required(report, "reference_frame", ""), "reference_frame", first, first + count - 1));
  const int take_reference = report.value("take_reference_frame", reference);
  if (count_wanted > 0) {
    if (first_wanted < first || first_wanted + count_wanted > first + count)
      ThrowError(folder, "frames",
                 "[" + std::to_string(first_wanted) + ", " + std::to_string(first_wanted + count_wanted) +
                     ") is not inside the frames [" + std::to_string(first) + ", " + std::to_string(first + count) +
                     ") of the stage folder");
    first = first_wanted;
    count = count_wanted;
  }
  solver::StageState& state = record.state;
  state.first_frame = first;
  state.reference_frame = std::clamp(count_wanted > 0 ? take_reference : reference, first, first + count - 1);
  state.evidence = vision::ParseEvidenceSource(reader.String(reader.Required(report, "evidence", ""), "evidence"),
                                               report_path + ": evidence");
  state.image_scales = reader.Numbers(reader.Required(report, "image_scales", ""), -1, "image_scales");
  for (std::size_t k = 0; k < state.image_scales.size(); ++k)
    if (!(state.image_scales[k] > 0 && state.image_scales[k] <= 1))
      reader.Fail("image_scales[" + std::to_string(k) + "]", "expected a scale in (0, 1]");
  state.outlines = ReadOutlineFiles(folder, report, reader);
  if (report.contains("background_outlines")) {
    try {
      state.background_outlines = report["background_outlines"].get<vision::SilhouetteOptions>();
    } catch (const std::exception& error) {
      reader.Fail("background_outlines", std::string("expected silhouette options: ") + error.what());
    }
  }
  const fs::path root(folder);
  state.base_mesh = ReadStageMesh(root / "base_mesh.ply");
  state.hierarchy = std::make_shared<const geometry::LoopHierarchy>(
      state.base_mesh.F, state.base_mesh.vertex_count(), levels, (root / "base_mesh.ply").string());
  *frame_count = count;
  return record;
}

geometry::TriangleMesh ReadStageHull(const std::string& folder, int frame) {
  return ReadStageMesh(fs::path(folder) / "hull" / (vision::FrameName(frame) + ".ply"));
}

geometry::Positions ReadStageControl(const std::string& folder, int frame, const geometry::LoopHierarchy& hierarchy) {
  const std::string path = ControlFilePath(folder, frame, hierarchy.finest_level());
  geometry::Positions control = ReadStageMesh(path).V;
  const Eigen::Index expected = hierarchy.VertexCount(hierarchy.finest_level());
  if (control.rows() != expected)
    ThrowError(path, "", std::to_string(control.rows()) + " control points, expected #V(n) = " +
                             std::to_string(expected) + " (the base mesh's hierarchy)");
  return control;
}

StageRecord ReadStageFolder(const std::string& folder, const std::string& expected_stage, int first_wanted,
                            int count_wanted) {
  int count = 0;
  StageRecord record = ReadStageFolderHead(folder, expected_stage, first_wanted, count_wanted, &count);
  solver::StageState& state = record.state;
  const int levels = state.Hierarchy().finest_level();
  for (int frame = state.first_frame; frame < state.first_frame + count; ++frame) {
    state.hulls.push_back(ReadStageHull(folder, frame));
    state.control.push_back(ReadStageMesh(ControlFilePath(folder, frame, levels)).V);
  }
  state.Check(folder);
  return record;
}

StageFolderFrames::StageFolderFrames(const std::string& folder, const std::string& expected_stage) : folder_(folder) {
  // In the body: frame_count_'s initializer would run after head_'s and reset it.
  head_ = ReadStageFolderHead(folder, expected_stage, 0, -1, &frame_count_);
}

geometry::Positions StageFolderFrames::Control(int i) const {
  return ReadStageControl(folder_, first_frame() + i, Hierarchy());
}

geometry::TriangleMesh StageFolderFrames::Hull(int i) const { return ReadStageHull(folder_, first_frame() + i); }


void SeedStageInput(StageRecord* in, const std::string& seed) {
  const nlohmann::json report = ReadJsonFile(ReportPath(seed), "a stage report (docs/stages.md)");
  const int seed_first = report.at("frames").at("first").get<int>();
  const int seed_end = seed_first + report.at("frames").at("count").get<int>();
  solver::StageState& state = in->state;
  const int first = std::max(seed_first, state.first_frame);
  const int end = std::min(seed_end, state.first_frame + state.frame_count());
  if (first >= end)
    ThrowError(seed, "frames",
               "shares no frame with the input's [" + std::to_string(state.first_frame) + ", " +
                   std::to_string(state.first_frame + state.frame_count()) + ")");
  const int frame = std::clamp(report.at("reference_frame").get<int>(), first, end - 1);
  // The seed's velocity at the shared frame, when the seed holds the frame before it (this
  // range continues forwards) or after it (backwards): offered to the first step here as its
  // previous step. Both frames in one read.
  const int direction = frame == state.first_frame && frame - 1 >= seed_first                       ? +1
                        : frame == state.first_frame + state.frame_count() - 1 && frame + 1 < seed_end ? -1
                                                                                                      : 0;
  const StageRecord source = ReadStageFolder(seed, "", std::min(frame, frame - direction), direction != 0 ? 2 : 1);
  if (source.state.base_mesh.F != state.base_mesh.F)
    ThrowError(seed, "base_mesh.ply", "another connectivity than the input's");
  const auto control_at = [&](int f) -> const geometry::Positions& {
    return source.state.control[f - source.state.first_frame];
  };
  state.reference_frame = frame;
  state.control[frame - state.first_frame] = control_at(frame);
  in->report["seed"] = {{"folder", fs::absolute(seed).lexically_normal().string()}, {"frame", frame}};
  if (direction != 0) {
    state.lead_in = solver::MotionLeadIn{direction, control_at(frame) - control_at(frame - direction)};
    in->report["seed"]["lead_in_frame"] = frame - direction;
  }
}

}  // namespace subflow::output
