// Which points of the true surface the cameras see, for observed-surface scoring
// (vision/evaluation.h).
//
// A point X on the true mesh is seen by camera c when ZBuffer::IsVisible(X, tolerance) on
// the z-buffer of the true mesh in c: it projects inside the image (undistorted pinhole;
// lens distortion changes which pixels are inside the image only near the borders) and
// lies no more than `tolerance` behind the nearest surface there. Its view count is the
// number of cameras that see it.
// Pixel footprint of X in camera c: depth / f̄ (f̄ = (fx + fy)/2) — the side of the square
// that one pixel covers on a plane facing the camera at X's depth (world units per pixel).
#pragma once

#include <vector>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/zbuffer.h"

namespace subflow::vision {

class SurfaceVisibility {
 public:
  // Renders `truth` into every camera (in parallel).
  SurfaceVisibility(const std::vector<Camera>& cameras, const geometry::TriangleMesh& truth, double tolerance);

  // View count of every row of `points` (#P×3). When `footprints` is given, it receives
  // each point's pixel footprint averaged over the cameras that see it (0 when none does).
  std::vector<int> ViewCounts(const geometry::Positions& points, std::vector<double>* footprints = nullptr) const;

 private:
  std::vector<Camera> cameras_;
  std::vector<ZBuffer> zbuffers_;
  double tolerance_;
};

}  // namespace subflow::vision
