#include "vision/still_evidence.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "vision/voxel_projection.h"

namespace subflow::vision {
namespace {

// The trusted points inside the volume, with the depth step (world units) at each.
void TrustedPoints(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                   const std::vector<double>& steps, const Bounds& bounds, std::vector<Eigen::Vector3d>* points,
                   std::vector<double>* depth_steps) {
  for (std::size_t k = 0; k < cameras.size(); ++k)
    for (int v = 0; v < trusted[k].rows; ++v)
      for (int u = 0; u < trusted[k].cols; ++u) {
        const float q = trusted[k].at<float>(v, u);
        if (q <= 0) continue;
        const Eigen::Vector3d X = PointAtDepth(cameras[k], Eigen::Vector2d(u, v), 1.0 / q);
        if (!bounds.Contains(X)) continue;
        points->push_back(X);
        depth_steps->push_back(steps[k] / (q * q));
      }
}

// Pixels of every camera that see the plane n·X + d = 0 (ScorePlane ≥ min_score).
int PlanePixels(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                const std::vector<std::vector<int>>& neighbours, const Eigen::Vector3d& normal, double offset,
                const PlaneSweepOptions& options) {
  std::vector<int> counts(cameras.size(), 0);
  tbb::parallel_for(0, static_cast<int>(cameras.size()), [&](int k) {
    counts[k] = cv::countNonZero(ScorePlane(cameras, gray, k, neighbours[k], normal, offset, options).score >=
                                 options.min_score);
  });
  int total = 0;
  for (int count : counts) total += count;
  return total;
}

// The support plane (step 3 of the header): the plane perpendicular to the cameras' mean
// up direction, at the height in the lower half of the volume that the most pixels of all
// cameras see (a sweep of horizontal planes, coarse then fine, scored by ScorePlane: a
// floor seen at a grazing angle, which the fronto-parallel sweep hardly matches, is found
// this way); then refined by RANSAC (FindSupportPlane) over the trusted points near it
// when they hold a plane, and accepted by FindSupportPlane's tests.
SupportPlane FindPlane(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                       const std::vector<std::vector<int>>& neighbours, const std::vector<cv::Mat>& trusted,
                       const std::vector<double>& steps, const Bounds& bounds, const StillEvidenceOptions& options) {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> depth_steps;
  TrustedPoints(cameras, trusted, steps, bounds, &points, &depth_steps);
  if (points.size() < 3) return {};
  std::nth_element(depth_steps.begin(), depth_steps.begin() + depth_steps.size() / 2, depth_steps.end());
  const double tolerance = options.support_tolerance_planes * depth_steps[depth_steps.size() / 2];
  // Up: upright cameras (no roll) have horizontal image x axes, so up is the direction
  // most perpendicular to all of them (smallest eigenvector of Σ x xᵀ), signed like the
  // mean of their −y axes (image y points down).
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  Eigen::Vector3d down = Eigen::Vector3d::Zero(), viewpoint = Eigen::Vector3d::Zero();
  for (const Camera& camera : cameras) {
    scatter += camera.R().row(0).transpose() * camera.R().row(0);
    down += camera.R().row(1).transpose();
    viewpoint += camera.Center() / static_cast<double>(cameras.size());
  }
  Eigen::Vector3d up = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  if (up.dot(down) > 0) up = -up;
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d X((corner & 1) ? bounds.max.x() : bounds.min.x(), (corner & 2) ? bounds.max.y() : bounds.min.y(),
                            (corner & 4) ? bounds.max.z() : bounds.min.z());
    low = std::min(low, up.dot(X));
    high = std::max(high, up.dot(X));
  }
  // Heights h (the plane up·X = h), coarse steps of 4 tolerances over the lower half, then
  // steps of ½ tolerance around the best.
  double best_height = low;
  int best_pixels = -1;
  const auto sweep = [&](double from, double to, double step) {
    for (double h = from; h <= to + 1e-12; h += step) {
      const int pixels = PlanePixels(cameras, gray, neighbours, up, -h, options.sweep);
      if (pixels > best_pixels) best_pixels = pixels, best_height = h;
    }
  };
  sweep(low, 0.5 * (low + high), 4 * tolerance);
  sweep(best_height - 4 * tolerance, best_height + 4 * tolerance, 0.5 * tolerance);

