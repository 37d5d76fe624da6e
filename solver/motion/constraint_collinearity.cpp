#include "solver/motion/constraint_collinearity.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::solver {
namespace {

// Deletion residuals t_i (step 2 of the header) of the rank-2 fit of `rows`; −1 where a
// row is not testable.
void DeletionResiduals(const NormalFlowConstraints& constraints, const std::vector<int>& rows,
                       std::vector<double>* t) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int c : rows) {
    const Eigen::Vector3d g = constraints.gradient.row(c).transpose();
    normal += g * g.transpose();
    rhs += constraints.rhs(c) * g;
  }
  t->assign(rows.size(), -1.0);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(normal);  // closed form (3×3): a fraction of the iterative solver's time
  const double largest = eigen.eigenvalues()(2);
  if (!(largest > 0.0)) return;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 2> basis = Eigen::Matrix<double, 3, 2>::Zero();  // u_j / √λ_j
  for (int j = 1; j < 3; ++j) {  // eigenvalues ascending: the two largest
    const double lambda = eigen.eigenvalues()(j);
    if (lambda <= 1e-9 * largest) continue;
    const Eigen::Vector3d u = eigen.eigenvectors().col(j);
    velocity += (u.dot(rhs) / lambda) * u;
    basis.col(j - 1) = u / std::sqrt(lambda);
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Eigen::RowVector3d g = constraints.gradient.row(rows[i]);
    const double leverage = (g * basis).squaredNorm();
    if (1.0 - leverage < 1e-9) continue;
    const double r = g.dot(velocity.transpose()) - constraints.rhs(rows[i]);
    (*t)[i] = std::abs(r) / std::sqrt(1.0 - leverage);
  }
}

}  // namespace

double TukeyWeight(double x) {
  if (!(std::abs(x) < 1.0)) return 0.0;
  const double t = 1.0 - x * x;
  return t * t;
}

double RobustScale(const std::vector<double>& values, double floor) {
  if (values.empty()) return floor;
  std::vector<double> absolute(values.size());
  std::transform(values.begin(), values.end(), absolute.begin(), [](double v) { return std::abs(v); });
  const std::size_t mid = absolute.size() / 2;
  std::nth_element(absolute.begin(), absolute.begin() + mid, absolute.end());
  return std::max(1.4826 * absolute[mid], floor);
}

CollinearityResult CollinearityWeights(const NormalFlowConstraints& constraints, int sample_count,
                                       const CollinearityOptions& options) {
  SUBFLOW_CHECK(options.min_cameras >= 3, "two planes always meet in a line");
  const int count = constraints.size();
  CollinearityResult result;
  result.weights = Eigen::VectorXd::Ones(count);
  // Constraints per sample (counting sort).
  std::vector<int> first(sample_count + 1, 0), order(count);
  for (int c = 0; c < count; ++c) {
    SUBFLOW_CHECK(constraints.sample[c] >= 0 && constraints.sample[c] < sample_count,
                  "sample index out of range");
    ++first[constraints.sample[c] + 1];
  }
  for (int s = 0; s < sample_count; ++s) first[s + 1] += first[s];
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (int c = 0; c < count; ++c) order[fill[constraints.sample[c]]++] = c;
  auto rows_of = [&](int s) {
    return std::vector<int>(order.begin() + first[s], order.begin() + first[s + 1]);
  };
  auto tested = [&](int s) { return first[s + 1] - first[s] >= options.min_cameras; };

  // σ from the first fit of every tested sample.
  std::vector<double> first_fit(count, -1.0);
  tbb::parallel_for(0, sample_count, [&](int s) {
    if (!tested(s)) return;
    const std::vector<int> rows = rows_of(s);
    std::vector<double> t;
    DeletionResiduals(constraints, rows, &t);
    for (std::size_t i = 0; i < rows.size(); ++i) first_fit[rows[i]] = t[i];
  });
  std::vector<double> testable;
  for (double t : first_fit)
    if (t >= 0.0) testable.push_back(t);
  result.scale = RobustScale(testable, options.noise_floor);
  const double limit = options.threshold * result.scale;

  std::atomic<int> tested_samples{0}, removed_single{0}, pruned_samples{0};
  tbb::parallel_for(0, sample_count, [&](int s) {
    if (!tested(s)) return;
    ++tested_samples;
    std::vector<int> rows = rows_of(s);
    // The first fit of all the sample's rows is the one σ came from.
    std::vector<double> t(rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) t[i] = first_fit[rows[i]];
    for (bool refit = false;; refit = true) {
      if (refit) DeletionResiduals(constraints, rows, &t);
      const auto worst = std::max_element(t.begin(), t.end());
      if (*worst <= limit) break;
      if (static_cast<int>(rows.size()) <= options.min_cameras) {
        for (int c : rows) result.weights(c) = 0.0;
        ++pruned_samples;
        return;
      }
      const std::size_t i = static_cast<std::size_t>(worst - t.begin());
      result.weights(rows[i]) = 0.0;
      rows.erase(rows.begin() + static_cast<std::ptrdiff_t>(i));
      ++removed_single;
    }
    for (std::size_t i = 0; i < rows.size(); ++i)
      result.weights(rows[i]) = t[i] < 0.0 ? 1.0 : TukeyWeight(t[i] / limit);
  });
  result.tested_samples = tested_samples;
  result.removed_single = removed_single;
  result.pruned_samples = pruned_samples;
  result.pruned = static_cast<int>((result.weights.array() == 0.0).count());
  return result;
}

}  // namespace subflow::solver
