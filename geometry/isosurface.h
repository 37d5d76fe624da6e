// Iso-surface of an occupancy volume as a closed, 2-manifold, well-shaped triangle mesh
// (section 4.1 of the method: "an iso-surface extraction algorithm determines the initial
// shape and topology of the mesh").
//
// The surface is { x : f(x) = iso_value }, where f is the trilinear interpolation of the
// samples of `volume` (sample (i, j, k) at origin + spacing·(i, j, k), see scalar_volume.h)
// after three preparations:
//   1. padding by at least `padding_voxels` samples of value 0 on every side (and by more
//      than the blur's reach, ceil(3σ) + 1), so that the border samples stay 0 ≤ iso_value
//      and an object touching the border of the volume still gets a closed surface (it is
//      capped about half a voxel outside the outermost occupied sample);
//   2. a separable Gaussian blur of standard deviation σ = `smoothing_sigma_voxels`, so
//      that the binary {0,1} occupancy of voxel carving does not give a staircase. The
//      blur is a step of mean-curvature flow for the 0.5 level: it moves the surface
//      towards its centres of curvature by ≈ σ²·H (H the mean curvature; σ²/R on a ball
//      or a spherical cavity of radius R: 0.05 voxel for R = 20, 0.17 for R = 6), and
//      sheets thinner than ≈ 1.4σ, rods thinner than ≈ 2.4σ, blobs smaller than ≈ 3σ
//      across vanish;
//   3. the inside is f > iso_value (strictly).
// The surface is sampled by CGAL Mesh_3 (restricted Delaunay refinement on a gray-level
// image domain, surface criteria only, manifold topology): vertices lie on the surface (to
// 0.001 voxel), triangles have angles ≥ facet_angle_degrees. Refinement is seeded on every
// 6-connected component of the inside and of the outside, so that no object and no cavity
// is missed. Faces are counter-clockwise seen from outside: normals point out of the
// object, into cavities.
//
// Units: positions are world units (those of `volume.origin` and `volume.spacing`); every
// length option is in voxels (multiples of `volume.spacing`). Deterministic: the random
// generator of Mesh_3 is seeded with `random_seed`.
#pragma once

#include <string>
#include <vector>

#include "geometry/scalar_volume.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct IsosurfaceOptions {
  // Level of the surface; the inside is value > iso_value. 0.5 for an occupancy in {0,1}.
  // Must be ≥ 0 so that the zero padding is outside.
  double iso_value = 0.5;
  // Standard deviation of the Gaussian blur applied before extraction, in voxels. 0 = none
  // (use 0 for a field that is already smooth). The kernel is truncated at 3σ.
  double smoothing_sigma_voxels = 1.0;
  // Minimum number of empty samples added on every side before blurring (≥ 1); at least
  // ceil(3σ) + 1 are added so that the blur never reaches the border of the padded grid.
  int padding_voxels = 2;

  // Mesh_3 surface criteria (see CGAL::Mesh_facet_criteria_3):
  // lower bound on the smallest angle of every surface triangle, degrees (≤ 30 is safe).
  double facet_angle_degrees = 30.0;
  // upper bound on the radius of every triangle's surface Delaunay ball, in voxels
  // (≈ edge length / √3 for an equilateral triangle); smaller = more triangles.
  double facet_size_voxels = 2.0;
  // upper bound on the distance from a triangle's circumcentre to the surface, voxels.
  double facet_distance_voxels = 0.25;

  // Safety valve against runaway refinement: Mesh_3 stops at this many vertices (and the
  // extraction fails with an error if the surface is then not closed). 0 = no limit.
  int max_vertex_count = 2000000;
  // Seed of CGAL's random generator (Mesh_3 and the domain); fixed for reproducibility.
  unsigned int random_seed = 0;

  // Throws subflow::Error naming the field when an option is out of range.
  void Check() const;
};

// Statistics of one extraction, for logs and report.json.
struct IsosurfaceSummary {
  int component_count = 0;        // 6-connected components of { f > iso_value }
  int cavity_count = 0;           // components of { f ≤ iso_value } not touching the border
  int vertex_count = 0;
  int face_count = 0;
  double prepare_seconds = 0.0;   // padding + blur + component search
  double mesh_seconds = 0.0;      // Mesh_3 refinement
  double extract_seconds = 0.0;   // boundary extraction and manifold check
};

// The iso-surface of `volume` (see the header comment). Returns V (#V×3, world units) and
// F (#F×3, CCW seen from outside). `summary` may be null.
// Throws subflow::Error ("<source>: <field>: <problem>") when the volume is malformed
// (non-positive sizes, values.size() ≠ nx·ny·nz, non-finite origin, spacing ≤ 0), holds a
// NaN or infinite value, is empty (no value > iso_value) or fully occupied (every value >
// iso_value: the working volume does not enclose the object), when the options are out of
// range, or when the extracted surface is not a closed 2-manifold.
TriangleMesh ExtractIsosurface(const ScalarVolume& volume, const IsosurfaceOptions& options,
                               IsosurfaceSummary* summary = nullptr,
                               const std::string& source = "occupancy volume");

// The steps of ExtractIsosurface that need no CGAL, exposed for tests and reuse.

// Throws subflow::Error naming `source` when `volume` is malformed or not finite
// (see ExtractIsosurface).
void CheckScalarVolume(const ScalarVolume& volume, const std::string& source);

// `volume` padded by `padding` zero samples on every side (the origin moves by
// −padding·spacing so that world positions of samples are unchanged), then blurred by a
// separable Gaussian of standard deviation sigma_voxels (truncated at 3σ, normalized;
// samples beyond the padded grid count as 0). sigma_voxels = 0 only pads.
ScalarVolume PadAndSmoothVolume(const ScalarVolume& volume, int padding, double sigma_voxels);

// One segment per seed: `inside` is a sample with value > iso_value, `outside` its
// 6-neighbour with value ≤ iso_value, so the trilinear field crosses iso_value exactly once
// on the segment. Seeds are spread over every 6-connected component of the inside
// { value > iso } and of the outside { value ≤ iso } (so that cavities get seeds too): for
// each component, its extreme samples along the 26 directions of {−1, 0, 1}³ \ {0}, each
// paired with its neighbour across the surface (none where that is off the grid).
// Components are numbered in scan order, inside ones and outside ones in one sequence.
struct IsosurfaceSeed {
  int component = 0;
  Eigen::Vector3d inside = Eigen::Vector3d::Zero();
  Eigen::Vector3d outside = Eigen::Vector3d::Zero();
};
std::vector<IsosurfaceSeed> FindIsosurfaceSeeds(const ScalarVolume& volume, double iso_value,
                                                int* inside_component_count = nullptr,
                                                int* outside_component_count = nullptr);

}  // namespace subflow::geometry
