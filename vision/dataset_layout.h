// Internal to vision/dataset.cpp: the validated file layout of a dataset
// (../shared/DATASET.md) and the checked reading of one image file.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/camera.h"
#include "vision/dataset.h"

namespace subflow::vision {

struct DatasetLayout {
  std::string directory;     // as given
  std::string cameras_path;  // <directory>/cameras.json
  std::vector<Camera> cameras;
  DatasetInfo info;
  int frame_count = 0;
  bool videos = false, masks = false, background = false, groundtruth = false;
  std::vector<std::string> video_paths;  // per camera, when `videos`
  std::vector<std::string> image_extensions;  // per camera, when images/ (".png", ".jpg", ...)
  // Legal but worth saying (pixel formats that differ between cameras or frames, 16-bit
  // data), found while checking the PNG headers.
  std::vector<std::string> warnings;

  std::string ImagePath(int camera, int frame) const;  // the video's path when `videos`
  std::string MaskPath(int camera, int frame) const;
  std::string BackgroundPath(int camera) const;
  std::string GroundTruthMeshPath(int frame) const;
  // Throws subflow::Error when camera ∉ [0, #cameras) or frame ∉ [0, frame_count).
  void CheckIndex(int camera, int frame) const;
};

// Reads cameras.json and checks every file the layout requires or allows (folder names,
// frame names, every camera having every frame, optionally each PNG header's size).
DatasetLayout ScanDatasetLayout(const std::string& directory, bool check_image_headers);

// cv::imread(path, IMREAD_UNCHANGED) checked to be 8/16-bit with 1, 3 or 4 channels and
// of the camera's size; throws naming `path` otherwise.
cv::Mat ReadImageFile(const std::string& path, const Camera& camera);
// Throws "<what>: size: expected W×H (camera "name"), got w×h" when sizes differ.
void CheckImageSize(const cv::Mat& image, const Camera& camera, const std::string& what);

}  // namespace subflow::vision
