// Qualisys calibration (.qca.txt, the XML that QTM exports) read as Pose2Sim reads it
// (perfanalytics/pose2sim, Pose2Sim/calibration.py: read_qca, calib_qca_fun), for each
// <camera> under <cameras> whose model is a video camera ("video", "hybrid" or "none" in
// its `model`, as Pose2Sim selects them), cameras in natural order of `serial` (the name):
//
//   image size      w = (fov_video.right − fov_video.left + 1) / b,  h likewise (top, bottom)
//   intrinsics      fx = focalLengthU / 64 / b,  fy = focalLengthV / 64 / b      (QTM's
//                   sub-pixel units are 1/64 pixel; b = binning factor, usually 1)
//                   cx = centerPointU / 64 / b − fov_video.left,  cy likewise with top
//   distortion      k1 k2 = radialDistortion1,2 / 64 / b,  p1 p2 = tangentalDistortion1,2
//                   / 64 / b (Pose2Sim's scaling; raw_distortion keeps them as printed);
//                   radialDistortion3 (dropped by Pose2Sim) is kept as k3, scaled alike
//   pose            <transform> gives the camera centre C = (x, y, z) in mm and a matrix
//                   M = [r11 r12 r13; r21 r22 r23; r31 r32 r33] whose rows are the camera's
//                   axes in the world with the camera looking along −z, +y up. In OpenCV's
//                   camera frame (rotated by π about x): R = diag(1, −1, −1) M,
//                   t = −R C / 1000 (metres).
//   world           Qualisys' lab frame: +z up, floor at z = 0 (the L-frame on the floor).
//
// Nonzero `skew` is refused (Pose2Sim ignores it and its unit is not documented); a
// `viewrotation` other than 0 is noted (Pose2Sim ignores it: the videos must be stored in
// the orientation the calibration describes). Errors name the file, the camera and the
// element or attribute.
#pragma once

#include <string>

#include "vision/calibration_import.h"

namespace subflow::vision {

struct QualisysImportOptions {
  // Pose2Sim's binning_factor: 2 when the video was recorded binned (e.g. 540p on a 1080p
  // sensor). The import also detects an exact integer ratio between the calibrated and
  // the decoded video size (vision/dataset_import.h), so this is rarely needed.
  int binning_factor = 1;
  // Keep the distortion coefficients as QTM prints them instead of dividing them by 64
  // as Pose2Sim does (see the report of issue 13 for what the pose2sim take shows).
  bool raw_distortion = false;
};

// Parses the text of a .qca.txt file; `source` names it in messages.
Calibration ParseQualisysCalibration(const std::string& text, const std::string& source,
                                     const QualisysImportOptions& options = {});
Calibration ReadQualisysCalibration(const std::string& path, const QualisysImportOptions& options = {});

}  // namespace subflow::vision
