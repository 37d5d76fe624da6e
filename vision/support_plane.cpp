#include "vision/support_plane.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <spdlog/fmt/fmt.h>

#include "core/error.h"

namespace subflow::vision {

void SupportPlaneOptions::Check() const {
  const std::string source = "support plane options";
  if (!std::isfinite(tolerance)) ThrowError(source, "tolerance", "expected a finite value (≤ 0 = automatic)");
  if (iterations < 1 || iterations > 1000000) ThrowError(source, "iterations", "expected 1..1000000");
  if (sample_points < 3) ThrowError(source, "sample_points", "expected ≥ 3");
  if (!(min_inlier_fraction > 0 && min_inlier_fraction <= 1))
    ThrowError(source, "min_inlier_fraction", "expected a value in (0, 1]");
  if (!(min_above_fraction >= 0 && min_above_fraction <= 1))
    ThrowError(source, "min_above_fraction", "expected a value in [0, 1]");
}

std::string SupportPlane::Describe() const {
  return fmt::format("n = ({:.3f}, {:.3f}, {:.3f}), d = {:.4g}, tolerance {:.3g}, inliers {}/{}, {:.1f} % of the rest "
                     "above{}",
                     normal.x(), normal.y(), normal.z(), offset, tolerance, inliers, points, 100 * above_fraction,
                     found ? "" : " (not a support plane)");
}

SupportPlane FindSupportPlane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& viewpoint,
                              double tolerance, const SupportPlaneOptions& options) {
  options.Check();
  if (!(tolerance > 0) || !std::isfinite(tolerance))
    ThrowError("support plane", "tolerance", "expected a finite value > 0");
  SupportPlane plane;
  plane.tolerance = tolerance;
  plane.points = static_cast<int>(points.size());
  if (points.size() < 3) return plane;

  std::mt19937 random(options.seed);
  std::vector<int> sample(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) sample[i] = static_cast<int>(i);
  if (static_cast<int>(sample.size()) > options.sample_points) {
    std::shuffle(sample.begin(), sample.end(), random);
    sample.resize(options.sample_points);
  }
  std::uniform_int_distribution<std::size_t> pick(0, sample.size() - 1);
  Eigen::Vector3d best_normal = Eigen::Vector3d::UnitZ();
  double best_offset = 0;
  int best_count = -1;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const Eigen::Vector3d& a = points[sample[pick(random)]];
    const Eigen::Vector3d n = (points[sample[pick(random)]] - a).cross(points[sample[pick(random)]] - a);
    if (n.norm() < 1e-12 * (1 + a.squaredNorm())) continue;
    const Eigen::Vector3d normal = n.normalized();
    const double offset = -normal.dot(a);
    int count = 0;
    for (int i : sample) count += std::abs(normal.dot(points[i]) + offset) <= tolerance;
    if (count > best_count) best_count = count, best_normal = normal, best_offset = offset;
  }

  // Least squares on all inliers of the best hypothesis.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int count = 0;
  for (const Eigen::Vector3d& X : points)
    if (std::abs(best_normal.dot(X) + best_offset) <= tolerance) mean += X, ++count;
  if (count >= 3) {
    mean /= count;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& X : points)
      if (std::abs(best_normal.dot(X) + best_offset) <= tolerance) covariance += (X - mean) * (X - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    best_normal = solver.eigenvectors().col(0).normalized();
    best_offset = -best_normal.dot(mean);
  }
  if (best_normal.dot(viewpoint) + best_offset < 0) best_normal = -best_normal, best_offset = -best_offset;
  plane.normal = best_normal;
  plane.offset = best_offset;

  int above = 0, rest = 0;
  plane.inliers = 0;
  for (const Eigen::Vector3d& X : points) {
    const double distance = plane.SignedDistance(X);
    if (std::abs(distance) <= tolerance) {
      ++plane.inliers;
    } else {
      ++rest;
      above += distance > 0;
    }
  }
  plane.above_fraction = rest ? static_cast<double>(above) / rest : 1.0;
  plane.found = plane.inliers >= options.min_inlier_fraction * points.size() &&
                plane.above_fraction >= options.min_above_fraction;
  return plane;
}

}  // namespace subflow::vision
