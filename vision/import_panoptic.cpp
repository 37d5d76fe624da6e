#include "vision/import_panoptic.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "vision/camera.h"

namespace subflow::vision {
namespace {

using nlohmann::json;

Eigen::MatrixXd Numbers(const json& value, int rows, int cols, const std::string& source, const std::string& field) {
  // rows × cols nested, or flat with rows·cols numbers (t may be [[x], [y], [z]] or [x, y, z]).
  std::vector<double> flat;
  auto add = [&](const json& number) {
    if (!number.is_number() || !std::isfinite(number.get<double>()))
      ThrowError(source, field, "expected numbers, got " + number.dump());
    flat.push_back(number.get<double>());
  };
  if (!value.is_array()) ThrowError(source, field, "expected an array, got " + value.dump());
  for (const json& item : value) {
    if (item.is_array()) for (const json& number : item) add(number);
    else add(item);
  }
  if (static_cast<int>(flat.size()) != rows * cols)
    ThrowError(source, field, "expected " + std::to_string(rows * cols) + " numbers, got " + std::to_string(flat.size()));
  Eigen::MatrixXd out(rows, cols);
  for (int i = 0; i < rows * cols; ++i) out(i / cols, i % cols) = flat[i];
  return out;
}

}  // namespace

Calibration ParsePanopticCalibration(const std::string& text, const std::string& source) {
  // One mapping of JSON failures (core/json_reader.h): a number like 1e999 is an error
  // naming the field, not an nlohmann exception (found by fuzz/calibration_fuzzer).
  const json root = ParseJson(text, source, "Panoptic's calibration JSON {\"cameras\": [...]}");
  if (!root.is_object() || !root.contains("cameras") || !root["cameras"].is_array())
    ThrowError(source, "cameras", "missing (expected Panoptic's {\"cameras\": [...]})");
  Calibration calibration;
  calibration.format = "panoptic";
  calibration.units = "cm";
  int index = 0;
  for (const json& entry : root["cameras"]) {
    const std::string where = "cameras[" + std::to_string(index++) + "]";
    if (!entry.is_object()) ThrowError(source, where, "expected a camera object");
    for (const char* key : {"name", "resolution", "K", "distCoef", "R", "t"})
      if (!entry.contains(key)) ThrowError(source, where + "." + key, "missing");
    if (!entry["name"].is_string()) ThrowError(source, where + ".name", "expected a string");
    CalibratedCamera camera;
    camera.name = entry["name"].get<std::string>();
    camera.source = source + ": " + where;
    const Eigen::MatrixXd size = Numbers(entry["resolution"], 1, 2, source, where + ".resolution");
    camera.width = ImageSideFromNumber(size(0, 0), source, where + ".resolution[0] (width)");
    camera.height = ImageSideFromNumber(size(0, 1), source, where + ".resolution[1] (height)");
    camera.K = Numbers(entry["K"], 3, 3, source, where + ".K");
    const json& d = entry["distCoef"];
    const int n = d.is_array() ? static_cast<int>(d.size()) : 0;
    if (n != 4 && n != 5 && n != 8) ThrowError(source, where + ".distCoef", "expected 4, 5 or 8 numbers (k1 k2 p1 p2 k3 ...)");
    camera.distortion = Numbers(d, n, 1, source, where + ".distCoef");
    camera.R = Numbers(entry["R"], 3, 3, source, where + ".R");
    camera.t = Numbers(entry["t"], 3, 1, source, where + ".t");
    calibration.cameras.push_back(camera);
  }
  calibration.notes.push_back("Panoptic: OpenCV conventions, centimetres → metres");
  CheckCameraNames(calibration, source);
  return calibration;
}

Calibration ReadPanopticCalibration(const std::string& path) {
  return ParsePanopticCalibration(ReadCalibrationFile(path, "a Panoptic calibration_<seq>.json"), path);
}

}  // namespace subflow::vision