  // RANSAC among the trusted points near the swept plane, when they hold one close to it.
  std::vector<Eigen::Vector3d> near;
  for (const Eigen::Vector3d& X : points)
    if (std::abs(up.dot(X) - best_height) <= 3 * tolerance) near.push_back(X);
  SupportPlaneOptions near_options = options.support_plane;
  near_options.min_inlier_fraction = 0.5;
  near_options.min_above_fraction = 0.0;
  const SupportPlane refined = FindSupportPlane(near, viewpoint, tolerance, near_options);
  Eigen::Vector3d normal = up;
  double offset = -best_height;
  if (refined.found && refined.normal.dot(up) > std::cos(10.0 * M_PI / 180.0)) {
    normal = refined.normal;
    offset = refined.offset;
  }
  // The tests of FindSupportPlane on all trusted points, for this plane.
  SupportPlane plane;
  plane.normal = normal;
  plane.offset = offset;
  plane.tolerance = tolerance;
  plane.CountSides(points);
  plane.found = plane.above_fraction >= options.support_plane.min_above_fraction && best_pixels > 0;
  return plane;
}

}  // namespace

void StillEvidenceOptions::Check() const {
  backdrop.Check();
  sweep.Check();
  fusion.Check();
  support_plane.Check();
  if (!(support_tolerance_planes > 0 && support_tolerance_planes < 1000))
    ThrowError("still evidence options", "support_tolerance_planes", "expected a value in (0, 1000)");
}

StillEvidence ComputeStillEvidence(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                   const Bounds& bounds, int resolution, const StillEvidenceOptions& options,
                                   const std::vector<cv::Mat>& known) {
  options.Check();
  Stopwatch start;
  StillEvidence result = StillEvidenceFromDepthMaps(
      cameras, gray, SweepDepthMaps(cameras, gray, bounds, options.sweep, known), bounds, resolution, options, known);
  result.seconds = start.Seconds();
  return result;
}

StillEvidence StillEvidenceFromDepthMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                         const std::vector<DepthMap>& maps, const Bounds& bounds, int resolution,
                                         const StillEvidenceOptions& options, const std::vector<cv::Mat>& known) {
  options.Check();
  Stopwatch start;
  StillEvidence result;
  const int count = static_cast<int>(cameras.size());
  if (maps.size() != cameras.size()) ThrowError("still evidence", "depth maps", "expected one per camera");
  std::vector<cv::Mat> trusted = TrustedDepths(cameras, maps, options.fusion);
  std::vector<double> steps(count);
  result.cameras.resize(count);
  for (int k = 0; k < count; ++k) {
    steps[k] = maps[k].inverse_depth_step;
    StillCameraReport& report = result.cameras[k];
    report.name = cameras[k].name();
    report.planes = maps[k].planes;
    report.depth_pixels = maps[k].pixels_with_depth;
    report.trusted_pixels = cv::countNonZero(trusted[k] >= 0);
    report.sweep_seconds = maps[k].seconds;
  }

  if (options.remove_support_plane) {
    std::vector<std::vector<int>> neighbours(count);
    for (int k = 0; k < count; ++k) neighbours[k] = maps[k].neighbours;
    result.support = FindPlane(cameras, gray, neighbours, trusted, steps, bounds, options);
    spdlog::debug("still evidence: support plane {}", result.support.Describe());
  }
  if (result.support.found) {
    tbb::parallel_for(0, count, [&](int k) {
      const PlaneHypothesis plane = ScorePlane(cameras, gray, k, maps[k].neighbours, result.support.normal,
                                               result.support.offset, options.sweep);
      cv::Mat& depths = trusted[k];
      for (int v = 0; v < depths.rows; ++v)
        for (int u = 0; u < depths.cols; ++u) {
          if (depths.at<float>(v, u) >= 0 || plane.score.at<float>(v, u) < options.sweep.min_score) continue;
          if (!known.empty() && !known[k].empty() && !known[k].at<uchar>(v, u)) continue;
          depths.at<float>(v, u) = plane.inverse_depth.at<float>(v, u);
          ++result.cameras[k].support_pixels;
        }
    });
  }

  result.fused = FuseDepthMaps(cameras, trusted, steps, bounds, resolution, &result.support, options.fusion);
  result.silhouettes.resize(count);
  tbb::parallel_for(0, count, [&](int k) {
    result.silhouettes[k] = ProjectOccupancy(cameras[k], result.fused.occupancy);
    result.cameras[k].silhouette_pixels = cv::countNonZero(result.silhouettes[k]);
  });
  result.seconds = start.Seconds();
  return result;
}

}  // namespace subflow::vision
