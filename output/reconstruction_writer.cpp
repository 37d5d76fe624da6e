#include "output/reconstruction_writer.h"

#include <filesystem>

#include "output/options_json.h"
#include "output/report.h"
#include "output/result_files.h"
#include "output/result_writer.h"
#include "output/sequence_writer.h"

namespace subflow::output {

void WriteReconstruction(const CommandRun& run, const vision::Dataset& dataset,
                         const solver::ReconstructionOptions& options, const solver::ReconstructionResult& result,
                         const Stopwatch& since_start) {
  const Stopwatch write_start;
  const std::string& out = run.out;
  const int first = result.first_frame;
  nlohmann::json report = ReportHead(run, dataset);
  report["options"] = options;
  report["shape_init"] = ShapeInitJson(dataset, options.shape, result.shape);
  report["motion_init"] = MotionInitJson(options.motion, result.motion, first);
  if (result.refinement) report["refinement"] = RefinementJson(options.refinement, *result.refinement, first);
  if (result.retrack) report["retrack"] = MotionInitJson(options.RetrackOptions(), *result.retrack, first);
  report["rigid_motion"] = RigidMotionJson(result.split.rigid, first);
  report["flow"] = WriteSequence(out, result.hierarchy(), first, result.control, result.split);
  WriteHullFiles(out, result.shape);
  report["timings_seconds"] = {{"shape_init", result.shape_seconds},
                               {"motion_init", result.motion_seconds},
                               {"refinement", result.refinement_seconds},
                               {"retrack", result.retrack_seconds},
                               {"rigid_split", result.split.seconds},
                               {"writing", write_start.Seconds()},
                               {"total", since_start.Seconds()}};
  report["total_seconds"] = report["timings_seconds"]["total"];
  WriteJsonFile((std::filesystem::path(out) / "report.json").string(), report);
}

}  // namespace subflow::output
