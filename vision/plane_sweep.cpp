#include "vision/plane_sweep.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/stopwatch.h"

namespace subflow::vision {
namespace {

constexpr float kNone = -1.0f;

// The undistorted normalized point of a pixel.
Eigen::Vector2d NormalizedPoint(const Camera& camera, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = (camera.K().inverse() * pixel.homogeneous()).head<2>();
  return camera.HasDistortion() ? camera.lens_distortion().Undistort(xy) : xy;
}

// Depths along the camera's axis at which C + z Rᵀ(x, y, 1) is inside the bounds (slabs).
bool SlabDepths(const Camera& camera, const Eigen::Vector2d& xy, const Bounds& bounds, double* z_near,
                double* z_far) {
  const Eigen::Vector3d direction = camera.R().transpose() * xy.homogeneous();
  const Eigen::Vector3d C = camera.Center();
  double z0 = 1e-9, z1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-15) {
      if (C[a] < bounds.min[a] || C[a] > bounds.max[a]) return false;
      continue;
    }
    double ta = (bounds.min[a] - C[a]) / direction[a], tb = (bounds.max[a] - C[a]) / direction[a];
    if (ta > tb) std::swap(ta, tb);
    z0 = std::max(z0, ta);
    z1 = std::min(z1, tb);
  }
  *z_near = z0;
  *z_far = z1;
  return z0 < z1;
}

// Per pixel of the reference camera: the undistorted normalized ray (x, y, 1) and the
// inverse depths [q_far, q_near] over which it lies inside the volume (q_near = −1: misses it).
struct ReferenceRays {
  cv::Mat x, y;            // CV_32FC1
  cv::Mat q_near, q_far;   // CV_32FC1
  double q_max = 0, q_min = std::numeric_limits<double>::infinity();  // over all pixels
};

// The normalized rays of every pixel (q_near, q_far left empty).
ReferenceRays PixelRays(const Camera& camera) {
  ReferenceRays rays;
  const int w = camera.width(), h = camera.height();
  rays.x.create(h, w, CV_32F);
  rays.y.create(h, w, CV_32F);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d xy = NormalizedPoint(camera, Eigen::Vector2d(u, v));
      rays.x.at<float>(v, u) = static_cast<float>(xy.x());
      rays.y.at<float>(v, u) = static_cast<float>(xy.y());
    }
  return rays;
}

ReferenceRays TraceRays(const Camera& camera, const Bounds& bounds) {
  ReferenceRays rays = PixelRays(camera);
  const int w = camera.width(), h = camera.height();
  rays.q_near.create(h, w, CV_32F);
  rays.q_far.create(h, w, CV_32F);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      double z0 = 0, z1 = 0;
      const Eigen::Vector2d xy(rays.x.at<float>(v, u), rays.y.at<float>(v, u));
      const bool hits = SlabDepths(camera, xy, bounds, &z0, &z1);
      rays.q_near.at<float>(v, u) = hits ? static_cast<float>(1.0 / z0) : kNone;
      rays.q_far.at<float>(v, u) = hits ? static_cast<float>(1.0 / z1) : kNone;
      if (hits) {
        rays.q_max = std::max(rays.q_max, 1.0 / z0);
        rays.q_min = std::min(rays.q_min, 1.0 / z1);
      }
    }
  return rays;
}

}  // namespace

