// What the exports need to know of a result besides its meshes: the frame rate, the
// world units and the dataset it came from. Looked up in this order:
//   dataset   --dataset if given (must hold cameras.json), else report.json's
//             dataset.directory as written (absolute, or relative to the working
//             directory, the result folder or its parent), else none;
//   fps       --fps if given, else report.json's dataset.fps, else the dataset's
//             cameras.json "fps", else kDefaultFps (and fps_source says so);
//   units     report.json's dataset.units, else cameras.json "units", else "" (unknown).
#pragma once

#include <optional>
#include <string>

#include "output/result_reader.h"

namespace subflow::output {

// The frame rate assumed when neither the result nor its dataset gives one: the common
// video rate. Exports say when they use it.
inline constexpr double kDefaultFps = 30.0;

struct ResultMetadata {
  std::string dataset_directory;  // "" when not found
  double fps = kDefaultFps;
  std::string fps_source;         // "--fps", "report.json", "<dataset>/cameras.json" or "default"
  std::string units;              // e.g. "meters"; "" when unknown

  // Display of lengths: metres (and unknown units from a metric rig) are shown as mm.
  double DisplayFactor() const;      // 1000 for metres, 1 otherwise
  std::string DisplayUnit() const;   // "mm", or the units, or "units"
};

// Throws subflow::Error when `dataset_option` is given and holds no cameras.json, or
// when fps_option is not positive.
ResultMetadata ResolveResultMetadata(const ResultReader& result, const std::string& dataset_option,
                                     std::optional<double> fps_option);

}  // namespace subflow::output
