// `subflow import FORMAT SOURCE --out DATASET`: a rig's calibration as its tool wrote it
// (vision/read_calibration.h) and the cameras' videos or images become a dataset in the
// layout of ../shared/DATASET.md (vision/dataset_import.h, docs/import.md), plus
// DATASET/report.json (what was read, the conventions applied, the working volume).
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "output/report.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "output/result_writer.h"
#include <filesystem>


#include "vision/calibration_preview.h"
#include "vision/dataset.h"
#include "vision/dataset_import.h"
#include "vision/dataset_writer.h"
#include "vision/read_calibration.h"

namespace subflow::cli {
namespace {

struct ImportArguments {
  std::string format, source, out, link = "symlink";
  bool preview = false;
  std::vector<double> bounds;
  int frames = 0;
  vision::CalibrationReadOptions read;
  vision::DatasetImportOptions options;
};

nlohmann::json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json ImportReport(const ImportArguments& arguments, const vision::DatasetImportResult& result,
                            const vision::Dataset& dataset, double seconds) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const auto& camera : result.cameras)
    cameras.push_back({{"name", camera.name},
                       {"width", camera.width},
                       {"height", camera.height},
                       {"centre", Vector(camera.centre)},
                       {"intrinsics_scaled_by", camera.rescaled},
                       {"media", camera.media},
                       {"media_frames", camera.media_frames}});
  const vision::DatasetImportOptions& o = arguments.options;
  return {{"command", "import"},
          {"arguments", InvocationArguments()},
          {"format", arguments.format},
          {"source", arguments.source},
          {"options",
           {{"videos", o.videos}, {"images", o.images}, {"name_pattern", o.name_pattern}, {"link", arguments.link},
            {"skip_unmatched", o.skip_unmatched}, {"frames", arguments.frames}, {"bounds", arguments.bounds},
            {"units", o.units}, {"floor", o.floor}, {"min_camera_fraction", o.working_volume.min_camera_fraction},
            {"binning", arguments.read.qualisys.binning_factor},
            {"qualisys_raw_distortion", arguments.read.qualisys.raw_distortion},
            {"colmap_names", arguments.read.colmap_names}}},
          {"cameras", cameras},
          {"frame_count", result.frame_count},
          {"fps", result.fps ? nlohmann::json(*result.fps) : nlohmann::json()},
          {"units", result.units},
          {"bounds", {{"min", Vector(result.bounds.min)}, {"max", Vector(result.bounds.max)},
                      {"origin", result.bounds_origin}}},
          {"skipped_cameras", result.skipped_cameras},
          {"unused_entries", result.unused_entries},
          {"notes", result.notes},
          {"dataset", output::DatasetJson(dataset)},
          {"seconds", seconds},
          {"versions", output::VersionsJson()}};
}

// <out>/preview/<camera>.png: frame 0 with the volume, the floor grid and the axes.
void WritePreviews(const vision::Dataset& dataset, const vision::Calibration& calibration,
                   const vision::DatasetImportOptions& options) {
  vision::PreviewOptions preview;
  if (options.floor == "auto") {
    preview.up = calibration.up;
  } else if (options.floor != "none") {
    Eigen::Vector3d up = Eigen::Vector3d::Zero();
    up[options.floor[1] - 'x'] = options.floor[0] == '-' ? -1 : 1;
    preview.up = up;
  }
  preview.grid_spacing = std::max(0.05, std::pow(10.0, std::floor(std::log10(dataset.bounds().Diagonal()))) / 2);
  const std::filesystem::path folder = std::filesystem::path(dataset.directory()) / "preview";
  std::filesystem::create_directories(folder);
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const cv::Mat image = vision::DrawCalibrationPreview(dataset.camera(c), dataset.Image(c, 0), dataset.bounds(), preview);
    const std::string path = (folder / (dataset.camera(c).name() + ".png")).string();
    vision::WritePng(path, image);
  }
}

