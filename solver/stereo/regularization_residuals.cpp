#include "solver/stereo/regularization_residuals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "solver/stereo/linear_residual_cost.h"
#include "solver/stereo/stereo_refinement.h"

namespace subflow::solver {

void AddMembraneResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem) {
  const double weight = window.options->membrane_weight;
  const geometry::IndexRange ring = window.hierarchy->Topology(window.level).Ring(vertex);
  if (weight <= 0 || ring.size() == 0) return;
  const double w = weight * (1.0 / window.h);
  std::vector<Eigen::MatrixXd> A{w * window.Basis(frame, vertex)};
  std::vector<double*> blocks{window.Increment(frame, vertex)};
  const double share = w / ring.size();
  for (int u : ring) {
    A.push_back(-share * window.Basis(frame, u));
    blocks.push_back(window.Increment(frame, u));
  }
  problem->AddResidualBlock(new LinearResidualCost(std::move(A)), nullptr, blocks);
}

void AddTemporalSmoothnessResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem) {
  const double weight = window.options->temporal_smoothness;
  if (weight <= 0 || frame <= window.span_first || frame >= window.SpanLast()) return;
  // Measured with 2-frame overlaps: on synth rigid, a level-0 term on the world
  // trajectories gave accuracy P90 0.94 mm against 0.80 mm with this one (end-point error
  // 0.101 against 0.107 mm); on blob frames 0–11 it gave 0.540 against 0.510 mm (end-point
  // error 0.053 against 0.058).
  const int dof = window.dof;
  const double w = weight * (1.0 / window.h);
  std::vector<Eigen::MatrixXd> A;
  Eigen::VectorXd offset;
  if (window.level == 0) {
    A = {w * window.Basis(frame - 1, vertex), -2.0 * w * window.Basis(frame, vertex),
         w * window.Basis(frame + 1, vertex)};
  } else {
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(dof, dof);
    A = {w * I, -2.0 * w * I, w * I};
    const auto detail = [&](int t) {
      return (*window.trajectory)[t].Detail(window.level).row(vertex).leftCols(dof).transpose();
    };
    offset = w * (detail(frame - 1) - 2.0 * detail(frame) + detail(frame + 1));
  }
  std::vector<double*> blocks;
  for (int t : {frame - 1, frame, frame + 1}) blocks.push_back(window.Increment(t, vertex));
  problem->AddResidualBlock(new LinearResidualCost(std::move(A), std::move(offset)), nullptr, blocks);
}

void AddSlideCoherenceResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem) {
  const double weight = window.options->slide_coherence;
  // Frame t with t + 1 (so a window's last frame with the next, unrefined one, which the
  // next window solves again with it). Pairing t − 1 with t instead (a window's first frame
  // with the previous window's result) was worse on five of six figures of bust_front,
  // pair_dome and critter_ring with --slide-at-outlines (observed accuracy P90 mm /
  // EPE_rel): 0.6575 / 0.0572, 0.7665 / 0.1096, 0.7224 / 0.0947 against 0.6516 / 0.0564,
  // 0.7637 / 0.1088, 0.7264 / 0.0939 with t + 1.
  if (weight <= 0 || window.dof != 3 || !window.states.count(frame + 1)) return;  // states end at SpanLast()
  double* now = window.Increment(frame, vertex);
  double* after = window.Increment(frame + 1, vertex);
  if (window.options->tangential_only_at_outlines && !window.sliding.count(now) && !window.sliding.count(after))
    return;
  const Eigen::MatrixXd basis = window.Basis(frame, vertex);  // (n, t1, t2)
  const Eigen::MatrixXd tangents = basis.rightCols(2).transpose();
  const double w = weight * (1.0 / window.h);
  std::vector<Eigen::MatrixXd> A{w * tangents * basis, -w * tangents * window.Basis(frame + 1, vertex)};
  problem->AddResidualBlock(new LinearResidualCost(std::move(A)), nullptr, std::vector<double*>{now, after});
}

void AddDampingResidual(RefinementWindow& window, int frame, int vertex, ceres::Problem* problem) {
  const double weight = window.options->damping;
  if (weight <= 0) return;
  std::vector<Eigen::MatrixXd> A{Eigen::MatrixXd::Identity(window.dof, window.dof) * (weight * (1.0 / window.h))};
  problem->AddResidualBlock(new LinearResidualCost(std::move(A)), nullptr, window.Increment(frame, vertex));
}

std::pair<double, double> SlabRange(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                    const vision::Bounds& bounds) {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(n(a)) < 1e-12) continue;
    double t0 = (bounds.min(a) - p(a)) / n(a), t1 = (bounds.max(a) - p(a)) / n(a);
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  }
  return {std::min(lo, 0.0), std::max(hi, 0.0)};
}

int BoundIncrements(RefinementWindow& window, const vision::Bounds& bounds, ceres::Problem* problem) {
  const int dof = window.dof;
  const int vertices = static_cast<int>(window.active_vertices.size());
  const double limit = window.options->max_step * window.h;
  int free_blocks = 0;
  for (auto& [frame, state] : window.states) {
    for (int v = 0; v < vertices; ++v) {
      double* block = window.Increment(frame, v);
      if (!problem->HasParameterBlock(block)) continue;
      if (frame < window.first || frame > window.last || !window.active_vertices[v]) {
        problem->SetParameterBlockConstant(block);
        continue;
      }
      double lo = -limit, hi = limit;
      if (dof == 1) {
        const auto [slab_lo, slab_hi] = SlabRange(state.level_control.row(v).transpose(), state.basis[v].col(0), bounds);
        lo = std::max(lo, slab_lo);
        hi = std::min(hi, slab_hi);
      }
      for (int d = 0; d < dof; ++d) {
        problem->SetParameterLowerBound(block, d, lo);
        problem->SetParameterUpperBound(block, d, hi);
      }
      ++free_blocks;
    }
  }
  return free_blocks * dof;
}

}  // namespace subflow::solver
