// The surface samples of one refinement level (solver/stereo/stereo_refinement.h): a
// pattern inside every face (patch) of level ℓ (AppendFaceSamplePattern, at least
// min_density² per patch, about samples_per_pixel per pixel² of its finest view), their
// level-ℓ limit stencils grouped per face — the Jacobian of the samples with respect to
// the level-ℓ control points (eq. 12–13: the limit surface of the refined mesh is that of
// c(ℓ)) — and the limit matrices of the same material points on the finest level, where
// the current surface is evaluated (nested faces: child k of face f is 4f + k).
#pragma once

#include <vector>

#include "geometry/limit_evaluation.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/stereo/ncc_cost.h"
#include "vision/camera.h"

namespace subflow::solver {

struct StereoRefinementOptions;

struct LevelSampling {
  std::vector<geometry::FaceSample> samples;  // on level-ℓ faces, face by face
  std::vector<int> face_first;                // #F(ℓ) + 1 offsets into samples
  // L, ∂L/∂u, ∂L/∂v of the samples on the finest level: #S × #V(n).
  geometry::SparseMatrix finest_limit, finest_du, finest_dv;
  std::vector<std::vector<int>> support;  // per face: the level-ℓ vertices its samples depend on
  std::vector<PatchStencil> stencil;      // per face: m × #support limit-stencil weights

  int FaceSampleCount(int face) const { return face_first[face + 1] - face_first[face]; }
};

// Samples of `level` for the level's control points `level_control` (#V(ℓ)×3, the
// densities follow their projected areas in `cameras`); with `active_faces` (#F(ℓ)), only
// the faces marked 1 get samples (the others an empty range).
LevelSampling SampleLevel(const geometry::LoopHierarchy& hierarchy, int level,
                          const geometry::Positions& level_control,
                          const std::vector<vision::Camera>& cameras,
                          const StereoRefinementOptions& options,
                          const std::vector<char>* active_faces = nullptr);

}  // namespace subflow::solver
