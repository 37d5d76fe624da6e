// `subflow view RESULT --out viewer.html`: one self-contained HTML page that plays the
// result in any browser without network (output/viewer_writer.h). Writes
// viewer.html.report.json beside it.
#include <iostream>
#include <memory>
#include <optional>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "output/report.h"
#include "core/stopwatch.h"
#include "output/overwrite_guard.h"
#include "output/result_metadata.h"
#include "output/result_reader.h"
#include "output/result_writer.h"
#include "output/viewer_writer.h"

namespace subflow::cli {
namespace {

struct ViewArguments {
  std::string result;
  std::string dataset;
  std::string out;
  std::optional<double> fps;
  bool no_texture = false;
  bool overwrite = false;
  int stride = 0;
  double max_megabytes = 256;
};

void RunView(const ViewArguments& arguments) {
  const Stopwatch stopwatch;
  const output::ResultReader result(arguments.result);
  const output::ResultMetadata metadata = output::ResolveResultMetadata(result, arguments.dataset, arguments.fps);
  output::CheckOutputFile(arguments.out, arguments.overwrite, "");
  std::unique_ptr<vision::Dataset> dataset;
  if (!arguments.no_texture && !metadata.dataset_directory.empty())
    dataset = std::make_unique<vision::Dataset>(metadata.dataset_directory);
  output::ViewerOptions options;
  options.texture = !arguments.no_texture;
  options.title = arguments.result;
  options.stride = arguments.stride;
  options.max_bytes = static_cast<std::size_t>(arguments.max_megabytes * (1 << 20));
  ProgressBar progress;
  const output::ViewerSummary summary =
      output::WriteViewer(result, dataset.get(), metadata, arguments.out, options, &progress);
  output::WriteJsonFile(arguments.out + ".report.json", {{"command", "view"},
                                                         {"arguments", InvocationArguments()},
                                                         {"versions", output::VersionsJson()},
                                                         {"result", arguments.result},
                                                         {"dataset", metadata.dataset_directory},
                                                         {"out", arguments.out},
                                                         {"bytes", summary.bytes},
                                                         {"colourings", summary.colourings},
                                                         {"stride", summary.stride},
                                                         {"frames_in_page", summary.frames_in_page},
                                                         {"max_megabytes", arguments.max_megabytes},
                                                         {"fps", metadata.fps},
                                                         {"fps_source", metadata.fps_source},
                                                         {"seconds", stopwatch.Seconds()}});
  if (arguments.stride == 0 && summary.stride > 1)
    std::cerr << "warning: " << arguments.out << ": every frame would make a page of about "
              << summary.estimated_bytes_all_frames / (1 << 20) << " MB (over --max-megabytes "
              << arguments.max_megabytes << "): the page holds every " << summary.stride << "th frame ("
              << summary.frames_in_page << " of " << result.frame_count()
              << "); choose with --stride, or export a .glb / point cache for every frame\n";
  std::cout << arguments.out << ": " << summary.frames_in_page << " frames of " << result.vertex_count()
            << " vertices, " << summary.bytes << " bytes, colourings";
  for (const std::string& name : summary.colourings) std::cout << " " << name;
  std::cout << " in " << stopwatch.Seconds() << " s\n";
}

}  // namespace

Command AddViewCommand(CLI::App& app) {
  auto arguments = std::make_shared<ViewArguments>();
  CLI::App* command = app.add_subcommand(
      "view", "Write one self-contained HTML page that plays the result in a browser (three.js inside, no network): "
              "orbit controls, frame slider, play/pause, flow or texture colours with their scale.");
  command->add_option("RESULT", arguments->result, "Result folder (meshes/<frame>.ply, report.json)")->required();
  command->add_option("--out,-o", arguments->out, "Output .html")->required();
  command->add_option("--dataset", arguments->dataset, "The result's dataset, for the texture colouring and the up "
                      "direction (default: report.json's dataset.directory)");
  command->add_option("--fps", arguments->fps, "Playback frame rate (default: the result's)");
  command->add_option("--stride", arguments->stride, "Put every K-th frame into the page (default: 1, or the "
                      "smallest K that keeps the page under --max-megabytes)")->check(CLI::PositiveNumber);
  command->add_option("--max-megabytes", arguments->max_megabytes, "Size cap of the page when --stride is not given "
                      "(browsers refuse a page's data over ~512 MB)")->check(CLI::Range(1.0, 480.0));
  command->add_flag("--no-texture", arguments->no_texture, "No texture colouring (smaller page, no dataset read)");
  command->add_flag("--overwrite", arguments->overwrite, "Replace an existing page");
  command->footer("Example: subflow view out/result --out blob.html && chromium blob.html");
  return {command, [arguments] { RunView(*arguments); }};
}

}  // namespace subflow::cli