std::vector<int> ChooseNeighbours(const std::vector<Camera>& cameras, int r, const PlaneSweepOptions& options) {
  std::vector<std::pair<double, int>> candidates;
  const double scale = 1e-9 * (1.0 + cameras[r].Center().norm());
  for (int j = 0; j < static_cast<int>(cameras.size()); ++j) {
    if (j == r || (cameras[j].Center() - cameras[r].Center()).norm() < scale) continue;
    const double cosine = std::clamp(cameras[j].ViewDirection().dot(cameras[r].ViewDirection()), -1.0, 1.0);
    const double degrees = std::acos(cosine) * 180.0 / M_PI;
    if (degrees <= options.max_neighbour_degrees) candidates.emplace_back(degrees, j);
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<int> chosen;
  for (int i = 0; i < std::min<int>(options.neighbours, candidates.size()); ++i) chosen.push_back(candidates[i].second);
  return chosen;
}

namespace {

// The pixel of camera `target` that the point at inverse depth q on reference ray (x, y, 1)
// projects to: X_target ∝ R (x, y, 1) + q b (q = 0: the point at infinity).
struct RayTransfer {
  Eigen::Matrix3d R;  // R_target R_refᵀ
  Eigen::Vector3d b;  // t_target − R t_ref
  const Camera* target = nullptr;

  RayTransfer(const Camera& reference, const Camera& target_camera)
      : R(target_camera.R() * reference.R().transpose()),
        b(target_camera.t() - target_camera.R() * reference.R().transpose() * reference.t()),
        target(&target_camera) {}
  // false when behind the target camera.
  bool Pixel(double x, double y, double q, Eigen::Vector2d* pixel) const {
    const Eigen::Vector3d X = R * Eigen::Vector3d(x, y, 1) + q * b;
    if (X.z() <= 1e-12) return false;
    Eigen::Vector2d xy(X.x() / X.z(), X.y() / X.z());
    if (target->HasDistortion()) xy = target->lens_distortion().Distort(xy);
    *pixel = (target->K() * xy.homogeneous()).head<2>();
    return true;
  }
};

// Number of planes over [q_low, q_high]: the longest epipolar segment of a grid of
// reference pixels in any neighbour, divided by the allowed step.
int CountPlanes(const ReferenceRays& rays, const std::vector<RayTransfer>& transfers, double q_low, double q_high,
                const PlaneSweepOptions& options) {
  double longest = 0;
  const int h = rays.x.rows, w = rays.x.cols;
  for (int gy = 0; gy <= 8; ++gy)
    for (int gx = 0; gx <= 8; ++gx) {
      const int u = std::min(w - 1, gx * (w - 1) / 8), v = std::min(h - 1, gy * (h - 1) / 8);
      if (rays.q_near.at<float>(v, u) < 0) continue;
      const double high = rays.q_near.at<float>(v, u);
      const double low = options.sweep_beyond_volume ? q_low : rays.q_far.at<float>(v, u);
      for (const RayTransfer& transfer : transfers) {
        Eigen::Vector2d p0, p1;
        if (transfer.Pixel(rays.x.at<float>(v, u), rays.y.at<float>(v, u), low, &p0) &&
            transfer.Pixel(rays.x.at<float>(v, u), rays.y.at<float>(v, u), high, &p1))
          longest = std::max(longest, (p1 - p0).norm());
      }
    }
  (void)q_high;
  const int planes = static_cast<int>(std::ceil(longest / options.max_step_pixels)) + 1;
  return std::clamp(planes, 2, options.max_planes);
}

// The map of one neighbour: where each reference pixel's ray meets plane q in its image.
// Exact at the nodes of a grid of kGridStep pixels (and the last row / column), bilinear in
// between: for one plane the map is a smooth function (a homography between two lens
// distortions), so the interpolation error is far below a pixel, and the lens model is
// evaluated 1 / kGridStep² as often.
constexpr int kGridStep = 4;

struct NeighbourGrid {
  RayTransfer transfer;
  std::vector<int> us, vs;                       // grid node coordinates
  std::vector<Eigen::Vector3d> rays, rotated;    // (x, y, 1) and R (x, y, 1) at the nodes, row-major
};

NeighbourGrid MakeGrid(const ReferenceRays& rays, const RayTransfer& transfer) {
  NeighbourGrid grid{transfer, {}, {}, {}, {}};
  const int h = rays.x.rows, w = rays.x.cols;
  for (int u = 0; u < w; u += kGridStep) grid.us.push_back(u);
  if (grid.us.back() != w - 1) grid.us.push_back(w - 1);
  for (int v = 0; v < h; v += kGridStep) grid.vs.push_back(v);
  if (grid.vs.back() != h - 1) grid.vs.push_back(h - 1);
  for (int v : grid.vs)
    for (int u : grid.us) {
      grid.rays.emplace_back(rays.x.at<float>(v, u), rays.y.at<float>(v, u), 1);
      grid.rotated.push_back(transfer.R * grid.rays.back());
    }
  return grid;
}

// map_x, map_y where each reference pixel's ray meets the surface of inverse depth
// q(ray) (a plane of the reference camera: constant; a world plane: linear in the ray),
// −10 where that point is behind the target camera or q < 0.
template <typename InverseDepth>
void SurfaceMap(const NeighbourGrid& grid, const InverseDepth& q_of_ray, cv::Mat* map_x, cv::Mat* map_y) {
  const int nu = static_cast<int>(grid.us.size()), nv = static_cast<int>(grid.vs.size());
  std::vector<Eigen::Vector2f> nodes(grid.rays.size());
  const Camera& target = *grid.transfer.target;
  for (std::size_t n = 0; n < grid.rays.size(); ++n) {
    const double q = q_of_ray(grid.rays[n]);
    const Eigen::Vector3d X = grid.rotated[n] + q * grid.transfer.b;
    if (q < 0 || X.z() <= 1e-12) {
      nodes[n] = Eigen::Vector2f(-1e6f, -1e6f);
      continue;
    }
    Eigen::Vector2d xy(X.x() / X.z(), X.y() / X.z());
    if (target.HasDistortion()) xy = target.lens_distortion().Distort(xy);
    nodes[n] = (target.K() * xy.homogeneous()).head<2>().cast<float>();
  }
  for (int gv = 0; gv + 1 < nv; ++gv)
    for (int gu = 0; gu + 1 < nu; ++gu) {
      const Eigen::Vector2f &a = nodes[gv * nu + gu], &b = nodes[gv * nu + gu + 1], &c = nodes[(gv + 1) * nu + gu],
                            &d = nodes[(gv + 1) * nu + gu + 1];
      const int u0 = grid.us[gu], u1 = grid.us[gu + 1], v0 = grid.vs[gv], v1 = grid.vs[gv + 1];
      const bool behind = a.x() < -1e5f || b.x() < -1e5f || c.x() < -1e5f || d.x() < -1e5f;
      for (int v = v0; v <= v1; ++v) {
        const float t = static_cast<float>(v - v0) / (v1 - v0);
        float* mx = map_x->ptr<float>(v);
        float* my = map_y->ptr<float>(v);
        for (int u = u0; u <= u1; ++u) {
          const float s = static_cast<float>(u - u0) / (u1 - u0);
          const Eigen::Vector2f p = (1 - t) * ((1 - s) * a + s * b) + t * ((1 - s) * c + s * d);
          mx[u] = behind ? -10.0f : p.x();
          my[u] = behind ? -10.0f : p.y();
        }
      }
    }
}

// Box-filtered statistics of the reference image for the NCC window.
struct ReferenceStatistics {
  cv::Mat image, mean, variance;
};

ReferenceStatistics MakeStatistics(const cv::Mat& image, const PlaneSweepOptions& options) {
  ReferenceStatistics statistics{image, {}, {}};
  const cv::Size window(2 * options.window_radius + 1, 2 * options.window_radius + 1);
  cv::Mat square;
  cv::boxFilter(image, statistics.mean, CV_32F, window);
  cv::boxFilter(image.mul(image), square, CV_32F, window);
  statistics.variance = cv::max(square - statistics.mean.mul(statistics.mean), 0.0);
  return statistics;
}

// NCC of the reference windows with the neighbour image sampled at (map_x, map_y); −1
// where a window has a pixel that is not `valid` (1 / 0) or texture-less.
cv::Mat WarpNcc(const ReferenceStatistics& reference, const cv::Mat& neighbour_image, const cv::Mat& map_x,
                const cv::Mat& map_y, const cv::Mat& valid, const PlaneSweepOptions& options) {
  const int h = reference.image.rows, w = reference.image.cols;
  cv::Mat warped;
  cv::remap(neighbour_image, warped, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const cv::Size window(2 * options.window_radius + 1, 2 * options.window_radius + 1);
  cv::Mat mean, mean_square, mean_product, valid_fraction;
  cv::boxFilter(warped, mean, CV_32F, window);
  cv::boxFilter(warped.mul(warped), mean_square, CV_32F, window);
  cv::boxFilter(warped.mul(reference.image), mean_product, CV_32F, window);
  cv::boxFilter(valid, valid_fraction, CV_32F, window);
  cv::Mat ncc(h, w, CV_32F);
  for (int v = 0; v < h; ++v) {
    const float* m = mean.ptr<float>(v);
    const float* m2 = mean_square.ptr<float>(v);
    const float* mp = mean_product.ptr<float>(v);
    const float* vf = valid_fraction.ptr<float>(v);
    const float* rm = reference.mean.ptr<float>(v);
    const float* rv = reference.variance.ptr<float>(v);
    float* out = ncc.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const float variance = std::max(0.0f, m2[u] - m[u] * m[u]);
      const float denominator = std::sqrt(variance * rv[u]);
      out[u] = vf[u] >= 0.999f && denominator > 1e-8f ? (mp[u] - m[u] * rm[u]) / denominator : kNone;
    }
  }
  return ncc;
}

// 1 where the map lands inside the target image and `takes_part(u, v)`, else 0.
template <typename TakesPart>
cv::Mat ValidSamples(const cv::Mat& map_x, const cv::Mat& map_y, const Camera& target, const TakesPart& takes_part) {
  cv::Mat valid(map_x.size(), CV_32F);
  const float low = -0.5f, high_x = target.width() - 0.5f, high_y = target.height() - 0.5f;
  for (int v = 0; v < map_x.rows; ++v) {
    const float* mx = map_x.ptr<float>(v);
    const float* my = map_y.ptr<float>(v);
    float* ok = valid.ptr<float>(v);
    for (int u = 0; u < map_x.cols; ++u)
      ok[u] = takes_part(u, v) && mx[u] >= low && mx[u] < high_x && my[u] >= low && my[u] < high_y ? 1.0f : 0.0f;
  }
  return valid;
}

// NCC of the reference window with the neighbour image sampled on plane q of the sweep.
cv::Mat PlaneNcc(const ReferenceStatistics& reference, const ReferenceRays& rays, const NeighbourGrid& grid,
                 const cv::Mat& neighbour_image, double q, const PlaneSweepOptions& options) {
  cv::Mat map_x(reference.image.size(), CV_32F), map_y(reference.image.size(), CV_32F);
  SurfaceMap(grid, [q](const Eigen::Vector3d&) { return q; }, &map_x, &map_y);
  const float plane = static_cast<float>(q);
  const cv::Mat valid = ValidSamples(map_x, map_y, *grid.transfer.target, [&](int u, int v) {
    const float q_near = rays.q_near.at<float>(v, u);
    return q_near >= 0 && plane <= q_near && (options.sweep_beyond_volume || plane >= rays.q_far.at<float>(v, u));
  });
  return WarpNcc(reference, neighbour_image, map_x, map_y, valid, options);
}

// The best-views mean of the neighbours' NCC per pixel, quantized to 8 bits (q / 127.5 − 1).
cv::Mat BestViewsScore(const std::vector<cv::Mat>& ncc, int views) {
  const int h = ncc.front().rows, w = ncc.front().cols;
  cv::Mat quantized(h, w, CV_8U);
  std::vector<const float*> rows(ncc.size());
  std::vector<float> best(views);
  for (int v = 0; v < h; ++v) {
    for (std::size_t j = 0; j < ncc.size(); ++j) rows[j] = ncc[j].ptr<float>(v);
    uchar* out = quantized.ptr<uchar>(v);
    for (int u = 0; u < w; ++u) {
      std::fill(best.begin(), best.end(), -1.0f);
      for (const float* row : rows) {  // insertion into the sorted best `views`
        float value = row[u];
        for (int k = 0; k < views && value > -1.0f; ++k)
          if (value > best[k]) std::swap(value, best[k]);
      }
      float score = 0;
      for (int k = 0; k < views; ++k) score += best[k];
      out[u] = static_cast<uchar>(std::lround((std::clamp(score / views, -1.0f, 1.0f) + 1.0f) * 127.5f));
    }
  }
  return quantized;
}

// The box of the pixels to measure (inside the volume, and `known` when given), grown by
// the NCC window's radius plus one and then out to nodes of the whole image's map grid
// (kGridStep): every window of a measured pixel lies inside it and the maps are
// interpolated between the same nodes, so the sweep on the box gives those pixels exactly
// what it gives on the whole image.
cv::Rect MeasuredBox(const ReferenceRays& rays, const cv::Mat& known, int window_radius) {
  cv::Mat measured = rays.q_near >= 0;
  if (!known.empty()) measured &= known != 0;
  const cv::Rect box = cv::boundingRect(measured);
  if (box.empty()) return box;
  const int grow = window_radius + 1, w = rays.x.cols, h = rays.x.rows;
  const auto node_below = [](int i) { return std::max(0, i) / kGridStep * kGridStep; };
  const auto node_above = [](int i, int last) { return std::min(last, (i + kGridStep - 1) / kGridStep * kGridStep); };
  const int u0 = node_below(box.x - grow), v0 = node_below(box.y - grow);
  const int u1 = node_above(box.x + box.width - 1 + grow, w - 1), v1 = node_above(box.y + box.height - 1 + grow, h - 1);
  return cv::Rect(u0, v0, u1 - u0 + 1, v1 - v0 + 1);
}

// `rays` restricted to `box` (views, no copies; q_min / q_max kept).
ReferenceRays Crop(const ReferenceRays& rays, const cv::Rect& box) {
  ReferenceRays cropped = rays;
  cropped.x = rays.x(box), cropped.y = rays.y(box), cropped.q_near = rays.q_near(box), cropped.q_far = rays.q_far(box);
  return cropped;
}

DepthMap SweepOne(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray, const Bounds& bounds,
                  const PlaneSweepOptions& options, const cv::Mat& known, int r) {
  Stopwatch start;
  DepthMap result;
  const Camera& camera = cameras[r];
  const int h = camera.height(), w = camera.width();
  result.inverse_depth = cv::Mat(h, w, CV_32F, cv::Scalar(kNotSwept));
  result.score = cv::Mat(h, w, CV_32F, cv::Scalar(kNone));
  result.neighbours = ChooseNeighbours(cameras, r, options);
  const ReferenceRays all_rays = TraceRays(camera, bounds);
  if (result.neighbours.empty() || !(all_rays.q_min < all_rays.q_max)) return result;
  result.inverse_depth.setTo(kNoDepth, all_rays.q_near >= 0);
  std::vector<RayTransfer> transfers;
  for (int j : result.neighbours) transfers.emplace_back(camera, cameras[j]);
  const double q_low = options.sweep_beyond_volume ? 0.0 : all_rays.q_min, q_high = all_rays.q_max;
  const int planes = CountPlanes(all_rays, transfers, q_low, q_high, options);
  result.planes = planes;
  result.inverse_depth_step = (q_high - q_low) / (planes - 1);
  const int views = std::min<int>(options.consistent_views, transfers.size());

  // Everything below works on the box of the pixels measured.
  const cv::Rect box = MeasuredBox(all_rays, known, options.window_radius);
  if (box.empty()) {
    result.seconds = start.Seconds();
    return result;
  }
  const ReferenceRays rays = Crop(all_rays, box);
  std::vector<NeighbourGrid> grids;
  for (const RayTransfer& transfer : transfers) grids.push_back(MakeGrid(rays, transfer));
  const ReferenceStatistics full = MakeStatistics(gray[r], options);
  const ReferenceStatistics reference{full.image(box), full.mean(box), full.variance(box)};

  // Scores of every plane (8 bits), kept for the uniqueness test.
  std::vector<cv::Mat> volume(planes);
  std::vector<cv::Mat> ncc(transfers.size());
  const auto plane_q = [&](int i) { return q_low + result.inverse_depth_step * i; };
  for (int i = 0; i < planes; ++i) {
    for (std::size_t j = 0; j < transfers.size(); ++j)
      ncc[j] = PlaneNcc(reference, rays, grids[j], gray[result.neighbours[j]], plane_q(i), options);
    volume[i] = BestViewsScore(ncc, views);
  }

  // Best plane, uniqueness, texture, known.
  const auto decode = [](uchar q) { return q / 127.5f - 1.0f; };
  std::vector<uchar> scores(planes);
  for (int v = 0; v < box.height; ++v)
    for (int u = 0; u < box.width; ++u) {
      const int image_u = box.x + u, image_v = box.y + v;
      if (rays.q_near.at<float>(v, u) < 0) continue;
      if (!known.empty() && !known.at<uchar>(image_v, image_u)) continue;
      if (std::sqrt(reference.variance.at<float>(v, u)) < options.min_texture) continue;
      int best = -1;
      uchar best_q = 0;
      for (int i = 0; i < planes; ++i) {
        scores[i] = volume[i].at<uchar>(v, u);
        if (scores[i] > best_q) best_q = scores[i], best = i;
      }
      if (best < 0) continue;
      const float best_score = decode(best_q);
      if (best_score < options.min_score) continue;
      uchar rival_q = 0;
      for (int i = 0; i < planes; ++i)
        if (std::abs(i - best) > options.uniqueness_planes) rival_q = std::max(rival_q, scores[i]);
      if (best_score - decode(rival_q) < options.uniqueness_margin) continue;
      result.inverse_depth.at<float>(image_v, image_u) = static_cast<float>(plane_q(best));
      result.score.at<float>(image_v, image_u) = best_score;
      ++result.pixels_with_depth;
    }
  result.seconds = start.Seconds();
  return result;
}

}  // namespace

PlaneHypothesis ScorePlane(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray, int r,
                           const std::vector<int>& neighbours, const Eigen::Vector3d& normal, double offset,
                           const PlaneSweepOptions& options) {
  const Camera& camera = cameras[r];
  PlaneHypothesis result;
  const int h = camera.height(), w = camera.width();
  result.inverse_depth = cv::Mat(h, w, CV_32F, cv::Scalar(kNone));
  result.score = cv::Mat(h, w, CV_32F, cv::Scalar(kNone));
  if (neighbours.empty()) return result;
  // n·(C + z Rᵀ ray) + d = 0  ⇒  q = 1/z = −(n·Rᵀ ray) / (n·C + d).
  const Eigen::Vector3d n_camera = camera.R() * normal;
  const double height = normal.dot(camera.Center()) + offset;
  if (std::abs(height) < 1e-12) return result;  // the camera lies on the plane
  const auto q_of_ray = [&](const Eigen::Vector3d& ray) { return -n_camera.dot(ray) / height; };
  const ReferenceRays rays = PixelRays(camera);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const double q = q_of_ray(Eigen::Vector3d(rays.x.at<float>(v, u), rays.y.at<float>(v, u), 1));
      if (q > 0) result.inverse_depth.at<float>(v, u) = static_cast<float>(q);
    }
  const ReferenceStatistics reference = MakeStatistics(gray[r], options);
  std::vector<cv::Mat> ncc;
  for (int j : neighbours) {
    const NeighbourGrid grid = MakeGrid(rays, RayTransfer(camera, cameras[j]));
    cv::Mat map_x(h, w, CV_32F), map_y(h, w, CV_32F);
    SurfaceMap(grid, q_of_ray, &map_x, &map_y);
    const cv::Mat valid = ValidSamples(map_x, map_y, cameras[j],
                                       [&](int u, int v) { return result.inverse_depth.at<float>(v, u) > 0; });
    ncc.push_back(WarpNcc(reference, gray[j], map_x, map_y, valid, options));
  }
  const cv::Mat quantized = BestViewsScore(ncc, std::min<int>(options.consistent_views, ncc.size()));
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      if (result.inverse_depth.at<float>(v, u) > 0 && std::sqrt(reference.variance.at<float>(v, u)) >= options.min_texture)
        result.score.at<float>(v, u) = quantized.at<uchar>(v, u) / 127.5f - 1.0f;
  return result;
}

