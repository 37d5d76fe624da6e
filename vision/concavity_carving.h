// Photo-consistent carving of a visual hull's concavities (issue 12: hollows).
//
// A visual hull cannot see into a concavity: the cavity of a mug, an eye socket, a mouth,
// the space between two people that every camera sees behind one of them all stay filled,
// because some silhouette covers every ray through them. The cameras' images do show what
// is behind: a ray that enters the hull at the cavity's lid meets the surface on the far
// wall or the floor of the cavity. So, per frame:
//
//   1. depth maps of every camera by plane sweep with NCC (vision/plane_sweep.h), over
//      the hull's bounding box only (grown by one voxel) and only at the pixels the hull
//      covers (its projection): what depth inside the hull each pixel sees. The images
//      are reduced so that a voxel spans about `pixels_per_voxel` pixels at the hull's
//      centre (vision/working_scale.h: EvidenceScale; never enlarged): the carving
//      decides whole voxels, and finer images only cost time;
//   2. trusted depths: confirmed by other cameras' depth maps (vision/depth_fusion.h:
//      TrustedDepths), so a chance match of one pair carves nothing;
//   3. every hull voxel that at least `fusion.free_votes` cameras see through (a trusted
//      depth behind it by more than the depth tolerance plus surface_margin_voxels, none
//      at it or in front), and at which no camera measures a surface (surface_veto), is
//      emptied (depth_fusion.h: CarveSeenThrough); nothing is ever added;
//   4. the empty space after carving (outside the hull, and emptied) is opened by a box of
//      radius opening_radius: only emptied voxels that such a box of free space covers
//      stay empty. The hull's margin trimmed along its surface and a hollow opened to the
//      outside stay; narrow tunnels and pockets go — the trace of wrong depths behind the
//      surface, which no camera can refute (every camera sees the object's surface in
//      front of them): on ../shared/data/blob such tunnels reached 31 mm into the object;
//   5. emptied regions that reach no deeper than min_depth face-steps into the hull are
//      refilled: hollows are carved, the hull's margin (about a voxel over the object,
//      which the refinement corrects from the images anyway) is not;
//   6. the carved hull is cleaned as the hull was: components smaller than
//      min_component_fraction of the largest removed, interior cavities filled.
//
// Off by default. Measured (docs/shape.md, 2026-12-05): without the surface veto it opens
// the mug's cup and the space under the critter (observed accuracy P90 4.13 -> 2.09 px and
// 1.26 -> 1.13 px), but on ../shared/data/blob (rendered by Blender) it costs 6 % in
// accuracy and on an untextured sphere wrong depths from shading cut into the object.
// With the veto (the default of these options) the blob and the sphere stay as they were
// and the gains are small (mug 3.36 px, critter 1.23 px), for ~1 s a frame.
//
// Texture-less surface gives no depth and so carves nothing: the hull stays where the
// images cannot say. As a guard against depth maps gone wrong (repetitive texture, a
// frame with motion blur), a carving that would remove more than max_carved_fraction of
// the hull's voxels is not applied (the report says so).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/scalar_volume.h"
#include "vision/camera.h"
#include "vision/depth_fusion.h"
#include "vision/plane_sweep.h"

namespace subflow::vision {

struct ConcavityCarvingOptions {
  // Shape initialization carves the hulls when enabled (off by default: see the
  // measurements in docs/shape.md): every frame's with every_frame, else only the
  // reference frame's (the base mesh's; measured worse: the other frames' fits then pull
  // the hollows shut).
  bool enabled = false;
  bool every_frame = true;
  PlaneSweepOptions sweep = DefaultSweep();
  // fusion.free_votes: cameras that must see through a voxel to empty it (two: one
  // camera's wrong depth never carves); the other fields as in vision/depth_fusion.h.
  DepthFusionOptions fusion = DefaultFusion();
  // Nothing is carved unless at least 2 cameras have this many sweep neighbours (cameras
  // within sweep.max_neighbour_degrees of their viewing direction): with one neighbour
  // every depth rests on one pair. On ../shared/data/pose2sim_multiperson (4 cameras,
  // one neighbour each) the filters of steps 4–5 kept 27 of 1,786 voxels emptied, at
  // 0.5 s a frame.
  int min_neighbours = 2;
  // Image scale of the sweep: a voxel spans about this many pixels (0 = the images' size).
  double pixels_per_voxel = 2.0;
  // Free space is trusted only this many voxels in front of a measured surface, beyond the
  // depth tolerance (step 3), so that depths wrong by a plane or two cannot cut into the
  // object (0 = the tolerance alone).
  double surface_margin_voxels = 0.0;
  // A voxel at which some camera measures a surface is never emptied (step 3): the free
  // space a wrong depth behind the surface implies crosses the surface other cameras
  // measure. Keeps the blob and an untextured sphere whole (docs/shape.md).
  bool surface_veto = true;
  // Only emptied voxels inside a box of radius opening_radius (voxels) of empty space stay
  // empty (step 4; 0 = every emptied voxel).
  int opening_radius = 1;
  // Emptied regions that reach no deeper than this many face-steps into the hull are
  // refilled (step 5; 0 = none).
  int min_depth = 3;
  // The most of the hull one carving may remove; above it nothing is removed.
  double max_carved_fraction = 0.3;
  // Components kept after carving: at least this fraction of the largest one's voxels.
  double min_component_fraction = 0.1;

  void Check() const;  // throws subflow::Error naming the field

  static PlaneSweepOptions DefaultSweep() {
    PlaneSweepOptions sweep;
    sweep.sweep_beyond_volume = false;  // the hull's box: what lies behind it is not asked
    return sweep;
  }
  static DepthFusionOptions DefaultFusion() {
    DepthFusionOptions fusion;
    fusion.free_votes = 2;
    return fusion;
  }
};

struct ConcavityCarvingReport {
  bool applied = false;          // the carving was kept
  std::string skipped;           // why not, "" when applied or when nothing was carved
  std::size_t hull_voxels = 0;   // occupied before
  std::size_t carved_voxels = 0; // emptied by free space (before cleaning)
  std::size_t removed_voxels = 0;  // occupied before and not after (carving and cleaning)
  int trusted_pixels = 0;        // trusted depths over all cameras
  double seconds = 0;
};

// Carves `occupancy` (0 / 1, vision/voxel_carving.h's grid) in place. `gray[k]`: camera
// k's image of the frame, CV_32FC1 in [0, 1], of cameras[k]'s size. Throws
// subflow::Error on sizes that disagree.
ConcavityCarvingReport CarveConcavities(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                        const ConcavityCarvingOptions& options, geometry::ScalarVolume* occupancy);

}  // namespace subflow::vision
