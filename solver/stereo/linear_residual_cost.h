// A residual linear in its parameter blocks, r = Σ_b A_b e_b + r0 (A_b: rows × size of
// block b, dense), for the regularization terms of the stereo refinement: membrane and
// damping of the increments, temporal second differences of the trajectories (r0: those
// of the current ones).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <ceres/cost_function.h>

namespace subflow::solver {

class LinearResidualCost final : public ceres::CostFunction {
 public:
  // `blocks`: A_b, all with the same row count; `offset`: r0 (empty = zero). Throws
  // subflow::Error when the sizes disagree.
  explicit LinearResidualCost(std::vector<Eigen::MatrixXd> blocks, Eigen::VectorXd offset = {});

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  std::vector<Eigen::MatrixXd> blocks_;
  Eigen::VectorXd offset_;
};

}  // namespace subflow::solver
