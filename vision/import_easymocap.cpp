#include "vision/import_easymocap.h"

#include <cmath>
#include <filesystem>

#include <opencv2/core.hpp>

#include "core/error.h"
#include "core/file_status.h"
#include "vision/camera.h"
#include "vision/import_toml.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

cv::FileStorage Open(const std::string& text, const std::string& source) {
  try {
    cv::FileStorage storage(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    if (!storage.isOpened()) ThrowError(source, "", "cannot parse (expected OpenCV FileStorage YAML)");
    return storage;
  } catch (const cv::Exception& e) {
    ThrowError(source, "", "cannot parse (expected OpenCV FileStorage YAML): " + e.msg);
  } catch (const std::exception& e) {  // the parser also lets std::length_error and the like out
    ThrowError(source, "", std::string("cannot parse (expected OpenCV FileStorage YAML): ") + e.what());
  }
}

// storage[key]; OpenCV throws when the document's top level is not a map.
cv::FileNode Node(const cv::FileStorage& storage, const std::string& key, const std::string& source) {
  try {
    return storage[key];
  } catch (const cv::Exception& e) {
    ThrowError(source, key, "cannot look up (expected a YAML map at the top level): " + e.msg);
  }
}

// The matrix stored at `node` (an !!opencv-matrix), as doubles. Its rows and cols are
// checked against its data before OpenCV allocates them (a calibration matrix is small).
cv::Mat ReadMat(const cv::FileNode& node, const std::string& key, const std::string& source) {
  constexpr int kMaxSide = 64;
  cv::Mat mat;
  try {
    if (!node.isMap()) ThrowError(source, key, "expected an !!opencv-matrix (rows, cols, dt, data)");
    const cv::FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
    if (!rows.isInt() || !cols.isInt() || !data.isSeq())
      ThrowError(source, key, "expected an !!opencv-matrix with integer rows and cols and a data list");
    const int r = static_cast<int>(rows), c = static_cast<int>(cols);
    if (r < 1 || c < 1 || r > kMaxSide || c > kMaxSide || static_cast<std::size_t>(r) * c != data.size())
      ThrowError(source, key, "expected rows and cols in 1.." + std::to_string(kMaxSide) +
                                  " with rows × cols values in data, got " + std::to_string(r) + "×" +
                                  std::to_string(c) + " and " + std::to_string(data.size()) + " values");
    node >> mat;
    mat.convertTo(mat, CV_64F);
  } catch (const cv::Exception& e) {
    ThrowError(source, key, "expected an !!opencv-matrix: " + e.msg);
  }
  return mat;
}

// The matrix at `key` with `rows`×`cols` (or the transposed shape) doubles.
Eigen::MatrixXd Matrix(const cv::FileStorage& storage, const std::string& key, int rows, int cols,
                       const std::string& source, bool required = true) {
  const cv::FileNode node = Node(storage, key, source);
  if (node.empty()) {
    if (required) ThrowError(source, key, "missing (expected a " + std::to_string(rows) + "×" + std::to_string(cols) + " !!opencv-matrix)");
    return Eigen::MatrixXd();
  }
  const cv::Mat mat = ReadMat(node, key, source);
  if (mat.empty() || mat.channels() != 1 || !((mat.rows == rows && mat.cols == cols) || (mat.rows == cols && mat.cols == rows)))
    ThrowError(source, key, "expected a " + std::to_string(rows) + "×" + std::to_string(cols) + " matrix, got " +
                                std::to_string(mat.rows) + "×" + std::to_string(mat.cols));
  Eigen::MatrixXd out(mat.rows, mat.cols);
  for (int r = 0; r < mat.rows; ++r)
    for (int c = 0; c < mat.cols; ++c) {
      out(r, c) = mat.at<double>(r, c);
      if (!std::isfinite(out(r, c))) ThrowError(source, key, "expected finite values");
    }
  return out;
}

std::vector<std::string> Names(const cv::FileStorage& storage, const std::string& source) {
  const cv::FileNode node = Node(storage, "names", source);
  if (!node.isSeq() || node.size() == 0) ThrowError(source, "names", "missing (expected a list of camera names)");
  std::vector<std::string> names;
  for (const cv::FileNode& item : node) {
    std::string name = item.isString() ? item.string() : (item.isInt() ? std::to_string(static_cast<int>(item)) : "");
    if (name.empty()) ThrowError(source, "names", "expected strings (or integers)");
    if (name != "none") names.push_back(name);  // read_camera skips "none"
  }
  return names;
}

// An image side (H_<name>, W_<name>), 0 when absent.
int OptionalImageSide(const cv::FileStorage& storage, const std::string& key, const std::string& source) {
  const cv::FileNode node = Node(storage, key, source);
  if (node.empty()) return 0;
  if (!node.isInt() && !node.isReal()) ThrowError(source, key, "expected an integer");
  return ImageSideFromNumber(node.real(), source, key);
}

}  // namespace

