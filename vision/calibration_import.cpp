#include "vision/calibration_import.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"

namespace subflow::vision {

double MetresPerUnit(const std::string& units, const std::string& field) {
  if (units == "m") return 1.0;
  if (units == "cm") return 0.01;
  if (units == "mm") return 0.001;
  ThrowError("", field, "expected m, cm or mm, got \"" + units + "\"");
}

std::vector<Camera> ToCameras(const Calibration& calibration, double metres_per_unit) {
  std::vector<Camera> cameras;
  for (const CalibratedCamera& c : calibration.cameras) {
    if (c.width <= 0 || c.height <= 0)
      ThrowError(c.source, "camera \"" + c.name + "\": image size",
                 "unknown (the calibration has none): give the camera's video or images (--videos / --images)");
    cameras.emplace_back(c.name, c.width, c.height, c.K, c.R, metres_per_unit * c.t, c.distortion, c.source,
                         c.distortion_model);
  }
  return cameras;
}

void CheckCameraNames(const Calibration& calibration, const std::string& source) {
  std::map<std::string, std::string> seen;
  for (const CalibratedCamera& c : calibration.cameras) {
    if (c.name.empty() || c.name == "." || c.name == ".." || c.name.find_first_of("/\\") != std::string::npos)
      ThrowError(c.source.empty() ? source : c.source, "camera name",
                 "expected a non-empty name usable as a folder name (no '/', '\\', \".\" or \"..\"), got \"" +
                     c.name + "\"");
    if (!seen.emplace(c.name, c.source).second)
      ThrowError(c.source.empty() ? source : c.source, "camera name",
                 "expected unique camera names, \"" + c.name + "\" appears twice");
  }
  if (calibration.cameras.empty()) ThrowError(source, "cameras", "none found (expected at least one camera)");
}

std::string ReadCalibrationFile(const std::string& path, const std::string& what) {
  std::ifstream file(path, std::ios::binary);
  if (!file) ThrowError(path, "", "cannot open (expected " + what + ")");
  std::ostringstream text;
  text << file.rdbuf();
  if (file.bad()) ThrowError(path, "", "cannot read (expected " + what + ")");
  return text.str();
}

bool ParseFiniteNumber(const std::string& text, double* value) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double parsed = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(parsed)) return false;  // overflow gives ±inf
  while (*end == ' ' || *end == '\t' || *end == '\r' || *end == '\n') ++end;
  if (*end != '\0') return false;
  *value = parsed;
  return true;
}

}  // namespace subflow::vision