void PlaneSweepOptions::Check() const {
  const std::string source = "plane sweep options";
  if (neighbours < 1 || neighbours > 64) ThrowError(source, "neighbours", "expected 1..64");
  if (!(max_neighbour_degrees > 0 && max_neighbour_degrees <= 180))
    ThrowError(source, "max_neighbour_degrees", "expected a value in (0, 180]");
  if (consistent_views < 1 || consistent_views > neighbours)
    ThrowError(source, "consistent_views", "expected 1..neighbours");
  if (window_radius < 1 || window_radius > 15) ThrowError(source, "window_radius", "expected 1..15");
  if (!(max_step_pixels > 0.05 && max_step_pixels <= 20)) ThrowError(source, "max_step_pixels", "expected (0.05, 20]");
  if (max_planes < 2 || max_planes > 4096) ThrowError(source, "max_planes", "expected 2..4096");
  if (!(min_score > -1 && min_score < 1)) ThrowError(source, "min_score", "expected a value in (−1, 1)");
  if (!(min_texture >= 0 && min_texture < 1)) ThrowError(source, "min_texture", "expected a value in [0, 1)");
  if (!(uniqueness_margin >= 0 && uniqueness_margin < 2))
    ThrowError(source, "uniqueness_margin", "expected a value in [0, 2)");
  if (uniqueness_planes < 0) ThrowError(source, "uniqueness_planes", "expected ≥ 0");
  if (threads < 0) ThrowError(source, "threads", "expected ≥ 0 (0 = all available)");
}

