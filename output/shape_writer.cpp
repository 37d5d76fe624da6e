#include "output/shape_writer.h"

#include <filesystem>
#include <vector>

#include "output/options_json.h"
#include "output/report.h"
#include "output/result_files.h"
#include "output/result_writer.h"

namespace subflow::output {

void WriteShapeResult(const CommandRun& run, const vision::Dataset& dataset,
                      const solver::ShapeInitOptions& options, const solver::ShapeInitResult& result,
                      const Stopwatch& since_start) {
  const std::string& out = run.out;
  const geometry::LoopHierarchy& hierarchy = *result.hierarchy;
  const int finest = hierarchy.finest_level();
  const int first = result.frames.front().frame;
  WriteHullFiles(out, result);
  std::vector<geometry::Positions> limit_surfaces;
  std::vector<std::vector<geometry::Positions>> control;
  for (const solver::FrameShapeInit& frame : result.frames) {
    control.push_back(frame.control);
    limit_surfaces.push_back(hierarchy.LimitPositions(finest) * frame.control[finest]);
  }
  WriteControlFiles(out, hierarchy, first, control);
  WriteResultMeshes(out, first, hierarchy.LevelFaces(finest), limit_surfaces);

  nlohmann::json report = ReportHead(run, dataset);
  report["options"] = {{"shape_init", options}};
  report["shape_init"] = ShapeInitJson(dataset, options, result);
  report["total_seconds"] = since_start.Seconds();
  WriteJsonFile((std::filesystem::path(out) / "report.json").string(), report);
}

}  // namespace subflow::output
