// cameras.json of ../shared/DATASET.md: ReadCamerasJson (vision/dataset.h) and
// WriteCamerasJson (vision/dataset_writer.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "vision/dataset.h"
#include "vision/dataset_writer.h"

namespace subflow::vision {
namespace {

using nlohmann::json;

Eigen::Matrix3d Matrix3(const JsonReader& reader, const json& value, const std::string& field) {
  const std::vector<double> m = reader.Matrix(value, 3, 3, field);
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data());
}

Eigen::VectorXd Vector(const JsonReader& reader, const json& value, int size, const std::string& field) {
  const std::vector<double> v = reader.Numbers(value, size, field);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

json MatrixJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (int r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

json VectorJson(const Eigen::VectorXd& v) {
  json out = json::array();
  for (int i = 0; i < v.size(); ++i) out.push_back(v[i]);
  return out;
}

void CheckCameraName(const std::string& name, const std::string& path, const std::string& field) {
  if (name.empty() || name == "." || name == ".." ||
      name.find_first_of("/\\") != std::string::npos)
    ThrowError(path, field, "expected a non-empty camera name usable as a folder name (no '/', '\\', "
                            "\".\" or \"..\"), got \"" + name + "\"");
}

}  // namespace

std::vector<Camera> ReadCamerasJson(const std::string& path, DatasetInfo* info) {
  const json root = ReadJsonFile(
      path, "the dataset's cameras.json, format \"" + std::string(kDatasetFormat) + "\"");
  const JsonReader reader(path);
  reader.OnlyKeys(root, {"format", "fps", "frame_count", "units", "bounds", "cameras"}, "");

  const json& format = reader.Required(root, "format", "");
  if (!format.is_string() || format.get<std::string>() != kDatasetFormat)
    reader.Fail("format", "expected \"" + std::string(kDatasetFormat) + "\", got " + ShowJson(format));

  DatasetInfo parsed;
  if (const json* fps = reader.Optional(root, "fps", "")) {
    parsed.fps = reader.Number(*fps, "fps");
    if (!(*parsed.fps > 0)) reader.Fail("fps", "expected a positive number, got " + ShowJson(*fps));
  }
  if (const json* frame_count = reader.Optional(root, "frame_count", ""))
    parsed.frame_count = static_cast<int>(reader.Integer(*frame_count, "frame_count", 1, kMaxFrameCount));
  if (const json* units = reader.Optional(root, "units", "")) parsed.units = reader.String(*units, "units");
  if (const json* bounds = reader.Optional(root, "bounds", "")) {
    if (!bounds->is_object())
      reader.Fail("bounds", "expected {\"min\": [x, y, z], \"max\": [x, y, z]}, got " + ShowJson(*bounds));
    reader.OnlyKeys(*bounds, {"min", "max"}, "bounds");
    Bounds box;
    box.min = Vector(reader, reader.Required(*bounds, "min", "bounds"), 3, "bounds.min");
    box.max = Vector(reader, reader.Required(*bounds, "max", "bounds"), 3, "bounds.max");
    if (!(box.min.array() < box.max.array()).all())
      reader.Fail("bounds", "expected min < max on every axis, got min " + ShowJson((*bounds)["min"]) +
                                ", max " + ShowJson((*bounds)["max"]));
    parsed.bounds = box;
  }

  const json& list = reader.Required(root, "cameras", "");
  if (!list.is_array() || list.empty())
    reader.Fail("cameras", "expected a non-empty array of cameras, got " + ShowJson(list));
  std::vector<Camera> cameras;
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    std::string where = "cameras[" + std::to_string(i) + "]";
    const json& entry = list[i];
    reader.RequireObject(entry, where);
    const std::string name = reader.String(reader.Required(entry, "name", where), where + ".name");
    CheckCameraName(name, path, where + ".name");
    where += " (\"" + name + "\")";
    if (!names.insert(name).second)
      reader.Fail(where + ".name", "expected unique camera names, \"" + name + "\" appears twice");
    reader.OnlyKeys(entry, {"name", "width", "height", "K", "R", "t", "distortion", "distortion_model"}, where);
    const int width = static_cast<int>(
        reader.Integer(reader.Required(entry, "width", where), where + ".width", 1, kMaxImageSide));
    const int height = static_cast<int>(
        reader.Integer(reader.Required(entry, "height", where), where + ".height", 1, kMaxImageSide));
    const Eigen::Matrix3d K = Matrix3(reader, reader.Required(entry, "K", where), where + ".K");
    const Eigen::Matrix3d R = Matrix3(reader, reader.Required(entry, "R", where), where + ".R");
    const Eigen::Vector3d t = Vector(reader, reader.Required(entry, "t", where), 3, where + ".t");
    Eigen::VectorXd distortion;
    if (const json* values = reader.Optional(entry, "distortion", where))
      distortion = Vector(reader, *values, -1, where + ".distortion");
    DistortionModel model = DistortionModel::kOpenCV;
    if (const json* value = reader.Optional(entry, "distortion_model", where)) {
      if (!value->is_string() || !ParseDistortionModel(value->get<std::string>(), &model))
        reader.Fail(where + ".distortion_model", "expected \"opencv\" or \"fisheye\", got " + value->dump());
    }
    cameras.emplace_back(name, width, height, K, R, t, distortion, path, model);
  }
  if (info) *info = parsed;
  return cameras;
}

void WriteCamerasJson(const std::string& path, const std::vector<Camera>& cameras,
                      std::optional<double> fps, std::optional<int> frame_count,
                      const std::optional<Bounds>& bounds, const std::string& units) {
  json root;
  root["format"] = kDatasetFormat;
  if (fps) {
    if (!(*fps > 0)) ThrowError(path, "fps", "expected a positive number, got " + std::to_string(*fps));
    root["fps"] = *fps;
  }
  if (frame_count) {
    if (*frame_count <= 0)
      ThrowError(path, "frame_count", "expected a positive integer, got " + std::to_string(*frame_count));
    root["frame_count"] = *frame_count;
  }
  if (!units.empty()) root["units"] = units;
  if (bounds) {
    if (!bounds->IsValid()) ThrowError(path, "bounds", "expected finite min < max on every axis");
    root["bounds"] = {{"min", VectorJson(bounds->min)}, {"max", VectorJson(bounds->max)}};
  }
  if (cameras.empty()) ThrowError(path, "cameras", "expected at least one camera");
  json list = json::array();
  std::set<std::string> names;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const Camera& camera = cameras[i];
    const std::string field = "cameras[" + std::to_string(i) + "].name";
    CheckCameraName(camera.name(), path, field);
    if (!names.insert(camera.name()).second)
      ThrowError(path, field, "expected unique camera names, \"" + camera.name() + "\" appears twice");
    json entry;
    entry["name"] = camera.name();
    entry["width"] = camera.width();
    entry["height"] = camera.height();
    entry["K"] = MatrixJson(camera.K());
    entry["R"] = MatrixJson(camera.R());
    entry["t"] = VectorJson(camera.t());
    entry["distortion"] = VectorJson(camera.distortion());
    if (camera.distortion_model() != DistortionModel::kOpenCV)
      entry["distortion_model"] = DistortionModelName(camera.distortion_model());
    list.push_back(entry);
  }
  root["cameras"] = list;

  // nlohmann::json prints doubles with the shortest representation that reads back to the
  // same double, so the round trip is exact.
  WriteFileAtomically(path, root.dump(1) + "\n");
}

}  // namespace subflow::vision
