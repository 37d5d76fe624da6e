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

#include "core/error.h"
#include "vision/dataset.h"
#include "vision/dataset_writer.h"

namespace subflow::vision {
namespace {

using nlohmann::json;

std::string TypeName(const json& value) { return value.type_name(); }

// Line and column of a byte offset, for parse errors.
std::string LineColumn(const std::string& text, std::size_t byte) {
  int line = 1, column = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

class JsonReader {
 public:
  explicit JsonReader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    ThrowError(path_, field, problem);
  }

  const json& Required(const json& object, const std::string& key, const std::string& where) const {
    auto it = object.find(key);
    if (it == object.end())
      Fail(Join(where, key), "missing required field \"" + key + "\"");
    return *it;
  }

  double Number(const json& value, const std::string& field) const {
    if (!value.is_number()) Fail(field, "expected a number, got " + TypeName(value) + " " + value.dump());
    const double x = value.get<double>();
    if (!std::isfinite(x)) Fail(field, "expected a finite number, got " + value.dump());
    return x;
  }

  int PositiveInt(const json& value, const std::string& field) const {
    if (!value.is_number_integer() || value.get<long long>() <= 0 ||
        value.get<long long>() > std::numeric_limits<int>::max())
      Fail(field, "expected a positive integer, got " + value.dump());
    return value.get<int>();
  }

  Eigen::VectorXd Vector(const json& value, int size, const std::string& field) const {
    if (!value.is_array() || (size >= 0 && static_cast<int>(value.size()) != size))
      Fail(field, "expected an array of " + (size >= 0 ? std::to_string(size) : std::string("")) +
                      " numbers, got " + value.dump());
    Eigen::VectorXd out(value.size());
    for (std::size_t i = 0; i < value.size(); ++i)
      out[i] = Number(value[i], field + "[" + std::to_string(i) + "]");
    return out;
  }

  Eigen::Matrix3d Matrix3(const json& value, const std::string& field) const {
    if (!value.is_array() || value.size() != 3)
      Fail(field, "expected a 3×3 matrix as 3 rows of 3 numbers, got " + value.dump());
    Eigen::Matrix3d out;
    for (int r = 0; r < 3; ++r) {
      if (!value[r].is_array() || value[r].size() != 3)
        Fail(field, "expected a 3×3 matrix as 3 rows of 3 numbers, row " + std::to_string(r) +
                        " is " + value[r].dump());
      out.row(r) = Vector(value[r], 3, field + "[" + std::to_string(r) + "]").transpose();
    }
    return out;
  }

  void OnlyKeys(const json& object, const std::set<std::string>& allowed, const std::string& where) const {
    for (auto it = object.begin(); it != object.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& key : allowed) list += (list.empty() ? "" : ", ") + key;
        Fail(Join(where, it.key()), "unknown field (expected one of: " + list + ")");
      }
  }

  static std::string Join(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
  }

 private:
  std::string path_;
};

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
  std::ifstream file(path, std::ios::binary);
  if (!file)
    ThrowError(path, "", "cannot open (expected the dataset's cameras.json, format \"" +
                             std::string(kDatasetFormat) + "\")");
  std::stringstream buffer;
  buffer << file.rdbuf();
  const std::string text = buffer.str();
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    ThrowError(path, "JSON syntax at " + LineColumn(text, e.byte),
               std::string("expected valid JSON: ") + e.what());
  }
  const JsonReader reader(path);
  if (!root.is_object()) reader.Fail("(top level)", "expected a JSON object, got " + TypeName(root));
  reader.OnlyKeys(root, {"format", "fps", "frame_count", "units", "bounds", "cameras"}, "");

  const json& format = reader.Required(root, "format", "");
  if (!format.is_string() || format.get<std::string>() != kDatasetFormat)
    reader.Fail("format", "expected \"" + std::string(kDatasetFormat) + "\", got " + format.dump());

  DatasetInfo parsed;
  if (root.contains("fps")) {
    parsed.fps = reader.Number(root["fps"], "fps");
    if (!(*parsed.fps > 0)) reader.Fail("fps", "expected a positive number, got " + root["fps"].dump());
  }
  if (root.contains("frame_count")) parsed.frame_count = reader.PositiveInt(root["frame_count"], "frame_count");
  if (root.contains("units")) {
    if (!root["units"].is_string()) reader.Fail("units", "expected a string, got " + root["units"].dump());
    parsed.units = root["units"].get<std::string>();
  }
  if (root.contains("bounds")) {
    const json& bounds = root["bounds"];
    if (!bounds.is_object())
      reader.Fail("bounds", "expected {\"min\": [x, y, z], \"max\": [x, y, z]}, got " + bounds.dump());
    reader.OnlyKeys(bounds, {"min", "max"}, "bounds");
    Bounds box;
    box.min = reader.Vector(reader.Required(bounds, "min", "bounds"), 3, "bounds.min");
    box.max = reader.Vector(reader.Required(bounds, "max", "bounds"), 3, "bounds.max");
    if (!(box.min.array() < box.max.array()).all())
      reader.Fail("bounds", "expected min < max on every axis, got min " + bounds["min"].dump() +
                                ", max " + bounds["max"].dump());
    parsed.bounds = box;
  }

  const json& list = reader.Required(root, "cameras", "");
  if (!list.is_array() || list.empty())
    reader.Fail("cameras", "expected a non-empty array of cameras, got " + list.dump());
  std::vector<Camera> cameras;
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    std::string where = "cameras[" + std::to_string(i) + "]";
    const json& entry = list[i];
    if (!entry.is_object()) reader.Fail(where, "expected a camera object, got " + TypeName(entry));
    const json& name_json = reader.Required(entry, "name", where);
    if (!name_json.is_string()) reader.Fail(where + ".name", "expected a string, got " + name_json.dump());
    const std::string name = name_json.get<std::string>();
    CheckCameraName(name, path, where + ".name");
    where += " (\"" + name + "\")";
    if (!names.insert(name).second)
      reader.Fail(where + ".name", "expected unique camera names, \"" + name + "\" appears twice");
    reader.OnlyKeys(entry, {"name", "width", "height", "K", "R", "t", "distortion", "distortion_model"}, where);
    const int width = reader.PositiveInt(reader.Required(entry, "width", where), where + ".width");
    const int height = reader.PositiveInt(reader.Required(entry, "height", where), where + ".height");
    const Eigen::Matrix3d K = reader.Matrix3(reader.Required(entry, "K", where), where + ".K");
    const Eigen::Matrix3d R = reader.Matrix3(reader.Required(entry, "R", where), where + ".R");
    const Eigen::Vector3d t = reader.Vector(reader.Required(entry, "t", where), 3, where + ".t");
    Eigen::VectorXd distortion;
    if (entry.contains("distortion"))
      distortion = reader.Vector(entry["distortion"], -1, where + ".distortion");
    DistortionModel model = DistortionModel::kOpenCV;
    if (entry.contains("distortion_model")) {
      const json& value = entry["distortion_model"];
      if (!value.is_string() || !ParseDistortionModel(value.get<std::string>(), &model))
        reader.Fail(where + ".distortion_model", "expected \"opencv\" or \"fisheye\", got " + value.dump());
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
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) ThrowError(path, "", "cannot write (could not create " + temporary + ")");
    file << root.dump(1) << "\n";
    if (!file) ThrowError(path, "", "cannot write (write to " + temporary + " failed)");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) ThrowError(path, "", "cannot write (rename from " + temporary + " failed: " + error.message() + ")");
}

}  // namespace subflow::vision
