#include "vision/zbuffer.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::vision {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// A vertex of a (possibly clipped) triangle on screen: pixel position, 1 / depth, and its
// barycentric weights (w0, w1, w2) with respect to the original mesh triangle.
struct ScreenVertex {
  Eigen::Vector2d pixel;
  double inverse_depth = 0.0;
  Eigen::Vector3d weights;
};

// Lexicographic order of screen points: orders the two ends of an edge the same way in
// both triangles that share it.
bool ScreenLess(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
}

// The edge function of a→b, E(p) = (b − a) × (p − a), written E = A x + B y + C with
// A, B, C computed from the canonical (lexicographically smaller) end: the edge b→a of
// the neighbouring triangle gets exactly −A, −B, −C, and since rounding is symmetric
// it gets exactly −E at every pixel. So a shared edge's pixel centres are claimed once.
struct Edge {
  double A = 0.0, B = 0.0, C = 0.0;
  bool owns_ties = false;  // a centre with E = 0 is inside (one of the two directions)

  Edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const bool forward = ScreenLess(a, b);
    const Eigen::Vector2d& origin = forward ? a : b;
    const Eigen::Vector2d direction = forward ? Eigen::Vector2d(b - a) : Eigen::Vector2d(a - b);
    const double sign = forward ? 1.0 : -1.0;
    A = -sign * direction.y();
    B = sign * direction.x();
    C = sign * (direction.y() * origin.x() - direction.x() * origin.y());
    const Eigen::Vector2d d = b - a;
    owns_ties = d.y() > 0.0 || (d.y() == 0.0 && d.x() < 0.0);
  }
  bool Inside(double e) const { return owns_ties ? !(e < 0.0) : e > 0.0; }
};

}  // namespace

// Draws screen triangles into a ZBuffer (a friend, to write its buffers directly).
class TriangleRasterizer {
 public:
  TriangleRasterizer(ZBuffer& zbuffer, const ZBufferOptions& options)
      : zbuffer_(zbuffer), cull_back_faces_(options.cull_back_faces), depth_only_(options.depth_only) {}

  void Draw(const ScreenVertex& a, const ScreenVertex& b_in, const ScreenVertex& c_in, int face) {
    const double area = (b_in.pixel - a.pixel).x() * (c_in.pixel - a.pixel).y() -
                        (b_in.pixel - a.pixel).y() * (c_in.pixel - a.pixel).x();
    if (!(area != 0.0) || !std::isfinite(area)) return;
    // In pixel coordinates (y down) a triangle counter-clockwise seen from the camera
    // has negative area.
    if (cull_back_faces_ && area > 0.0) return;
    // Orient so that the area is positive: inside ⇔ all three edge functions ≥ 0.
    const ScreenVertex& b = area > 0.0 ? b_in : c_in;
    const ScreenVertex& c = area > 0.0 ? c_in : b_in;
    const ScreenVertex* v[3] = {&a, &b, &c};

    const int width = zbuffer_.width_, height = zbuffer_.height_;
    const double min_x = std::min({a.pixel.x(), b.pixel.x(), c.pixel.x()});
    const double max_x = std::max({a.pixel.x(), b.pixel.x(), c.pixel.x()});
    const double min_y = std::min({a.pixel.y(), b.pixel.y(), c.pixel.y()});
    const double max_y = std::max({a.pixel.y(), b.pixel.y(), c.pixel.y()});
    const int x0 = static_cast<int>(std::ceil(std::max(min_x, 0.0)));
    const int x1 = static_cast<int>(std::floor(std::min(max_x, width - 1.0)));
    const int y0 = static_cast<int>(std::ceil(std::max(min_y, 0.0)));
    const int y1 = static_cast<int>(std::floor(std::min(max_y, height - 1.0)));
    if (x0 > x1 || y0 > y1) return;

    // Edge k is opposite vertex k: E_k = 2 area · (screen barycentric of vertex k).
    const Edge edges[3] = {Edge(b.pixel, c.pixel), Edge(c.pixel, a.pixel), Edge(a.pixel, b.pixel)};
    const double twice_area = std::abs(area);
    // Unclipped triangles (corner weights = unit vectors): (u, v) are the weights of the
    // vertices that came in second and third.
    const bool corner_weights = a.weights == Eigen::Vector3d::UnitX() &&
                                b_in.weights == Eigen::Vector3d::UnitY() &&
                                c_in.weights == Eigen::Vector3d::UnitZ();
    const bool swapped = area < 0.0;
    for (int y = y0; y <= y1; ++y) {
      const double row[3] = {edges[0].B * y + edges[0].C, edges[1].B * y + edges[1].C,
                             edges[2].B * y + edges[2].C};
      for (int x = x0; x <= x1; ++x) {
        const double e0 = edges[0].A * x + row[0];
        if (!edges[0].Inside(e0)) continue;
        const double e1 = edges[1].A * x + row[1];
        if (!edges[1].Inside(e1)) continue;
        const double e2 = edges[2].A * x + row[2];
        if (!edges[2].Inside(e2)) continue;
        // Perspective-correct: 1/z and the 3D barycentrics are the screen barycentrics
        // λ_k = E_k / 2A weighted by 1/z_k: 1/z = Σ λ_k/z_k, b_k = (λ_k/z_k) · z.
        const double w0 = e0 * v[0]->inverse_depth, w1 = e1 * v[1]->inverse_depth,
                     w2 = e2 * v[2]->inverse_depth;
        const double s = w0 + w1 + w2;
        if (!(s > 0.0)) continue;
        const double depth = twice_area / s;
        const std::size_t index = zbuffer_.Index(x, y);
        if (!(depth < zbuffer_.depth_[index])) continue;
        zbuffer_.depth_[index] = static_cast<float>(depth);
        if (depth_only_) continue;
        zbuffer_.face_[index] = face;
        const double inverse_s = 1.0 / s;
        if (corner_weights) {
          zbuffer_.barycentric_[2 * index] = static_cast<float>((swapped ? w2 : w1) * inverse_s);
          zbuffer_.barycentric_[2 * index + 1] = static_cast<float>((swapped ? w1 : w2) * inverse_s);
        } else {
          const Eigen::Vector3d weights = (w0 * a.weights + w1 * b.weights + w2 * c.weights) * inverse_s;
          zbuffer_.barycentric_[2 * index] = static_cast<float>(weights.y());
          zbuffer_.barycentric_[2 * index + 1] = static_cast<float>(weights.z());
        }
      }
    }
  }

