// One entry point over the calibration importers, by format name (what `subflow import
// FORMAT SOURCE` dispatches to). Each importer is also callable alone (vision/import_*.h).
#pragma once

#include <string>
#include <vector>

#include "vision/calibration_import.h"
#include "vision/import_qualisys.h"

namespace subflow::vision {

struct CalibrationReadOptions {
  QualisysImportOptions qualisys;
  // COLMAP: camera named after the image file's stem ("stem") or its folder ("folder").
  std::string colmap_names = "stem";
};

// The format names, with what SOURCE is for each: {"qualisys", "Calib.qca.txt"}, ...
std::vector<std::pair<std::string, std::string>> CalibrationFormats();

// Reads `source` as `format`; throws subflow::Error for an unknown format or a bad file.
Calibration ReadCalibration(const std::string& format, const std::string& source,
                            const CalibrationReadOptions& options = {});

}  // namespace subflow::vision
