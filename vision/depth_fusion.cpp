#include "vision/depth_fusion.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "vision/voxel_carving.h"
#include "vision/voxel_morphology.h"

namespace subflow::vision {
namespace {

Eigen::Vector2d NormalizedPixel(const Camera& camera, int u, int v) {
  const Eigen::Vector2d xy = (camera.K().inverse() * Eigen::Vector3d(u, v, 1)).head<2>();
  return camera.HasDistortion() ? camera.lens_distortion().Undistort(xy) : xy;
}

constexpr float kOutside = -3.0f;

// The map's inverse depth at the pixel nearest `pixel`; kOutside outside the image.
float MapAt(const cv::Mat& inverse_depth, const Eigen::Vector2d& pixel) {
  const int u = static_cast<int>(std::lround(pixel.x())), v = static_cast<int>(std::lround(pixel.y()));
  if (u < 0 || v < 0 || u >= inverse_depth.cols || v >= inverse_depth.rows) return kOutside;
  return inverse_depth.at<float>(v, u);
}

// What camera c says about a voxel of edge s centred at X: it sees it (X projects into its
// image, in front of it); it frees it (a trusted pixel of the voxel's footprint — a box of
// its half diagonal — sees a surface behind it, and none sees one at it or in front); it
// hits it (some pixel sees a surface at it or in front).
struct FreeSpaceVote {
  bool sees = false, frees = false, hits = false;
  bool at = false;  // some pixel sees a surface at the voxel (within the tolerance)
};

class FreeSpaceVoter {
 public:
  FreeSpaceVoter(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                 const std::vector<double>& steps, double voxel_size, const DepthFusionOptions& options,
                 double margin = 0.0)
      : cameras_(cameras), trusted_(trusted), steps_(steps), half_diagonal_(0.5 * std::sqrt(3.0) * voxel_size),
        margin_(margin), free_space_planes_(options.free_space_planes) {}

  FreeSpaceVote Vote(int c, const Eigen::Vector3d& X) const {
    FreeSpaceVote vote;
    const Camera& camera = cameras_[c];
    double depth = 0;
    const Eigen::Vector2d pixel = camera.Project(X, &depth);
    if (depth <= 0 || !camera.InImage(pixel)) return vote;
    vote.sees = true;
    const double q = 1.0 / depth;
    const double tolerance = free_space_planes_ * steps_[c] + (half_diagonal_ + margin_) * q * q;
    const double radius = half_diagonal_ * q * 0.5 * (camera.K()(0, 0) + camera.K()(1, 1));
    const cv::Mat& map = trusted_[c];
    const int u0 = std::max(0, static_cast<int>(std::ceil(pixel.x() - radius))),
              u1 = std::min(map.cols - 1, static_cast<int>(std::floor(pixel.x() + radius)));
    const int v0 = std::max(0, static_cast<int>(std::ceil(pixel.y() - radius))),
              v1 = std::min(map.rows - 1, static_cast<int>(std::floor(pixel.y() + radius)));
    int through = 0, surface = 0, at = 0;
    for (int v = v0; v <= v1; ++v)
      for (int u = u0; u <= u1; ++u) {
        const float Q = map.at<float>(v, u);
        if (Q < 0) continue;
        through += q - Q > tolerance;
        surface += Q >= q - tolerance;  // a surface at the voxel or in front of it
        at += std::abs(Q - q) <= tolerance;
      }
    vote.frees = through > 0 && surface == 0;
    vote.hits = surface > 0;
    vote.at = at > 0;
    return vote;
  }

 private:
  const std::vector<Camera>& cameras_;
  const std::vector<cv::Mat>& trusted_;
  const std::vector<double>& steps_;
  double half_diagonal_, margin_, free_space_planes_;
};

void CheckTrustedMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                      const std::vector<double>& steps) {
  if (trusted.size() != cameras.size() || steps.size() != cameras.size())
    ThrowError("depth fusion", "depth maps", "expected one map and one plane step per camera");
  for (std::size_t k = 0; k < cameras.size(); ++k)
    if (trusted[k].type() != CV_32FC1 || trusted[k].cols != cameras[k].width() ||
        trusted[k].rows != cameras[k].height())
      ThrowError("depth fusion", "depth map of camera " + cameras[k].name(), "expected CV_32FC1 of the camera's size");
}

}  // namespace

void DepthFusionOptions::Check() const {
  const std::string source = "depth fusion options";
  if (consistent_cameras < 1) ThrowError(source, "consistent_cameras", "expected ≥ 1");
  if (!(unconfirmed_min_score > -1 && unconfirmed_min_score <= 1.5))
    ThrowError(source, "unconfirmed_min_score", "expected a value in (−1, 1.5] (above 1: never)");
  if (!(consistency_planes > 0)) ThrowError(source, "consistency_planes", "expected > 0");
  if (!(free_space_planes >= 0)) ThrowError(source, "free_space_planes", "expected ≥ 0");
  if (free_votes < 1) ThrowError(source, "free_votes", "expected ≥ 1");
  if (min_cameras < 1) ThrowError(source, "min_cameras", "expected ≥ 1");
  if (min_hits < 0) ThrowError(source, "min_hits", "expected ≥ 0");
  if (!(min_component_fraction >= 0 && min_component_fraction <= 1))
    ThrowError(source, "min_component_fraction", "expected a value in [0, 1]");
}

