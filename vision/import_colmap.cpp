#include "vision/import_colmap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "core/error.h"
#include "core/file_status.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

struct ColmapIntrinsics {
  int width = 0, height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::VectorXd distortion;
  DistortionModel model = DistortionModel::kOpenCV;
};

struct ModelInfo {
  const char* name;
  int id, parameters;
};
const ModelInfo kModels[] = {{"SIMPLE_PINHOLE", 0, 3}, {"PINHOLE", 1, 4},          {"SIMPLE_RADIAL", 2, 4},
                             {"RADIAL", 3, 5},         {"OPENCV", 4, 8},           {"OPENCV_FISHEYE", 5, 8},
                             {"FULL_OPENCV", 6, 12},   {"SIMPLE_RADIAL_FISHEYE", 8, 4}, {"RADIAL_FISHEYE", 9, 5}};
const char* const kOtherModels[] = {"FOV",  "THIN_PRISM_FISHEYE", "RAD_TAN_THIN_PRISM_FISHEYE", "SIMPLE_DIVISION",
                                    "DIVISION", "SIMPLE_FISHEYE", "FISHEYE", "EUCM", "EQUIRECTANGULAR"};

std::string SupportedModels() {
  std::string list;
  for (const ModelInfo& m : kModels) list += (list.empty() ? "" : ", ") + std::string(m.name);
  return list;
}

const ModelInfo* FindModel(const std::string& name) {
  for (const ModelInfo& m : kModels)
    if (name == m.name) return &m;
  return nullptr;
}

// (fx, fy, cx, cy, distortion) of a COLMAP model's parameters; COLMAP's pixel centres.
ColmapIntrinsics Intrinsics(const ModelInfo& model, const std::vector<double>& p, int width, int height,
                            const std::string& source, const std::string& field) {
  for (double value : p)
    if (!std::isfinite(value)) ThrowError(source, field, "expected finite parameters");
  const std::string name = model.name;
  const bool single_focal = p.size() == 3 || name == "SIMPLE_RADIAL" || name == "RADIAL" ||
                            name == "SIMPLE_RADIAL_FISHEYE" || name == "RADIAL_FISHEYE";
  const double fx = p[0], fy = single_focal ? p[0] : p[1];
  const double cx = single_focal ? p[1] : p[2], cy = single_focal ? p[2] : p[3];
  const std::vector<double> extra(p.begin() + (single_focal ? 3 : 4), p.end());
  if (!(fx > 0) || !(fy > 0)) ThrowError(source, field, "expected positive focal lengths");
  ColmapIntrinsics out;
  out.width = width;
  out.height = height;
  out.K << fx, 0, cx - 0.5, 0, fy, cy - 0.5, 0, 0, 1;  // COLMAP: top-left pixel centre at (0.5, 0.5)
  const bool fisheye = name.find("FISHEYE") != std::string::npos;
  out.model = fisheye ? DistortionModel::kFisheye : DistortionModel::kOpenCV;
  out.distortion = Eigen::VectorXd::Zero(fisheye ? 4 : (extra.size() > 5 ? 8 : 5));
  if (name == "SIMPLE_RADIAL" || name == "RADIAL" || fisheye) {
    for (std::size_t i = 0; i < extra.size(); ++i) out.distortion[i] = extra[i];  // k1 (k2 (k3 k4))
  } else {
    for (std::size_t i = 0; i < extra.size(); ++i) out.distortion[i] = extra[i];  // k1 k2 p1 p2 (k3 k4 k5 k6)
  }
  return out;
}

std::string CameraName(const std::string& image_name, ColmapImportOptions::NameFrom name_from) {
  const fs::path path(image_name);
  if (name_from == ColmapImportOptions::NameFrom::kParentFolder) return path.parent_path().filename().string();
  return path.stem().string();
}

void AddImage(Calibration* calibration, const std::map<std::uint64_t, ColmapIntrinsics>& intrinsics,
              std::map<std::string, std::string>* names, std::uint64_t camera_id, const Eigen::Vector4d& q,
              const Eigen::Vector3d& t, const std::string& image_name, const std::string& source,
              const std::string& field, const std::string& cameras_source, const ColmapImportOptions& options) {
  const Eigen::Quaterniond quaternion(q[0], q[1], q[2], q[3]);
  if (!q.allFinite() || !(q.norm() > 1e-12)) ThrowError(source, field + ": QW QX QY QZ", "expected a non-zero quaternion");
  if (!t.allFinite()) ThrowError(source, field + ": TX TY TZ", "expected finite numbers");
  auto it = intrinsics.find(camera_id);
  if (it == intrinsics.end())
    ThrowError(source, field + ": CAMERA_ID", "camera id " + std::to_string(camera_id) + " is not in " + cameras_source);
  const std::string name = CameraName(image_name, options.name_from);
  if (name.empty()) ThrowError(source, field + ": NAME", "cannot name a camera from \"" + image_name + "\"");
  if (names->count(name))
    ThrowError(source, field + ": NAME", "camera name \"" + name + "\" already used on " + (*names)[name] +
                                             " (expected one image per camera; see --colmap-names)");
  (*names)[name] = field;
  CalibratedCamera camera;
  camera.name = name;
  camera.width = it->second.width;
  camera.height = it->second.height;
  camera.K = it->second.K;
  camera.distortion = it->second.distortion;
  camera.distortion_model = it->second.model;
  camera.R = quaternion.normalized().toRotationMatrix();
  camera.t = t;
  camera.image_name = image_name;
  camera.source = source + ": " + field;
  calibration->cameras.push_back(camera);
}

