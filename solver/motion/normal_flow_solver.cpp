#include "solver/motion/normal_flow_solver.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/local_frames.h"
#include "geometry/loop_operators.h"
#include "solver/motion/conjugate_gradient.h"
#include "solver/motion/constraint_collinearity.h"
#include "solver/motion/multigrid_preconditioner.h"
#include "solver/motion/row_product.h"

namespace subflow::solver {
namespace {

using geometry::Positions;
using Sparse = Eigen::SparseMatrix<double>;
using VectorMap = Eigen::Map<Eigen::VectorXd>;
using ConstVectorMap = Eigen::Map<const Eigen::VectorXd>;

// Limit weights are O(1) (a row of L sums to 1); what the products L P_i leave of the
// finest stencil's other ancestors cancels to ~1e-16.
constexpr double kCancelledWeight = 1e-12;
// μ_lo / κ_lo: the base level is not damped, only kept definite.
constexpr double kBaseDamping = 1e-9;

// A ⊗ I3 for a scalar sparse matrix A: entry (r, c) becomes the 3×3 block at (3r, 3c).
template <typename Matrix>
Sparse Kron3(const Matrix& A) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(3 * static_cast<std::size_t>(A.nonZeros()));
  for (int outer = 0; outer < A.outerSize(); ++outer)
    for (typename Matrix::InnerIterator it(A, outer); it; ++it)
      for (int a = 0; a < 3; ++a)
        triplets.emplace_back(3 * static_cast<int>(it.row()) + a, 3 * static_cast<int>(it.col()) + a,
                              it.value());
  Sparse result(3 * A.rows(), 3 * A.cols());
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace

void NormalFlowSolverOptions::Check() const {
  auto finite_nonnegative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!finite_nonnegative(smoothness))
    ThrowError("normal flow solver", "smoothness", "expected a finite value ≥ 0");
  if (!finite_nonnegative(detail_damping))
    ThrowError("normal flow solver", "detail_damping", "expected a finite value ≥ 0");
  if (coarsest_level < 0)
    ThrowError("normal flow solver", "coarsest_level", "expected ≥ 0");
  if (finest_level >= 0 && finest_level < coarsest_level)
    ThrowError("normal flow solver", "finest_level", "expected −1 or ≥ coarsest_level");
  if (reweighting_iterations < 0 || reweighting_iterations > 50)
    ThrowError("normal flow solver", "reweighting_iterations", "expected 0..50");
  if (!std::isfinite(robust_threshold) || robust_threshold <= 0.0)
    ThrowError("normal flow solver", "robust_threshold", "expected a finite value > 0");
  if (!finite_nonnegative(noise_floor))
    ThrowError("normal flow solver", "noise_floor", "expected a finite value ≥ 0 (intensity)");
  if (collinearity_min_cameras < 3)
    ThrowError("normal flow solver", "collinearity_min_cameras",
               "expected ≥ 3 (two planes always intersect in a line)");
  if (!std::isfinite(cg_tolerance) || cg_tolerance <= 0.0 || cg_tolerance >= 1.0)
    ThrowError("normal flow solver", "cg_tolerance", "expected a value in (0, 1)");
  if (!std::isfinite(cg_reweighting_tolerance) || cg_reweighting_tolerance <= 0.0 ||
      cg_reweighting_tolerance >= 1.0)
    ThrowError("normal flow solver", "cg_reweighting_tolerance", "expected a value in (0, 1)");
  if (!std::isfinite(min_samples_per_face) || min_samples_per_face < 0.0)
    ThrowError("normal flow solver", "min_samples_per_face", "expected a finite value ≥ 0");
  if (cg_max_iterations < 1)
    ThrowError("normal flow solver", "cg_max_iterations", "expected ≥ 1");
  if (multigrid_min_vertices < 0)
    ThrowError("normal flow solver", "multigrid_min_vertices", "expected ≥ 0 (control points of a level)");
}

NormalFlowSolver::NormalFlowSolver(const geometry::LoopHierarchy& hierarchy,
                                   const geometry::SparseMatrix& sample_limit,
                                   const Positions& reference_control,
                                   const NormalFlowSolverOptions& options)
    : hierarchy_(&hierarchy), options_(options) {
  options_.Check();
  n_ = hierarchy.finest_level();
  lo_ = options_.coarsest_level;
  hi_ = options_.finest_level;
  if (hi_ < 0) {
    hi_ = lo_;
    while (hi_ < n_ && static_cast<double>(sample_limit.rows()) / hierarchy.FaceCount(hi_ + 1) >=
                           options_.min_samples_per_face)
      ++hi_;
  }
  if (hi_ > n_ || lo_ > n_)
    ThrowError("normal flow solver", "levels",
               "coarsest/finest level beyond the hierarchy's finest level " + std::to_string(n_));
  const int vertices = hierarchy.VertexCount(n_);
  if (sample_limit.cols() != vertices)
    ThrowError("normal flow solver", "sample limit matrix",
               std::to_string(sample_limit.cols()) + " columns, expected #V(n) = " +
                   std::to_string(vertices));
  if (reference_control.rows() != vertices)
    ThrowError("normal flow solver", "reference control points",
               std::to_string(reference_control.rows()) + " rows, expected " +
                   std::to_string(vertices));
  if (!sample_limit.isCompressed())
    ThrowError("normal flow solver", "sample limit matrix", "expected a compressed matrix (makeCompressed)");
  limit_ = &sample_limit;

  // Prolongations P_i = C(n−1)⋯C(i), Laplacian Gram matrices, length scales.
  prolongation3_.resize(n_ + 1);
  level_limit_.resize(n_ + 1);
  coarsening_.resize(n_ + 1);
  level_matrix_.resize(n_ + 1);
  smoothness3_.resize(n_ + 1);
  std::vector<SymmetricPattern> data_pattern(n_ + 1);
  length_ratio4_.assign(n_ + 1, 0.0);
  geometry::SparseMatrix P(vertices, vertices);
  P.setIdentity();
  const Eigen::RowVector3d centroid = reference_control.colwise().mean();
  const double radius =
      std::sqrt((reference_control.rowwise() - centroid).rowwise().squaredNorm().mean());
  const geometry::MeshTopology& finest = hierarchy.Topology(n_);
  double edge_sum = 0.0;
  for (int e = 0; e < finest.edge_count(); ++e)
    edge_sum += (reference_control.row(finest.EdgeVertex(e, 0)) -
                 reference_control.row(finest.EdgeVertex(e, 1))).norm();
  const double finest_edge = edge_sum / std::max(1, finest.edge_count());
  if (!(radius > 0.0) || !(finest_edge > 0.0))
    ThrowError("normal flow solver", "reference control points", "are degenerate (zero size)");
  for (int level = n_; level >= lo_; --level) {
    if (level < n_) P = geometry::SparseMatrix(P * hierarchy.Refinement(level));
    if (level == hi_) {
      MakeStencils(geometry::SparseMatrix(sample_limit * P), &stencils_);
      data_pattern[level] = stencils_.pattern;
    } else if (level < hi_) {
      coarsening_[level] = CoarseningMap(data_pattern[level + 1], hierarchy.Refinement(level), &data_pattern[level]);
    }
    if (level <= hi_) {
      if (level < hi_) {  // level hi's is the stencils' own (LevelLimit)
        level_limit_[level] = LevelLimit(level + 1) * hierarchy.Refinement(level);
        level_limit_[level].prune(1.0, kCancelledWeight);
        level_limit_[level].makeCompressed();
      }
      prolongation3_[level] = Kron3(P);
      const geometry::SparseMatrix U = geometry::UmbrellaLaplacian(hierarchy.Topology(level));
      smoothness3_[level] = Kron3(geometry::SparseMatrix(U.transpose() * U));
      length_ratio4_[level] = std::pow(radius / (finest_edge * std::ldexp(1.0, n_ - level)), 4);
      Sparse identity(smoothness3_[level].rows(), smoothness3_[level].cols());
      identity.setIdentity();
      Sparse regularizer3 = options_.smoothness * length_ratio4_[level] * smoothness3_[level] +
                            (level == lo_ ? kBaseDamping : options_.detail_damping) * identity;
      regularizer3.makeCompressed();
      level_matrix_[level] = MakeLevelMatrix(data_pattern[level], regularizer3);
    }
  }
}

void NormalFlowSolver::MakeStencils(const geometry::SparseMatrix& limit, SampleStencils* out) {
  SampleStencils& stencils = *out;
  stencils.limit = limit.pruned(1.0, kCancelledWeight);
  stencils.limit.makeCompressed();
  const geometry::SparseMatrix& L = stencils.limit;
  // Pattern of Lᵀ L (all-ones values: no cancellation).
  Sparse ones = L;
  for (int k = 0; k < ones.outerSize(); ++k)
    for (Sparse::InnerIterator it(ones, k); it; ++it) it.valueRef() = 1.0;
  stencils.pattern = MakeSymmetricPattern(Sparse(ones.transpose() * ones));
  auto entry = [&](int row, int column) {
    const int e = stencils.pattern.Entry(row, column);
    SUBFLOW_CHECK(e >= 0, "LᵀL pattern misses a pair");
    return e;
  };
  const int samples = static_cast<int>(L.rows());
  // Each sample's stencil pairs p ≤ q: their pattern entry (in parallel), then the entries'
  // rows by a counting sort in sample order.
  std::vector<long> sample_pair_offset(samples + 1, 0);
  for (int s = 0; s < samples; ++s) {
    const long k = L.outerIndexPtr()[s + 1] - L.outerIndexPtr()[s];
    sample_pair_offset[s + 1] = sample_pair_offset[s] + k * (k + 1) / 2;
  }
  std::vector<int> pair_entry(static_cast<std::size_t>(sample_pair_offset.back()));
  tbb::parallel_for(0, samples, [&](int s) {
    const int begin = L.outerIndexPtr()[s], k = L.outerIndexPtr()[s + 1] - begin;
    const int* columns = L.innerIndexPtr() + begin;
    int* pairs = pair_entry.data() + sample_pair_offset[s];
    for (int p = 0; p < k; ++p)
      for (int q = p; q < k; ++q)
        *pairs++ = entry(std::min(columns[p], columns[q]), std::max(columns[p], columns[q]));
  });
  const int entries = stencils.pattern.entries();
  geometry::SparseMatrix& E = stencils.entry_weights;
  E.resize(entries, samples);
  E.resizeNonZeros(static_cast<Eigen::Index>(pair_entry.size()));
  int* outer = E.outerIndexPtr();
  std::fill(outer, outer + entries + 1, 0);
  for (int e : pair_entry) ++outer[e + 1];
  for (int e = 0; e < entries; ++e) outer[e + 1] += outer[e];
  std::vector<int> fill(outer, outer + entries);
  const int* pairs = pair_entry.data();
  for (int s = 0; s < samples; ++s) {
    const int begin = L.outerIndexPtr()[s], k = L.outerIndexPtr()[s + 1] - begin;
    const double* l = L.valuePtr() + begin;
    for (int p = 0; p < k; ++p)
      for (int q = p; q < k; ++q) {
        const int slot = fill[*pairs++]++;
        E.innerIndexPtr()[slot] = s;
        E.valuePtr()[slot] = l[p] * l[q];
      }
  }
}

std::vector<double> NormalFlowSolver::DataSums(
    const SampleStencils& stencils, const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>& M) {
  // Block (a, b) of N = Σ_s L_sᵀ L_s ⊗ M_s is Σ_s l_sa l_sb M_s: symmetric, and equal to
  // block (b, a). Only the upper pattern entries (row ≤ column) hold sums, 6 values each:
  // the product E M of the entries' weights and the samples' blocks, gathered entry by
  // entry in parallel (each entry's samples added in ascending order: deterministic, no
  // per-thread copies of the sums to clear and add up).
  const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> sums = RowParallelProduct<6>(stencils.entry_weights, M);
  return std::vector<double>(sums.data(), sums.data() + sums.size());
}

Positions NormalFlowSolver::SampleMotion(const Positions& displacement) const {
  SUBFLOW_CHECK(displacement.rows() == limit_->cols(), "displacement of another level");
  return RowParallelProduct<3>(*limit_, displacement);
}

std::vector<Positions> NormalFlowSolver::RigidPart(const Positions& control,
                                                  const Positions& previous) const {
  std::vector<Positions> rigid_part(n_ + 1);
  if (!options_.rigid_invariant_smoothness || previous.rows() != control.rows()) return rigid_part;
  Positions midpoints = control + 0.5 * previous;
  const RigidMotion rigid = FitRigidMotion(midpoints, previous);
  for (int level = n_; level >= lo_; --level) {
    if (level <= hi_) rigid_part[level] = rigid.Velocity(midpoints);
    if (level > lo_) midpoints = hierarchy_->Coarsening(level) * midpoints;
  }
  return rigid_part;
}

void NormalFlowSolver::SolveLevels(const NormalFlowConstraints& constraints,
                                   const Eigen::VectorXd& weights,
                                   const std::vector<Positions>& rigid_part,
                                   double cg_tolerance, NormalFlowSolution* solution,
                                   Positions* sample_motion_out) const {
  const int samples = static_cast<int>(limit_->rows());
  const int vertices = static_cast<int>(limit_->cols());
  // Per-sample aggregates: M_s = Σ w g gᵀ (6 unique entries), h_s = Σ w b g.
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> M =
      Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>::Zero(samples, 6);
  Positions h = Positions::Zero(samples, 3);
  auto aggregate = [&](int first, int last) {
    for (int c = first; c < last; ++c) {
      const double w = weights(c);
      if (w == 0.0) continue;
      const Eigen::RowVector3d g = constraints.gradient.row(c);
      const int s = constraints.sample[c];
      M.row(s) += w * Eigen::Matrix<double, 1, 6>(g(0) * g(0), g(0) * g(1), g(0) * g(2),
                                                  g(1) * g(1), g(1) * g(2), g(2) * g(2));
      h.row(s) += (w * constraints.rhs(c)) * g;
    }
  };
  // Rows ordered by sample (as the builders make them): parallel over chunks that end at a
  // sample boundary, each sample's rows still added in row order.
  if (std::is_sorted(constraints.sample.begin(), constraints.sample.end())) {
    const int chunk_count = std::max(1, constraints.size() / 16384);
    std::vector<int> bounds(chunk_count + 1, constraints.size());
    bounds[0] = 0;
    for (int i = 1; i < chunk_count; ++i) {
      int c = static_cast<int>(static_cast<long>(constraints.size()) * i / chunk_count);
      while (c > 0 && c < constraints.size() && constraints.sample[c] == constraints.sample[c - 1]) ++c;
      bounds[i] = std::max(bounds[i - 1], c);
    }
    tbb::parallel_for(0, chunk_count, [&](int i) { aggregate(bounds[i], bounds[i + 1]); });
  } else {
    aggregate(0, constraints.size());
  }
  solution->displacement = Positions::Zero(vertices, 3);
  VectorMap D(solution->displacement.data(), 3 * vertices);
  Positions sample_motion = Positions::Zero(samples, 3);  // L D
  solution->level_motion.resize(n_ + 1);
  solution->levels.clear();
  Positions coarse_motion = Positions::Zero(hierarchy_->VertexCount(lo_), 3);  // W_i
  // Data matrices of the levels (block sums): accumulated on level hi, carried to the
  // coarser ones one refinement step at a time, P_iᵀ N P_i = C(i)ᵀ (P_{i+1}ᵀ N P_{i+1}) C(i).
  std::vector<std::vector<double>> data(n_ + 1);
  data[hi_] = DataSums(stencils_, M);
  for (int level = hi_ - 1; level >= lo_; --level) data[level] = CoarsenBlockSums(coarsening_[level], data[level + 1]);
  for (int level = lo_; level <= hi_; ++level) {
    const int unknowns = 3 * hierarchy_->VertexCount(level);
    const Sparse& P3 = prolongation3_[level];
    const geometry::SparseMatrix& level_limit = LevelLimit(level);
    LevelSolveReport report;
    report.level = level;
    report.unknowns = unknowns;
    report.data_stiffness = DataStiffness(level_matrix_[level], data[level]);
    Positions& delta = solution->level_motion[level];
    if (delta.rows() != hierarchy_->VertexCount(level))
      delta = Positions::Zero(hierarchy_->VertexCount(level), 3);
    VectorMap x(delta.data(), unknowns);
    if (report.data_stiffness > 0.0) {
      report.smoothness_weight =
          options_.smoothness * report.data_stiffness * length_ratio4_[level];
      Positions smooth_about = coarse_motion;  // W_i − ρ_i
      if (rigid_part[level].rows() == smooth_about.rows()) smooth_about -= rigid_part[level];
      const ConstVectorMap W(smooth_about.data(), unknowns);
      // Data part of the right-hand side: P_iᵀ (Lᵀ h − Lᵀ M L D) = L_iᵀ (h_s − M_s (L D)_s).
      Positions sample_rhs(samples, 3);
      tbb::parallel_for(tbb::blocked_range<int>(0, samples, 4096),
                        [&](const tbb::blocked_range<int>& range) {
        for (int s = range.begin(); s < range.end(); ++s) {
          const double* m6 = M.row(s).data();
          const double u0 = sample_motion(s, 0), u1 = sample_motion(s, 1), u2 = sample_motion(s, 2);
          sample_rhs(s, 0) = h(s, 0) - (m6[0] * u0 + m6[1] * u1 + m6[2] * u2);
          sample_rhs(s, 1) = h(s, 1) - (m6[1] * u0 + m6[3] * u1 + m6[4] * u2);
          sample_rhs(s, 2) = h(s, 2) - (m6[2] * u0 + m6[4] * u1 + m6[5] * u2);
        }
      });
      const Positions data_rhs = TransposeParallelProduct<3>(level_limit, sample_rhs);
      const Eigen::VectorXd rhs = ConstVectorMap(data_rhs.data(), unknowns) -
                                  report.smoothness_weight * (smoothness3_[level] * W);
      // λ_i U_iᵀU_i + μ_i I = κ_i (smoothness (R/h_i)⁴ U_iᵀU_i + β_i I), precomputed.
      const BlockSparseMatrix A = AssembleLevelBlocks(level_matrix_[level], data[level], report.data_stiffness);
      Eigen::VectorXd solution_vector = x;
      const Stopwatch cg_start;
      const bool cycle = options_.multigrid && level > lo_ && unknowns >= 3 * options_.multigrid_min_vertices;
      const std::unique_ptr<MultigridPreconditioner> multigrid =
          cycle ? MakeMultigrid(A, data, level, report.data_stiffness) : nullptr;
      const ConjugateGradientResult cg = SolveConjugateGradient(
          A, rhs, cg_tolerance, options_.cg_max_iterations, &solution_vector, multigrid.get());
      spdlog::debug("normal flow level {}: {} unknowns, {} blocks, {} CG iterations to {:.2g} in {:.3f} s{}", level,
                    unknowns, A.row.size(), cg.iterations, cg.relative_residual, cg_start.Seconds(),
                    multigrid ? " (multigrid)" : "");
      x = solution_vector;
      report.cg_iterations = cg.iterations;
      report.cg_error = cg.relative_residual;
    } else {
      x.setZero();
    }
    D += P3 * x;
    sample_motion += RowParallelProduct<3>(level_limit, delta);
    solution->cg_iterations += report.cg_iterations;
    solution->levels.push_back(report);
    if (level < hi_)
      coarse_motion = hierarchy_->Refinement(level) * Positions(coarse_motion + delta);
  }
  *sample_motion_out = std::move(sample_motion);
}

std::unique_ptr<MultigridPreconditioner> NormalFlowSolver::MakeMultigrid(const BlockSparseMatrix& A,
                                                                         const std::vector<std::vector<double>>& data,
                                                                         int level, double stiffness) const {
  std::vector<BlockSparseMatrix> coarse;
  std::vector<const geometry::SparseMatrix*> refinement;
  double scale = stiffness;
  for (int j = level - 1; j >= lo_; --j) {
    scale *= 4.0;  // the fine regularizer's weight on a net of ¼ the vertices (multigrid_preconditioner.h)
    coarse.push_back(AssembleLevelBlocks(level_matrix_[j], data[j], scale));
    // The base level's own regularizer has no damping; the fine level's has.
    if (j == lo_) AddToBlockDiagonal((options_.detail_damping - kBaseDamping) * scale, &coarse.back());
    refinement.push_back(&hierarchy_->Refinement(j));
  }
  return std::make_unique<MultigridPreconditioner>(A, std::move(coarse), std::move(refinement));
}

NormalFlowSolution NormalFlowSolver::Solve(const NormalFlowConstraints& constraints,
                                           const Positions& control,
                                           const NormalFlowSolution* warm_start) const {
  const int samples = static_cast<int>(limit_->rows());
  if (control.rows() != limit_->cols())
    ThrowError("normal flow solver", "control points",
               std::to_string(control.rows()) + " rows, expected #V(n) = " +
                   std::to_string(limit_->cols()));
  for (int c = 0; c < constraints.size(); ++c)
    if (constraints.sample[c] < 0 || constraints.sample[c] >= samples)
      ThrowError("normal flow solver", "constraint " + std::to_string(c),
                 "sample index " + std::to_string(constraints.sample[c]) + " out of range");
  NormalFlowSolution solution;
  if (warm_start) solution.level_motion = warm_start->level_motion;
  solution.collinearity_weights = Eigen::VectorXd::Ones(constraints.size());
  if (options_.collinearity_pruning) {
    CollinearityOptions collinearity;
    collinearity.min_cameras = options_.collinearity_min_cameras;
    collinearity.threshold = options_.robust_threshold;
    collinearity.noise_floor = options_.noise_floor;
    const CollinearityResult tested = CollinearityWeights(constraints, samples, collinearity);
    solution.collinearity_weights = tested.weights;
    solution.collinearity_pruned = tested.pruned;
  }
  Eigen::VectorXd weights = solution.collinearity_weights;
  Eigen::VectorXd residual;
  Positions previous = warm_start ? warm_start->displacement : Positions();
  Positions sample_motion;
  for (int pass = 0; pass <= options_.reweighting_iterations; ++pass) {
    const bool last = pass == options_.reweighting_iterations;
    SolveLevels(constraints, weights, RigidPart(control, previous),
                last ? options_.cg_tolerance : options_.cg_reweighting_tolerance, &solution, &sample_motion);
    previous = solution.displacement;
    residual = constraints.Residuals(sample_motion);
    if (last) break;
    std::vector<double> active;
    for (int c = 0; c < constraints.size(); ++c)
      if (solution.collinearity_weights(c) > 0.0) active.push_back(residual(c));
    const double sigma = RobustScale(active, options_.noise_floor);
    if (!(sigma > 0.0)) break;
    solution.robust_scale = sigma;
    for (int c = 0; c < constraints.size(); ++c)
      weights(c) = solution.collinearity_weights(c) *
                   TukeyWeight(residual(c) / (options_.robust_threshold * sigma));
  }
  solution.weights = weights;
  solution.rigid = FitRigidMotion(control + 0.5 * solution.displacement, solution.displacement);
  double sum_zero = 0.0, sum = 0.0;
  int kept = 0;
  for (int c = 0; c < constraints.size(); ++c) {
    sum_zero += constraints.rhs(c) * constraints.rhs(c);
    if (weights(c) > 0.0) {
      sum += residual(c) * residual(c);
      ++kept;
    } else {
      ++solution.pruned;
    }
  }
  solution.rms_residual_zero = constraints.size() > 0 ? std::sqrt(sum_zero / constraints.size()) : 0.0;
  solution.rms_residual = kept > 0 ? std::sqrt(sum / kept) : 0.0;
  return solution;
}

std::vector<Positions> LocalDetailMotion(const geometry::LoopHierarchy& hierarchy,
                                         const Positions& finest_control,
                                         const NormalFlowSolution& solution, int coarsest_level) {
  const int n = hierarchy.finest_level();
  SUBFLOW_CHECK(finest_control.rows() == hierarchy.VertexCount(n), "finest control points expected");
  std::vector<Positions> local(n + 1);
  Positions fine = finest_control;
  for (int level = n; level >= 1; --level) {
    Positions coarse = hierarchy.Coarsening(level) * fine;
    if (level > coarsest_level && level < static_cast<int>(solution.level_motion.size()) &&
        solution.level_motion[level].rows() == hierarchy.VertexCount(level)) {
      const Positions predicted = hierarchy.Refinement(level - 1) * coarse;
      local[level] =
          geometry::ComputeLocalFrames(hierarchy, level, predicted).ToLocal(solution.level_motion[level]);
    }
    fine = std::move(coarse);
  }
  return local;
}

}  // namespace subflow::solver
