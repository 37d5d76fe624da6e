// Import of cameras given as 3×4 projection matrices P ∝ K [R | t] (DTU / Middlebury
// style), decomposed with cv::decomposeProjectionMatrix (RQ decomposition). The scale
// and sign of P are free: the result has K(2,2) = 1, fx, fy > 0 and det R = +1. No
// distortion (these formats have none). Pixel convention: these files use pixel centres
// at integers like subflow, so no offset is applied.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "vision/calibration_import.h"
#include "vision/camera.h"

namespace subflow::vision {

// Decomposes P = λ K [R | t] (any λ ≠ 0). Throws subflow::Error naming `source` when the
// left 3×3 block of P is singular or the values are not finite.
Camera CameraFromProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P, std::string name,
                                  int width, int height, const std::string& source = "");

struct ProjectionMatrixImportOptions {
  // Image size of every camera. When 0, it is read from the image whose stem equals the
  // camera name in `image_directory` (DTU-style folders) or from the image named in the
  // Middlebury file (beside the *_par.txt file).
  int width = 0;
  int height = 0;
  std::string image_directory;  // "" = the folder of the matrix files
  std::string extension = ".txt";  // matrix files of a DTU-style folder
};

// A folder of matrix files (DTU "pos_001.txt", PMVS "00000000.txt"): each file holds 12
// numbers, 3 lines of 4, optionally after a first line "CONTOUR". Camera name = file
// stem; cameras sorted by name. Throws naming the file and line for malformed files.
std::vector<Camera> ReadProjectionMatrixFolder(const std::string& directory,
                                               const ProjectionMatrixImportOptions& options = {});

// A Middlebury multi-view "*_par.txt": first line the camera count n, then n lines
// "imgname k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3"
// (P = K [R | t] given as K, R, t; as the files print R to limited precision, Camera takes
// the nearest rotation, vision/rotation.h). Camera
// name = stem of imgname. Throws naming the file and line.
std::vector<Camera> ReadMiddleburyParameters(const std::string& par_file,
                                             const ProjectionMatrixImportOptions& options = {});

// The same as Calibrations for `subflow import` (formats "matrices" and "middlebury"):
// sizes found as above, or left 0 (taken from the media) unless `require_sizes`.
Calibration ReadProjectionMatrixCalibration(const std::string& directory,
                                            const ProjectionMatrixImportOptions& options = {},
                                            bool require_sizes = false);
Calibration ReadMiddleburyCalibration(const std::string& par_file, const ProjectionMatrixImportOptions& options = {},
                                      bool require_sizes = false);
// K, R, t of P = λ K [R | t] (see CameraFromProjectionMatrix), size unknown.
CalibratedCamera DecomposeProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P, const std::string& name,
                                           const std::string& source);

}  // namespace subflow::vision
