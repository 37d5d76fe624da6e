// Synthetic subjects built as signed-distance functions (vision/synthetic_sdf.h), meshed
// once at rest into one fixed-connectivity mesh, and deformed per frame
// (vision/synthetic_deformation.h): vertex i is one material point at every frame.
//
// Meshing: the SDF s is sampled on a grid of `voxel_size` over the subject's box (+ 3
// voxels), mapped to the occupancy-like field v = clamp(½ − s / (4·voxel), 0, 1) (linear
// within ±2 voxels of the surface, so its trilinear interpolation puts the 0.5 level within
// O(voxel²·curvature) of s = 0), extracted by geometry::ExtractIsosurface (CGAL Mesh_3,
// no blur, facets of `facet_size_voxels`), and every vertex is then moved onto s = 0 by
// Newton steps along the numerical gradient, x ← x − s(x) ∇s / |∇s|² (3 steps), so the
// ground truth is the SDF's surface, not its voxelization. Parts thinner than ~2 voxels
// are not resolved: the voxel must be well below the thinnest part (the ears: 3 mm).
//
// World: metres, +z up, subjects face −y (camera 0 of the rigs), centred near the origin
// within a radius of ≈ 0.13 m.
//   bust     head-like: ellipsoid cranium on a neck, brow ridge, a nose, two deep eye
//            sockets (≈ 15 mm), a mouth slit hollow (≈ 12 mm), ear-like plates 3 mm thick
//            standing off the sides. Turns (yaw ±25°, period 120) while the jaw (the front
//            below the mouth line, blended over 1–1.5 cm) opens 0 → 14° (ramp, period 96).
//   mug      an object with a handle (genus 1): a cup 9 cm across with 6 mm walls and a
//            torus-segment handle; tumbles (±20° about a tilted axis), translates (±1.5 cm),
//            bends (±8° ramp along its height) and its handle flexes (±10°).
//   pair     two separate figures (torso, head, arms, legs) 6 cm apart, moving
//            independently: the left one turns (±35°) and raises an arm (0 → 50°); the
//            right one sways sideways (±2 cm), bends at the waist (±15°) and swings its legs.
//   critter  animal-like: a long body on four thin legs (12 mm), a thin curled tail (8 mm),
//            a head with a snout and ear plates 3 mm thick. The body twists about its long
//            axis (±15°), the tail wags (±30°), the head turns (±20°), the legs swing in
//            diagonal pairs (±15°), the whole yaws (±20°) and moves (±1 cm).
#pragma once

#include <string>
#include <vector>

#include "core/progress.h"
#include "geometry/triangle_mesh.h"
#include "vision/synthetic_deformation.h"
#include "vision/synthetic_sdf.h"

namespace subflow::vision {

struct SdfSubject {
  std::string name;
  Sdf sdf;                     // at rest
  Eigen::Vector3d box_min, box_max;  // contains { s ≤ 0 } at rest
  Deformation deformation;
  int component_count = 1;     // connected components of the surface
  int genus = 0;               // of each component (a handle: 1)
};

std::vector<std::string> SdfSubjectNames();  // bust, mug, pair, critter
bool IsSdfSubject(const std::string& name);
// Throws subflow::Error naming the subject when it is unknown.
SdfSubject MakeSdfSubject(const std::string& name);

struct SdfMeshOptions {
  double voxel_size = 0.0015;    // metres; the thinnest part (3 mm) needs ≤ 1.5 mm
  double facet_size_voxels = 1.5;  // CGAL facet size bound (≈ edge / √3), voxels
  int newton_steps = 3;

  void Check() const;  // throws subflow::Error naming the field
};

// The rest mesh of `subject` (closed, 2-manifold, CCW from outside), see the file comment.
geometry::TriangleMesh MeshSdfSubject(const SdfSubject& subject, const SdfMeshOptions& options,
                                      Progress* progress = nullptr);

}  // namespace subflow::vision
