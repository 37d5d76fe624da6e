#include "solver/stereo/window_solve.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <ceres/ceres.h>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/stopwatch.h"
#include "solver/stereo/photometric_residuals.h"
#include "solver/stereo/regularization_residuals.h"
#include "solver/stereo/stereo_refinement.h"
#include "solver/stereo/view_cache.h"

namespace subflow::solver {
namespace {

// Per frame of the sequence: the sum and count of the figures of `records` at the current
// parameters — per stereo pair NCC ≈ 1 − ‖r_pair‖² / (2 W) (exact for ε = 0), per
// silhouette block the squared outline distance in pixels.
// The views must have been sampled at the current parameters (ViewCache).
void Evaluate(ceres::Problem& problem, const std::vector<ResidualRecord>& records, bool ncc,
              double silhouette_weight, int frames, std::vector<double>* sum, std::vector<int>* count) {
  sum->assign(frames, 0.0);
  count->assign(frames, 0);
  Eigen::VectorXd r;
  std::vector<double*> blocks;
  for (const ResidualRecord& record : records) {
    if (ncc) {
      problem.GetParameterBlocksForResidualBlock(record.id, &blocks);
      r.resize(record.correlation->pair_residual_count());
      record.correlation->PairResiduals(blocks.data(), r.data());
      int offset = 0;
      for (const CorrelationPair& pair : record.correlation->pairs()) {
        const int n = static_cast<int>(pair.rows.size());
        if (pair.weight > 0) {
          (*sum)[record.frame] += 1.0 - r.segment(offset, n).squaredNorm() / (2.0 * pair.weight);
          ++(*count)[record.frame];
        }
        offset += n;
      }
      continue;
    }
    double cost = 0.0;
    r.resize(problem.GetCostFunctionForResidualBlock(record.id)->num_residuals());
    problem.EvaluateResidualBlockAssumingParametersUnchanged(record.id, false, &cost, r.data(), nullptr);
    (*sum)[record.frame] += std::pow(std::max(0.0, r(0)) / silhouette_weight, 2);
    ++(*count)[record.frame];
  }
}

// Every residual family over the window, patch by patch and then vertex by vertex.
void BuildResiduals(RefinementWindow& window, ceres::LossFunction* ncc_loss, ceres::Problem* problem,
                    std::vector<ResidualRecord>* stereo, std::vector<ResidualRecord>* silhouette) {
  const int faces = static_cast<int>(window.active_faces.size());
  for (int t = window.first; t <= window.last; ++t) {
    for (int f = 0; f < faces; ++f) {
      if (!window.active_faces[f]) continue;
      const PatchCameras seen = CamerasOfPatch(window, t, f);
      if (auto record = AddStereoResidual(window, t, f, seen, ncc_loss, problem)) stereo->push_back(*record);
      AddTemporalResiduals(window, t, f, seen, ncc_loss, problem);
      AddSilhouetteResiduals(window, t, f, problem, silhouette);
    }
  }
  const int vertices = static_cast<int>(window.active_vertices.size());
  for (int t = window.first; t <= window.last; ++t) {
    for (int v = 0; v < vertices; ++v) {
      if (!window.active_vertices[v]) continue;
      AddMembraneResidual(window, t, v, problem);
      AddTemporalSmoothnessResidual(window, t, v, problem);
      AddSlideCoherenceResidual(window, t, v, problem);
      AddDampingResidual(window, t, v, problem);
    }
  }
}

// Holds every free increment block of the window's frames that no measured outline moves
// (window.sliding) to its normal: only its first coordinate varies. Returns how many.
int HoldToNormals(RefinementWindow& window, ceres::Manifold* normal_only, ceres::Problem* problem) {
  int held = 0;
  const int vertices = static_cast<int>(window.active_vertices.size());
  for (int t = window.first; t <= window.last; ++t)
    for (int v = 0; v < vertices; ++v) {
      double* block = window.Increment(t, v);
      if (!problem->HasParameterBlock(block) || problem->IsParameterBlockConstant(block) ||
          window.sliding.count(block))
        continue;
      problem->SetManifold(block, normal_only);
      ++held;
    }
  return held;
}

}  // namespace

WindowSolution SolveWindow(RefinementWindow& window, const vision::Bounds& bounds) {
  const StereoRefinementOptions& options = *window.options;
  ViewCache views(window.states.begin()->first, static_cast<int>(window.states.size()),
                  static_cast<int>(window.cameras->size()), static_cast<int>(window.active_faces.size()), window.dof);
  window.views = &views;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.evaluation_callback = &views;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::SubsetManifold normal_only(3, {1, 2});  // outlives the problem
  ceres::Problem problem(problem_options);
  std::unique_ptr<ceres::LossFunction> ncc_loss;
  if (options.ncc_loss_scale > 0) ncc_loss = std::make_unique<ceres::CauchyLoss>(options.ncc_loss_scale);

  std::vector<ResidualRecord> stereo, silhouette;
  BuildResiduals(window, ncc_loss.get(), &problem, &stereo, &silhouette);
  WindowSolution solution;
  solution.first = window.first;
  solution.last = window.last;
  solution.parameters = BoundIncrements(window, bounds, &problem);
  solution.vertex_blocks = solution.parameters / window.dof;
  if (window.dof == 3 && options.tangential_only_at_outlines) {
    const int held = HoldToNormals(window, &normal_only, &problem);
    spdlog::debug("refinement level {} frames {}–{}: {} of {} vertex blocks held to their normals", window.level,
                  window.first, window.last, held, solution.parameters / 3);
    solution.parameters -= 2 * held;
  }
  solution.residual_blocks = problem.NumResidualBlocks();

  const int frames = window.frame_count;
  std::vector<double> ncc_before, silhouette_before, ncc_after, silhouette_after;
  std::vector<int> ncc_count, silhouette_count;
  views.PrepareForEvaluation(false, true);
  Evaluate(problem, stereo, true, options.silhouette_weight, frames, &ncc_before, &ncc_count);
  Evaluate(problem, silhouette, false, options.silhouette_weight, frames, &silhouette_before, &silhouette_count);
  if (problem.NumParameterBlocks() > 0 && problem.NumResidualBlocks() > 0) {
    ceres::Solver::Summary summary;
    solution.iterative = options.solver.Iterative(solution.vertex_blocks);  // as ToCeres chooses
    const Stopwatch solve_start;
    ceres::Solve(options.solver.ToCeres(solution.vertex_blocks), &problem, &summary);
    solution.solver_seconds = solve_start.Seconds();
    solution.iterations = static_cast<int>(summary.iterations.size());
    std::string costs;  // and the linear solver's iterations in brackets
    for (const ceres::IterationSummary& iteration : summary.iterations)
      costs += fmt::format("{}{:.4g}{} [{}]", costs.empty() ? "" : " ", iteration.cost,
                           iteration.step_is_successful ? "" : "✗", iteration.linear_solver_iterations);
    spdlog::debug("refinement level {} frames {}–{}: {} residuals in {} blocks, {} views; {}; jacobians {:.2f} s, "
                  "residuals {:.2f} s, linear solver {:.2f} s; cost per iteration {}", window.level, window.first,
                  window.last, problem.NumResiduals(), problem.NumResidualBlocks(), views.size(),
                  summary.BriefReport(), summary.jacobian_evaluation_time_in_seconds,
                  summary.residual_evaluation_time_in_seconds, summary.linear_solver_time_in_seconds, costs);
  }
  views.PrepareForEvaluation(false, true);  // at the solution Ceres wrote back
  Evaluate(problem, stereo, true, options.silhouette_weight, frames, &ncc_after, &ncc_count);
  Evaluate(problem, silhouette, false, options.silhouette_weight, frames, &silhouette_after, &silhouette_count);
  window.views = nullptr;

  const int vertices = static_cast<int>(window.active_vertices.size());
  for (int t = window.first; t <= window.last; ++t) {
    const FrameState& state = window.states.at(t);
    WindowSolution::Increments e = Eigen::Map<const WindowSolution::Increments>(state.increments.data(), vertices,
                                                                                window.dof);
    geometry::Positions world(vertices, 3);
    for (int v = 0; v < vertices; ++v) {
      Eigen::Vector3d moved = Eigen::Vector3d::Zero();
      for (int d = 0; d < window.dof; ++d) moved += e(v, d) * state.basis[v].col(d);
      world.row(v) = moved.transpose();
    }
    solution.increments.push_back(std::move(e));
    solution.displacement.push_back(std::move(world));
    WindowFrameFigures figures;
    figures.frame = t;
    figures.stereo_pairs = ncc_count[t];
    if (ncc_count[t] > 0) {
      figures.ncc_before = ncc_before[t] / ncc_count[t];
      figures.ncc_after = ncc_after[t] / ncc_count[t];
      figures.silhouette_rms_before = silhouette_count[t] ? std::sqrt(silhouette_before[t] / silhouette_count[t]) : 0.0;
      figures.silhouette_rms_after = silhouette_count[t] ? std::sqrt(silhouette_after[t] / silhouette_count[t]) : 0.0;
    }
    solution.frames.push_back(figures);
  }
  return solution;
}

}  // namespace subflow::solver
