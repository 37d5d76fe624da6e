// Object evidence of a STILL image set — one frame of every camera, or the static scene of
// a take (the backgrounds estimated from its video) — without masks, background images or
// motion: multi-view photo-consistency inside the working volume (issue 13, item 3).
//
//   1. depth maps of every camera by plane sweep with NCC (vision/plane_sweep.h), inside
//      the volume and behind it (the room around the object is measured too);
//   2. trusted depths: confirmed by the depth maps of other cameras
//      (vision/depth_fusion.h: TrustedDepths);
//   3. the support plane (floor, treadmill, table top) from the trusted points inside the
//      volume (vision/support_plane.h: RANSAC; inlier tolerance support_tolerance_planes ×
//      the median depth step of those points), then tested as a whole in every camera
//      (ScorePlane: windows warped by its homography): a pixel that has no trusted depth
//      and sees the plane (score ≥ the sweep's min_score) takes the plane's depth as a
//      trusted one. The floor seen at a grazing angle, and beyond the volume, then frees
//      the space above it;
//   4. free-space fusion of the trusted depths into voxels, the support plane removed
//      (vision/depth_fusion.h: FuseDepthMaps);
//   5. per camera, the silhouette of the fused occupancy (ProjectOccupancy): the evidence
//      that voxel carving, the motion stage and refinement read like any other.
//
// Why photo-consistency with support planes and free space, and not a segmentation:
// when the object has its surroundings' texture (the synthetic bust in its textured
// room), colour models cannot separate them (GrabCut seeded by the projected working
// volume labelled every pixel background), and colour consistency of voxels alone keeps
// the textured floor (a hull 80–87 mm off against 4.9 mm from masks); geometry separates
// them: the floor is a plane under the object, the walls lie behind the volume.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/camera.h"
#include "vision/depth_fusion.h"
#include "vision/plain_backdrop.h"
#include "vision/plane_sweep.h"
#include "vision/support_plane.h"
#include "vision/working_volume.h"

namespace subflow::vision {

struct StillEvidenceOptions {
  // Shape initialization uses the still evidence when nothing else finds the object
  // (solver/shape/shape_init.h); false = never (such datasets are then an error).
  bool enabled = true;
  // Before the photo-consistency: when every camera's backdrop is plain
  // (vision/plain_backdrop.h), the silhouettes are the differences to its colour instead
  // (solver/shape/shape_init.h); enabled = false: always the photo-consistency.
  PlainBackdropOptions backdrop;
  PlaneSweepOptions sweep;
  DepthFusionOptions fusion;
  // Find and remove a support plane (step 3).
  bool remove_support_plane = true;
  SupportPlaneOptions support_plane;
  // Inlier tolerance of the support plane, in depth steps of the sweep (median over the
  // trusted points inside the volume, in world units).
  double support_tolerance_planes = 2.0;

  void Check() const;  // throws subflow::Error naming the field
};

struct StillCameraReport {
  std::string name;
  int planes = 0;              // planes swept
  int depth_pixels = 0;        // pixels with a depth kept by the sweep
  int trusted_pixels = 0;      // of those, trusted (step 2)
  int support_pixels = 0;      // pixels given the support plane's depth (step 3)
  int silhouette_pixels = 0;   // pixels of the silhouette (step 5)
  double sweep_seconds = 0;
};

struct StillEvidence {
  std::vector<cv::Mat> silhouettes;  // per camera, CV_8UC1 0 / 255, the camera's size
  FusedOccupancy fused;
  SupportPlane support;
  std::vector<StillCameraReport> cameras;
  double seconds = 0;
};

// `gray[k]`: camera k's still image, CV_32FC1 in [0, 1], of cameras[k]'s size; `known[k]`
// (optional, as for SweepDepthMaps): the pixels that show the still scene (e.g. the
// known pixels of an estimated background). `resolution`: voxels along the longest axis
// of `bounds` (vision/voxel_carving.h). Throws subflow::Error on inputs of the wrong size.
StillEvidence ComputeStillEvidence(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                   const Bounds& bounds, int resolution, const StillEvidenceOptions& options = {},
                                   const std::vector<cv::Mat>& known = {});
// Steps 2–5 on depth maps already swept (SweepDepthMaps of the same images).
StillEvidence StillEvidenceFromDepthMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                         const std::vector<DepthMap>& maps, const Bounds& bounds, int resolution,
                                         const StillEvidenceOptions& options = {},
                                         const std::vector<cv::Mat>& known = {});

}  // namespace subflow::vision
