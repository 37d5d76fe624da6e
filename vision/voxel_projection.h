// Projection of a voxel grid into a camera: the corners of the voxels (for footprints, in
// voxel carving) and the occupied voxels as a silhouette (for the silhouette IoU).
//
// Voxel corners: the grid is a geometry::ScalarVolume whose sample (i, j, k) is the
// CENTRE of voxel (i, j, k); corner (i, j, k), 0 ≤ i ≤ nx, 0 ≤ j ≤ ny, 0 ≤ k ≤ nz, is at
//   origin + spacing · ((i, j, k) − ½),
// so voxel (i, j, k) spans corners (i..i+1, j..j+1, k..k+1).
//
// Pixels are those of the RAW image (Camera::Project, with lens distortion), pixel (0, 0)
// the centre of the top-left pixel, because silhouettes are in raw image coordinates.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "geometry/scalar_volume.h"
#include "vision/camera.h"

namespace subflow::vision {

// Marks a corner that cannot be projected: behind the camera (depth ≤ 0) or, for a
// distorted camera, with its pinhole pixel farther outside the image than the image's
// size (there the distortion polynomial can fold back into the image). A footprint
// containing it starts left of any image, so the voxel is not seen.
inline constexpr float kInvalidPixel = -1e30f;

class VoxelCornerProjector {
 public:
  // Keeps references: `camera` and `grid` must outlive the projector.
  VoxelCornerProjector(const Camera& camera, const geometry::ScalarVolume& grid);

  // World position of corner (i, j, k).
  Eigen::Vector3d Corner(int i, int j, int k) const;
  // Pixel of corner (i, j, k); false (and kInvalidPixel) when it cannot be projected.
  bool ProjectCorner(int i, int j, int k, float* u, float* v) const;
  // Pixels of the corners [i0, i1] × [j0, j1] × [k0, k1] (inclusive), x fastest, then y,
  // then z: (i1 − i0 + 1)(j1 − j0 + 1)(k1 − k0 + 1) values each. A pinhole camera's
  // h = K (R X + t) is affine in (i, j, k), so a corner costs a multiply-add per
  // coordinate and one division (float, error ~1e-5 px); a distorted camera goes through
  // Camera::Project.
  void ProjectCorners(int i0, int i1, int j0, int j1, int k0, int k1, float* us, float* vs) const;

 private:
  const Camera& camera_;
  const geometry::ScalarVolume& grid_;
  bool distorted_;
  Eigen::Vector3d h0_, dh_i_, dh_j_, dh_k_;  // h(i, j, k) = h0 + i dh_i + j dh_j + k dh_k
};

// The pixels of every corner of a grid in one camera (ProjectCorner's values, kInvalidPixel
// where it cannot project), corner (i, j, k) at i + (nx + 1)(j + (ny + 1) k).
struct GridCornerPixels {
  int nx = 0, ny = 0, nz = 0;  // the grid's voxels per axis (corners: one more)
  std::vector<float> u, v;
  std::size_t Index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx + 1) * (j + static_cast<std::size_t>(ny + 1) * k);
  }
  std::size_t Bytes() const { return (u.size() + v.size()) * sizeof(float); }
};
// Projects them all (parallel over the grid's planes).
GridCornerPixels ProjectGridCorners(const Camera& camera, const geometry::ScalarVolume& grid);

// Whether the pixel of world point X (Camera::Project, same validity rule as above) lies
// in the image; false behind the camera.
bool ProjectsIntoImage(const Camera& camera, const Eigen::Vector3d& X);

// CV_8UC1 0 / 255 image of the camera: the projection of the occupied voxels (> 0.5),
// each cube's outline (convex hull of its 8 projected corners) filled at the pixels whose
// centres it contains; only voxels with an empty face-neighbour are drawn (they bound the
// projection). Voxels with a corner that cannot be projected are skipped.
cv::Mat ProjectOccupancy(const Camera& camera, const geometry::ScalarVolume& occupancy);

// The occupied voxels (> 0.5) with an empty (or outside) face-neighbour, in index order.
std::vector<Eigen::Vector3i> SurfaceVoxels(const geometry::ScalarVolume& occupancy);
// ProjectOccupancy for a precomputed list of voxels of `grid` (e.g. SurfaceVoxels, shared
// by several cameras).
cv::Mat ProjectVoxels(const Camera& camera, const geometry::ScalarVolume& grid,
                      const std::vector<Eigen::Vector3i>& voxels);

// |a ∩ b| / |a ∪ b| of two CV_8UC1 images of one size (non-zero = in); 1 when both are empty.
double SilhouetteIoU(const cv::Mat& a, const cv::Mat& b);

}  // namespace subflow::vision