std::vector<cv::Mat> TrustedDepths(const std::vector<Camera>& cameras, const std::vector<DepthMap>& maps,
                                   const DepthFusionOptions& options) {
  const int count = static_cast<int>(cameras.size());
  std::vector<cv::Mat> trusted(count);
  tbb::parallel_for(0, count, [&](int r) {
    const Camera& camera = cameras[r];
    const cv::Mat& map = maps[r].inverse_depth;
    trusted[r] = cv::Mat(map.size(), CV_32F, cv::Scalar(kNoDepth));
    std::vector<Eigen::Matrix3d> rotation(count);
    std::vector<Eigen::Vector3d> offset(count);
    for (int j = 0; j < count; ++j) {
      rotation[j] = cameras[j].R() * camera.R().transpose();
      offset[j] = cameras[j].t() - rotation[j] * camera.t();
    }
    for (int v = 0; v < map.rows; ++v)
      for (int u = 0; u < map.cols; ++u) {
        const float q = map.at<float>(v, u);
        if (q < 0) continue;
        const Eigen::Vector3d ray = NormalizedPixel(camera, u, v).homogeneous();
        int agree = 0, against = 0;
        for (int j = 0; j < count; ++j) {
          if (j == r || maps[j].inverse_depth.empty()) continue;
          // X in j: z (R ray + q b), so its pixel is π(H) and its inverse depth q / H.z.
          const Eigen::Vector3d H = rotation[j] * ray + q * offset[j];
          if (H.z() <= 1e-12) continue;
          Eigen::Vector2d xy = H.head<2>() / H.z();
          if (cameras[j].HasDistortion()) xy = cameras[j].lens_distortion().Distort(xy);
          const float measured = MapAt(maps[j].inverse_depth, (cameras[j].K() * xy.homogeneous()).head<2>());
          if (measured < 0) continue;  // no depth there, or not swept, or outside the image
          const double difference = measured - q / H.z(), tolerance = options.consistency_planes * maps[j].inverse_depth_step;
          if (std::abs(difference) <= tolerance) ++agree;
          else if (difference < 0) ++against;  // j sees through X (a surface in front of X only occludes it)
        }
        const bool confirmed = agree >= 1 && agree >= std::min(options.consistent_cameras, agree + against);
        const bool alone = agree + against == 0 && maps[r].score.at<float>(v, u) >= options.unconfirmed_min_score;
        if (confirmed || alone) trusted[r].at<float>(v, u) = q;
      }
  });
  return trusted;
}

FusedOccupancy FuseDepthMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                             const std::vector<double>& steps, const Bounds& bounds, int resolution,
                             const SupportPlane* support, const DepthFusionOptions& options) {
  options.Check();
  Stopwatch start;
  CheckTrustedMaps(cameras, trusted, steps);
  const int count = static_cast<int>(cameras.size());
  FusedOccupancy result;
  const bool remove_plane = support != nullptr && support->found;

  // Free space, per voxel.
  result.occupancy = MakeVoxelGrid(bounds, resolution);
  geometry::ScalarVolume& grid = result.occupancy;
  const FreeSpaceVoter voter(cameras, trusted, steps, grid.spacing, options);
  tbb::parallel_for(0, grid.nz, [&](int k) {
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i) {
        const Eigen::Vector3d X = grid.VoxelCenter(i, j, k);
        if (remove_plane && support->SignedDistance(X) <= support->tolerance) continue;
        int seen = 0, freed = 0, hits = 0;
        for (int c = 0; c < count && freed < options.free_votes; ++c) {
          const FreeSpaceVote vote = voter.Vote(c, X);
          seen += vote.sees;
          freed += vote.frees;
          hits += vote.hits;
        }
        if (freed < options.free_votes && seen >= options.min_cameras && hits >= options.min_hits)
          grid.at(i, j, k) = 1.0f;
      }
  });
  KeepLargeComponents(&grid, options.min_component_fraction);
  result.occupied_voxels = static_cast<std::size_t>(std::count(grid.values.begin(), grid.values.end(), 1.0f));
  result.seconds = start.Seconds();
  return result;
}

std::size_t CarveSeenThrough(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& trusted,
                             const std::vector<double>& steps, const DepthFusionOptions& options,
                             double margin, bool veto_at_surface, geometry::ScalarVolume* occupancy) {
  options.Check();
  CheckTrustedMaps(cameras, trusted, steps);
  if (!(margin >= 0)) ThrowError("depth fusion", "margin", "expected ≥ 0");
  const int free_votes = options.free_votes;
  geometry::ScalarVolume& grid = *occupancy;
  const FreeSpaceVoter voter(cameras, trusted, steps, grid.spacing, options, margin);
  const int count = static_cast<int>(cameras.size());
  std::vector<std::size_t> carved(grid.nz, 0);
  // Votes are read from the input occupancy only (the maps), so the order does not matter.
  tbb::parallel_for(0, grid.nz, [&](int k) {
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i) {
        if (grid.at(i, j, k) <= 0.5f) continue;
        const Eigen::Vector3d X = grid.VoxelCenter(i, j, k);
        // Without the veto the count may stop at free_votes; with it every camera is asked
        // until one measures a surface at the voxel.
        int freed = 0;
        bool vetoed = false;
        for (int c = 0; c < count && !vetoed && (veto_at_surface || freed < free_votes); ++c) {
          const FreeSpaceVote vote = voter.Vote(c, X);
          freed += vote.frees;
          vetoed = veto_at_surface && vote.at;
        }
        if (freed >= free_votes && !vetoed) grid.at(i, j, k) = 0.0f, ++carved[k];
      }
  });
  std::size_t total = 0;
  for (std::size_t n : carved) total += n;
  return total;
}

}  // namespace subflow::vision
