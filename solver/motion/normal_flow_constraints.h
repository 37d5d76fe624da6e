// Normal-flow constraints on surface samples (method eq. 6 and 24).
//
// Brightness constancy −∂I/∂t = ∇Iᵀ dp/dt, with the chain rule through the projection
// p_k(P) of camera k and the surface point P = s = L c (eq. 12–13):
//   −∂I(p_k)/∂t = ∇I(p_k)ᵀ (∂p_k/∂P) ∂P/∂t = gᵀ ∂P/∂t,   g = J_kᵀ ∇I(p_k)  (eq. 24)
// J_k = vision::Camera::ProjectionJacobian (2×3, pixels per world unit), ∇I in intensity
// per pixel, so g is in intensity per world unit. One constraint per (sample, camera)
// where the sample is visible (SampleVisibility). Geometrically g is the normal of the
// constraint plane {V : gᵀV = b} in 3D velocity space: the plane through the camera's
// viewing ray and the image's iso-brightness line (g ⟂ the ray, since J_k annihilates it).
//
// Two forms, both linear in the unknown motion of the sample:
//   * Frame form (eq. 24 literally; BuildFrameConstraints): at frame f with
//     SpatioTemporalDerivatives, g = J_kᵀ ∇I_f(p_k(X)), b = −I_t(p_k(X)); the unknown is
//     the velocity ∂P/∂t in world units per frame.
//   * Step form (BuildStepConstraints, what the motion solver uses): between an image
//     `before` (frame f) and `after` (frame f + 1, or any later frame), for a current guess
//     u_s of the sample's displacement (X' = X + u_s; u = 0 on the first pass):
//       ḡ = ½ (∇I_before(p_k(X)) + ∇I_after(p_k(X'))),   g = J_k(X')ᵀ ḡ,
//       gᵀ u_total = b,   b = I_before(p_k(X)) − I_after(p_k(X')) + gᵀ u_s.
//     With u_s = 0 this is eq. 24 with the temporal derivative I_after − I_before and the
//     gradient taken at the half step (second-order accurate there); with u_s from a
//     previous pass it is the re-linearization (image warping) of the same constraint
//     about the displaced point, written for the TOTAL displacement u_total so that a
//     smoothness term can act on the whole motion field.
//
// Rows are ordered by sample, then by camera: the constraints of sample s are contiguous
// (what the per-sample collinearity test of the solver relies on).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"
#include "solver/observation/image_derivatives.h"
#include "solver/observation/sample_visibility.h"
#include "vision/camera.h"

namespace subflow::solver {

struct NormalFlowConstraints {
  std::vector<int> sample;   // sample index per constraint
  std::vector<int> camera;   // camera index per constraint
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> gradient;  // g per row (#C×3)
  Eigen::VectorXd rhs;       // b per row
  // Photometric difference I_after(p_k(X')) − I_before(p_k(X)) per row at the guess the
  // constraints were built for (step form; −I_t in the frame form).
  Eigen::VectorXd photometric;

  int size() const { return static_cast<int>(sample.size()); }
  // r_c = g_c · u(sample_c) − b_c for per-sample motions u (#S×3).
  Eigen::VectorXd Residuals(const geometry::Positions& sample_motion) const;
};

// Step form (see the file comment). `before` and `after` hold one smoothed image per
// camera; `sample_positions` are the samples at the `before` frame (#S×3);
// `sample_displacement` the current guess u (#S×3; empty = zero). A (sample, camera)
// gives a constraint when `visibility` says so and both bilinear footprints are inside
// the images. Parallel over samples.
NormalFlowConstraints BuildStepConstraints(const std::vector<vision::Camera>& cameras,
                                           const std::vector<SmoothedImage>& before,
                                           const std::vector<SmoothedImage>& after,
                                           const geometry::Positions& sample_positions,
                                           const geometry::Positions& sample_displacement,
                                           const SampleVisibility& visibility);

// The `photometric` column alone of BuildStepConstraints for the same arguments (same
// rows, same order), from intensities only: no gradients, no Jacobians. For reports (the
// photometric error of a motion) at a fraction of the cost.
Eigen::VectorXd StepPhotometricDifferences(const std::vector<vision::Camera>& cameras,
                                           const std::vector<SmoothedImage>& before,
                                           const std::vector<SmoothedImage>& after,
                                           const geometry::Positions& sample_positions,
                                           const geometry::Positions& sample_displacement,
                                           const SampleVisibility& visibility);

// Frame form (eq. 24 at one frame): one SpatioTemporalDerivatives per camera.
NormalFlowConstraints BuildFrameConstraints(
    const std::vector<vision::Camera>& cameras,
    const std::vector<SpatioTemporalDerivatives>& derivatives,
    const geometry::Positions& sample_positions, const SampleVisibility& visibility);

}  // namespace subflow::solver
