// COLMAP sparse models (src/colmap/scene/reconstruction_io_{text,binary}.cc): cameras.txt +
// images.txt, or cameras.bin + images.bin (little-endian; cameras: uint64 count, then per
// camera uint32 id, int32 model id, uint64 width, uint64 height, double params[]; images:
// uint64 count, then per image uint32 id, double qw qx qy qz tx ty tz, uint32 camera id,
// NUL-terminated name, uint64 #points, (double x, double y, uint64 point3D id) each).
//
// COLMAP's pose convention is ours (Xc = R X + t, R of the unit quaternion qw qx qy qz),
// its pixel convention is not: COLMAP puts the centre of the top-left pixel at (0.5, 0.5),
// subflow at (0, 0), so cx = cx_colmap − 0.5, cy = cy_colmap − 0.5.
//
// Camera models (COLMAP's ids): SIMPLE_PINHOLE 0 (f cx cy), PINHOLE 1 (fx fy cx cy),
// SIMPLE_RADIAL 2 (f cx cy k), RADIAL 3 (f cx cy k1 k2), OPENCV 4 (fx fy cx cy k1 k2 p1
// p2), OPENCV_FISHEYE 5 (fx fy cx cy k1 k2 k3 k4: cv::fisheye), FULL_OPENCV 6 (... k1 k2
// p1 p2 k3 k4 k5 k6: the rational model), SIMPLE_RADIAL_FISHEYE 8 (f cx cy k) and
// RADIAL_FISHEYE 9 (f cx cy k1 k2) as cv::fisheye with the other coefficients 0. Other
// models are an error naming the camera.
//
// One Camera per image, named after the image's file stem ("cam03/000000.png" → "000000")
// or its folder ("cam03"); the image's NAME is kept as the camera's image (the import
// links it as the camera's still when no folder matches the name).
#pragma once

#include <string>
#include <vector>

#include "vision/calibration_import.h"
#include "vision/camera.h"

namespace subflow::vision {

struct ColmapImportOptions {
  enum class NameFrom { kFileStem, kParentFolder };
  NameFrom name_from = NameFrom::kFileStem;
};

// <directory>/cameras.bin + images.bin when both exist, else cameras.txt + images.txt.
Calibration ReadColmapModel(const std::string& directory, const ColmapImportOptions& options = {});
// The same from the files' contents (`source` names them in messages).
Calibration ParseColmapTextModel(const std::string& cameras_txt, const std::string& images_txt,
                                 const std::string& source, const ColmapImportOptions& options = {});
Calibration ParseColmapBinaryModel(const std::string& cameras_bin, const std::string& images_bin,
                                   const std::string& source, const ColmapImportOptions& options = {});

// The text model as Cameras, sorted by name (sizes are COLMAP's).
std::vector<Camera> ReadColmapTextModel(const std::string& directory, const ColmapImportOptions& options = {});

}  // namespace subflow::vision