Calibration Finish(Calibration calibration, const std::string& source) {
  calibration.format = "colmap";
  calibration.notes.push_back("COLMAP: principal point moved by −½ px (COLMAP's pixel centres are at +½); "
                              "no metric scale (translations written as they are)");
  if (calibration.cameras.empty()) ThrowError(source, "images", "none (expected at least one registered image)");
  std::sort(calibration.cameras.begin(), calibration.cameras.end(),
            [](const CalibratedCamera& a, const CalibratedCamera& b) { return a.name < b.name; });
  CheckCameraNames(calibration, source);
  return calibration;
}

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

// Little-endian reader of a COLMAP .bin file with bounds checks.
class BinaryReader {
 public:
  BinaryReader(const std::string& bytes, std::string source) : bytes_(bytes), source_(std::move(source)) {}
  template <typename T>
  T Read(const std::string& field) {
    if (bytes_.size() - at_ < sizeof(T))
      ThrowError(source_, field, "truncated at byte " + std::to_string(at_) + " (expected COLMAP's binary model)");
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));  // x86-64 and ARM: little-endian like COLMAP's files
    at_ += sizeof(T);
    return value;
  }
  std::string ReadName(const std::string& field) {
    const std::size_t end = bytes_.find('\0', at_);
    if (end == std::string::npos) ThrowError(source_, field, "truncated name (expected a NUL-terminated string)");
    std::string name = bytes_.substr(at_, end - at_);
    at_ = end + 1;
    return name;
  }
  void Skip(std::uint64_t count, std::size_t size, const std::string& field) {
    if (count > (bytes_.size() - at_) / size)
      ThrowError(source_, field, "truncated (" + std::to_string(count) + " entries announced)");
    at_ += count * size;
  }
  std::size_t remaining() const { return bytes_.size() - at_; }

 private:
  const std::string& bytes_;
  std::string source_;
  std::size_t at_ = 0;
};

}  // namespace

Calibration ParseColmapTextModel(const std::string& cameras_txt, const std::string& images_txt,
                                 const std::string& source, const ColmapImportOptions& options) {
  const std::string cameras_source = source + "/cameras.txt", images_source = source + "/images.txt";
  std::map<std::uint64_t, ColmapIntrinsics> intrinsics;
  std::istringstream cameras_in(cameras_txt);
  std::string text;
  for (int line = 1; std::getline(cameras_in, text); ++line) {
    text = Trim(text);
    if (text.empty() || text[0] == '#') continue;
    const std::string field = "line " + std::to_string(line);
    std::istringstream in(text);
    std::uint64_t id = 0;
    long long width = 0, height = 0;
    std::string model;
    if (!(in >> id >> model >> width >> height))
      ThrowError(cameras_source, field, "expected \"CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\", got \"" + text + "\"");
    const ModelInfo* info = FindModel(model);
    if (!info)
      ThrowError(cameras_source, field + ": MODEL",
                 "unsupported camera model \"" + model + "\" (expected one of " + SupportedModels() + ")");
    std::vector<double> p(info->parameters);
    for (double& value : p)
      if (!(in >> value))
        ThrowError(cameras_source, field + ": PARAMS",
                   "expected " + std::to_string(info->parameters) + " numbers for model " + model);
    std::string extra;
    if (in >> extra)
      ThrowError(cameras_source, field + ": PARAMS",
                 "expected exactly " + std::to_string(info->parameters) + " numbers for model " + model + ", got more");
    const int w = ImageSideFromNumber(static_cast<double>(width), cameras_source, field + ": WIDTH");
    const int h = ImageSideFromNumber(static_cast<double>(height), cameras_source, field + ": HEIGHT");
    if (!intrinsics.emplace(id, Intrinsics(*info, p, w, h, cameras_source, field + ": PARAMS")).second)
      ThrowError(cameras_source, field + ": CAMERA_ID", "duplicate camera id " + std::to_string(id));
  }
  Calibration calibration;
  std::map<std::string, std::string> names;
  std::istringstream images_in(images_txt);
  for (int line = 1; std::getline(images_in, text); ++line) {
    text = Trim(text);
    if (text.empty() || text[0] == '#') continue;
    const std::string field = "line " + std::to_string(line);
    std::istringstream in(text);
    std::uint64_t image_id = 0, camera_id = 0;
    Eigen::Vector4d q;
    Eigen::Vector3d t;
    std::string name;
    if (!(in >> image_id >> q[0] >> q[1] >> q[2] >> q[3] >> t[0] >> t[1] >> t[2] >> camera_id >> name))
      ThrowError(images_source, field, "expected \"IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\", got \"" + text + "\"");
    AddImage(&calibration, intrinsics, &names, camera_id, q, t, name, images_source, field, cameras_source, options);
    // The POINTS2D line follows every image line, and may be empty: skip it unread.
    if (!std::getline(images_in, text)) break;
    ++line;
  }
  return Finish(calibration, images_source);
}

