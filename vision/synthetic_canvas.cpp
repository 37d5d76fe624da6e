#include "vision/synthetic_canvas.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"
#include "vision/camera_rig.h"

namespace subflow::vision {

SampleCanvas::SampleCanvas(const Camera& camera, int factor)
    : camera_(camera), factor_(factor), distorted_(camera.HasDistortion()) {
  SUBFLOW_CHECK(factor >= 1, "canvas factor ≥ 1");
  if (!distorted_) {
    canvas_ = SupersampledCamera(camera, factor);
    return;
  }
  const int W = camera.width(), H = camera.height();
  corners_.resize(static_cast<std::size_t>(W + 1) * (H + 1));
  Eigen::Vector2d low = Eigen::Vector2d::Constant(1e300), high = -low;
  for (int y = 0; y <= H; ++y) {
    for (int x = 0; x <= W; ++x) {
      const Eigen::Vector3d ray = camera.BackProject({x - 0.5, y - 0.5});
      const Eigen::Vector2d u = camera.ProjectUndistorted(camera.Center() + ray);
      corners_[static_cast<std::size_t>(y) * (W + 1) + x] = u;
      low = low.cwiseMin(u);
      high = high.cwiseMax(u);
    }
  }
  u0_ = (low.array().floor() - 1.0).matrix();
  const Eigen::Vector2d extent = high - u0_;
  const int width = static_cast<int>(std::ceil(factor * extent.x())) + 2;
  const int height = static_cast<int>(std::ceil(factor * extent.y())) + 2;
  if (width > 4 * factor * W || height > 4 * factor * H)
    ThrowError("camera " + camera.name(), "distortion", "undistorts the image to more than 4x its size");
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = S(1, 1) = factor;
  S(0, 2) = -factor * u0_.x();
  S(1, 2) = -factor * u0_.y();
  canvas_ = Camera(camera.name(), width, height, S * camera.K(), camera.R(), camera.t());
}

void SampleCanvas::Render(const geometry::Positions& V, const geometry::Faces& F, const ZBufferOptions& options) {
  zbuffer_.Render(canvas_, V, F, options);
}

Eigen::Vector2d SampleCanvas::Undistorted(double px, double py) const {
  const int W = camera_.width();
  const double gx = std::clamp(px + 0.5, 0.0, static_cast<double>(W) - 1e-9);
  const double gy = std::clamp(py + 0.5, 0.0, static_cast<double>(camera_.height()) - 1e-9);
  const int x = static_cast<int>(gx), y = static_cast<int>(gy);
  const double fx = gx - x, fy = gy - y;
  auto at = [&](int i, int j) { return corners_[static_cast<std::size_t>(j) * (W + 1) + i]; };
  return (1 - fy) * ((1 - fx) * at(x, y) + fx * at(x + 1, y)) + fy * ((1 - fx) * at(x, y + 1) + fx * at(x + 1, y + 1));
}

CanvasHit SampleCanvas::Hit(int x, int y, int i, int j, const geometry::Positions& V,
                            const geometry::Faces& F) const {
  CanvasHit hit;
  const int s = factor_;
  if (!distorted_) {
    const int fx = s * x + i, fy = s * y + j;
    hit.face = zbuffer_.Face(fx, fy);
    if (hit.face >= 0) {
      const Eigen::Vector2f uv = zbuffer_.Barycentric(fx, fy);
      hit.w1 = uv.x();
      hit.w2 = uv.y();
    }
    return hit;
  }
  const Eigen::Vector2d u = Undistorted((s * x + i + 0.5) / s - 0.5, (s * y + j + 0.5) / s - 0.5);
  const int ci = static_cast<int>(std::lround(s * (u.x() - u0_.x())));
  const int cj = static_cast<int>(std::lround(s * (u.y() - u0_.y())));
  if (ci < 0 || cj < 0 || ci >= canvas_.width() || cj >= canvas_.height()) return hit;
  const int face = zbuffer_.Face(ci, cj);
  if (face < 0) return hit;
  // Möller–Trumbore on the face's plane (no inside test: the z-buffer chose the face).
  const Eigen::Vector3d origin = camera_.Center(), direction = camera_.BackProjectUndistorted(u);
  const Eigen::Vector3d a = V.row(F(face, 0)), b = V.row(F(face, 1)), c = V.row(F(face, 2));
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return hit;
  const Eigen::Vector3d t = origin - a, q = t.cross(e1);
  hit.face = face;
  hit.w1 = t.dot(p) / det;
  hit.w2 = direction.dot(q) / det;
  return hit;
}

}  // namespace subflow::vision
