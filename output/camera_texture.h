// Colour of surface points taken from the input cameras that see them best (textured
// new views). For a surface point X with unit normal n at one frame, camera c (centre
// C_c) counts when its z-buffer of the surface sees X (ZBuffer::IsVisible) and
//   w_c = n · (C_c − X) / |C_c − X| > min_cosine;
// the colour is the w_c²-weighted mean over the `blend` cameras of largest w_c of their
// image at X's pixel (Camera::Project, lens distortion included: the raw image is
// sampled, bilinearly). Gray cameras give gray; 16-bit images are scaled to [0, 1].
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "geometry/triangle_mesh.h"
#include "vision/dataset.h"
#include "vision/zbuffer.h"

namespace subflow::output {

struct CameraTextureOptions {
  int blend = 2;              // cameras mixed per point (the best ones)
  double min_cosine = 0.1;    // cameras seeing the surface more obliquely are left out
  double depth_tolerance = 0; // world units for IsVisible; 0 = half the mean edge length
};

class CameraTexture {
 public:
  // Renders the z-buffers of (V, F) at `frame` into every camera and loads the images.
  CameraTexture(const vision::Dataset& dataset, int frame, const geometry::Positions& V, const geometry::Faces& F,
                const CameraTextureOptions& options = {});
  // sRGB colour of X (normal n); false (and *rgb untouched) when no camera sees it.
  bool Colour(const Eigen::Vector3d& X, const Eigen::Vector3d& n, Eigen::Vector3f* rgb) const;

 private:
  const vision::Dataset& dataset_;
  CameraTextureOptions options_;
  std::vector<vision::ZBuffer> zbuffers_;
  std::vector<cv::Mat> images_;  // CV_32FC3 RGB in [0, 1]
};

// A dataset image as 8-bit BGR (gray replicated, 16-bit scaled, alpha dropped).
cv::Mat ToBgr8(const cv::Mat& image);

}  // namespace subflow::output