Eigen::Vector3d PointAtDepth(const Camera& camera, const Eigen::Vector2d& pixel, double z) {
  return camera.R().transpose() * (z * NormalizedPoint(camera, pixel).homogeneous() - camera.t());
}

bool RayDepthsInBounds(const Camera& camera, const Eigen::Vector2d& pixel, const Bounds& bounds, double* z_near,
                       double* z_far) {
  return SlabDepths(camera, NormalizedPoint(camera, pixel), bounds, z_near, z_far);
}

std::vector<DepthMap> SweepDepthMaps(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                     const Bounds& bounds, const PlaneSweepOptions& options,
                                     const std::vector<cv::Mat>& known) {
  options.Check();
  if (cameras.size() < 2) ThrowError("plane sweep", "cameras", "expected at least 2 cameras");
  if (gray.size() != cameras.size()) ThrowError("plane sweep", "images", "expected one image per camera");
  if (!known.empty() && known.size() != cameras.size())
    ThrowError("plane sweep", "known", "expected one mask per camera, or none");
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    if (gray[k].type() != CV_32FC1 || gray[k].cols != cameras[k].width() || gray[k].rows != cameras[k].height())
      ThrowError("plane sweep", "image of camera " + cameras[k].name(),
                 "expected CV_32FC1 of the camera's size " + std::to_string(cameras[k].width()) + "×" +
                     std::to_string(cameras[k].height()));
    if (!known.empty() && !known[k].empty() && (known[k].type() != CV_8UC1 || known[k].size() != gray[k].size()))
      ThrowError("plane sweep", "known pixels of camera " + cameras[k].name(), "expected CV_8UC1 of the image's size");
  }
  std::vector<DepthMap> maps(cameras.size());
  const auto run = [&] {
    tbb::parallel_for(0, static_cast<int>(cameras.size()), [&](int r) {
      maps[r] = SweepOne(cameras, gray, bounds, options, known.empty() ? cv::Mat() : known[r], r);
    });
  };
  if (options.threads > 0) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, options.threads);
    run();
  } else {
    run();
  }
  return maps;
}

}  // namespace subflow::vision
