#include "vision/still_evidence.h"

#include <algorithm>

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "vision/voxel_projection.h"

namespace subflow::vision {
namespace {

// The support plane from the trusted points inside the volume (step 3 of the header).
SupportPlane FindPlane(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                       const std::vector<double>& steps, const Bounds& bounds, const StillEvidenceOptions& options) {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> depth_steps;
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    viewpoint += cameras[k].Center() / static_cast<double>(cameras.size());
    for (int v = 0; v < trusted[k].rows; ++v)
      for (int u = 0; u < trusted[k].cols; ++u) {
        const float q = trusted[k].at<float>(v, u);
        if (q <= 0) continue;
        const Eigen::Vector3d X = PointAtDepth(cameras[k], Eigen::Vector2d(u, v), 1.0 / q);
        if (!bounds.Contains(X)) continue;
        points.push_back(X);
        depth_steps.push_back(steps[k] / (q * q));
      }
  }
  if (points.size() < 3) return {};
  std::nth_element(depth_steps.begin(), depth_steps.begin() + depth_steps.size() / 2, depth_steps.end());
  const double tolerance = options.support_tolerance_planes * depth_steps[depth_steps.size() / 2];
  return FindSupportPlane(points, viewpoint, tolerance, options.support_plane);
}

}  // namespace

void StillEvidenceOptions::Check() const {
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
    result.support = FindPlane(cameras, trusted, steps, bounds, options);
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
