// MergeStageFolders (declared in output/stage_pipeline.h).
#include <algorithm>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "output/stage_pipeline.h"

namespace subflow::output {

namespace {

// The input that holds dataset frame `frame` farthest from its range's ends (−1: none).
int SourceOfFrame(const std::vector<StageRecord>& records, int frame) {
  int best = -1, best_depth = -1;
  for (int k = 0; k < static_cast<int>(records.size()); ++k) {
    const solver::StageState& state = records[k].state;
    const int i = frame - state.first_frame;
    if (i < 0 || i >= state.frame_count()) continue;
    const int depth = std::min(i, state.frame_count() - 1 - i);
    if (depth > best_depth) best = k, best_depth = depth;
  }
  return best;
}

void CheckSameConnectivity(const StageRecord& first, const StageRecord& other, const std::string& source) {
  const nlohmann::json& a = first.report;
  const nlohmann::json& b = other.report;
  if (a.value("stage", "") != b.value("stage", ""))
    ThrowError(source, "stage", "expected \"" + a.value("stage", "") + "\" as in the first input, found \"" +
                                    b.value("stage", "") + "\"");
  const geometry::LoopHierarchy& h = first.state.Hierarchy();
  if (other.state.Hierarchy().finest_level() != h.finest_level() ||
      other.state.base_mesh.vertex_count() != first.state.base_mesh.vertex_count() ||
      other.state.base_mesh.F != first.state.base_mesh.F)
    ThrowError(source, "base_mesh.ply",
               "another connectivity than the first input's (merge needs ranges run from one shape stage)");
}

}  // namespace

StageRecord MergeStageFolders(const CommandRun& run, const std::vector<std::string>& inputs,
                              const std::string& folder) {
  if (inputs.empty()) ThrowError("merge", "inputs", "expected at least one stage folder");
  std::vector<StageRecord> records;
  int first = std::numeric_limits<int>::max(), end = std::numeric_limits<int>::min();
  for (const std::string& input : inputs) {
    records.push_back(ReadStageFolder(input));
    if (records.size() > 1) CheckSameConnectivity(records.front(), records.back(), input);
    first = std::min(first, records.back().state.first_frame);
    end = std::max(end, records.back().state.first_frame + records.back().state.frame_count());
  }

  StageRecord merged;
  merged.state = records.front().state;
  merged.state.first_frame = first;
  merged.state.hulls.clear();
  merged.state.control.clear();
  nlohmann::json sources = nlohmann::json::array();
  for (int frame = first; frame < end; ++frame) {
    const int k = SourceOfFrame(records, frame);
    if (k < 0) ThrowError("merge", "frames", "no input holds frame " + std::to_string(frame) + " (a gap)");
    const solver::StageState& source = records[k].state;
    merged.state.hulls.push_back(source.hulls[frame - source.first_frame]);
    merged.state.control.push_back(source.control[frame - source.first_frame]);
    sources.push_back(k);
  }
  // The first input's reference frame (moved into the merged range).
  const int reference = records.front().state.reference_frame;
  merged.state.reference_frame = std::clamp(reference, first, end - 1);

  nlohmann::json& report = merged.report;
  report = records.front().report;
  report["command"] = run.command;
  report["output"] = run.out;
  report["overwrite"] = run.overwrite;
  nlohmann::json ranges = nlohmann::json::array();
  for (std::size_t k = 0; k < records.size(); ++k)
    ranges.push_back({{"folder", std::filesystem::absolute(inputs[k]).lexically_normal().string()},
                      {"frames", records[k].report["frames"]}});
  report["merged_from"] = ranges;
  report["frame_sources"] = sources;  // per frame, the index of the input it came from
  // Each input's figures of its own stage, per range.
  const std::string section = StageSection(StageNamed(report.value("stage", ""), inputs.front()));
  nlohmann::json figures = nlohmann::json::array();
  for (const StageRecord& record : records) figures.push_back(record.report.value(section, nlohmann::json()));
  report[section] = {{"ranges", figures}};
  WriteStageFolder(folder, merged);
  return merged;
}

}  // namespace subflow::output
