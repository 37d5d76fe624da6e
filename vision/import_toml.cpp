#include "vision/import_toml.h"

#include <cmath>
#include <set>

#include <Eigen/Geometry>
#include <toml++/toml.h>

#include "core/error.h"
#include "vision/camera.h"

namespace subflow::vision {
namespace {

class TomlCamera {
 public:
  TomlCamera(const toml::table& table, std::string source, std::string key)
      : table_(table), source_(std::move(source)), key_(std::move(key)) {}

  std::string Field(const std::string& what) const { return "[" + key_ + "] " + what; }

  const toml::array& Array(const char* key) const {
    const toml::array* array = table_[key].as_array();
    if (!array) ThrowError(source_, Field(key), table_.contains(key) ? "expected an array" : "missing");
    return *array;
  }

  double Number(const toml::node& node, const std::string& field) const {
    if (const auto* f = node.as_floating_point()) {
      if (!std::isfinite(f->get())) ThrowError(source_, Field(field), "expected a finite number");
      return f->get();
    }
    if (const auto* i = node.as_integer()) return static_cast<double>(i->get());
    ThrowError(source_, Field(field), "expected a number");
  }

  Eigen::VectorXd Vector(const char* key, int min_size, int max_size) const {
    const toml::array& array = Array(key);
    const int n = static_cast<int>(array.size());
    if (n < min_size || n > max_size)
      ThrowError(source_, Field(key), "expected " + std::to_string(min_size) +
                                          (max_size > min_size ? " to " + std::to_string(max_size) : "") +
                                          " numbers, got " + std::to_string(n));
    Eigen::VectorXd out(n);
    for (int i = 0; i < n; ++i) out[i] = Number(*array.get(i), std::string(key) + "[" + std::to_string(i) + "]");
    return out;
  }

  Eigen::Matrix3d Matrix(const char* key) const {
    const toml::array& rows = Array(key);
    if (rows.size() != 3) ThrowError(source_, Field(key), "expected 3 rows of 3 numbers");
    Eigen::Matrix3d out;
    for (int r = 0; r < 3; ++r) {
      const toml::array* row = rows.get(r)->as_array();
      if (!row || row->size() != 3) ThrowError(source_, Field(key), "expected 3 rows of 3 numbers");
      for (int c = 0; c < 3; ++c)
        out(r, c) = Number(*row->get(c), std::string(key) + "[" + std::to_string(r) + "][" + std::to_string(c) + "]");
    }
    return out;
  }

  int Whole(double value, const std::string& field) const { return ImageSideFromNumber(value, source_, Field(field)); }

 private:
  const toml::table& table_;
  std::string source_, key_;
};

}  // namespace

Eigen::Matrix3d RodriguesToRotation(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

Calibration ParseTomlCalibration(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    ThrowError(source, "TOML at line " + std::to_string(e.source().begin.line) + ", column " +
                           std::to_string(e.source().begin.column),
               std::string("expected a Pose2Sim / Anipose calibration: ") + std::string(e.description()));
  }
  static const std::set<std::string> kNotCameras = {"metadata", "capture_volume", "charuco", "checkerboard"};
  Calibration calibration;
  calibration.format = "toml";
  calibration.units = "m";
  for (const auto& [key, node] : root) {
    const std::string name(key.str());
    const toml::table* table = node.as_table();
    if (!table || kNotCameras.count(name)) continue;
    const TomlCamera reader(*table, source, name);
    CalibratedCamera camera;
    camera.source = source;
    camera.name = (*table)["name"].value_or(name);
    const Eigen::VectorXd size = reader.Vector("size", 2, 2);
    camera.width = reader.Whole(size[0], "size[0]");
    camera.height = reader.Whole(size[1], "size[1]");
    camera.K = reader.Matrix("matrix");
    const bool fisheye = (*table)["fisheye"].value_or(false);
    camera.distortion_model = fisheye ? DistortionModel::kFisheye : DistortionModel::kOpenCV;
    camera.distortion = reader.Vector("distortions", fisheye ? 4 : 4, fisheye ? 4 : 8);
    if (!fisheye && camera.distortion.size() != 4 && camera.distortion.size() != 5 && camera.distortion.size() != 8)
      ThrowError(source, reader.Field("distortions"), "expected 4, 5 or 8 numbers (k1 k2 p1 p2 [k3 [k4 k5 k6]])");
    camera.R = RodriguesToRotation(reader.Vector("rotation", 3, 3));
    camera.t = reader.Vector("translation", 3, 3);
    calibration.cameras.push_back(camera);
  }
  if (calibration.cameras.empty())
    ThrowError(source, "", "no camera table (expected [cam_0] or [cam01] tables with size, matrix, distortions, "
                           "rotation, translation)");
  calibration.notes.push_back("Calib.toml: Rodrigues rotations, OpenCV intrinsics; translations taken in " +
                              std::string("metres (Pose2Sim) unless --units says otherwise (Anipose: usually mm)"));
  CheckCameraNames(calibration, source);
  return calibration;
}

Calibration ReadTomlCalibration(const std::string& path) {
  return ParseTomlCalibration(ReadCalibrationFile(path, "a Pose2Sim / Anipose Calib.toml"), path);
}

}  // namespace subflow::vision
