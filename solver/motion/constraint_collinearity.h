// Pruning bad correspondences by the collinearity of normal-flow constraint planes
// (method §4.2), and the robust statistics shared with the solver's re-weighting.
//
// The constraints of one surface sample seen by K cameras are planes {V : g_kᵀ V = b_k}
// in 3D velocity space. When the sample's correspondences are right every g_k lies in
// span{∇_S ρ, n} (the surface texture gradient and the normal: J_k removes only the
// component along camera k's viewing ray), so the planes share one line — the 3D
// normal-flow line — and the K×3 system has rank 2 and is consistent: its pairwise
// intersection lines are collinear. The test, per sample with K ≥ min_cameras:
//   1. rank-2 least squares over the sample's active constraints (the two largest
//      eigen-directions u_j, λ_j of Σ g gᵀ): V = Σ_j (u_jᵀ Σ b g / λ_j) u_j;
//      residuals r_i = g_iᵀ V − b_i, leverages h_i = Σ_j (g_iᵀ u_j)² / λ_j;
//   2. deletion residual t_i = |r_i| / √(1 − h_i): how far constraint i is from the line
//      the others define, in the units of the data (intensity); t_i² is the drop of the
//      residual sum when i is removed (rows with 1 − h_i < 1e−9 are not testable);
//   3. the sample is inconsistent when max t_i > threshold · σ; then, while more than
//      min_cameras constraints remain, the one with the largest t_i is removed (weight 0)
//      and the fit is repeated — a single wrong measurement (an occluder, a highlight in
//      one view) is dropped and the rest kept; if min_cameras constraints remain and they
//      are still inconsistent, the correspondence itself is wrong (the shape is off
//      there) and all of them are pruned;
//   4. kept constraints get Tukey weights (1 − (t/(threshold σ))²)².
// σ = RobustScale of the first fit's t over all tested constraints.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "solver/motion/normal_flow_constraints.h"

namespace subflow::solver {

// Tukey's biweight of x = residual / (threshold · σ): (1 − x²)² for |x| < 1, else 0.
double TukeyWeight(double x);

// 1.4826 · median |value| (the normal-consistent MAD), at least `floor`.
double RobustScale(const std::vector<double>& values, double floor);

struct CollinearityOptions {
  int min_cameras = 3;       // samples with fewer constraints are not tested (weight 1)
  double threshold = 4.685;  // in robust standard deviations
  double noise_floor = 0.002;  // lower bound of σ (intensity)
};

struct CollinearityResult {
  Eigen::VectorXd weights;           // per constraint, in [0, 1]; 1 when not tested
  double scale = 0.0;                // σ
  int tested_samples = 0;
  int removed_single = 0;            // constraints removed one at a time (step 3)
  int pruned_samples = 0;            // samples pruned as a whole
  int pruned = 0;                    // constraints with weight 0 in all
};

// `sample_count` bounds the sample indices of `constraints` (any row order).
CollinearityResult CollinearityWeights(const NormalFlowConstraints& constraints, int sample_count,
                                       const CollinearityOptions& options);

}  // namespace subflow::solver
