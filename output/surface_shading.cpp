#include "output/surface_shading.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace subflow::output {
namespace {

// Interpolated unit normal and shading factor at a covered pixel.
double ShadingAt(const vision::ZBuffer& zbuffer, int x, int y, const geometry::Positions& V,
                 const geometry::Faces& F, const geometry::Positions& normals, double ambient,
                 Eigen::Vector3d* X, Eigen::Vector3d* n) {
  const int f = zbuffer.Face(x, y);
  const Eigen::Vector2f uv = zbuffer.Barycentric(x, y);
  const double w[3] = {1.0 - uv.x() - uv.y(), uv.x(), uv.y()};
  *X = Eigen::Vector3d::Zero();
  *n = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    *X += w[k] * V.row(F(f, k)).transpose();
    *n += w[k] * normals.row(F(f, k)).transpose();
  }
  if (n->norm() > 0) n->normalize();
  const Eigen::Vector3d to_camera = (zbuffer.camera().Center() - *X).normalized();
  return ambient + (1.0 - ambient) * std::abs(n->dot(to_camera));
}

cv::Mat Shade(const vision::ZBuffer& zbuffer, const geometry::Positions& V, const geometry::Faces& F,
              const geometry::Positions& normals, const PixelColour& colour, const ShadingOptions& options) {
  cv::Mat picture(zbuffer.height(), zbuffer.width(), CV_8UC3, options.background);
  for (int y = 0; y < zbuffer.height(); ++y)
    for (int x = 0; x < zbuffer.width(); ++x) {
      if (!zbuffer.Covered(x, y)) continue;
      Eigen::Vector3d X, n;
      const double s = ShadingAt(zbuffer, x, y, V, F, normals, options.ambient, &X, &n);
      const Eigen::Vector3f rgb = colour(x, y, X, n);
      cv::Vec3b& pixel = picture.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c)
        pixel[2 - c] = static_cast<std::uint8_t>(std::clamp(std::lround(255.0 * s * rgb[c]), 0L, 255L));
    }
  return picture;
}

}  // namespace

cv::Mat ShadeVertexColours(const vision::ZBuffer& zbuffer, const geometry::Positions& V, const geometry::Faces& F,
                           const geometry::Positions& normals, const Eigen::MatrixX3f& vertex_colours,
                           const ShadingOptions& options) {
  return Shade(zbuffer, V, F, normals,
               [&](int x, int y, const Eigen::Vector3d&, const Eigen::Vector3d&) {
                 const int f = zbuffer.Face(x, y);
                 const Eigen::Vector2f uv = zbuffer.Barycentric(x, y);
                 return Eigen::Vector3f((1.0f - uv.x() - uv.y()) * vertex_colours.row(F(f, 0)) +
                                        uv.x() * vertex_colours.row(F(f, 1)) + uv.y() * vertex_colours.row(F(f, 2)));
               },
               options);
}

cv::Mat ShadePixelColours(const vision::ZBuffer& zbuffer, const geometry::Positions& V, const geometry::Faces& F,
                          const geometry::Positions& normals, const PixelColour& colour,
                          const ShadingOptions& options) {
  return Shade(zbuffer, V, F, normals, colour, options);
}

cv::Mat SurfaceOutline(const vision::ZBuffer& zbuffer) {
  const cv::Mat mask = zbuffer.Mask();
  cv::Mat eroded;
  cv::erode(mask, eroded, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)), cv::Point(-1, -1), 1,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  return mask - eroded;
}

}  // namespace subflow::output
