#include "solver/stereo/ncc_cost.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Cholesky>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::solver {
namespace {

// Intensity and gradient at a pixel; outside the image the pixel is clamped to the border
// and the gradient is zero (the residual stays defined, its derivative vanishes there).
double SampleClamped(const SmoothedImage& image, const Eigen::Vector2d& pixel,
                     Eigen::Vector2d* gradient) {
  double intensity = 0.0;
  if (SampleImage(image, pixel, &intensity, gradient)) return intensity;
  const Eigen::Vector2d clamped(std::clamp(pixel.x(), 0.0, image.width() - 1.0 - 1e-6),
                                std::clamp(pixel.y(), 0.0, image.height() - 1.0 - 1e-6));
  Eigen::Vector2d unused;
  SampleImage(image, clamped, &intensity, &unused);
  gradient->setZero();
  return intensity;
}

// X = X⁰ + Σ_j w_j B_j e_j for one sample (row `k` of the stencil).
Eigen::Vector3d SamplePosition(const Eigen::Vector3d& base, const double* weights, int support,
                               const SupportBases& basis, int dof,
                               double const* const* parameters, int first_block) {
  Eigen::Vector3d X = base;
  for (int j = 0; j < support; ++j) {
    if (weights[j] == 0.0) continue;
    const double* e = parameters[first_block + j];
    for (int d = 0; d < dof; ++d) X += weights[j] * e[d] * basis[j].col(d);
  }
  return X;
}

}  // namespace

void SampleView(const PatchView& view, const PatchStencil& stencil, int dof,
                double const* const* parameters, Eigen::VectorXd* intensities,
                RowJacobian* jacobian, const std::vector<int>* rows) {
  const int m = static_cast<int>(stencil.rows());
  const int support = static_cast<int>(stencil.cols());
  // Displacement of each support vertex, B_j e_j (support × 3).
  thread_local Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> moved;
  moved.resize(support, 3);
  for (int j = 0; j < support; ++j) {
    const double* e = parameters[view.first_block + j];
    Eigen::Vector3d delta = view.basis[j].col(0) * e[0];
    for (int d = 1; d < dof; ++d) delta += view.basis[j].col(d) * e[d];
    moved.row(j) = delta.transpose();
  }
  intensities->setZero(m);
  if (jacobian) {
    jacobian->resize(m, support * dof);
    if (!rows) jacobian->setZero();
    else for (int k : *rows) jacobian->row(k).setZero();
  }
  auto sample = [&](int k) {
    const Eigen::Vector3d X = view.base[k] + (stencil.row(k) * moved).transpose();
    Eigen::Vector2d gradient;
    (*intensities)(k) = SampleClamped(*view.image, view.camera->ProjectUndistorted(X), &gradient);
    if (!jacobian || gradient.isZero()) return;
    const Eigen::RowVector3d g = gradient.transpose() * view.camera->ProjectionJacobian(X);
    double* row = jacobian->row(k).data();
    const double* weights = stencil.row(k).data();
    for (int j = 0; j < support; ++j) {
      const double w = weights[j];
      if (w == 0.0) continue;
      const Eigen::Matrix3d& B = view.basis[j];
      for (int d = 0; d < dof; ++d) row[j * dof + d] = w * (g(0) * B(0, d) + g(1) * B(1, d) + g(2) * B(2, d));
    }
  };
  if (rows) {
    for (int k : *rows) sample(k);
  } else {
    for (int k = 0; k < m; ++k) sample(k);
  }
}

namespace {

// In-place form of NormalizeIntensities: x becomes x̂, J becomes ∂x̂/∂θ (no allocation
// once the thread's scratch vectors have grown to size).
void NormalizeInPlace(Eigen::VectorXd& x, double epsilon, RowJacobian* J) {
  const double m = static_cast<double>(x.size());
  x.array() -= x.mean();
  const double sigma = std::sqrt(x.squaredNorm() + m * epsilon * epsilon);
  if (!(sigma > 0.0)) {  // constant vector and ε = 0: no correlation information
    x.setZero();
    if (J) J->setZero();
    return;
  }
  x /= sigma;
  if (!J) return;
  thread_local Eigen::RowVectorXd column_means, projection;
  column_means.noalias() = J->colwise().sum() / m;
  projection.noalias() = x.transpose() * *J;
  J->rowwise() -= column_means;
  J->noalias() -= x * projection;
  *J /= sigma;
}

}  // namespace

