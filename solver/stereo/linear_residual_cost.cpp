#include "solver/stereo/linear_residual_cost.h"

#include <utility>

#include "core/error.h"

namespace subflow::solver {

LinearResidualCost::LinearResidualCost(std::vector<Eigen::MatrixXd> blocks, Eigen::VectorXd offset)
    : blocks_(std::move(blocks)), offset_(std::move(offset)) {
  SUBFLOW_CHECK(!blocks_.empty(), "a linear residual needs at least one parameter block");
  set_num_residuals(static_cast<int>(blocks_.front().rows()));
  if (offset_.size() == 0) offset_ = Eigen::VectorXd::Zero(num_residuals());
  SUBFLOW_CHECK(offset_.size() == num_residuals(), "offset does not match the residuals");
  for (const Eigen::MatrixXd& A : blocks_) {
    SUBFLOW_CHECK(A.rows() == num_residuals(), "blocks with different row counts");
    mutable_parameter_block_sizes()->push_back(static_cast<int>(A.cols()));
  }
}

bool LinearResidualCost::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const int rows = num_residuals();
  Eigen::Map<Eigen::VectorXd> r(residuals, rows);
  r = offset_;
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const Eigen::MatrixXd& A = blocks_[b];
    r += A * Eigen::Map<const Eigen::VectorXd>(parameters[b], A.cols());
    if (jacobians && jacobians[b])
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[b], rows,
                                                                                       A.cols()) = A;
  }
  return true;
}

}  // namespace subflow::solver
