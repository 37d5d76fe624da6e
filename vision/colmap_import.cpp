#include "vision/colmap_import.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

struct ColmapCamera {
  int width = 0, height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::VectorXd distortion;  // k1 k2 p1 p2 k3
  int line = 0;
};

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

std::string LineField(int line) { return "line " + std::to_string(line); }

// Parameter count and the mapping to (fx, fy, cx, cy, k1 k2 p1 p2 k3) of each model.
bool ModelParameters(const std::string& model, int* count) {
  static const std::map<std::string, int> kCounts = {{"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4},
                                                     {"SIMPLE_RADIAL", 4},  {"RADIAL", 5},
                                                     {"OPENCV", 8},         {"FULL_OPENCV", 12}};
  auto it = kCounts.find(model);
  if (it == kCounts.end()) return false;
  *count = it->second;
  return true;
}

std::map<int, ColmapCamera> ReadCameras(const std::string& path) {
  std::ifstream file(path);
  if (!file) ThrowError(path, "", "cannot open (expected COLMAP's cameras.txt)");
  std::map<int, ColmapCamera> cameras;
  std::string text;
  for (int line = 1; std::getline(file, text); ++line) {
    text = Trim(text);
    if (text.empty() || text[0] == '#') continue;
    std::istringstream in(text);
    int id = 0, width = 0, height = 0;
    std::string model;
    if (!(in >> id >> model >> width >> height))
      ThrowError(path, LineField(line), "expected \"CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\", got \"" + text + "\"");
    int count = 0;
    if (!ModelParameters(model, &count))
      ThrowError(path, LineField(line) + ": MODEL",
                 "unsupported camera model \"" + model +
                     "\" (expected SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV or FULL_OPENCV)");
    if (width <= 0 || height <= 0)
      ThrowError(path, LineField(line) + ": WIDTH HEIGHT",
                 "expected positive integers, got " + std::to_string(width) + " " + std::to_string(height));
    std::vector<double> p(count);
    for (double& value : p)
      if (!(in >> value))
        ThrowError(path, LineField(line) + ": PARAMS",
                   "expected " + std::to_string(count) + " numbers for model " + model);
    std::string extra;
    if (in >> extra)
      ThrowError(path, LineField(line) + ": PARAMS",
                 "expected exactly " + std::to_string(count) + " numbers for model " + model + ", got more");
    ColmapCamera camera;
    camera.width = width;
    camera.height = height;
    camera.line = line;
    double fx, fy, cx, cy;
    Eigen::VectorXd d = Eigen::VectorXd::Zero(5);
    if (model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL") {
      fx = fy = p[0];
      cx = p[1];
      cy = p[2];
      if (model != "SIMPLE_PINHOLE") d[0] = p[3];
      if (model == "RADIAL") d[1] = p[4];
    } else {
      fx = p[0];
      fy = p[1];
      cx = p[2];
      cy = p[3];
      for (int i = 4; i < std::min(count, 8); ++i) d[i - 4] = p[i];
      if (model == "FULL_OPENCV") {
        d[4] = p[8];
        if (p[9] != 0 || p[10] != 0 || p[11] != 0)
          ThrowError(path, LineField(line) + ": PARAMS",
                     "FULL_OPENCV's k4 k5 k6 must be 0 (subflow models k1 k2 p1 p2 k3 only)");
      }
    }
    if (!(fx > 0) || !(fy > 0))
      ThrowError(path, LineField(line) + ": PARAMS", "expected positive focal lengths");
    // COLMAP: centre of the top-left pixel at (0.5, 0.5); subflow: at (0, 0).
    camera.K << fx, 0, cx - 0.5, 0, fy, cy - 0.5, 0, 0, 1;
    camera.distortion = d;
    if (!cameras.emplace(id, camera).second)
      ThrowError(path, LineField(line) + ": CAMERA_ID", "duplicate camera id " + std::to_string(id));
  }
  return cameras;
}

std::string CameraName(const std::string& image_name, ColmapImportOptions::NameFrom name_from) {
  const fs::path path(image_name);
  if (name_from == ColmapImportOptions::NameFrom::kParentFolder) return path.parent_path().filename().string();
  return path.stem().string();
}

}  // namespace

std::vector<Camera> ReadColmapTextModel(const std::string& directory, const ColmapImportOptions& options) {
  const std::string cameras_path = (fs::path(directory) / "cameras.txt").string();
  const std::string images_path = (fs::path(directory) / "images.txt").string();
  const std::map<int, ColmapCamera> intrinsics = ReadCameras(cameras_path);
  std::ifstream file(images_path);
  if (!file) ThrowError(images_path, "", "cannot open (expected COLMAP's images.txt)");
  std::vector<Camera> cameras;
  std::map<std::string, int> name_lines;
  std::string text;
  for (int line = 1; std::getline(file, text); ++line) {
    text = Trim(text);
    if (text.empty() || text[0] == '#') continue;
    std::istringstream in(text);
    int image_id = 0, camera_id = 0;
    double qw, qx, qy, qz, tx, ty, tz;
    std::string name;
    if (!(in >> image_id >> qw >> qx >> qy >> qz >> tx >> ty >> tz >> camera_id >> name))
      ThrowError(images_path, LineField(line),
                 "expected \"IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\", got \"" + text + "\"");
    const Eigen::Quaterniond q(qw, qx, qy, qz);
    if (!(q.norm() > 1e-12) || !std::isfinite(q.norm()))
      ThrowError(images_path, LineField(line) + ": QW QX QY QZ", "expected a non-zero quaternion");
    auto it = intrinsics.find(camera_id);
    if (it == intrinsics.end())
      ThrowError(images_path, LineField(line) + ": CAMERA_ID",
                 "camera id " + std::to_string(camera_id) + " is not in " + cameras_path);
    const std::string camera_name = CameraName(name, options.name_from);
    if (camera_name.empty())
      ThrowError(images_path, LineField(line) + ": NAME", "cannot name a camera from \"" + name + "\"");
    if (name_lines.count(camera_name))
      ThrowError(images_path, LineField(line) + ": NAME",
                 "camera name \"" + camera_name + "\" already used on line " +
                     std::to_string(name_lines[camera_name]) + " (expected one image per camera)");
    name_lines[camera_name] = line;
    const ColmapCamera& intrinsic = it->second;
    cameras.emplace_back(camera_name, intrinsic.width, intrinsic.height, intrinsic.K,
                         q.normalized().toRotationMatrix(), Eigen::Vector3d(tx, ty, tz),
                         intrinsic.distortion, images_path + ": " + LineField(line));
    // The POINTS2D line follows every image line, and may be empty: skip it unread.
    if (!std::getline(file, text)) break;
    ++line;
  }
  if (cameras.empty()) ThrowError(images_path, "", "no images (expected at least one image line)");
  std::sort(cameras.begin(), cameras.end(),
            [](const Camera& a, const Camera& b) { return a.name() < b.name(); });
  return cameras;
}

}  // namespace subflow::vision
