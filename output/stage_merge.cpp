// MergeStageFolders (declared in output/stage_pipeline.h): file by file, so that memory
// does not grow with the take.
#include <algorithm>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "core/json_reader.h"
#include "geometry/mesh_io.h"
#include "output/result_writer.h"
#include "output/stage_pipeline.h"
#include "vision/dataset.h"

namespace subflow::output {

namespace fs = std::filesystem;

namespace {

struct MergeInput {
  std::string folder;
  nlohmann::json report;
  int first = 0, count = 0;
};

// The input that holds dataset frame `frame` farthest from its range's ends (−1: none).
int SourceOfFrame(const std::vector<MergeInput>& inputs, int frame) {
  int best = -1, best_depth = -1;
  for (int k = 0; k < static_cast<int>(inputs.size()); ++k) {
    const int i = frame - inputs[k].first;
    if (i < 0 || i >= inputs[k].count) continue;
    const int depth = std::min(i, inputs[k].count - 1 - i);
    if (depth > best_depth) best = k, best_depth = depth;
  }
  return best;
}

MergeInput ReadMergeInput(const std::string& folder) {
  // Reading its first frame checks the folder (complete, layout version, files) without
  // holding all of it.
  if (!StageFolderComplete(folder)) ReadStageFolder(folder);  // throws: unfinished
  const nlohmann::json report = ReadJsonFile((fs::path(folder) / "report.json").string(), "a stage report");
  const int first = report.value("frames", nlohmann::json::object()).value("first", 0);
  const StageRecord head = ReadStageFolder(folder, "", first, 1);
  return {folder, head.report, first, head.report["frames"].value("count", 0)};
}

void CheckSameConnectivity(const MergeInput& first, const MergeInput& other) {
  const std::string stage = first.report.value("stage", "");
  if (other.report.value("stage", "") != stage)
    ThrowError(other.folder, "stage", "expected \"" + stage + "\" as in the first input, found \"" +
                                          other.report.value("stage", "") + "\"");
  const auto faces = [](const MergeInput& input) {
    geometry::MeshReadOptions options;
    options.require_manifold = false;
    return geometry::ReadMesh((fs::path(input.folder) / "base_mesh.ply").string(), options).F;
  };
  if (other.report.value("levels", -1) != first.report.value("levels", -1) || faces(other) != faces(first))
    ThrowError((fs::path(other.folder) / "base_mesh.ply").string(), "",
               "another connectivity than the first input's (merge needs ranges run from one shape stage)");
}

// Copies `from` to `to` through "<to>.tmp" and a rename (a directory: every file in it).
void CopyFinished(const fs::path& from, const fs::path& to) {
  if (fs::is_directory(from)) {
    fs::create_directories(to);
    for (const auto& entry : fs::directory_iterator(from)) CopyFinished(entry.path(), to / entry.path().filename());
    return;
  }
  if (!fs::exists(from)) ThrowError(from.string(), "", "missing (expected a file of the stage folder)");
  fs::create_directories(to.parent_path());
  const fs::path temporary = to.string() + ".tmp";
  fs::copy_file(from, temporary, fs::copy_options::overwrite_existing);
  fs::rename(temporary, to);
}

}  // namespace

nlohmann::json MergeStageFolders(const CommandRun& run, const std::vector<std::string>& inputs,
                                 const std::string& folder) {
  if (inputs.empty()) ThrowError("merge", "inputs", "expected at least one stage folder");
  std::vector<MergeInput> parts;
  int first = std::numeric_limits<int>::max(), end = std::numeric_limits<int>::min();
  for (const std::string& input : inputs) {
    parts.push_back(ReadMergeInput(input));
    if (parts.size() > 1) CheckSameConnectivity(parts.front(), parts.back());
    first = std::min(first, parts.back().first);
    end = std::max(end, parts.back().first + parts.back().count);
  }
  std::vector<int> sources;
  for (int frame = first; frame < end; ++frame) {
    sources.push_back(SourceOfFrame(parts, frame));
    if (sources.back() < 0) ThrowError("merge", "frames", "no input holds frame " + std::to_string(frame) + " (a gap)");
  }

  const fs::path out(folder);
  fs::remove(out / "report.json");
  CopyFinished(fs::path(parts.front().folder) / "base_mesh.ply", out / "base_mesh.ply");
  if (fs::exists(fs::path(parts.front().folder) / "outlines"))  // the report's "outlines" lists them
    CopyFinished(fs::path(parts.front().folder) / "outlines", out / "outlines");
  for (int frame = first; frame < end; ++frame) {
    const fs::path source(parts[sources[frame - first]].folder);
    const std::string name = vision::FrameName(frame);
    CopyFinished(source / "hull" / (name + ".ply"), out / "hull" / (name + ".ply"));
    CopyFinished(source / "control" / name, out / "control" / name);
    if (fs::exists(source / "meshes" / (name + ".ply")))
      CopyFinished(source / "meshes" / (name + ".ply"), out / "meshes" / (name + ".ply"));
  }

  nlohmann::json report = parts.front().report;
  report["command"] = run.command;
  report["arguments"] = run.arguments;
  report["output"] = run.out;
  report["overwrite"] = run.overwrite;
  report["frames"] = {{"first", first}, {"count", end - first}};
  report["reference_frame"] =
      std::clamp(report.value("take_reference_frame", report.value("reference_frame", first)), first, end - 1);
  nlohmann::json ranges = nlohmann::json::array(), figures = nlohmann::json::array();
  const std::string section = StageSection(StageNamed(report.value("stage", ""), parts.front().folder));
  for (const MergeInput& part : parts) {
    ranges.push_back({{"folder", fs::absolute(part.folder).lexically_normal().string()},
                      {"frames", part.report["frames"]},
                      {"seed", part.report.value("seed", nlohmann::json())}});
    figures.push_back(part.report.value(section, nlohmann::json()));
  }
  report["merged_from"] = ranges;
  report["frame_sources"] = sources;  // per frame, the index of the input it came from
  report[section] = {{"ranges", figures}};  // each input's figures of its stage
  report.erase("seed");
  WriteJsonFile((out / "report.json").string(), report);
  return report;
}

}  // namespace subflow::output
