// A regular 3D grid of scalar samples (e.g. evidence or occupancy of voxels), the
// exchange type between voxel carving (vision/) and iso-surface extraction (geometry/).
//
// Sample (i, j, k) sits at the CENTRE of voxel (i, j, k): world position
//   origin + spacing · (i, j, k),   0 ≤ i < nx, 0 ≤ j < ny, 0 ≤ k < nz,
// and is stored at values[i + nx · (j + ny · k)] (x fastest). Voxels are cubes of edge
// `spacing` (world units).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace subflow::geometry {

struct ScalarVolume {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // centre of voxel (0, 0, 0)
  double spacing = 1.0;                              // voxel edge length
  int nx = 0, ny = 0, nz = 0;
  std::vector<float> values;                         // nx·ny·nz samples, x fastest

  ScalarVolume() = default;
  ScalarVolume(const Eigen::Vector3d& origin_, double spacing_, int nx_, int ny_, int nz_,
               float fill = 0.0f)
      : origin(origin_), spacing(spacing_), nx(nx_), ny(ny_), nz(nz_),
        values(static_cast<size_t>(nx_) * ny_ * nz_, fill) {}

  size_t Index(int i, int j, int k) const {
    return static_cast<size_t>(i) + static_cast<size_t>(nx) * (j + static_cast<size_t>(ny) * k);
  }
  float& at(int i, int j, int k) { return values[Index(i, j, k)]; }
  float at(int i, int j, int k) const { return values[Index(i, j, k)]; }
  bool InRange(int i, int j, int k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < nx && j < ny && k < nz;
  }
  Eigen::Vector3d VoxelCenter(int i, int j, int k) const {
    return origin + spacing * Eigen::Vector3d(i, j, k);
  }
  size_t size() const { return values.size(); }
};

}  // namespace subflow::geometry
