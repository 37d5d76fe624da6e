// Multi-view depth maps by plane sweep inside the working volume, with normalized
// cross-correlation (NCC) of image windows: where a still image set (one frame, or the
// static scene of a take) has texture, which depth inside the volume each pixel sees.
//
// For a reference camera r and each pixel p (raw image, pixel-centre convention), the ray
// X(q) = C_r + (1/q) R_rᵀ (x, y, 1) with (x, y) the undistorted normalized point of p (lens
// distortion removed: LensDistortion::Undistort) and q = 1/z the inverse depth along r's
// optical axis. Hypotheses are fronto-parallel planes of r, uniform in q, from the nearest
// depth at which r's rays enter the working volume to the farthest at which they leave it
// or, with sweep_beyond_volume, to infinity (q = 0: what lies behind the volume, the room
// around it, is then measured too, so that a pixel can say "nothing inside the volume
// along my ray"); spaced so that one step moves the projection by at most max_step_pixels
// in every neighbour camera (capped at max_planes). A pixel takes part at a plane when the
// plane's point is inside the volume or (sweep_beyond_volume) behind it, never in front of it.
// For each plane and neighbour j, the image of j is sampled where X(q) projects
// (distortion included; bilinear), and
//     NCC_j(p, q) = cov(I_r, I_j∘π_j) / sqrt(var(I_r) var(I_j∘π_j))
// over the (2w + 1)² window around p (box filters; a window with a pixel outside j's image
// or not taking part is invalid). The score of p at q is the mean of the best
// k = consistent_views values of NCC_j over the neighbours (a repeated or occluded texture
// agrees with one camera by chance far more often than with k); the pixel's inverse depth
// is the plane of the highest score. A pixel keeps it when
//   score ≥ min_score, the window's standard deviation in r ≥ min_texture (texture-less
//   windows correlate with anything), and the best score beats the best score farther than
//   `uniqueness_planes` planes away by uniqueness_margin (repeating texture).
// Pixels outside `known` (when given) get none.
//
// Neighbours of r: the cameras whose optical axes make an angle of at most
// max_neighbour_degrees with r's (patches seen at larger angles are too foreshortened to
// correlate), sorted by that angle, the first `neighbours` of them; the camera itself and
// cameras with (nearly) the same centre are skipped.
//
// Cost per reference camera: D planes × neighbours × (one projection per pixel, one
// remap, four box filters).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "vision/camera.h"
#include "vision/working_volume.h"

namespace subflow::vision {

struct PlaneSweepOptions {
  // Neighbour cameras each reference camera is compared with (the closest in viewing
  // direction within max_neighbour_degrees).
  int neighbours = 4;
  double max_neighbour_degrees = 70.0;
  // The score of a depth is the mean NCC of the best `consistent_views` neighbours (at
  // most the neighbours available). 1 = the best single neighbour: the cross-check of
  // vision/depth_fusion.h rejects what one pair matched by chance, and a surface that only
  // two cameras see (next to an occluding object) keeps its depth; on the synthetic bust
  // still (11 cameras) the hull from 1 was 6.6 mm off (observed P90) against 8.4 mm from 2.
  int consistent_views = 1;
  // Window half-width w (pixels of the working image): windows of (2w + 1)².
  int window_radius = 3;
  // Depth planes: one step moves the projection by at most this many pixels in every
  // neighbour; at most max_planes planes.
  double max_step_pixels = 1.0;
  int max_planes = 512;
  // Sweep on behind the volume, to infinity (see the file comment).
  bool sweep_beyond_volume = true;
  // A pixel keeps its depth when its score reaches min_score,
  double min_score = 0.6;
  // its window's standard deviation (intensity in [0, 1]) reaches min_texture,
  double min_texture = 0.02;
  // and its score exceeds the best score outside ±uniqueness_planes planes by this much.
  double uniqueness_margin = 0.05;
  int uniqueness_planes = 4;
  // Worker threads (TBB) over reference cameras; 0 = all available.
  int threads = 0;

  void Check() const;  // throws subflow::Error naming the field
};

// The depth map of one camera (the working image's size).
inline constexpr float kNoDepth = -1.0f;
inline constexpr float kNotSwept = -2.0f;

struct DepthMap {
  // CV_32FC1: inverse depth q = 1/z along the optical axis (1 / world units); 0 = at
  // infinity; kNoDepth = swept without a depth kept; kNotSwept = the pixel's ray misses
  // the volume.
  cv::Mat inverse_depth;
  cv::Mat score;  // CV_32FC1: the best score (mean NCC of the best views); −1 where none
  int planes = 0;                 // planes swept
  double inverse_depth_step = 0;  // their spacing in q
  std::vector<int> neighbours;    // camera indices compared with
  int pixels_with_depth = 0;
  double seconds = 0;
};

// Depth maps of every camera. `gray[k]`: camera k's image, CV_32FC1 in [0, 1], of
// cameras[k]'s size; `known[k]` (optional: empty vector or empty Mat = every pixel): CV_8UC1,
// non-zero where the image shows the scene to be measured. Throws subflow::Error on sizes
// that disagree or fewer than 2 cameras.
std::vector<DepthMap> SweepDepthMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                     const Bounds& bounds, const PlaneSweepOptions& options = {},
                                     const std::vector<cv::Mat>& known = {});

// The hypothesis that every pixel of camera r sees the world plane normal·X + offset = 0
// (e.g. a support plane, which continues beyond the working volume): per pixel the plane's
// inverse depth (−1 where it is behind the camera) and the score of the sweep (mean NCC of
// the best consistent_views of `neighbours`), with the neighbours' windows warped by the
// plane's homography, so that a floor seen at a grazing angle correlates as well as a
// fronto-parallel surface; −1 where undefined or texture-less (min_texture).
struct PlaneHypothesis {
  cv::Mat inverse_depth;  // CV_32FC1
  cv::Mat score;          // CV_32FC1
};
PlaneHypothesis ScorePlane(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray, int r,
                           const std::vector<int>& neighbours, const Eigen::Vector3d& normal, double offset,
                           const PlaneSweepOptions& options = {});

// The neighbours camera r is compared with (see the file comment), nearest in viewing
// direction first.
std::vector<int> ChooseNeighbours(const std::vector<Camera>& cameras, int r, const PlaneSweepOptions& options = {});

// The world point of pixel (u, v) of `camera` at depth z (z along the optical axis).
Eigen::Vector3d PointAtDepth(const Camera& camera, const Eigen::Vector2d& pixel, double z);

// The depths [z_near, z_far] (along the optical axis) over which the ray of pixel (u, v)
// of `camera` lies inside `bounds`; false when it misses them.
bool RayDepthsInBounds(const Camera& camera, const Eigen::Vector2d& pixel, const Bounds& bounds, double* z_near,
                       double* z_far);

}  // namespace subflow::vision
