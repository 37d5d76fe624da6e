// What the solver stages read of a window of frames (motion initialization, stereo
// refinement): per camera and frame, the gray image and the object's silhouette, both
// undistorted to the pinhole camera (Camera::UndistortImage), since the stages project
// with Camera::ProjectUndistorted. Frames are numbered 0..frame_count − 1 within the
// window; window frame f is dataset frame first_frame + f.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/silhouettes.h"

namespace subflow::vision {

class Dataset;

// An image of camera `camera` (index into the cameras) at window frame `frame`.
using ImageLoader = std::function<cv::Mat(int camera, int frame)>;

struct ImageSequence {
  std::vector<Camera> cameras;
  int first_frame = 0;  // dataset frame of window frame 0 (for reports and messages)
  int frame_count = 0;
  // Gray image, any type solver::GrayFloat accepts (8/16-bit, float, BGR), undistorted.
  ImageLoader gray;
  // Silhouette, CV_8UC1 (nonzero = object), undistorted; an empty Mat, or no loader at
  // all, means none for that camera and frame.
  ImageLoader silhouette;
  // Per camera: 1 when its silhouette is the object's own outline (a mask), so the
  // surface's outline must reach it; 0 when it only bounds the object (a projected visual
  // hull, which contains it). Empty: every camera's silhouette is the object's outline.
  std::vector<char> tight_outline;

  int camera_count() const { return static_cast<int>(cameras.size()); }
  // Throws subflow::Error naming `stage` when there is no camera, no frame or no gray loader.
  void Check(const std::string& stage) const;
};

// `image` as the pinhole camera sees it: Camera::UndistortImage with `interpolation`
// (cv::INTER_LINEAR for images, cv::INTER_NEAREST for masks) when the camera has
// distortion, else `image` itself.
cv::Mat Undistorted(const Camera& camera, const cv::Mat& image, int interpolation);

// The window [first_frame, first_frame + frame_count) of `dataset` (which must outlive the
// sequence, as must `hulls`). Silhouette of camera k at window frame f: where the camera's
// evidence (`evidence`, kAuto resolved by AutomaticSource, as shape initialization does) is
// a mask, the dataset's mask; otherwise hulls[f] (the frame's visual hull, world
// coordinates) rendered into the camera (ZBuffer::Mask), none when `hulls` is null or that
// hull is empty; tight_outline says which. `working`: per camera, the working camera (vision/working_scale.h) whose
// size every image is resized to before undistortion, and which the sequence's cameras
// are; null = the stored cameras and sizes. `outlines` (may be null or empty; else one per
// camera, which must outlive the sequence): a camera without a mask whose outline is not
// empty takes it as its mask in every frame (CV_8UC1 in raw image coordinates, resized to
// the working size at half coverage), a tight outline. `background_outlines` (may be null):
// a camera whose evidence is a background image takes, as its tight outline, each frame's
// background-image silhouette made with these options (BackgroundImageSilhouette; each
// computed once per sequence and kept, compressed, within a fixed memory budget).
ImageSequence DatasetImages(const Dataset& dataset, int first_frame, int frame_count,
                            EvidenceSource evidence = EvidenceSource::kAuto,
                            const std::vector<geometry::TriangleMesh>* hulls = nullptr,
                            const std::vector<Camera>* working = nullptr,
                            const std::vector<cv::Mat>* outlines = nullptr,
                            const SilhouetteOptions* background_outlines = nullptr);

}  // namespace subflow::vision
