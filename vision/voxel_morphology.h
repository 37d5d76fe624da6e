// Binary 3D morphology and connected components on occupancy volumes (method §4.1: "the
// voxel volume is smoothed and thresholded using 3D morphological filters").
//
// All functions take a geometry::ScalarVolume whose voxels are occupied where the value
// is > 0.5, and write back 0 / 1. The structuring element of radius r is the box
// (2r + 1)³, applied as three separable 1D passes (x, y, z), each O(1) per voxel (a
// running count over the window), so a pass costs O(nx·ny·nz) whatever r.
//
// Border convention: outside the volume counts as EMPTY for a dilation and as OCCUPIED
// for an erosion. Hence closing(X) ⊇ X and opening(X) ⊆ X hold up to the border, and an
// object cut by the border is neither eroded from that side nor grown beyond it.
//
// Connectivity: 6 (faces) or 26 (faces, edges, corners). The empty space uses the
// complementary connectivity (26 ↔ 6), the consistent pair for digital topology.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/scalar_volume.h"

namespace subflow::vision {

// Occupancy as bytes: values[i + nx·(j + ny·k)] ∈ {0, 1} (the layout of ScalarVolume).
// The working type of the functions below; the ScalarVolume overloads convert to it and back.
struct BinaryVolume {
  int nx = 0, ny = 0, nz = 0;
  std::vector<uint8_t> values;

  BinaryVolume() = default;
  BinaryVolume(int nx_, int ny_, int nz_, uint8_t fill = 0)
      : nx(nx_), ny(ny_), nz(nz_), values(static_cast<std::size_t>(nx_) * ny_ * nz_, fill) {}
  // Occupied where volume.values > 0.5.
  explicit BinaryVolume(const geometry::ScalarVolume& volume);
  // Writes 0 / 1 into a volume of the same dimensions.
  void CopyTo(geometry::ScalarVolume* volume) const;

  std::size_t Index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k);
  }
  uint8_t& at(int i, int j, int k) { return values[Index(i, j, k)]; }
  uint8_t at(int i, int j, int k) const { return values[Index(i, j, k)]; }
  std::size_t size() const { return values.size(); }
  std::size_t Count() const;  // occupied voxels
};

// δ_r(X): voxels within box distance r of an occupied voxel.
void DilateBox(BinaryVolume* volume, int radius);
void DilateBox(geometry::ScalarVolume* volume, int radius);
// ε_r(X): voxels whose whole (2r + 1)³ box is occupied (outside counts as occupied).
void ErodeBox(BinaryVolume* volume, int radius);
void ErodeBox(geometry::ScalarVolume* volume, int radius);
// Closing ε_r(δ_r(X)): fills gaps and holes narrower than the box, keeps the rest.
void CloseBox(BinaryVolume* volume, int radius);
void CloseBox(geometry::ScalarVolume* volume, int radius);
// Opening δ_r(ε_r(X)): removes specks and spurs thinner than the box, keeps the rest.
void OpenBox(BinaryVolume* volume, int radius);
void OpenBox(geometry::ScalarVolume* volume, int radius);

struct ComponentSummary {
  int found = 0;           // connected components of occupied voxels
  int kept = 0;            // components kept
  std::size_t largest = 0; // voxels of the largest component
  std::size_t removed_voxels = 0;
};

// Labels the connected components of occupied voxels (iterative flood fill, no recursion)
// and keeps those with at least min_fraction × (voxels of the largest one) voxels;
// min_fraction in [0, 1] (0 keeps all, 1 keeps only the largest and its equals).
ComponentSummary KeepLargeComponents(BinaryVolume* volume, double min_fraction, int connectivity = 26);
ComponentSummary KeepLargeComponents(geometry::ScalarVolume* volume, double min_fraction,
                                     int connectivity = 26);

// Fills interior cavities: empty voxels not connected (with the complementary
// connectivity of `connectivity`) to an empty voxel on the volume's border become
// occupied, so the object's boundary is one closed surface per component.
// Returns the number of voxels filled.
std::size_t FillCavities(BinaryVolume* volume, int connectivity = 26);
std::size_t FillCavities(geometry::ScalarVolume* volume, int connectivity = 26);

}  // namespace subflow::vision
