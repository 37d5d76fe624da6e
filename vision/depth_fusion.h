// Evidence voxels from multi-view depth maps (vision/plane_sweep.h) of a still image set:
// what occupies the working volume, found by where the cameras see THROUGH it.
//
// 1. Trusted depths. The depth of pixel p of camera r (inverse depth q, X its point) is
//    trusted when at least `consistent_cameras` other cameras j, into whose image X
//    projects in front of them, measured the same inverse depth there:
//        |q_j(X) − Q_j(π_j(X))| ≤ consistency_planes · Δq_j
//    (q_j(X) = 1 / depth of X in j, Q_j j's map at the nearest pixel, Δq_j j's plane step).
//    Wrong matches (repeated texture, occlusion) rarely agree across cameras.
// 2. Support plane (vision/support_plane.h) from the trusted points inside the volume;
//    inlier tolerance = support_tolerance_planes × the median depth step (world units) of
//    those points. Voxels within that tolerance of it or below it are empty.
// 3. Free space. Camera k sees voxel V (centre X, inverse depth q_V in k) through the
//    trusted depth Q at X's pixel; V lies in front of that surface, so is empty, when
//        q_V − Q > free_space_planes · Δq_k + (√3/2) s q_V²      (s = voxel edge)
//    i.e. the surface is farther than the voxel by the depth tolerance plus half the
//    voxel's diagonal. A voxel freed by at least free_votes cameras is empty. Depths
//    behind the volume (the room, PlaneSweepOptions::sweep_beyond_volume) free the whole
//    ray: a background pixel carves like a silhouette's background, and a surface pixel
//    carves the space in front of the surface, which a silhouette cannot.
// 4. A voxel is occupied when it is not empty, and at least min_cameras cameras see it
//    (its centre projects into their image, in front of them): as in voxel carving, one
//    view cannot place anything along its rays. Nothing is said about voxels no trusted
//    depth reaches (texture-less surroundings), which therefore stay occupied.
// The result is cleaned as carving's (components ≥ min_component_fraction of the largest).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "geometry/scalar_volume.h"
#include "vision/camera.h"
#include "vision/plane_sweep.h"
#include "vision/support_plane.h"
#include "vision/working_volume.h"

namespace subflow::vision {

struct DepthFusionOptions {
  int consistent_cameras = 2;
  double consistency_planes = 2.0;
  double free_space_planes = 2.0;
  int free_votes = 1;
  int min_cameras = 2;
  int min_hits = 2;
  bool remove_support_plane = true;
  double support_tolerance_planes = 2.0;
  SupportPlaneOptions support_plane;
  double min_component_fraction = 0.1;

  void Check() const;  // throws subflow::Error naming the field
};

struct FusedOccupancy {
  geometry::ScalarVolume occupancy;   // 0 / 1 per voxel (vision/voxel_carving.h's grid)
  SupportPlane support;               // found = removed
  std::vector<int> trusted_pixels;    // per camera
  std::vector<int> depth_pixels;      // per camera: pixels with a depth before the check
  std::size_t occupied_voxels = 0;
  double seconds = 0;
};

// `maps[k]` belongs to cameras[k] (of its size); `resolution`: voxels along the longest
// axis of `bounds` (vision/voxel_carving.h: MakeVoxelGrid).
FusedOccupancy FuseDepthMaps(const std::vector<Camera>& cameras, const std::vector<DepthMap>& maps,
                             const Bounds& bounds, int resolution, const DepthFusionOptions& options = {});

// Per camera, CV_8UC1 255 where the depth of the pixel is trusted (step 1 above).
std::vector<cv::Mat> TrustedDepths(const std::vector<Camera>& cameras, const std::vector<DepthMap>& maps,
                                   const DepthFusionOptions& options = {});

}  // namespace subflow::vision
