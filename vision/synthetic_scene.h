// Synthetic deforming scenes with ground truth, for `subflow synth` and the tests.
//
// Every scene is one fixed-connectivity triangle mesh (an icosphere of `subdivisions`
// levels, faces counter-clockwise from outside) whose vertex positions change per frame:
// vertex i at frame f + 1 minus vertex i at frame f is the true 3D motion. `rest` holds
// each vertex's rest position (the material coordinate the texture is bound to).
// World units are metres, +z is up, the objects sit near the origin (radius ≈ 0.1 m).
// Time: τ = motion · f (frame f), so `motion` scales every velocity of the scene.
//
//   blob   icosphere r = 0.1 displaced along the rest normals by three travelling
//          sinusoids of the rest position (|k| = 28, 34, 40 rad/m, amplitude 3 mm
//          each, 0.3 rad per unit τ) plus a translation of 1.27 mm per unit τ along
//          (1, −0.6, 0.5)/|·|.
//   rigid  a lumpy, non-symmetric potato (ellipsoid 0.10 × 0.075 × 0.06 with two bumps
//          and a dent) rotating 2° per unit τ about a tilted axis through its centre and
//          translating 1.5 mm per unit τ: every vertex moves rigidly.
//   head   an ellipsoid head (0.075 wide, 0.09 deep, 0.10 high) facing −y with nose,
//          brow and cheek bumps and eye dents, turning (yaw 1.2° per unit τ about +z)
//          while a "jaw" region (front, below the mouth line) rotates open about a hinge
//          axis parallel to x by 0.8° per unit τ, blended smoothly into the rest.
//   sphere a round sphere r = 0.1 (the icosphere's vertices lie on it) spinning 2° per
//          unit τ about a tilted axis through its centre and translating 1.5 mm per
//          unit τ along (1, 0.5, −0.4)/|·|: its silhouette in any camera is known
//          analytically (the pixels whose ray passes within r of the centre, which is
//          the mean of the vertices), which checks the renderer and the camera
//          convention independently of the z-buffer; and it is convex.
//   bust, mug, pair, critter   signed-distance subjects with thin parts, hollows, a
//          handle, two bodies, articulations (vision/synthetic_subject.h), meshed at
//          `voxel_size` (not `subdivisions`).
// Frame f is rendered at τ = motion · (start_frame + f): a still (frame_count 1) of any
// moment of a scene is start_frame = that moment.
#pragma once

#include <string>
#include <vector>

#include "core/progress.h"
#include "geometry/triangle_mesh.h"

namespace subflow::vision {

struct SyntheticSceneOptions {
  std::string scene = "blob";  // SyntheticSceneNames()
  int frame_count = 24;        // frames 0..frame_count−1
  int start_frame = 0;         // frame f shows the scene at its frame start_frame + f
  double motion = 1.0;         // scales the motion per frame (0 = static)
  int subdivisions = 5;        // icosphere levels: 5 → 10242 vertices, 20480 triangles
  double voxel_size = 0.0015;  // SDF subjects: meshing voxel (m); ≤ 1.5 mm resolves 3 mm plates

  // Throws subflow::Error naming the field when a value is out of range.
  void Check() const;
};

struct SyntheticScene {
  std::string name;
  geometry::Faces F;                      // #F×3, the same at every frame
  geometry::Positions rest;               // #V×3 material (texture) coordinates
  std::vector<geometry::Positions> frames;  // frame_count × (#V×3) positions

  int frame_count() const { return static_cast<int>(frames.size()); }
  geometry::TriangleMesh Mesh(int frame) const { return {frames[frame], F}; }
};

// The scene names MakeSyntheticScene accepts.
std::vector<std::string> SyntheticSceneNames();

SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& options, Progress* progress = nullptr);

}  // namespace subflow::vision
