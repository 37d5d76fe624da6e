#include "vision/import_projection_matrices.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/file_status.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

std::string LineField(int line) { return "line " + std::to_string(line); }

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

// Size of the image at `path`; false when there is none. An entry that is there but no
// readable image (empty, a folder, a link to nothing or to itself) is an error naming it.
bool ImageSize(const fs::path& path, int* width, int* height) {
  std::error_code error;  // a name too long for the filesystem is no image, not a crash
  const fs::file_status entry = fs::symlink_status(path, error);
  if (error || entry.type() == fs::file_type::not_found) return false;
  const cv::Mat image = IsFile(path) ? cv::imread(path.string(), cv::IMREAD_UNCHANGED) : cv::Mat();
  if (image.empty()) ThrowError(path.string(), "", "not a readable image (expected the camera's image, for its size)");
  *width = image.cols;
  *height = image.rows;
  return true;
}

// Leaves the size 0 when it is unknown and `required` is false.
void SizeFor(const std::string& name, const fs::path& folder, const ProjectionMatrixImportOptions& options,
             const std::string& source, int* width, int* height, const std::string& image_file = "",
             bool required = true) {
  if (options.width > 0 && options.height > 0) {
    *width = options.width;
    *height = options.height;
    return;
  }
  const fs::path directory = options.image_directory.empty() ? folder : fs::path(options.image_directory);
  if (!image_file.empty()) {
    if (ImageSize(directory / image_file, width, height) || !required) return;
    ThrowError(source, "image size",
               "unknown: cannot read " + (directory / image_file).string() + " (give width and height)");
  }
  for (const char* extension : {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm"})
    if (ImageSize(directory / (name + extension), width, height)) return;
  if (!required) return;
  ThrowError(source, "image size",
             "unknown: no readable image " + name + ".<png|jpg|...> in " + directory.string() +
                 " (give width and height)");
}

}  // namespace

CalibratedCamera DecomposeProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P, const std::string& name,
                                           const std::string& source) {
  const std::string field = "camera \"" + name + "\": P";
  if (!P.allFinite()) ThrowError(source, field, "expected finite values");
  const Eigen::Matrix3d M = P.leftCols<3>();
  if (!(std::abs(M.determinant()) > 1e-12 * std::pow(M.norm(), 3)))
    ThrowError(source, field, "expected a 3×4 projection matrix with a non-singular left 3×3 block");
  cv::Mat P_cv(3, 4, CV_64F), K_cv, R_cv, C_cv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) P_cv.at<double>(r, c) = P(r, c);
  cv::decomposeProjectionMatrix(P_cv, K_cv, R_cv, C_cv);
  Eigen::Matrix3d K, R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      K(r, c) = K_cv.at<double>(r, c);
      R(r, c) = R_cv.at<double>(r, c);
    }
  // RQ is unique up to D = diag(±1): K R = (K D)(D R). Make K's diagonal positive, then
  // take out P's scale λ = K(2,2) and its sign (det R must be +1): P = λ K [R | t].
  const Eigen::Vector3d signs(K(0, 0) < 0 ? -1 : 1, K(1, 1) < 0 ? -1 : 1, K(2, 2) < 0 ? -1 : 1);
  K = K * signs.asDiagonal();
  R = signs.asDiagonal() * R;
  double lambda = K(2, 2);
  K /= lambda;
  if (R.determinant() < 0) {
    R = -R;
    lambda = -lambda;
  }
  K(1, 0) = K(2, 0) = K(2, 1) = 0;
  K(2, 2) = 1;
  CalibratedCamera camera;
  camera.name = name;
  camera.K = K;
  camera.R = R;
  camera.t = K.inverse() * P.col(3) / lambda;
  camera.source = source;
  return camera;
}

Camera CameraFromProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P, std::string name, int width,
                                  int height, const std::string& source) {
  const CalibratedCamera c = DecomposeProjectionMatrix(P, name, source);
  return Camera(std::move(name), width, height, c.K, c.R, c.t, Eigen::VectorXd(), source);
}

