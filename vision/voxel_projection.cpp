#include "vision/voxel_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::vision {
namespace {

using geometry::ScalarVolume;

// Pixels whose centres lie inside the convex polygon (vertices in order) are set to 255.
void FillConvex(const Eigen::Vector2f* polygon, int count, cv::Mat* image) {
  float y_lo = polygon[0].y(), y_hi = polygon[0].y();
  for (int p = 1; p < count; ++p) y_lo = std::min(y_lo, polygon[p].y()), y_hi = std::max(y_hi, polygon[p].y());
  const int row_first = std::max(0, static_cast<int>(std::ceil(y_lo)));
  const int row_last = std::min(image->rows - 1, static_cast<int>(std::floor(y_hi)));
  for (int y = row_first; y <= row_last; ++y) {
    // The polygon's extent along row y: where its edges cross the row (both ends of an
    // edge lying on the row).
    float x_lo = std::numeric_limits<float>::max(), x_hi = -x_lo;
    for (int e = 0; e < count; ++e) {
      const Eigen::Vector2f& a = polygon[e];
      const Eigen::Vector2f& b = polygon[(e + 1) % count];
      if ((y < a.y() && y < b.y()) || (y > a.y() && y > b.y())) continue;
      if (a.y() == b.y()) {
        x_lo = std::min({x_lo, a.x(), b.x()});
        x_hi = std::max({x_hi, a.x(), b.x()});
      } else {
        const float x = a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        x_lo = std::min(x_lo, x);
        x_hi = std::max(x_hi, x);
      }
    }
    const int x0 = std::max(0, static_cast<int>(std::ceil(x_lo)));
    const int x1 = std::min(image->cols - 1, static_cast<int>(std::floor(x_hi)));
    if (x0 <= x1) std::fill(image->ptr<uint8_t>(y) + x0, image->ptr<uint8_t>(y) + x1 + 1, 255);
  }
}

// Convex hull of 8 points (Andrew's monotone chain) into `hull`; returns its size.
int ConvexHull(Eigen::Vector2f points[8], Eigen::Vector2f hull[16]) {
  std::sort(points, points + 8, [](const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  auto cross = [](const Eigen::Vector2f& o, const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    while (n >= 2 && cross(hull[n - 2], hull[n - 1], points[i]) <= 0) --n;
    hull[n++] = points[i];
  }
  for (int i = 6, lower = n + 1; i >= 0; --i) {
    while (n >= lower && cross(hull[n - 2], hull[n - 1], points[i]) <= 0) --n;
    hull[n++] = points[i];
  }
  return n > 1 ? n - 1 : n;
}

}  // namespace

VoxelCornerProjector::VoxelCornerProjector(const Camera& camera, const ScalarVolume& grid)
    : camera_(camera), grid_(grid), distorted_(camera.HasDistortion()) {
  const Eigen::Matrix3d KR = camera.K() * camera.R();
  h0_ = KR * Corner(0, 0, 0) + camera.K() * camera.t();
  dh_i_ = grid.spacing * KR.col(0);
  dh_j_ = grid.spacing * KR.col(1);
  dh_k_ = grid.spacing * KR.col(2);
}

Eigen::Vector3d VoxelCornerProjector::Corner(int i, int j, int k) const {
  return grid_.origin + grid_.spacing * (Eigen::Vector3d(i, j, k) - Eigen::Vector3d::Constant(0.5));
}

bool VoxelCornerProjector::ProjectCorner(int i, int j, int k, float* u, float* v) const {
  *u = *v = kInvalidPixel;
  if (!distorted_) {
    const Eigen::Vector3d h = h0_ + i * dh_i_ + j * dh_j_ + k * dh_k_;  // K's last row is (0 0 1): h.z = depth
    if (!(h.z() > 0)) return false;
    *u = static_cast<float>(h.x() / h.z());
    *v = static_cast<float>(h.y() / h.z());
    return true;
  }
  const Eigen::Vector3d X = Corner(i, j, k);
  double depth = 0;
  const Eigen::Vector2d pinhole = camera_.ProjectUndistorted(X, &depth);
  if (!(depth > 0) || !camera_.InImage(pinhole, -std::max(camera_.width(), camera_.height())))
    return false;
  const Eigen::Vector2d p = camera_.Project(X);
  *u = static_cast<float>(p.x());
  *v = static_cast<float>(p.y());
  return true;
}

GridCornerPixels ProjectGridCorners(const Camera& camera, const geometry::ScalarVolume& grid) {
  GridCornerPixels corners;
  corners.nx = grid.nx, corners.ny = grid.ny, corners.nz = grid.nz;
  const std::size_t count = corners.Index(0, 0, grid.nz + 1);
  corners.u.resize(count);
  corners.v.resize(count);
  const VoxelCornerProjector projector(camera, grid);
  tbb::parallel_for(0, grid.nz + 1, [&](int k) {
    const std::size_t first = corners.Index(0, 0, k);
    projector.ProjectCorners(0, grid.nx, 0, grid.ny, k, k, corners.u.data() + first, corners.v.data() + first);
  });
  return corners;
}

void VoxelCornerProjector::ProjectCorners(int i0, int i1, int j0, int j1, int k0, int k1, float* us,
                                          float* vs) const {
  const int row = i1 - i0 + 1;
  size_t index = 0;
  if (distorted_) {
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i, ++index) ProjectCorner(i, j, k, &us[index], &vs[index]);
    return;
  }
  const float dx = static_cast<float>(dh_i_.x()), dy = static_cast<float>(dh_i_.y()),
              dz = static_cast<float>(dh_i_.z());
  for (int k = k0; k <= k1; ++k)
    for (int j = j0; j <= j1; ++j, index += row) {
      const Eigen::Vector3d base = h0_ + i0 * dh_i_ + j * dh_j_ + k * dh_k_;
      const float bx = static_cast<float>(base.x()), by = static_cast<float>(base.y()),
                  bz = static_cast<float>(base.z());
      float* u = us + index;
      float* v = vs + index;
      for (int i = 0; i < row; ++i) {  // vectorizable: no branches
        const float hx = bx + i * dx, hy = by + i * dy, hz = bz + i * dz;
        const bool in_front = hz > 0.0f;
        const float inverse = 1.0f / (in_front ? hz : 1.0f);
        u[i] = in_front ? hx * inverse : kInvalidPixel;
        v[i] = in_front ? hy * inverse : kInvalidPixel;
      }
    }
}

bool ProjectsIntoImage(const Camera& camera, const Eigen::Vector3d& X) {
  double depth = 0;
  const Eigen::Vector2d pinhole = camera.ProjectUndistorted(X, &depth);
  if (!(depth > 0)) return false;
  if (camera.HasDistortion() && !camera.InImage(pinhole, -std::max(camera.width(), camera.height())))
    return false;
  return camera.InImage(camera.Project(X));
}

double SilhouetteIoU(const cv::Mat& a, const cv::Mat& b) {
  SUBFLOW_CHECK(a.size() == b.size() && a.type() == CV_8UC1 && b.type() == CV_8UC1,
                "SilhouetteIoU expects two CV_8UC1 images of one size");
  const int both = cv::countNonZero((a != 0) & (b != 0));
  const int either = cv::countNonZero((a != 0) | (b != 0));
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

std::vector<Eigen::Vector3i> SurfaceVoxels(const ScalarVolume& occupancy) {
  auto occupied = [&](int i, int j, int k) {
    return occupancy.InRange(i, j, k) && occupancy.at(i, j, k) > 0.5f;
  };
  std::vector<Eigen::Vector3i> surface;
  for (int k = 0; k < occupancy.nz; ++k)
    for (int j = 0; j < occupancy.ny; ++j)
      for (int i = 0; i < occupancy.nx; ++i)
        if (occupied(i, j, k) &&
            !(occupied(i - 1, j, k) && occupied(i + 1, j, k) && occupied(i, j - 1, k) && occupied(i, j + 1, k) &&
              occupied(i, j, k - 1) && occupied(i, j, k + 1)))
          surface.emplace_back(i, j, k);
  return surface;
}

cv::Mat ProjectVoxels(const Camera& camera, const ScalarVolume& grid, const std::vector<Eigen::Vector3i>& voxels) {
  cv::Mat image = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  const VoxelCornerProjector projector(camera, grid);
  Eigen::Vector2f corners[8], hull[16];
  for (const Eigen::Vector3i& voxel : voxels) {
    bool valid = true;
    for (int c = 0; c < 8 && valid; ++c)
      valid = projector.ProjectCorner(voxel.x() + (c & 1), voxel.y() + ((c >> 1) & 1), voxel.z() + (c >> 2),
                                      &corners[c].x(), &corners[c].y());
    if (!valid) continue;
    // Most surface voxels project inside what is already drawn: skip those whose
    // bounding box has every pixel centre set.
    Eigen::Vector2f lo = corners[0], hi = corners[0];
    for (int c = 1; c < 8; ++c) lo = lo.cwiseMin(corners[c]), hi = hi.cwiseMax(corners[c]);
    const int x0 = std::max(0, static_cast<int>(std::ceil(lo.x()))), x1 = std::min(image.cols - 1, static_cast<int>(std::floor(hi.x())));
    const int y0 = std::max(0, static_cast<int>(std::ceil(lo.y()))), y1 = std::min(image.rows - 1, static_cast<int>(std::floor(hi.y())));
    bool covered = x0 <= x1 && y0 <= y1;
    for (int y = y0; y <= y1 && covered; ++y) {
      const uint8_t* row = image.ptr<uint8_t>(y);
      for (int x = x0; x <= x1 && covered; ++x) covered = row[x] != 0;
    }
    if (!covered) FillConvex(hull, ConvexHull(corners, hull), &image);
  }
  return image;
}

cv::Mat ProjectOccupancy(const Camera& camera, const ScalarVolume& occupancy) {
  return ProjectVoxels(camera, occupancy, SurfaceVoxels(occupancy));
}

}  // namespace subflow::vision
