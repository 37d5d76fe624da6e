// Evidence voxels from multi-view depth maps (vision/plane_sweep.h) of a still image set:
// what occupies the working volume, found from where the cameras see THROUGH it.
//
// 1. Trusted depths (TrustedDepths). The depth of pixel p of camera r (inverse depth q,
//    X its point) is checked against every other camera j into whose image X projects in
//    front of it and which measured a depth Q_j at that pixel (nearest):
//        agrees   |q_j(X) − Q_j| ≤ consistency_planes · Δq_j
//        against  Q_j < q_j(X) − tolerance: j sees through X, a surface behind it
//        (Q_j > q_j(X) + tolerance is a surface in front of X that hides it from j: no vote)
//    (q_j(X) = 1 / depth of X in j, Δq_j j's plane step). The depth is trusted when
//        agree ≥ 1 and agree ≥ min(consistent_cameras, agree + against)
//    — wrong matches (repeated texture, occlusion) rarely agree across cameras — or, when
//    no camera can vote (X is seen by no other camera that measured a depth there, e.g.
//    the room behind the volume seen by one pair), when its own score reaches
//    unconfirmed_min_score.
// 2. Free space (FuseDepthMaps). Camera k, looking at voxel V (centre X, inverse depth
//    q_V in k), compares the trusted depths Q of the pixels of V's footprint (a box of
//    V's half diagonal around X's pixel) with
//        tolerance = free_space_planes · Δq_k + (√3/2) s q_V²      (s = voxel edge):
//        through  Q < q_V − tolerance: the surface is behind V, so V is empty;
//        surface  Q ≥ q_V − tolerance: a surface at V or in front of it.
//    k frees V when its footprint has a pixel that sees through and none that sees a
//    surface (V straddling the object's outline is kept); k hits V when some pixel sees a
//    surface. V is occupied when fewer than free_votes cameras free it, at least min_hits
//    cameras hit it (something was seen there or in front of it from two directions:
//    space that no trusted depth reaches stays empty), and at least min_cameras cameras
//    see it (its centre projects into their image, in front of them). A support plane
//    (vision/support_plane.h), when given, empties the voxels within its tolerance of it
//    or below it.
//    Depths behind the volume (the room) free the whole ray: a background pixel carves as
//    a silhouette's background does, and a surface pixel carves the space in front of the
//    surface, which a silhouette cannot.
// The result is cleaned: components smaller than min_component_fraction of the largest
// are removed (vision/voxel_morphology.h).
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
  // Trusted depths: agreeing cameras asked for (fewer when fewer can vote), and the
  // agreement tolerance in plane steps of the other camera's sweep.
  int consistent_cameras = 2;
  double consistency_planes = 2.0;
  // A depth that no other camera can check is trusted on its own score from this value.
  double unconfirmed_min_score = 0.9;
  // Free space: depth tolerance in plane steps (plus half the voxel's diagonal).
  double free_space_planes = 2.0;
  int free_votes = 1;
  int min_hits = 2;
  int min_cameras = 2;
  double min_component_fraction = 0.1;

  void Check() const;  // throws subflow::Error naming the field
};

// Per camera, the inverse depths of `maps` that are trusted (step 1), kNoDepth elsewhere
// (CV_32FC1, the map's size).
std::vector<cv::Mat> TrustedDepths(const std::vector<Camera>& cameras, const std::vector<DepthMap>& maps,
                                   const DepthFusionOptions& options = {});

struct FusedOccupancy {
  geometry::ScalarVolume occupancy;  // 0 / 1 per voxel (vision/voxel_carving.h: MakeVoxelGrid)
  std::size_t occupied_voxels = 0;
  double seconds = 0;
};

// Step 2. `trusted[k]`: camera k's trusted inverse depths (TrustedDepths, possibly with
// more added), `steps[k]` the plane step Δq_k of its sweep; `resolution`: voxels along the
// longest axis of `bounds`; `support`: a plane to remove (null or not found = none).
FusedOccupancy FuseDepthMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                             const std::vector<double>& steps, const Bounds& bounds, int resolution,
                             const SupportPlane* support, const DepthFusionOptions& options = {});

// Step 2 inside a given occupancy (0 / 1, e.g. a visual hull): every occupied voxel that at
// least options.free_votes cameras free (see through it, as above) is emptied; nothing is
// added, and no camera is asked to hit a voxel (space that no trusted depth reaches keeps
// what the occupancy says). `margin` (world units, ≥ 0) is added to the depth tolerance:
// nothing within it of a measured surface is emptied. With `veto_at_surface`, a voxel at
// which any camera measures a surface (a trusted depth within the tolerance of the
// voxel's) is kept whatever the others see through: the free space a wrong depth behind
// the surface implies crosses the surface that other cameras measure. Returns the voxels
// emptied. Every vote reads the maps only, so the result does not depend on the order of
// the voxels.
std::size_t CarveSeenThrough(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                             const std::vector<double>& steps, const DepthFusionOptions& options, double margin,
                             bool veto_at_surface, geometry::ScalarVolume* occupancy);

}  // namespace subflow::vision
