// The regularization residual families of a refinement window (refinement_window.h), per
// active vertex v of level ℓ and frame t of the window, in units of the level's mean edge
// length h (weights / h), and the bounds of the increments:
//   membrane             w_m/h (B_v e_v − (1/K) Σ_{u ∈ ring(v)} B_u e_u)  (3 residuals)
//   temporal smoothness  w_s/h second difference over t − 1, t, t + 1 (interior frames of
//                        the sequence; frames outside the window enter with their current
//                        values): at ℓ > 0 of the detail in its local frame (n, r, q), d + e,
//                        which a rigid motion leaves unchanged, so only non-rigid
//                        acceleration is penalized; at ℓ = 0 of the world increments B e
//                        only, since the base control points' world trajectories
//                        accelerate with the rigid motion itself (a rotating or swinging
//                        object), which a smoothness term would fight;
//   slide coherence      w_c/h T_tᵀ (B_t e_t − B_{t+1} e_{t+1}) where the vertex may slide
//                        (dof 3; with tangential_only_at_outlines, where it slides at t or
//                        t + 1): the first difference of its tangential increments in frame
//                        t's tangent plane T_t (the basis' columns 1 and 2), so that the
//                        vertex slides alike over the frames (2 residuals; a frame after
//                        the window enters with its current value);
//   damping              w_d/h e_v;
//   bounds               |e_v,d| ≤ max_step · h per component and, for the normal-only
//                        parametrization, c(ℓ)_v + n e_v inside the working volume (the
//                        paper's inequality constraints).
#pragma once

#include <ceres/ceres.h>

#include "solver/stereo/refinement_window.h"
#include "vision/working_volume.h"

namespace subflow::solver {

// Each adds at most one block for vertex `vertex` at window frame `frame` (none when the
// term's weight is 0, the vertex has no ring, or the frame lacks the neighbours the term reads).
void AddMembraneResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem);
void AddTemporalSmoothnessResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem);
void AddSlideCoherenceResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem);
void AddDampingResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem);

// Holds the blocks of the context frames and of inactive vertices constant and bounds the
// others; returns the number of free scalar unknowns.
int BoundIncrements(RefinementWindow& window, const vision::Bounds& bounds, ceres::Problem* problem);

// [lo, hi] of a normal-only increment e such that p + n e stays in `bounds`, widened to
// contain 0 (a point already outside may stay where it is).
std::pair<double, double> SlabRange(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                    const vision::Bounds& bounds);

}  // namespace subflow::solver
