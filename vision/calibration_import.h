// What every calibration importer (vision/import_*.h) produces: the cameras of a rig as
// the source tool defines them, converted to the convention of ../shared/DATASET.md
// (Xc = R X + t, +z forward, +y down, pixel (0, 0) = centre of the top-left pixel, OpenCV
// distortion), with the world units and the up axis the format fixes, if any. Image sizes
// may be unknown (0) when the format has none; the import takes them from the camera's
// video or images (vision/dataset_import.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vision/camera.h"
#include "vision/lens_distortion.h"

namespace subflow::vision {

struct CalibratedCamera {
  std::string name;
  int width = 0, height = 0;  // pixels; 0 = unknown (from the media)
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // as read (a near-rotation; Camera re-orthonormalizes)
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // in the calibration's units
  Eigen::VectorXd distortion;                       // in the order of `distortion_model`
  DistortionModel distortion_model = DistortionModel::kOpenCV;
  std::string image_name;  // the image the calibration names for it (COLMAP NAME, Middlebury), or ""
  std::string source;      // the file (and entry) it was read from, for messages
};

struct Calibration {
  std::string format;  // "colmap", "qualisys", ...
  std::vector<CalibratedCamera> cameras;
  // Unit of the translations: "m", "cm", "mm", or "" when the format has no metric scale
  // (COLMAP, projection matrices: written as they are, without "units").
  std::string units;
  // The world's up direction where the format fixes one, the floor being the plane through
  // the origin normal to it (Qualisys: +z). Unset otherwise.
  std::optional<Eigen::Vector3d> up;
  // The conventions applied, one sentence each (printed by `subflow import`, recorded in
  // its report.json).
  std::vector<std::string> notes;
};

// Metres per unit of "m", "cm", "mm"; throws subflow::Error naming `field` otherwise.
double MetresPerUnit(const std::string& units, const std::string& field);

// The cameras, t multiplied by `metres_per_unit`. Throws subflow::Error naming the camera's
// source when a size is unknown or a camera is invalid (vision::Camera's checks).
std::vector<Camera> ToCameras(const Calibration& calibration, double metres_per_unit = 1.0);

// Throws subflow::Error naming `source` when two cameras share a name or a name is not
// usable as a folder name (DATASET.md: names are folder and file names).
void CheckCameraNames(const Calibration& calibration, const std::string& source);

// The whole content of the calibration file `path`; throws subflow::Error naming it
// ("cannot open (expected <what>)") when it cannot be read.
std::string ReadCalibrationFile(const std::string& path, const std::string& what);

// The number `text` is, entirely (surrounding blanks allowed): strtod's syntax, finite.
// False for "", "1.5x", "nan", "inf".
bool ParseFiniteNumber(const std::string& text, double* value);

}  // namespace subflow::vision
