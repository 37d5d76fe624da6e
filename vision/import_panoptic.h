// CMU Panoptic Studio calibration_<seq>.json (panoptic-toolbox: python/panutils.py
// projectPoints): {"calibDataSource": ..., "cameras": [{"name": "00_01", "type": "hd",
// "resolution": [1920, 1080], "panel": 0, "node": 1, "K": 3×3, "distCoef": [k1, k2, p1,
// p2, k3], "R": 3×3, "t": [[tx], [ty], [tz]] (or [tx, ty, tz])}, ...]}.
//
// OpenCV conventions (Xc = R X + t, pixel centres at integers, OpenCV's distortion);
// world units centimetres. panutils.projectPoints computes y' with the x' it has just
// distorted (an in-place update), which differs from OpenCV's formula, that Panoptic's
// calibration (and cv2.projectPoints) follows, by ~2 p2 Δx y ≲ 1e-5 px on HD cameras; the
// tests measure both. Errors name the file and the camera's entry.
#pragma once

#include <string>

#include "vision/calibration_import.h"

namespace subflow::vision {

Calibration ParsePanopticCalibration(const std::string& text, const std::string& source);
Calibration ReadPanopticCalibration(const std::string& path);

}  // namespace subflow::vision
