// `subflow render RESULT [--dataset D] --out DIR`: pictures of a result (PNG, optionally
// MP4) through the project's z-buffer — flow and non-rigid flow magnitude with colour
// bars from the dataset's cameras and a turntable of new views, textured new views,
// overlays on the input images and contact sheets (output/result_pictures.h).
// Writes DIR/report.json with every picture, its surface pixels and colour bar.
#include <iostream>
#include <memory>
#include <optional>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "output/report.h"
#include "core/stopwatch.h"
#include "output/result_metadata.h"
#include "output/result_pictures.h"
#include "output/result_reader.h"
#include "output/result_writer.h"

namespace subflow::cli {
namespace {

struct RenderArguments {
  std::string result;
  std::string dataset;
  std::string out;
  std::vector<int> frames;
  std::optional<double> fps;
  bool no_dataset = false;
  bool overwrite = false;
  output::RenderOptions options;
};

void RunRender(const RenderArguments& arguments) {
  const Stopwatch stopwatch;
  const output::ResultReader result(arguments.result);
  const output::ResultMetadata metadata =
      output::ResolveResultMetadata(result, arguments.no_dataset ? "" : arguments.dataset, arguments.fps);
  std::unique_ptr<vision::Dataset> dataset;
  if (!arguments.no_dataset && !metadata.dataset_directory.empty())
    dataset = std::make_unique<vision::Dataset>(metadata.dataset_directory);
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  output::RenderOptions options = arguments.options;
  options.frames = arguments.frames;
  ProgressBar progress;
  const output::RenderSummary summary =
      output::RenderResultPictures(result, dataset.get(), metadata, arguments.out, options, &progress);
  nlohmann::json report = summary.Json();
  report["command"] = "render";
  report["arguments"] = InvocationArguments();
  report["versions"] = output::VersionsJson();
  report["result"] = arguments.result;
  report["dataset"] = metadata.dataset_directory;
  report["fps"] = metadata.fps;
  report["seconds"] = stopwatch.Seconds();
  output::WriteJsonFile(arguments.out + "/report.json", report);
  std::cout << arguments.out << ": " << summary.pictures.size() << " pictures"
            << (dataset ? " from " + std::to_string(dataset->camera_count()) + " cameras of " + metadata.dataset_directory
                        : std::string(" (no dataset: turntable only)"))
            << " in " << stopwatch.Seconds() << " s\n";
}

}  // namespace

Command AddRenderCommand(CLI::App& app) {
  auto arguments = std::make_shared<RenderArguments>();
  output::RenderOptions& options = arguments->options;
  CLI::App* command = app.add_subcommand(
      "render", "Pictures of a result: flow and non-rigid flow magnitude with colour bars from the dataset's cameras "
                "and a turntable, textured new views, overlays on the input images, contact sheets, optional MP4.");
  command->add_option("RESULT", arguments->result, "Result folder (meshes/<frame>.ply, report.json)")->required();
  command->add_option("--out,-o", arguments->out, "Output directory (new or empty)")->required();
  command->add_option("--dataset", arguments->dataset, "The result's dataset (default: report.json's dataset.directory)");
  command->add_flag("--no-dataset", arguments->no_dataset, "Draw only the turntable (no input cameras or images)");
  command->add_option("--frames", arguments->frames, "Frames to picture (default: first, middle, last)")->delimiter(',');
  command->add_option("--turntable-frame", options.turntable_frame, "Frame of the turntable and textured views (default: middle)");
  command->add_option("--views", options.turntable.count, "New views around the object (0: none)")
      ->capture_default_str()->check(CLI::Range(0, 360));
  command->add_option("--view-width", options.turntable.width, "Width of new views (px)")->capture_default_str()->check(CLI::Range(16, 8192));
  command->add_option("--view-height", options.turntable.height, "Height of new views (px)")->capture_default_str()->check(CLI::Range(16, 8192));
  command->add_option("--elevation", options.turntable.elevation_degrees, "Elevation of new views (degrees)")
      ->capture_default_str()->check(CLI::Range(-89.0, 89.0));
  command->add_flag("!--no-textured", options.textured, "No textured new views");
  command->add_flag("!--no-overlays", options.overlays, "No overlays or contact sheets");
  command->add_flag("--mp4", options.mp4, "Also an MP4 of the overlays per camera (every frame)");
  command->add_option("--fps", arguments->fps, "MP4 frame rate (default: the result's)");
  command->add_flag("--overwrite", arguments->overwrite, "Write into a non-empty output directory");
  command->add_option("--colour-by", options.colour_by,
                      "Colour by this scalar vertex property instead of the flows (e.g. distance of "
                      "`subflow eval --error-maps`)");
  command->add_option("--colour-range", options.colour_range, "MIN,MAX of the --colour-by scale (world units)")
      ->delimiter(',')->expected(2);
  command->footer("Example: subflow render out/result --out out/pictures --frames 0,12,23 --mp4");
  return {command, [arguments] { RunRender(*arguments); }};
}

}  // namespace subflow::cli
