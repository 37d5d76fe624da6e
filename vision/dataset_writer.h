// Writing datasets in the layout of ../shared/DATASET.md (see vision/dataset.h):
// cameras.json, images/<cam>/<frame>.png, masks/<cam>/<frame>.png, background/<cam>.png
// and groundtruth/mesh/<frame>.ply. Numbers are written with 17 significant digits so
// that reading back gives the same doubles.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/dataset.h"

namespace subflow::vision {

// Writes `image` (8- or 16-bit, 1, 3 or 4 channels) as a PNG at `path`, creating its
// directory, through core/atomic_file.h: no half-written PNG ever carries the name.
// Throws subflow::Error naming the path when it cannot be encoded or written.
void WritePng(const std::string& path, const cv::Mat& image);

// Writes cameras.json (format "multiview-video/1"); absent optionals and an empty `units`
// are left out, through core/atomic_file.h. Throws subflow::Error naming the path
// when it cannot be written or a camera name is empty, duplicated or contains '/'.
void WriteCamerasJson(const std::string& path, const std::vector<Camera>& cameras,
                      std::optional<double> fps, std::optional<int> frame_count,
                      const std::optional<Bounds>& bounds, const std::string& units = "");

// Creates `directory` (and its parents) for a new dataset. Throws subflow::Error naming it
// when it exists and is not an empty directory, unless `overwrite` is set: then only its
// dataset entries (cameras.json, report.json, preview/, images/, videos/, masks/, background/,
// groundtruth/) are
// removed, nothing else.
void PrepareDatasetDirectory(const std::string& directory, bool overwrite);

// Throws, as PrepareDatasetDirectory would, when `directory` is not a directory or is a
// non-empty one and `overwrite` is false; changes nothing. For commands that check their
// output before doing any work.
void CheckDatasetDirectory(const std::string& directory, bool overwrite);

// Creates a dataset directory and fills it. The constructor writes cameras.json and
// creates images/<cam>/; the Write* calls write one file each (PNG, lossless). It never
// overwrites a non-empty existing directory unless `overwrite` is set (then the
// directory's previous dataset entries — cameras.json, images/, videos/, masks/,
// background/, groundtruth/ — are removed first; nothing else is touched).
class DatasetWriter {
 public:
  DatasetWriter(const std::string& directory, std::vector<Camera> cameras,
                const DatasetInfo& info, bool overwrite = false);

  const std::string& directory() const { return directory_; }
  const std::vector<Camera>& cameras() const { return cameras_; }

  // `image`: CV_8U or CV_16U with 1, 3 (BGR) or 4 channels, of the camera's size.
  void WriteImage(int camera, int frame, const cv::Mat& image) const;
  // `mask`: CV_8UC1 of the camera's size; written as 0 / 255 (non-zero → 255).
  void WriteMask(int camera, int frame, const cv::Mat& mask) const;
  void WriteBackground(int camera, const cv::Mat& image) const;
  // groundtruth/mesh/<frame>.ply via geometry::WriteMesh (binary PLY).
  void WriteGroundTruthMesh(int frame, const geometry::TriangleMesh& mesh) const;

 private:
  void CheckImage(int camera, const cv::Mat& image, const std::string& path) const;

  std::string directory_;
  std::vector<Camera> cameras_;
  DatasetInfo info_;
};

}  // namespace subflow::vision