Eigen::VectorXd NormalizeIntensities(const Eigen::VectorXd& x, double epsilon,
                                     RowJacobian* d_normalized) {
  Eigen::VectorXd normalized = x;
  NormalizeInPlace(normalized, epsilon, d_normalized);
  return normalized;
}

std::vector<std::vector<int>> RowsOfViews(const std::vector<CorrelationPair>& pairs, int views, int samples) {
  std::vector<std::vector<char>> needed(views, std::vector<char>(samples, 0));
  for (const CorrelationPair& pair : pairs) {
    if (pair.a < 0 || pair.a >= views || pair.b < 0 || pair.b >= views || pair.a == pair.b ||
        pair.rows.size() < 2 || !(pair.weight >= 0.0))
      ThrowError("PatchCorrelationCost", "pair",
                 "needs two different views, at least 2 sample rows and a weight ≥ 0");
    for (int row : pair.rows) {
      if (row < 0 || row >= samples) ThrowError("PatchCorrelationCost", "pair rows", "sample index out of range");
      needed[pair.a][row] = needed[pair.b][row] = 1;
    }
  }
  std::vector<std::vector<int>> rows(views);
  for (int v = 0; v < views; ++v)
    for (int k = 0; k < samples; ++k)
      if (needed[v][k]) rows[v].push_back(k);
  return rows;
}

PatchCorrelationCost::PatchCorrelationCost(PatchStencil stencil, std::vector<PatchView> views,
                                           std::vector<CorrelationPair> pairs, int block_count,
                                           int dof, double epsilon)
    : stencil_(std::move(stencil)),
      views_(std::move(views)),
      pairs_(std::move(pairs)),
      support_(static_cast<int>(stencil_.cols())),
      dof_(dof),
      epsilon_(epsilon) {
  for (const PatchView& view : views_) {
    if (!ViewFitsStencil(view, stencil_))
      ThrowError("PatchCorrelationCost", "view",
                 "needs an image, a camera, one position per sample and one basis per support "
                 "vertex, with its blocks inside the block count");
    first_blocks_.push_back(view.first_block);
  }
  Setup(static_cast<int>(views_.size()), static_cast<int>(stencil_.rows()), block_count);
}

PatchCorrelationCost::PatchCorrelationCost(PatchStencil stencil, PatchView a, PatchView b,
                                           int block_count, int dof, double weight, double epsilon)
    : PatchCorrelationCost(
          stencil, {std::move(a), std::move(b)},
          {CorrelationPair{0, 1,
                           [&] {
                             std::vector<int> rows(static_cast<std::size_t>(stencil.rows()));
                             for (std::size_t k = 0; k < rows.size(); ++k) rows[k] = static_cast<int>(k);
                             return rows;
                           }(),
                           weight}},
          block_count, dof, epsilon) {}

PatchCorrelationCost::PatchCorrelationCost(std::vector<const SampledView*> sampled, std::vector<int> first_blocks,
                                           std::vector<CorrelationPair> pairs, int support, int block_count,
                                           int dof, double epsilon)
    : sampled_(std::move(sampled)),
      first_blocks_(std::move(first_blocks)),
      pairs_(std::move(pairs)),
      support_(support),
      dof_(dof),
      epsilon_(epsilon) {
  if (first_blocks_.size() != sampled_.size() ||
      std::find(sampled_.begin(), sampled_.end(), nullptr) != sampled_.end())
    ThrowError("PatchCorrelationCost", "sampled views", "needs one sampled view and one first block per view");
  int samples = 0;
  for (const SampledView* view : sampled_) samples = std::max(samples, static_cast<int>(view->intensities.size()));
  for (const CorrelationPair& pair : pairs_)
    for (int row : pair.rows) samples = std::max(samples, row + 1);  // rows beyond a view's size fail below
  Setup(static_cast<int>(sampled_.size()), samples, block_count);
}