 private:
  ZBuffer& zbuffer_;
  bool cull_back_faces_, depth_only_;
};

void ZBufferOptions::Check() const {
  if (!(near > 0.0) || !std::isfinite(near))
    ThrowError("ZBufferOptions", "near", "expected a finite positive distance, got " +
                                             std::to_string(near));
}

ZBuffer::ZBuffer(const Camera& camera, const geometry::Positions& V, const geometry::Faces& F,
                 const ZBufferOptions& options) {
  Render(camera, V, F, options);
}

void ZBuffer::Render(const Camera& camera, const geometry::Positions& V,
                     const geometry::Faces& F, const ZBufferOptions& options) {
  options.Check();
  if (F.size() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= V.rows()))
    ThrowError("ZBuffer", "faces", "vertex index out of range [0, " + std::to_string(V.rows()) + ")");
  camera_ = camera;
  near_ = options.near;
  width_ = camera.width();
  height_ = camera.height();
  const std::size_t pixel_count = static_cast<std::size_t>(width_) * height_;
  depth_.assign(pixel_count, kInfinity);
  face_.assign(options.depth_only ? 0 : pixel_count, -1);
  barycentric_.assign(options.depth_only ? 0 : 2 * pixel_count, 0.0f);

  const Eigen::Matrix3d& K = camera.K();
  const Eigen::Matrix3d& R = camera.R();
  const Eigen::Vector3d& t = camera.t();
  auto to_pixel = [&K](const Eigen::Vector3d& Xc) {
    const double x = Xc.x() / Xc.z(), y = Xc.y() / Xc.z();
    return Eigen::Vector2d(K(0, 0) * x + K(0, 1) * y + K(0, 2), K(1, 1) * y + K(1, 2));
  };
  camera_points_.resize(static_cast<std::size_t>(V.rows()));
  pixels_.resize(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    camera_points_[i] = R * V.row(i).transpose() + t;
    if (camera_points_[i].z() >= near_) pixels_[i] = to_pixel(camera_points_[i]);
  }

  TriangleRasterizer rasterizer(*this, options);
  ScreenVertex corner[3];
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int index[3] = {F(f, 0), F(f, 1), F(f, 2)};
    int in_front = 0;
    for (int k = 0; k < 3; ++k) in_front += camera_points_[index[k]].z() >= near_ ? 1 : 0;
    if (in_front == 0) continue;
    if (in_front == 3) {
      for (int k = 0; k < 3; ++k) {
        corner[k].pixel = pixels_[index[k]];
        corner[k].inverse_depth = 1.0 / camera_points_[index[k]].z();
        corner[k].weights = Eigen::Vector3d::Unit(k);
      }
      rasterizer.Draw(corner[0], corner[1], corner[2], static_cast<int>(f));
      continue;
    }
    // Clip the triangle against z = near (Sutherland–Hodgman, one plane): 3 or 4 vertices.
    ScreenVertex polygon[4];
    int count = 0;
    auto add = [&](const Eigen::Vector3d& Xc, const Eigen::Vector3d& weights) {
      polygon[count].pixel = to_pixel(Xc);
      polygon[count].inverse_depth = 1.0 / Xc.z();
      polygon[count].weights = weights;
      ++count;
    };
    for (int k = 0; k < 3; ++k) {
      const int j = (k + 1) % 3;
      const Eigen::Vector3d& Xk = camera_points_[index[k]];
      const Eigen::Vector3d& Xj = camera_points_[index[j]];
      const bool k_in = Xk.z() >= near_, j_in = Xj.z() >= near_;
      if (k_in) add(Xk, Eigen::Vector3d::Unit(k));
      if (k_in != j_in) {
        // Interpolate from the lower vertex index so both faces of the edge agree.
        const bool k_first = index[k] < index[j];
        const int p = k_first ? k : j, q = k_first ? j : k;
        const Eigen::Vector3d& Xp = camera_points_[index[p]];
        const Eigen::Vector3d& Xq = camera_points_[index[q]];
        const double s = (near_ - Xp.z()) / (Xq.z() - Xp.z());
        Eigen::Vector3d Xc = Xp + s * (Xq - Xp);
        Xc.z() = near_;
        add(Xc, (1.0 - s) * Eigen::Vector3d::Unit(p) + s * Eigen::Vector3d::Unit(q));
      }
    }
    for (int k = 1; k + 1 < count; ++k)
      rasterizer.Draw(polygon[0], polygon[k], polygon[k + 1], static_cast<int>(f));
  }
}

