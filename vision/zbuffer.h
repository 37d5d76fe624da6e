// Z-buffer rasterization of a triangle mesh into a camera: per pixel the nearest surface
// point's depth, face and barycentric coordinates. The same buffers serve visibility in
// the reconstruction and the synthetic renderer.
//
// Conventions
//   Projection: the undistorted pinhole K [R | t] of vision/camera.h (ProjectUndistorted);
//   lens distortion, if the camera has one, is ignored (work on undistorted images).
//   Pixel (x, y) samples the image point (x, y): pixel (0, 0) is the centre of the
//   top-left pixel (../shared/DATASET.md). A pixel is covered by a triangle when its
//   centre lies inside the projected triangle; a centre exactly on an edge shared by two
//   triangles is given to exactly one of them (a tie rule on the edge's direction), so a
//   closed surface has no cracks and no double coverage.
//   Depth = camera z (Xc.z of Xc = R X + t), +inf where empty; face = row of F, −1 where
//   empty; barycentric (u, v) of the 3D surface point (perspective-correct):
//     X = (1 − u − v)·V[F(f,0)] + u·V[F(f,1)] + v·V[F(f,2)].
//   Triangles are clipped against the near plane z = near; nothing behind it is drawn.
//   Buffers are row-major: index = y·width + x.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::vision {

struct ZBufferOptions {
  // Near clipping plane, camera z in world units: geometry with z < near is not drawn.
  double near = 1e-4;
  // Skip triangles seen from behind (clockwise on screen for F counter-clockwise from
  // outside). Only for closed meshes seen from outside, where it changes nothing but speed.
  bool cull_back_faces = false;
  // Depth only (visibility tests): faces and barycentrics are not kept, so Face,
  // Barycentric and SurfacePoint must not be called; Covered, Mask, Depth and IsVisible
  // work as always. A quarter of the memory to clear and write per render.
  bool depth_only = false;

  void Check() const;  // throws subflow::Error on nonsense (near ≤ 0, not finite)
};

class ZBuffer {
 public:
  ZBuffer() = default;
  // Renders (V, F) into `camera` (V #V×3 world positions, F #F×3 vertex indices).
  // Throws subflow::Error when F indexes a vertex out of range.
  ZBuffer(const Camera& camera, const geometry::Positions& V, const geometry::Faces& F,
          const ZBufferOptions& options = {});
  // Same, reusing this buffer's memory.
  void Render(const Camera& camera, const geometry::Positions& V, const geometry::Faces& F,
              const ZBufferOptions& options = {});

  const Camera& camera() const { return camera_; }
  int width() const { return width_; }
  int height() const { return height_; }

  float Depth(int x, int y) const { return depth_[Index(x, y)]; }
  int Face(int x, int y) const { return face_[Index(x, y)]; }
  bool Covered(int x, int y) const { return depth_[Index(x, y)] < std::numeric_limits<float>::infinity(); }
  Eigen::Vector2f Barycentric(int x, int y) const {
    const std::size_t i = Index(x, y);
    return {barycentric_[2 * i], barycentric_[2 * i + 1]};
  }
  // World position of the surface point seen at a covered pixel (from V, F of the render).
  Eigen::Vector3d SurfacePoint(int x, int y, const geometry::Positions& V,
                               const geometry::Faces& F) const;

  // Raw buffers (row-major, width·height entries; barycentrics 2 per pixel: u, v; faces
  // and barycentrics empty after a depth-only render).
  const std::vector<float>& depth() const { return depth_; }
  const std::vector<int>& faces() const { return face_; }
  const std::vector<float>& barycentrics() const { return barycentric_; }

  cv::Mat Mask() const;        // CV_8UC1 silhouette: 255 where covered, else 0
  int CoveredPixelCount() const;

  // Whether world point X is seen by the camera: it lies in front of the near plane,
  // projects (undistorted) to an image point (u, v) inside the image
  // (−0.5 ≤ u < width − 0.5, same for v), and is not behind the surface there:
  //   z ≤ z_ref + depth_tolerance,  1/z_ref = bilinear interpolation of 1/Depth over the
  //   four pixel centres around (u, v) (empty pixels count as 1/Depth = 0).
  // 1/z is affine in image coordinates on a plane, so z_ref is exact on flat surfaces and
  // second-order accurate on curved ones; within a pixel of a silhouette the empty
  // neighbours make the test lean towards "visible". `depth_tolerance` is in world units
  // along the optical axis; use a few times the surface's sampling error.
  bool IsVisible(const Eigen::Vector3d& X, double depth_tolerance) const;
  // IsVisible for every row of `points` (#P×3): 1 = visible, 0 = not.
  std::vector<std::uint8_t> VisibleSamples(const geometry::Positions& points,
                                           double depth_tolerance) const;

 private:
  std::size_t Index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(x);
  }

  Camera camera_;
  double near_ = 1e-4;
  int width_ = 0, height_ = 0;
  std::vector<float> depth_;
  std::vector<int> face_;
  std::vector<float> barycentric_;
  // Per-vertex scratch, kept between renders.
  std::vector<Eigen::Vector3d> camera_points_;
  std::vector<Eigen::Vector2d> pixels_;

  friend class TriangleRasterizer;
};

// Renders the mesh into every camera, in parallel over cameras (TBB).
std::vector<ZBuffer> RenderZBuffers(const std::vector<Camera>& cameras,
                                    const geometry::Positions& V, const geometry::Faces& F,
                                    const ZBufferOptions& options = {});

}  // namespace subflow::vision