Calibration ReadProjectionMatrixCalibration(const std::string& directory,
                                            const ProjectionMatrixImportOptions& options, bool require_sizes) {
  if (!IsDirectory(directory))
    ThrowError(directory, "", "not a directory (expected a folder of 3×4 projection-matrix files)");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (entry.path().extension() != options.extension) continue;
    if (!IsFile(entry.path()))  // a folder or a link to nothing under a matrix file's name
      ThrowError(entry.path().string(), "", "not a readable file (expected a 3×4 projection matrix)");
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty())
    ThrowError(directory, "", "no *" + options.extension + " projection-matrix files");
  Calibration calibration;
  calibration.format = "matrices";
  for (const fs::path& file_path : files) {
    const std::string path = file_path.string();
    std::ifstream file(path);
    if (!file) ThrowError(path, "", "cannot open");
    Eigen::Matrix<double, 3, 4> P;
    int row = 0, line = 0;
    std::string text;
    bool first = true;
    while (std::getline(file, text)) {
      ++line;
      text = Trim(text);
      if (text.empty()) continue;
      if (first && text == "CONTOUR") {
        first = false;
        continue;
      }
      first = false;
      if (row == 3)
        ThrowError(path, LineField(line), "unexpected content after the 3 rows of the projection matrix: \"" +
                                              text + "\"");
      std::istringstream in(text);
      for (int c = 0; c < 4; ++c)
        if (!(in >> P(row, c)))
          ThrowError(path, LineField(line), "expected 4 numbers (row " + std::to_string(row) +
                                                " of a 3×4 projection matrix), got \"" + text + "\"");
      std::string extra;
      if (in >> extra)
        ThrowError(path, LineField(line), "expected 4 numbers (row " + std::to_string(row) +
                                              " of a 3×4 projection matrix), got more: \"" + text + "\"");
      ++row;
    }
    if (row != 3)
      ThrowError(path, LineField(line), "expected 3 rows of 4 numbers, got " + std::to_string(row) + " rows");
    const std::string name = file_path.stem().string();
    int width = 0, height = 0;
    SizeFor(name, file_path.parent_path(), options, path, &width, &height, "", require_sizes);
    CalibratedCamera camera = DecomposeProjectionMatrix(P, name, path);
    camera.width = width;
    camera.height = height;
    calibration.cameras.push_back(camera);
  }
  calibration.notes.push_back("3×4 projection matrices decomposed (RQ) into K [R | t]; pixel centres at integers; "
                              "no distortion, no metric scale");
  CheckCameraNames(calibration, directory);
  return calibration;
}

std::vector<Camera> ReadProjectionMatrixFolder(const std::string& directory,
                                               const ProjectionMatrixImportOptions& options) {
  return ToCameras(ReadProjectionMatrixCalibration(directory, options, true));
}

Calibration ReadMiddleburyCalibration(const std::string& par_file, const ProjectionMatrixImportOptions& options,
                                      bool require_sizes) {
  std::ifstream file(par_file);
  if (!file) ThrowError(par_file, "", "cannot open (expected a Middlebury *_par.txt file)");
  std::string text;
  int line = 0, count = -1;
  Calibration calibration;
  calibration.format = "middlebury";
  std::vector<CalibratedCamera>& cameras = calibration.cameras;
  while (std::getline(file, text)) {
    ++line;
    text = Trim(text);
    if (text.empty()) continue;
    std::istringstream in(text);
    if (count < 0) {
      std::string extra;
      if (!(in >> count) || count <= 0 || (in >> extra))
        ThrowError(par_file, LineField(line), "expected the number of cameras, got \"" + text + "\"");
      continue;
    }
    std::string image_name;
    double v[21];
    in >> image_name;
    for (double& value : v)
      if (!(in >> value))
        ThrowError(par_file, LineField(line),
                   "expected \"imgname k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 .. r33 t1 t2 t3\" "
                   "(a name and 21 numbers), got \"" + text + "\"");
    std::string extra;
    if (in >> extra)
      ThrowError(par_file, LineField(line), "expected a name and 21 numbers, got more: \"" + text + "\"");
    if (static_cast<int>(cameras.size()) == count)
      ThrowError(par_file, LineField(line), "more camera lines than the " + std::to_string(count) + " announced");
    Eigen::Matrix3d K, R;
    K << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
    R << v[9], v[10], v[11], v[12], v[13], v[14], v[15], v[16], v[17];
    const Eigen::Vector3d t(v[18], v[19], v[20]);
    const std::string source = par_file + ": " + LineField(line);
    // The files print R to limited precision: Camera takes the nearest rotation.
    const std::string name = fs::path(image_name).stem().string();
    int width = 0, height = 0;
    SizeFor(name, fs::path(par_file).parent_path(), options, source, &width, &height, image_name, require_sizes);
    CalibratedCamera camera;
    camera.name = name;
    camera.width = width;
    camera.height = height;
    camera.K = K;
    camera.R = R;
    camera.t = t;
    camera.image_name = image_name;
    camera.source = source;
    cameras.push_back(camera);
  }
  if (count < 0) ThrowError(par_file, "", "empty (expected the number of cameras on the first line)");
  if (static_cast<int>(cameras.size()) != count)
    ThrowError(par_file, LineField(line), "expected " + std::to_string(count) + " camera lines, got " +
                                              std::to_string(cameras.size()));
  calibration.notes.push_back("Middlebury *_par.txt: K, R, t as given (P = K [R | t]); no distortion, no metric scale");
  CheckCameraNames(calibration, par_file);
  return calibration;
}

std::vector<Camera> ReadMiddleburyParameters(const std::string& par_file,
                                             const ProjectionMatrixImportOptions& options) {
  return ToCameras(ReadMiddleburyCalibration(par_file, options, true));
}

}  // namespace subflow::vision