void PatchCorrelationCost::Setup(int views, int samples, int block_count) {
  if (dof_ != 1 && dof_ != 3) ThrowError("PatchCorrelationCost", "dof", "must be 1 or 3");
  if (!(epsilon_ >= 0.0)) ThrowError("PatchCorrelationCost", "epsilon", "must be finite and ≥ 0");
  if (pairs_.empty()) ThrowError("PatchCorrelationCost", "pairs", "needs at least one pair");
  for (int first : first_blocks_)
    if (first < 0 || first + support_ > block_count)
      ThrowError("PatchCorrelationCost", "view",
                 "needs an image, a camera, one position per sample and one basis per support "
                 "vertex, with its blocks inside the block count");
  view_rows_ = RowsOfViews(pairs_, views, samples);
  for (std::size_t v = 0; v < sampled_.size(); ++v)
    if (!view_rows_[v].empty() && view_rows_[v].back() >= sampled_[v]->intensities.size())
      ThrowError("PatchCorrelationCost", "sampled views", "a pair compares a row the view does not have");
  pair_residuals_ = 0;
  for (const CorrelationPair& pair : pairs_) pair_residuals_ += static_cast<int>(pair.rows.size());
  set_num_residuals(pair_residuals_);
  for (int i = 0; i < block_count; ++i) mutable_parameter_block_sizes()->push_back(dof_);
}

void PatchCorrelationCost::UseReducedForm() {
  const int unknowns = static_cast<int>(parameter_block_sizes().size()) * dof_;
  reduced_ = unknowns + 1 < pair_residuals_;
  set_num_residuals(reduced_ ? unknowns + 1 : pair_residuals_);
}

void PatchCorrelationCost::Correlate(double const* const* parameters, double* residuals,
                                     RowJacobian* jacobian) const {
  const int columns = support_ * dof_;
  // Per-thread scratch: Ceres evaluates blocks concurrently, and this is the hot path.
  thread_local std::vector<SampledView> own;
  thread_local std::vector<const SampledView*> views;
  thread_local Eigen::VectorXd xa, xb;
  thread_local RowJacobian ja, jb;
  if (sampled_.empty()) {
    if (own.size() < views_.size()) own.resize(views_.size());
    views.resize(views_.size());
    for (std::size_t v = 0; v < views_.size(); ++v) {
      SampleView(views_[v], stencil_, dof_, parameters, &own[v].intensities,
                 jacobian ? &own[v].jacobian : nullptr, &view_rows_[v]);
      views[v] = &own[v];
    }
  } else {
    views.assign(sampled_.begin(), sampled_.end());
  }
  if (jacobian) jacobian->setZero(pair_residuals_, static_cast<Eigen::Index>(parameter_block_sizes().size()) * dof_);

  int offset = 0;
  for (const CorrelationPair& pair : pairs_) {
    const int n = static_cast<int>(pair.rows.size());
    const double sqrt_weight = std::sqrt(pair.weight);
    const SampledView& a = *views[pair.a];
    const SampledView& b = *views[pair.b];
    xa.resize(n);
    xb.resize(n);
    if (jacobian) {
      ja.resize(n, columns);
      jb.resize(n, columns);
    }
    for (int i = 0; i < n; ++i) {
      const int k = pair.rows[i];
      xa(i) = a.intensities(k);
      xb(i) = b.intensities(k);
      if (jacobian) {
        ja.row(i) = a.jacobian.row(k);
        jb.row(i) = b.jacobian.row(k);
      }
    }
    NormalizeInPlace(xa, epsilon_, jacobian ? &ja : nullptr);
    NormalizeInPlace(xb, epsilon_, jacobian ? &jb : nullptr);
    Eigen::Map<Eigen::VectorXd>(residuals + offset, n) = sqrt_weight * (xa - xb);
    if (jacobian) {
      jacobian->block(offset, first_blocks_[pair.a] * dof_, n, columns) += sqrt_weight * ja;
      jacobian->block(offset, first_blocks_[pair.b] * dof_, n, columns) -= sqrt_weight * jb;
    }
    offset += n;
  }
}