Eigen::Vector3d ZBuffer::SurfacePoint(int x, int y, const geometry::Positions& V,
                                      const geometry::Faces& F) const {
  const int f = Face(x, y);
  SUBFLOW_CHECK(f >= 0 && f < F.rows(), "SurfacePoint needs a covered pixel of this mesh");
  const Eigen::Vector2f uv = Barycentric(x, y);
  return (1.0 - uv.x() - uv.y()) * V.row(F(f, 0)).transpose() +
         uv.x() * V.row(F(f, 1)).transpose() + uv.y() * V.row(F(f, 2)).transpose();
}

cv::Mat ZBuffer::Mask() const {
  cv::Mat mask(height_, width_, CV_8UC1);
  for (int y = 0; y < height_; ++y) {
    auto* row = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < width_; ++x) row[x] = Covered(x, y) ? 255 : 0;
  }
  return mask;
}

int ZBuffer::CoveredPixelCount() const {
  return static_cast<int>(std::count_if(depth_.begin(), depth_.end(), [](float d) { return d < kInfinity; }));
}

bool ZBuffer::IsVisible(const Eigen::Vector3d& X, double depth_tolerance) const {
  const Eigen::Vector3d Xc = camera_.R() * X + camera_.t();
  if (!(Xc.z() >= near_)) return false;
  const Eigen::Matrix3d& K = camera_.K();
  const double u = K(0, 0) * Xc.x() / Xc.z() + K(0, 1) * Xc.y() / Xc.z() + K(0, 2);
  const double v = K(1, 1) * Xc.y() / Xc.z() + K(1, 2);
  if (!(u >= -0.5 && v >= -0.5 && u < width_ - 0.5 && v < height_ - 0.5)) return false;
  const double fu = std::floor(u), fv = std::floor(v);
  const double au = u - fu, av = v - fv;
  const int x0 = static_cast<int>(fu), y0 = static_cast<int>(fv);
  double inverse_depth = 0.0;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const int x = std::clamp(x0 + i, 0, width_ - 1), y = std::clamp(y0 + j, 0, height_ - 1);
      const double weight = (i ? au : 1.0 - au) * (j ? av : 1.0 - av);
      inverse_depth += weight / static_cast<double>(Depth(x, y));  // 1/inf = 0
    }
  }
  if (!(inverse_depth > 0.0)) return true;
  return Xc.z() <= 1.0 / inverse_depth + depth_tolerance;
}

std::vector<std::uint8_t> ZBuffer::VisibleSamples(const geometry::Positions& points,
                                                  double depth_tolerance) const {
  std::vector<std::uint8_t> visible(static_cast<std::size_t>(points.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    visible[i] = IsVisible(points.row(i).transpose(), depth_tolerance) ? 1 : 0;
  return visible;
}

std::vector<ZBuffer> RenderZBuffers(const std::vector<Camera>& cameras,
                                    const geometry::Positions& V, const geometry::Faces& F,
                                    const ZBufferOptions& options) {
  std::vector<ZBuffer> buffers(cameras.size());
  tbb::parallel_for(std::size_t{0}, cameras.size(),
                    [&](std::size_t c) { buffers[c].Render(cameras[c], V, F, options); });
  return buffers;
}

}  // namespace subflow::vision
