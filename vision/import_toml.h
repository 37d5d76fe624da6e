// Pose2Sim / Anipose Calib.toml (aniposelib CameraGroup.dump, Pose2Sim's toml_write), one
// table per camera (any key except metadata, capture_volume, charuco, checkerboard, as
// Pose2Sim's retrieve_calib_params skips them), in key order as aniposelib loads them:
//
//   name = "cam01"            camera name (the table's key when absent)
//   size = [1088.0, 1920.0]   image width, height
//   matrix = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]   OpenCV convention (pixel centres)
//   distortions = [k1, k2, p1, p2(, k3)]             cv2.projectPoints' coefficients, or
//   fisheye = true  →  distortions = [k1, k2, k3, k4] cv2.fisheye's (aniposelib FisheyeCamera)
//   rotation = [rx, ry, rz]   Rodrigues vector of R (world → camera, cv2.Rodrigues)
//   translation = [tx, ty, tz]
//
// Units of the translations: Pose2Sim writes metres; Anipose the units of its board's
// square size (usually mm): the format's default is "m", `subflow import --units mm` for
// Anipose. Errors name the file, the table and the key.
#pragma once

#include <string>

#include "vision/calibration_import.h"

namespace subflow::vision {

Calibration ParseTomlCalibration(const std::string& text, const std::string& source);
Calibration ReadTomlCalibration(const std::string& path);

// R of a Rodrigues vector (rotation by |r| about r / |r|), as cv2.Rodrigues.
Eigen::Matrix3d RodriguesToRotation(const Eigen::Vector3d& rotation_vector);

}  // namespace subflow::vision