void PatchCorrelationCost::PairResiduals(double const* const* parameters, double* residuals) const {
  Correlate(parameters, residuals, nullptr);
}

bool PatchCorrelationCost::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const int blocks = static_cast<int>(parameter_block_sizes().size());
  const int unknowns = blocks * dof_;
  thread_local Eigen::VectorXd r;
  thread_local RowJacobian J;
  if (!reduced_) {
    Correlate(parameters, residuals, jacobians ? &J : nullptr);
    if (jacobians)
      for (int block = 0; block < blocks; ++block)
        if (jacobians[block])
          Eigen::Map<RowJacobian>(jacobians[block], pair_residuals_, dof_) = J.middleCols(block * dof_, dof_);
    return true;
  }
  r.resize(pair_residuals_);
  Correlate(parameters, r.data(), jacobians ? &J : nullptr);
  const double squared_norm = r.squaredNorm();
  Eigen::Map<Eigen::VectorXd> reduced(residuals, unknowns + 1);
  if (!jacobians) {
    reduced.setZero();
    reduced(0) = std::sqrt(squared_norm);
    return true;
  }
  // L Lᵀ = JᵀJ + δI, r̃ = [L⁻¹ Jᵀr ; rest], J̃ = [Lᵀ ; 0] (UseReducedForm in the header).
  thread_local Eigen::MatrixXd normal;
  thread_local Eigen::VectorXd gradient;
  normal.setZero(unknowns, unknowns);
  normal.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
  gradient.noalias() = J.transpose() * r;
  const double largest = normal.diagonal().maxCoeff();
  thread_local Eigen::MatrixXd shifted, factor;  // JᵀJ + δI; Lᵀ (upper triangular)
  // Reused by compute(), which keeps its storage while the size is unchanged, rather than a
  // new decomposition (and its n × n matrix) per evaluation.
  thread_local Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> cholesky;
  factor.setZero(unknowns, unknowns);
  reduced.setZero();
  if (largest > 0.0) {
    // JᵀJ is positive semi-definite; rounding can leave it a few ulps short, which δ covers.
    for (double jitter = 1e-12 * largest; jitter <= 1e-6 * largest; jitter *= 1e3) {
      shifted = normal;
      shifted.diagonal().array() += jitter;
      cholesky.compute(shifted);
      if (cholesky.info() != Eigen::Success) continue;
      reduced.head(unknowns) = cholesky.matrixL().solve(gradient);
      factor = cholesky.matrixU();
      break;
    }
  }
  reduced(unknowns) = std::sqrt(std::max(0.0, squared_norm - reduced.head(unknowns).squaredNorm()));
  for (int block = 0; block < blocks; ++block) {
    if (!jacobians[block]) continue;
    Eigen::Map<RowJacobian> Jb(jacobians[block], unknowns + 1, dof_);
    Jb.topRows(unknowns) = factor.middleCols(block * dof_, dof_);
    Jb.row(unknowns).setZero();
  }
  return true;
}