Calibration ParseColmapBinaryModel(const std::string& cameras_bin, const std::string& images_bin,
                                   const std::string& source, const ColmapImportOptions& options) {
  const std::string cameras_source = source + "/cameras.bin", images_source = source + "/images.bin";
  std::map<std::uint64_t, ColmapIntrinsics> intrinsics;
  BinaryReader cameras(cameras_bin, cameras_source);
  const std::uint64_t camera_count = cameras.Read<std::uint64_t>("camera count");
  for (std::uint64_t i = 0; i < camera_count; ++i) {
    const std::string field = "camera " + std::to_string(i);
    const std::uint32_t id = cameras.Read<std::uint32_t>(field + ": id");
    const std::int32_t model_id = cameras.Read<std::int32_t>(field + ": model id");
    const std::uint64_t width = cameras.Read<std::uint64_t>(field + ": width");
    const std::uint64_t height = cameras.Read<std::uint64_t>(field + ": height");
    const ModelInfo* info = nullptr;
    for (const ModelInfo& m : kModels)
      if (m.id == model_id) info = &m;
    if (!info) {
      const std::string known = model_id >= 7 && model_id <= 17 && model_id != 8 && model_id != 9
                                    ? std::string(" (") + kOtherModels[model_id == 7 ? 0 : model_id - 9] + ")"
                                    : "";
      ThrowError(cameras_source, field + ": model id",
                 "unsupported COLMAP camera model " + std::to_string(model_id) + known + " (expected one of " +
                     SupportedModels() + ")");
    }
    std::vector<double> p(info->parameters);
    for (double& value : p) value = cameras.Read<double>(field + ": params");
    const int w = ImageSideFromNumber(static_cast<double>(width), cameras_source, field + ": width");
    const int h = ImageSideFromNumber(static_cast<double>(height), cameras_source, field + ": height");
    if (!intrinsics.emplace(id, Intrinsics(*info, p, w, h, cameras_source, field)).second)
      ThrowError(cameras_source, field + ": id", "duplicate camera id " + std::to_string(id));
  }
  if (cameras.remaining() != 0)
    ThrowError(cameras_source, "", std::to_string(cameras.remaining()) + " bytes after the last camera");
  Calibration calibration;
  std::map<std::string, std::string> names;
  BinaryReader images(images_bin, images_source);
  const std::uint64_t image_count = images.Read<std::uint64_t>("image count");
  for (std::uint64_t i = 0; i < image_count; ++i) {
    const std::string field = "image " + std::to_string(i);
    images.Read<std::uint32_t>(field + ": id");
    Eigen::Vector4d q;
    Eigen::Vector3d t;
    for (int k = 0; k < 4; ++k) q[k] = images.Read<double>(field + ": quaternion");
    for (int k = 0; k < 3; ++k) t[k] = images.Read<double>(field + ": translation");
    const std::uint32_t camera_id = images.Read<std::uint32_t>(field + ": camera id");
    const std::string name = images.ReadName(field + ": name");
    const std::uint64_t points = images.Read<std::uint64_t>(field + ": point count");
    images.Skip(points, 2 * sizeof(double) + sizeof(std::uint64_t), field + ": points");
    AddImage(&calibration, intrinsics, &names, camera_id, q, t, name, images_source, field + " (\"" + name + "\")",
             cameras_source, options);
  }
  if (images.remaining() != 0)
    ThrowError(images_source, "", std::to_string(images.remaining()) + " bytes after the last image");
  return Finish(calibration, images_source);
}

Calibration ReadColmapModel(const std::string& directory, const ColmapImportOptions& options) {
  const fs::path root(directory);
  if (!IsDirectory(root)) ThrowError(directory, "", "not a directory (expected a COLMAP sparse model folder)");
  if (EntryExists(root / "cameras.bin") || EntryExists(root / "images.bin"))  // a broken .bin is reported
    return ParseColmapBinaryModel(ReadCalibrationFile((root / "cameras.bin").string(), "COLMAP's cameras.bin"),
                                  ReadCalibrationFile((root / "images.bin").string(), "COLMAP's images.bin"),
                                  directory, options);
  return ParseColmapTextModel(ReadCalibrationFile((root / "cameras.txt").string(), "COLMAP's cameras.txt"),
                              ReadCalibrationFile((root / "images.txt").string(), "COLMAP's images.txt"), directory,
                              options);
}

std::vector<Camera> ReadColmapTextModel(const std::string& directory, const ColmapImportOptions& options) {
  const fs::path root(directory);
  return ToCameras(ParseColmapTextModel(ReadCalibrationFile((root / "cameras.txt").string(), "COLMAP's cameras.txt"),
                                        ReadCalibrationFile((root / "images.txt").string(), "COLMAP's images.txt"),
                                        directory, options));
}

}  // namespace subflow::vision
