// The residuals of the spatio-temporal stereo functional (method §4.3, eq. 25) as Ceres
// cost functions with analytic derivatives.
//
// Surface model inside one refinement step. A patch is a face r of the level ℓ being
// refined; its samples k are limit-surface points whose position at frame t is
//     X_k(t) = X⁰_k(t) + Σ_j w_kj B_j(t) e_j(t)
// X⁰ the current surface (s = L c of the finest control points), j over the level-ℓ
// vertices of the face's stencil support, w_kj the limit-stencil weights of level ℓ
// (s = L_ℓ c_ℓ, eq. 12–13: the limit surface of the refined mesh is that of c_ℓ), B_j(t)
// the 3×dof basis of vertex j's parameter block e_j(t): the vertex's Hoppe frame columns
// (n, r, q) for detail increments, or the identity for base control points. The model is
// exactly linear in e.
//
// NCC residual (PatchCorrelationCost). Two views a and b of the same samples — cameras
// i ≠ j at one frame (stereo), or one camera at frames t ≠ s (the temporal
// self-correlation of eq. 25) — give intensity vectors x_a, x_b (bilinear samples of the
// smoothed images, one entry per sample). Each is normalized
//     x̂ = (x − mean x) / σ,   σ = √(‖x − mean x‖² + m ε²)
// (ε: the intensity noise floor, so a textureless patch gives a near-zero vector instead of
// amplified noise; ε = 0 is the plain unit norm), and the residual is
//     r = √W (x̂_a − x̂_b),   ‖r‖² = W (2 − 2 NCC)  when ε = 0,
// so minimizing ½‖r‖² maximizes the weighted correlation exactly. Derivatives:
//     ∂x_k/∂e_j = w_kj ∇I(p_k)ᵀ (∂p/∂X)(X_k) B_j         (eq. 4, 24: ProjectionJacobian)
//     ∂x̂/∂x   = (I − 11ᵀ/m − x̂ x̂ᵀ) / σ.
// A sample whose projection leaves the image is clamped to the border (its gradient
// there is zero), so the residual stays defined while the optimizer explores.
//
// Silhouette residual (SilhouetteCost): one sample, one camera, one frame,
//     r = w · D(p(X))        (one-sided: max(0, D) when `one_sided`)
// D the signed distance to the outline of the silhouette (pixels, > 0 outside; bilinear),
// so the surface's outline is pulled onto the mask and no point is pushed outside it.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include "geometry/triangle_mesh.h"
#include "solver/observation/image_derivatives.h"
#include "vision/camera.h"

