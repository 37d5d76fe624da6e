// EasyMocap's intri.yml / extri.yml (easymocap/mytools/camera_utils.py: read_camera,
// write_intri, write_extri), OpenCV FileStorage YAML read with cv::FileStorage:
//
//   intri.yml   names: ["01", "02", ...]; K_<name> (3×3); dist_<name> (1×5 k1 k2 p1 p2 k3,
//               or 1×4; D_<name> when dist_ is absent); H_<name>, W_<name> (image size,
//               optional: the media's size when absent)
//   extri.yml   R_<name> (3×1 Rodrigues vector, what read_camera uses), Rot_<name> (3×3,
//               used only when R_ is absent), T_<name> (3×1)
//
// OpenCV conventions throughout (Xc = R X + t, pixel centres at integers). EasyMocap
// works in metres. Errors name the file and the node.
#pragma once

#include <string>

#include "vision/calibration_import.h"

namespace subflow::vision {

Calibration ParseEasyMocapCalibration(const std::string& intri_yml, const std::string& extri_yml,
                                      const std::string& intri_source, const std::string& extri_source);
// `path`: the folder holding intri.yml and extri.yml.
Calibration ReadEasyMocapCalibration(const std::string& path);

}  // namespace subflow::vision