void RunImport(ImportArguments arguments) {
  const Stopwatch stopwatch;
  vision::DatasetImportOptions& options = arguments.options;
  if (arguments.link == "symlink") options.link = vision::LinkMode::kSymlink;
  else if (arguments.link == "hard") options.link = vision::LinkMode::kHardLink;
  else options.link = vision::LinkMode::kCopy;
  if (!arguments.bounds.empty()) {
    if (arguments.bounds.size() != 6)
      ThrowError("--bounds", "", "expected 6 numbers xmin,ymin,zmin,xmax,ymax,zmax");
    vision::Bounds box;
    box.min = Eigen::Vector3d(arguments.bounds[0], arguments.bounds[1], arguments.bounds[2]);
    box.max = Eigen::Vector3d(arguments.bounds[3], arguments.bounds[4], arguments.bounds[5]);
    options.bounds = box;
  }
  if (arguments.frames > 0) options.frames = arguments.frames;
  options.Check();
  vision::CheckDatasetDirectory(arguments.out, options.overwrite);  // before any work
  const vision::Calibration calibration = vision::ReadCalibration(arguments.format, arguments.source, arguments.read);
  ProgressBar progress;
  const vision::DatasetImportResult result = vision::ImportDataset(calibration, arguments.out, options, &progress);
  // The written dataset must open as any other (vision::Dataset checks the whole layout).
  const vision::Dataset dataset(arguments.out);
  if (arguments.preview) WritePreviews(dataset, calibration, options);
  output::WriteJsonFile(arguments.out + "/report.json", ImportReport(arguments, result, dataset, stopwatch.Seconds()));

  std::ostringstream text;
  text.precision(4);
  text << "import " << arguments.format << ": " << result.cameras.size() << " cameras, " << result.frame_count
       << " frames";
  if (result.fps) text << " at " << *result.fps << " fps";
  text << "\n";
  for (const auto& camera : result.cameras)
    text << "  " << camera.name << "  " << camera.width << "x" << camera.height << "  centre ["
         << camera.centre.transpose() << "]" << (result.units.empty() ? "" : " m")
         << (camera.media.empty() ? "" : "  " + camera.media) << "\n";
  text << "bounds: min [" << result.bounds.min.transpose() << "] max [" << result.bounds.max.transpose() << "] ("
       << result.bounds_origin << ")\n";
  for (const std::string& note : result.notes) text << "note: " << note << "\n";
  if (!result.skipped_cameras.empty()) {
    text << "skipped (no media):";
    for (const std::string& name : result.skipped_cameras) text << " " << name;
    text << "\n";
  }
  if (!result.unused_entries.empty()) {
    text << "unused entries of the media folder:";
    for (const std::string& entry : result.unused_entries) text << " " << entry;
    text << "\n";
  }
  text << "written to " << arguments.out << " (opens as a dataset: " << dataset.camera_count() << " cameras, "
       << dataset.frame_count() << " frames) in " << stopwatch.Seconds() << " s\n";
  std::cout << text.str();
}

}  // namespace

Command AddImportCommand(CLI::App& app) {
  auto arguments = std::make_shared<ImportArguments>();
  std::string formats;
  for (const auto& [name, what] : vision::CalibrationFormats()) formats += "\n  " + name + ": " + what;
  CLI::App* command = app.add_subcommand(
      "import", "Turn a rig's calibration (as its tool wrote it) and its videos or images into a dataset. "
                "FORMAT and SOURCE:" + formats);
  std::vector<std::string> names;
  for (const auto& [name, what] : vision::CalibrationFormats()) names.push_back(name);
  command->add_option("format", arguments->format, "Calibration format")->required()->check(CLI::IsMember(names));
  command->add_option("source", arguments->source, "Calibration file or folder")->required();
  command->add_option("--out,-o", arguments->out, "Dataset directory to write (new or empty)")->required();
  auto* videos = command->add_option("--videos", arguments->options.videos,
                                     "Folder with one video per camera (matched by name, docs/import.md)");
  command->add_option("--images", arguments->options.images,
                      "Folder with one image folder (or one still) per camera")->excludes(videos);
  command->add_option("--name-pattern", arguments->options.name_pattern,
                      "Regex whose first group, searched in a file name, is the camera name");
  command->add_option("--link", arguments->link, "How frames enter the dataset: symlink, hard or copy")
      ->check(CLI::IsMember({"symlink", "hard", "copy"}))->capture_default_str();
  command->add_flag("--skip-unmatched", arguments->options.skip_unmatched,
                    "Leave out the calibration's cameras that have no video / images");
  command->add_option("--frames", arguments->frames, "Frames to keep (the first N; default all)");
  command->add_option("--bounds", arguments->bounds,
                      "Working volume xmin,ymin,zmin,xmax,ymax,zmax in metres (default: derived)")->delimiter(',');
  command->add_option("--units", arguments->options.units,
                      "Unit of the calibration's translations: m, cm or mm (default: the format's)")
      ->check(CLI::IsMember({"m", "cm", "mm"}));
  command->add_option("--floor", arguments->options.floor,
                      "Up axis of the floor plane through the origin that clips the derived volume: auto (the "
                      "format's), none, +x, -x, +y, -y, +z, -z")->capture_default_str();
  command->add_option("--min-camera-fraction", arguments->options.working_volume.min_camera_fraction,
                      "Derived volume: seen by at least this fraction of the cameras")->capture_default_str();
  command->add_option("--binning", arguments->read.qualisys.binning_factor,
                      "qualisys: Pose2Sim's binning factor")->capture_default_str();
  command->add_flag("--qualisys-raw-distortion", arguments->read.qualisys.raw_distortion,
                    "qualisys: distortion coefficients as printed, not divided by 64 as Pose2Sim does");
  command->add_option("--colmap-names", arguments->read.colmap_names,
                      "colmap: camera name from the image's file stem or its folder")
      ->check(CLI::IsMember({"stem", "folder"}))->capture_default_str();
  command->add_flag("--preview", arguments->preview,
                    "Write DATASET/preview/<camera>.png: frame 0 with the volume, floor grid and axes drawn");
  command->add_flag("--overwrite", arguments->options.overwrite, "Replace the dataset in a non-empty directory");
  return {command, [arguments] { RunImport(*arguments); }};
}

}  // namespace subflow::cli
