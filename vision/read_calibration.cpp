#include "vision/read_calibration.h"

#include "core/error.h"
#include "vision/import_colmap.h"
#include "vision/import_easymocap.h"
#include "vision/import_panoptic.h"
#include "vision/import_projection_matrices.h"
#include "vision/import_toml.h"

namespace subflow::vision {

std::vector<std::pair<std::string, std::string>> CalibrationFormats() {
  return {
      {"colmap", "a COLMAP sparse model folder (cameras + images, .bin or .txt)"},
      {"matrices", "a folder of 3x4 projection-matrix files (DTU pos_*.txt, PMVS/Kinovis txt/)"},
      {"middlebury", "a Middlebury *_par.txt file"},
      {"qualisys", "a Qualisys .qca.txt file (read as Pose2Sim reads it)"},
      {"toml", "a Pose2Sim or Anipose Calib.toml (Anipose: add --units mm)"},
      {"easymocap", "a folder with EasyMocap's intri.yml and extri.yml"},
      {"panoptic", "a CMU Panoptic calibration_<seq>.json"},
  };
}

Calibration ReadCalibration(const std::string& format, const std::string& source,
                            const CalibrationReadOptions& options) {
  if (format == "qualisys") return ReadQualisysCalibration(source, options.qualisys);
  if (format == "colmap") {
    ColmapImportOptions colmap;
    colmap.name_from = options.colmap_names == "folder" ? ColmapImportOptions::NameFrom::kParentFolder
                                                        : ColmapImportOptions::NameFrom::kFileStem;
    return ReadColmapModel(source, colmap);
  }
  if (format == "matrices") return ReadProjectionMatrixCalibration(source);
  if (format == "middlebury") return ReadMiddleburyCalibration(source);
  if (format == "toml" || format == "pose2sim" || format == "anipose") return ReadTomlCalibration(source);
  if (format == "easymocap") return ReadEasyMocapCalibration(source);
  if (format == "panoptic") return ReadPanopticCalibration(source);
  std::string list;
  for (const auto& [name, what] : CalibrationFormats()) list += (list.empty() ? "" : ", ") + name;
  ThrowError(format, "FORMAT", "unknown calibration format (expected one of: " + list + ")");
}

}  // namespace subflow::vision