SignedDistanceImage ComputeSignedDistance(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8UC1)
    ThrowError("ComputeSignedDistance", "mask", "must be a non-empty 8-bit single-channel image");
  const cv::Mat inside = mask > 0;
  const cv::Mat outside = mask == 0;
  // distanceTransform gives each nonzero pixel its distance to the nearest zero pixel:
  // outside pixels → distance to the object, inside pixels → distance to the background.
  cv::Mat to_object, to_background;
  cv::distanceTransform(outside, to_object, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::distanceTransform(inside, to_background, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  SignedDistanceImage result;
  // The outline lies half a pixel between an inside and an outside centre.
  result.distance = cv::Mat(mask.size(), CV_32FC1);
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      result.distance.at<float>(y, x) = mask.at<std::uint8_t>(y, x) > 0
                                            ? 0.5f - to_background.at<float>(y, x)
                                            : to_object.at<float>(y, x) - 0.5f;
  return result;
}

bool SampleSignedDistance(const SignedDistanceImage& image, const Eigen::Vector2d& pixel, double* distance,
                          Eigen::Vector2d* gradient) {
  const cv::Mat& d = image.distance;
  double value = 0.0;
  if (!SampleScalar(d, pixel, &value)) return false;
  const int x0 = static_cast<int>(std::floor(pixel.x())), y0 = static_cast<int>(std::floor(pixel.y()));
  const double fx = pixel.x() - x0, fy = pixel.y() - y0;
  // Sobel as OpenCV separates it: a row pass, then a column pass, each in float; the
  // smoothing taps are ¼ at the centre and ⅛ on the sum of the two sides (every product is
  // exact, so fused or not, each pass rounds as cv::Sobel's does).
  const auto sobel = [&](int x, int y) {
    const int xm = std::max(x - 1, 0), xp = std::min(x + 1, d.cols - 1);
    const int ym = std::max(y - 1, 0), yp = std::min(y + 1, d.rows - 1);
    const float* rm = d.ptr<float>(ym);
    const float* r0 = d.ptr<float>(y);
    const float* rp = d.ptr<float>(yp);
    const float gx = 0.25f * (r0[xp] - r0[xm]) + 0.125f * ((rm[xp] - rm[xm]) + (rp[xp] - rp[xm]));
    const auto smooth = [&](const float* row) { return 0.25f * row[x] + 0.125f * (row[xm] + row[xp]); };
    const float gy = smooth(rp) - smooth(rm);
    return Eigen::Vector2d(gx, gy);
  };
  *gradient = (1.0 - fy) * ((1.0 - fx) * sobel(x0, y0) + fx * sobel(x0 + 1, y0)) +
              fy * ((1.0 - fx) * sobel(x0, y0 + 1) + fx * sobel(x0 + 1, y0 + 1));
  *distance = value;
  return true;
}

SilhouetteCost::SilhouetteCost(const SignedDistanceImage* distance, const vision::Camera* camera,
                               Eigen::Vector3d base, Eigen::VectorXd stencil,
                               SupportBases basis, int dof, double weight,
                               bool one_sided)
    : distance_(distance),
      camera_(camera),
      base_(std::move(base)),
      stencil_(std::move(stencil)),
      basis_(basis),
      dof_(dof),
      weight_(weight),
      one_sided_(one_sided) {
  if (!distance_ || !camera_ || !basis_.all || stencil_.size() != static_cast<Eigen::Index>(basis_.size()) ||
      (dof != 1 && dof != 3))
    ThrowError("SilhouetteCost", "arguments",
               "needs a distance image, a camera, one basis per stencil weight and dof 1 or 3");
  set_num_residuals(1);
  for (std::size_t j = 0; j < basis_.size(); ++j) mutable_parameter_block_sizes()->push_back(dof);
}

bool SilhouetteCost::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const int support = static_cast<int>(basis_.size());
  const Eigen::Vector3d X =
      SamplePosition(base_, stencil_.data(), support, basis_, dof_, parameters, 0);
  const Eigen::Vector2d pixel = camera_->ProjectUndistorted(X);
  double value = 0.0;  // beyond the image border: no information, no force
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
  SampleSignedDistance(*distance_, pixel, &value, &gradient);
  const bool active = !one_sided_ || value > 0.0;
  residuals[0] = active ? weight_ * value : 0.0;
  if (!jacobians) return true;
  const Eigen::RowVector3d g =
      active ? Eigen::RowVector3d(weight_ * gradient.transpose() * camera_->ProjectionJacobian(X))
             : Eigen::RowVector3d::Zero();
  for (int j = 0; j < support; ++j) {
    if (!jacobians[j]) continue;
    for (int d = 0; d < dof_; ++d) jacobians[j][d] = stencil_(j) * g.dot(basis_[j].col(d));
  }
  return true;
}

}  // namespace subflow::solver
