// The working volume: an axis-aligned box (world units) that contains the object at
// every frame — cameras.json's "bounds" (../shared/DATASET.md), or, where that is absent,
// the region that enough cameras see, derived from the cameras alone.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "vision/camera.h"

namespace subflow::vision {

// Axis-aligned box [min, max] in world coordinates; valid when min < max componentwise.
struct Bounds {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();

  bool IsValid() const { return (min.array() < max.array()).all() && min.allFinite() && max.allFinite(); }
  Eigen::Vector3d Center() const { return 0.5 * (min + max); }
  Eigen::Vector3d Size() const { return max - min; }
  double Diagonal() const { return (max - min).norm(); }
  bool Contains(const Eigen::Vector3d& X) const {
    return (X.array() >= min.array()).all() && (X.array() <= max.array()).all();
  }
};

struct WorkingVolumeOptions {
  // A point belongs to the working volume when at least this fraction of the cameras
  // see it (in front of the camera, projecting inside the image), and never fewer than
  // 2 cameras. 1.0 = the intersection of all viewing frusta.
  double min_camera_fraction = 0.75;
  // Grid points per axis of each of the two sampling passes (coarse, then refined).
  int grid_resolution = 48;
  // Points closer to a camera centre than this fraction of the sampling half-size are
  // not counted as seen by it (excludes the degenerate apex of each frustum).
  double near_fraction = 0.05;

  // Throws subflow::Error naming the field when an option is out of range.
  void Check() const;
};

// The working volume derived from the cameras (for datasets without "bounds"):
//  1. look-at point c = the least-squares point closest to all optical axes
//     (argmin Σ_k |(I − a_k a_kᵀ)(X − C_k)|², a_k = view direction, C_k = centre);
//     if the axes are (nearly) parallel (a forward-facing rig: smallest eigenvalue of
//     Σ_k (I − a_k a_kᵀ) below 1e-3 × the largest), c = mean centre + 5 × spread × mean
//     view direction, spread = the largest distance of a centre from the mean centre;
//  2. sampling box: the cube of half-size s = max_k |C_k − c| around c;
//  3. pass 1: a grid_resolution³ grid over that cube; a grid point counts as seen by
//     camera k when Xc.z > near_fraction·s and Project(X) is inside the image
//     (InImage, pixel-centre convention); points seen by ≥ n_min = max(2,
//     ceil(min_camera_fraction · #cameras)) cameras are kept;
//  4. pass 2: the same over the kept points' bounding box grown by one pass-1 cell;
//  5. result: the kept points' bounding box of pass 2 grown by one pass-2 cell on each
//     side (so the true region is covered to the grid's resolution).
// Throws subflow::Error (source = `source`, field "bounds") when fewer than 2 cameras
// are given or no sampled point is seen by n_min cameras.
Bounds EstimateWorkingVolume(const std::vector<Camera>& cameras,
                             const WorkingVolumeOptions& options = {},
                             const std::string& source = "");

}  // namespace subflow::vision