namespace subflow::solver {

// Where a block reads its samples' positions X⁰ and its support vertices' bases B_j: in
// place, in the frame's arrays that the refinement window keeps for the whole solve
// (refinement_window.h: FrameState), not as copies per block. Views and silhouette blocks
// are made per patch, camera and frame, so copies were hundreds of MB on an HD take
// (docs/speed.md). The arrays must outlive the cost functions that read them.
struct SamplePositions {
  const geometry::Positions* all = nullptr;  // one row per sample of the level
  int first = 0, count = 0;                  // the patch's samples: rows [first, first + count)
  std::size_t size() const { return static_cast<std::size_t>(count); }
  Eigen::Vector3d operator[](std::size_t k) const {
    return all->row(first + static_cast<Eigen::Index>(k)).transpose();
  }
};
struct SupportBases {
  const std::vector<Eigen::Matrix3d>* all = nullptr;  // B_v per vertex of the level
  const std::vector<int>* support = nullptr;          // the patch's support vertices
  std::size_t size() const { return support ? support->size() : 0; }
  const Eigen::Matrix3d& operator[](std::size_t j) const { return (*all)[(*support)[j]]; }
};

// The samples of one patch in one view: image, camera, and per sample its current
// position X⁰ (rows), all at one frame. `first_block` is the index, among the cost's
// parameter blocks, of the frame's block for support vertex 0; support vertex j uses
// first_block + j.
struct PatchView {
  const SmoothedImage* image = nullptr;
  const vision::Camera* camera = nullptr;
  SamplePositions base;  // X⁰ per sample (size m)
  // B_j per support vertex (3×dof each, column-major dof columns).
  SupportBases basis;
  int first_block = 0;
};

// Limit-stencil weights of the samples on the patch's support vertices (m × #support,
// dense: supports are small, 12 for a regular patch).
using PatchStencil = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// Whether `view` can be sampled with `stencil`: it has an image, a camera, one position
// per stencil row and one basis per stencil column.
inline bool ViewFitsStencil(const PatchView& view, const PatchStencil& stencil) {
  return view.image && view.camera && view.base.all && view.basis.all &&
         view.base.size() == static_cast<std::size_t>(stencil.rows()) &&
         view.basis.size() == static_cast<std::size_t>(stencil.cols());
}
// Jacobians of intensity vectors: one row per sample (row-major, rows are gathered).
using RowJacobian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Intensities (m) of a view at the current parameters, and ∂x/∂e (m × blocks·dof) when
// `jacobian` is given. `parameters` are the cost's parameter blocks. When `rows` is given
// only those samples are evaluated (the others are left at zero).
void SampleView(const PatchView& view, const PatchStencil& stencil, int dof,
                double const* const* parameters, Eigen::VectorXd* intensities,
                RowJacobian* jacobian, const std::vector<int>* rows = nullptr);

// What SampleView gives for one view: intensities (m) and ∂x/∂e (m × #support·dof), on the
// rows it was asked for (the others are zero).
struct SampledView {
  Eigen::VectorXd intensities;
  RowJacobian jacobian;
};

// x̂ = (x − mean)/σ (see the file comment); when `d_normalized` is given, it is replaced
// by ∂x̂/∂θ for ∂x/∂θ = *d_normalized on input (any column count).
Eigen::VectorXd NormalizeIntensities(const Eigen::VectorXd& x, double epsilon,
                                     RowJacobian* d_normalized = nullptr);

// One correlation of a patch: views a and b compared on the samples both see.
struct CorrelationPair {
  int a = 0, b = 0;
  std::vector<int> rows;  // sample indices (rows of the stencil), at least 2
  double weight = 1.0;    // W
};

// Per view (0 … views − 1): the sorted rows some pair compares it on. Throws subflow::Error
// on a pair with a view or row out of range, equal views, fewer than 2 rows or W < 0.
std::vector<std::vector<int>> RowsOfViews(const std::vector<CorrelationPair>& pairs, int views, int samples);

// All correlations of one patch in one residual block: the stereo pairs of a frame (the
// views share the frame's blocks), or the temporal self-correlations of a frame step (the
// views of frame t use blocks [0, #support), those of t + 1 the next #support). Each view
// is sampled once however many pairs use it; the residual is the concatenation of the
// pairs' √W (x̂_a − x̂_b), each normalized on its own rows, so ‖r‖² = Σ W (2 − 2 NCC).
class PatchCorrelationCost final : public ceres::CostFunction {
 public:
  // `block_count` parameter blocks of size `dof` (1 or 3). Throws subflow::Error on
  // inconsistent sizes, indices or weights.
  PatchCorrelationCost(PatchStencil stencil, std::vector<PatchView> views,
                       std::vector<CorrelationPair> pairs, int block_count, int dof, double epsilon);
  // A single pair (a, b) on all samples, weight W.
  PatchCorrelationCost(PatchStencil stencil, PatchView a, PatchView b, int block_count, int dof,
                       double weight, double epsilon);
  // Views sampled elsewhere, once per evaluation point for every block that compares them
  // (view_cache.h): view v's intensities and Jacobian are *sampled[v], valid on its rows of
  // RowsOfViews(pairs); first_blocks[v] is the index, among this cost's blocks, of v's
  // frame's block for support vertex 0 (as PatchView::first_block). `support` vertices.
  PatchCorrelationCost(std::vector<const SampledView*> sampled, std::vector<int> first_blocks,
                       std::vector<CorrelationPair> pairs, int support, int block_count, int dof,
                       double epsilon);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The reduced form (call before the block is added to a problem; it changes
  // num_residuals). The m pair residuals r, with Jacobian J (m × n, n = blocks · dof), are
  // replaced by n + 1 entries with the same squared norm, normal matrix and gradient:
  //     r̃ = [L⁻¹ Jᵀr ; √(‖r‖² − ‖L⁻¹ Jᵀr‖²)],   J̃ = [Lᵀ ; 0],   L Lᵀ = JᵀJ + δI
  // (δ = 1e-12 of the largest diagonal entry, so that L exists where J is rank-deficient).
  // Then ‖r̃‖² = ‖r‖², J̃ᵀJ̃ = JᵀJ + δI and J̃ᵀr̃ = Jᵀr, so a Gauss-Newton or
  // Levenberg-Marquardt step, a robust loss's correction (which only needs ‖r‖², Jᵀr and
  // JᵀJ) and the cost Ceres compares are those of the full block, while Ceres stores,
  // scales and multiplies an (n + 1) × n Jacobian instead of m × n (the patches' blocks
  // have m ≈ 10–20 n). When only the residuals are asked for, r̃ = [‖r‖, 0, …, 0].
  // No effect when m ≤ n + 1.
  void UseReducedForm();
  bool reduced() const { return reduced_; }

  const std::vector<CorrelationPair>& pairs() const { return pairs_; }
  // The pairs' residuals √W (x̂_a − x̂_b), concatenated in pair order (pair_residual_count()
  // entries), whatever the form: per pair NCC = 1 − ‖r_pair‖² / (2 W) when ε = 0.
  int pair_residual_count() const { return pair_residuals_; }
  void PairResiduals(double const* const* parameters, double* residuals) const;

 private:
  // Checks the pairs and the block count; sets the residual and parameter block sizes.
  void Setup(int views, int samples, int block_count);
  // The pair residuals (pair_residual_count()) and, when `jacobian` is given, their
  // Jacobian with respect to all blocks (pair_residual_count() × blocks · dof).
  void Correlate(double const* const* parameters, double* residuals, RowJacobian* jacobian) const;

  PatchStencil stencil_;
  std::vector<PatchView> views_;              // sampled by Evaluate (first two constructors)
  std::vector<const SampledView*> sampled_;   // or sampled elsewhere (third)
  std::vector<int> first_blocks_;             // per view
  std::vector<CorrelationPair> pairs_;
  std::vector<std::vector<int>> view_rows_;  // the rows each view must sample
  int support_;
  int dof_;
  double epsilon_;
  int pair_residuals_ = 0;
  bool reduced_ = false;
};

// Signed distance to a silhouette's outline, for SilhouetteCost.
struct SignedDistanceImage {
  cv::Mat distance;  // CV_32FC1, pixels, > 0 outside the silhouette, < 0 inside
};
// From a CV_8UC1 mask (nonzero = object). Throws subflow::Error on an empty or
// non-8-bit mask.
SignedDistanceImage ComputeSignedDistance(const cv::Mat& mask);

// The bilinear distance at `pixel` and the bilinear interpolation of its gradient: the 3×3
// Sobel derivatives / 8 (replicated border), taken at sampling time from the distance
// plane, in float as cv::Sobel(…, 1 / 8.0, BORDER_REPLICATE) computes them, to the bit (the
// refinement keeps a window's frames of every camera: one plane instead of three). False
// (outputs untouched) when the 2×2 neighbourhood is not inside the image.
bool SampleSignedDistance(const SignedDistanceImage& image, const Eigen::Vector2d& pixel, double* distance,
                          Eigen::Vector2d* gradient);

class SilhouetteCost final : public ceres::CostFunction {
 public:
  // One sample: X⁰, stencil weights on `basis.size()` support blocks of size dof.
  SilhouetteCost(const SignedDistanceImage* distance, const vision::Camera* camera,
                 Eigen::Vector3d base, Eigen::VectorXd stencil, SupportBases basis,
                 int dof, double weight, bool one_sided);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const SignedDistanceImage* distance_;
  const vision::Camera* camera_;
  Eigen::Vector3d base_;
  Eigen::VectorXd stencil_;
  SupportBases basis_;
  int dof_;
  double weight_;
  bool one_sided_;
};

}  // namespace subflow::solver