Calibration ParseEasyMocapCalibration(const std::string& intri_yml, const std::string& extri_yml,
                                      const std::string& intri_source, const std::string& extri_source) {
  const cv::FileStorage intri = Open(intri_yml, intri_source), extri = Open(extri_yml, extri_source);
  Calibration calibration;
  calibration.format = "easymocap";
  calibration.units = "m";
  for (const std::string& name : Names(intri, intri_source)) {
    CalibratedCamera camera;
    camera.name = name;
    camera.source = intri_source;
    camera.K = Matrix(intri, "K_" + name, 3, 3, intri_source);
    Eigen::MatrixXd d = Matrix(intri, "dist_" + name, 1, 5, intri_source, false);
    if (d.size() == 0) {
      const std::string key = Node(intri, "dist_" + name, intri_source).empty() ? "D_" + name : "dist_" + name;
      const cv::FileNode node = Node(intri, key, intri_source);
      const cv::Mat mat = node.empty() ? cv::Mat() : ReadMat(node, key, intri_source);
      if (mat.total() != 4 && mat.total() != 5 && mat.total() != 8)
        ThrowError(intri_source, key, "missing or not 4, 5 or 8 values (k1 k2 p1 p2 [k3 [k4 k5 k6]])");
      d.resize(1, mat.total());
      for (int i = 0; i < static_cast<int>(mat.total()); ++i) d(0, i) = mat.at<double>(i);
    }
    camera.distortion = Eigen::Map<const Eigen::VectorXd>(d.data(), d.size());
    camera.height = OptionalImageSide(intri, "H_" + name, intri_source);
    camera.width = OptionalImageSide(intri, "W_" + name, intri_source);
    const Eigen::MatrixXd rvec = Matrix(extri, "R_" + name, 3, 1, extri_source, false);
    if (rvec.size() == 3) camera.R = RodriguesToRotation(Eigen::Vector3d(rvec(0), rvec(1), rvec(2)));
    else camera.R = Matrix(extri, "Rot_" + name, 3, 3, extri_source);
    const Eigen::MatrixXd t = Matrix(extri, "T_" + name, 3, 1, extri_source);
    camera.t = Eigen::Vector3d(t(0), t(1), t(2));
    calibration.cameras.push_back(camera);
  }
  calibration.notes.push_back("EasyMocap intri.yml / extri.yml: R_ (Rodrigues) as read_camera uses it, metres");
  CheckCameraNames(calibration, intri_source);
  return calibration;
}

Calibration ReadEasyMocapCalibration(const std::string& path) {
  const fs::path folder = IsDirectory(path) ? fs::path(path) : fs::path(path).parent_path();
  const std::string intri = (folder / "intri.yml").string(), extri = (folder / "extri.yml").string();
  return ParseEasyMocapCalibration(ReadCalibrationFile(intri, "EasyMocap's intri.yml"),
                                   ReadCalibrationFile(extri, "EasyMocap's extri.yml"), intri, extri);
}

}  // namespace subflow::vision
