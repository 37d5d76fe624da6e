// Pictures of a surface through the project's z-buffer (vision/zbuffer.h): every covered
// pixel gets a colour (per-vertex colours interpolated with the z-buffer's barycentrics,
// or a per-pixel colour function) times a headlight shading
//   s = ambient + (1 − ambient) · |n · d|,
// n = the interpolated vertex normal, d = the unit direction from the surface point to
// the camera centre (two-sided, so open surfaces and back faces stay visible).
// Pictures are CV_8UC3 BGR; colours are sRGB in [0, 1] as Eigen (r, g, b).
#pragma once

#include <functional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "geometry/triangle_mesh.h"
#include "vision/zbuffer.h"

namespace subflow::output {

struct ShadingOptions {
  double ambient = 0.3;                          // share of light that does not depend on n · d
  cv::Scalar background = cv::Scalar(255, 255, 255);  // BGR of pixels the surface does not cover
};

// Colour of the surface point seen at pixel (x, y): world position X, unit normal n.
using PixelColour = std::function<Eigen::Vector3f(int x, int y, const Eigen::Vector3d& X, const Eigen::Vector3d& n)>;

// Shades the rendered `zbuffer` of (V, F) with unit vertex `normals` (#V×3) and
// `vertex_colours` (#V×3 sRGB).
cv::Mat ShadeVertexColours(const vision::ZBuffer& zbuffer, const geometry::Positions& V, const geometry::Faces& F,
                           const geometry::Positions& normals, const Eigen::MatrixX3f& vertex_colours,
                           const ShadingOptions& options = {});

// Same with a colour per pixel (e.g. sampled from the input images).
cv::Mat ShadePixelColours(const vision::ZBuffer& zbuffer, const geometry::Positions& V, const geometry::Faces& F,
                          const geometry::Positions& normals, const PixelColour& colour,
                          const ShadingOptions& options = {});

// The outline of the covered region: pixels covered whose 4-neighbourhood has an empty
// pixel or the image border (CV_8UC1, 255 on the outline).
cv::Mat SurfaceOutline(const vision::ZBuffer& zbuffer);

}  // namespace subflow::output
