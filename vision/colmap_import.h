// Import of a COLMAP text model (cameras.txt + images.txt) into subflow Cameras.
//
// COLMAP's pose convention is ours (Xc = R X + t, R from the quaternion QW QX QY QZ of
// images.txt, t = TX TY TZ), but its pixel convention is not: COLMAP puts the centre of
// the top-left pixel at (0.5, 0.5), subflow at (0, 0). So cx_ours = cx_colmap − 0.5 and
// cy_ours = cy_colmap − 0.5; focal lengths and distortion are unchanged.
//
// Camera models: SIMPLE_PINHOLE (f cx cy), PINHOLE (fx fy cx cy), SIMPLE_RADIAL (f cx cy
// k), RADIAL (f cx cy k1 k2), OPENCV (fx fy cx cy k1 k2 p1 p2), FULL_OPENCV (… k3 k4 k5
// k6, accepted only with k4 = k5 = k6 = 0). Others are an error naming the line.
#pragma once

#include <string>
#include <vector>

#include "vision/camera.h"

namespace subflow::vision {

struct ColmapImportOptions {
  // How a camera is named from images.txt's NAME: the file stem ("cam03/000000.png" →
  // "000000") or the parent folder ("cam03/000000.png" → "cam03").
  enum class NameFrom { kFileStem, kParentFolder };
  NameFrom name_from = NameFrom::kFileStem;
};

// Reads <directory>/cameras.txt and <directory>/images.txt. One Camera per image line,
// sorted by name. Throws subflow::Error naming the file and line for malformed lines,
// unknown camera ids or models, non-positive sizes or focal lengths, zero quaternions,
// and duplicate names.
std::vector<Camera> ReadColmapTextModel(const std::string& directory,
                                        const ColmapImportOptions& options = {});

}  // namespace subflow::vision
