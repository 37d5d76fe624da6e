#include "vision/read_calibration.h"

#include "core/error.h"

namespace subflow::vision {

std::vector<std::pair<std::string, std::string>> CalibrationFormats() {
  return {
      {"qualisys", "a Qualisys .qca.txt file (read as Pose2Sim reads it)"},
  };
}

Calibration ReadCalibration(const std::string& format, const std::string& source,
                            const CalibrationReadOptions& options) {
  if (format == "qualisys") return ReadQualisysCalibration(source, options.qualisys);
  std::string list;
  for (const auto& [name, what] : CalibrationFormats()) list += (list.empty() ? "" : ", ") + name;
  ThrowError(format, "FORMAT", "unknown calibration format (expected one of: " + list + ")");
}

}  // namespace subflow::vision
