#include "output/result_metadata.h"

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "vision/dataset.h"

namespace subflow::output {
namespace {

namespace fs = std::filesystem;

bool HoldsCameras(const fs::path& directory) {
  std::error_code error;
  return fs::is_regular_file(directory / "cameras.json", error);
}

std::string FindDataset(const ResultReader& result, const std::string& dataset_option) {
  if (!dataset_option.empty()) {
    if (!HoldsCameras(dataset_option))
      ThrowError(dataset_option, "", "not a dataset (expected cameras.json in it)");
    return dataset_option;
  }
  const nlohmann::json& report = result.report();
  if (!report.contains("dataset") || !report["dataset"].is_object() ||
      !report["dataset"].contains("directory") || !report["dataset"]["directory"].is_string())
    return "";
  const fs::path recorded = report["dataset"]["directory"].get<std::string>();
  if (recorded.is_absolute()) return HoldsCameras(recorded) ? recorded.string() : "";
  const fs::path folder(result.folder());
  for (const fs::path& base : {fs::path("."), folder, folder.parent_path()})
    if (HoldsCameras(base / recorded)) return (base / recorded).lexically_normal().string();
  return "";
}

}  // namespace

double ResultMetadata::DisplayFactor() const {
  return units == "meters" || units == "metres" || units == "m" ? 1000.0 : 1.0;
}

std::string ResultMetadata::DisplayUnit() const {
  if (DisplayFactor() == 1000.0) return "mm";
  return units.empty() ? "units" : units;
}

ResultMetadata ResolveResultMetadata(const ResultReader& result, const std::string& dataset_option,
                                     std::optional<double> fps_option) {
  ResultMetadata metadata;
  metadata.dataset_directory = FindDataset(result, dataset_option);
  vision::DatasetInfo info;
  if (!metadata.dataset_directory.empty())
    vision::ReadCamerasJson((fs::path(metadata.dataset_directory) / "cameras.json").string(), &info);
  const nlohmann::json& report = result.report();
  const nlohmann::json dataset = report.contains("dataset") ? report["dataset"] : nlohmann::json();
  auto recorded = [&](const char* key) {
    return dataset.is_object() && dataset.contains(key) ? dataset[key] : nlohmann::json();
  };
  if (fps_option) {
    if (!(*fps_option > 0.0) || !std::isfinite(*fps_option))
      ThrowError("--fps", "", "expected a positive frame rate");
    metadata.fps = *fps_option;
    metadata.fps_source = "--fps";
  } else if (recorded("fps").is_number() && recorded("fps").get<double>() > 0.0) {
    metadata.fps = recorded("fps").get<double>();
    metadata.fps_source = (fs::path(result.folder()) / "report.json").string();
  } else if (info.fps) {
    metadata.fps = *info.fps;
    metadata.fps_source = (fs::path(metadata.dataset_directory) / "cameras.json").string();
  } else {
    metadata.fps_source = "default";
  }
  if (recorded("units").is_string()) metadata.units = recorded("units").get<std::string>();
  else metadata.units = info.units;
  return metadata;
}

}  // namespace subflow::output
