// Visibility of surface samples per camera (method §4.2–4.3): the current limit surface is
// tessellated (TessellateLimitSurface of the samples' level, `tessellation_density`),
// rasterized into every camera (vision::ZBuffer), and a sample X with unit normal n is
// visible in camera k when
//   * ZBuffer::IsVisible(X, depth_tolerance): in front of the near plane, inside the image,
//     and not behind the z-buffered surface by more than the tolerance (world units along
//     the optical axis);
//   * it faces the camera at a usable angle: n · (C_k − X)/|C_k − X| ≥ min_view_cosine
//     (grazing views carry foreshortened, silhouette-contaminated gradients);
//   * its projection is at least `image_margin` pixels inside the image, so the bilinear
//     samples of the smoothed image and its gradient stay inside it.
// The tessellation's sample pattern and limit matrix are built once (the connectivity
// never changes); each frame only re-evaluates positions and re-renders.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/limit_evaluation.h"
#include "geometry/limit_tessellation.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/observation/surface_sampling.h"
#include "vision/camera.h"

namespace subflow::solver {

struct VisibilityOptions {
  // World units; 0 = automatic: half the mean edge length of the sampled level's control
  // mesh (the tessellation's chord error is far below that, a self-occluding fold far above).
  double depth_tolerance = 0.0;
  double min_view_cosine = 0.2;  // cosine of the largest accepted angle normal ↔ view ray
  double image_margin = 2.0;     // pixels kept clear of the image border
  // Z-buffer tessellation: density² triangles per face of the sampled level. 1 (the limit
  // points at the level's vertices) suffices: a flat facet of edge h on a surface of radius
  // R departs from it by h²/8R, far below the depth tolerance h/2 whenever h < 4R. Density 2
  // gave the blob's refinement the same surface to 0.4 µm (pixel 1.3 mm) at 4x the
  // rasterizing (docs/speed.md).
  int tessellation_density = 1;

  void Check() const;  // throws subflow::Error naming the field
};

struct SampleVisibility {
  // visible[k][s] = 1 when sample s is visible in camera k.
  std::vector<std::vector<std::uint8_t>> visible;
  double depth_tolerance = 0.0;  // the tolerance used (after the automatic choice)
  // Per camera asked for (VisibilityTester::Compute's coverage_of): where the surface
  // covers the image (CV_8UC1, 255 = covered, from the same z-buffer); else an empty Mat.
  std::vector<cv::Mat> coverage;

  int camera_count() const { return static_cast<int>(visible.size()); }
  // Cameras that see sample s, in camera order.
  std::vector<int> CamerasSeeing(int sample) const;
  // Number of samples seen by at least `min_cameras` cameras.
  int SamplesSeenBy(int min_cameras) const;
  // The cameras that see at least one sample of each face (the patch's camera set):
  // per face of the samples' level, camera indices in order.
  std::vector<std::vector<int>> CamerasSeeingFaces(const SurfaceSamples& samples) const;
};

class VisibilityTester {
 public:
  // Builds the tessellation of `level` and its limit matrix. Throws subflow::Error when the
  // options are invalid or the level is out of range.
  VisibilityTester(const geometry::LoopHierarchy& hierarchy, int level,
                   const VisibilityOptions& options = {});

  // Visibility of the samples (positions and unit normals #S×3, e.g. from
  // SurfaceSamples::SamplePositions / SampleNormals) for control points `control`
  // (#V(level)×3) in every camera, and the surface's coverage of the cameras with
  // coverage_of[k] (null: none). Renders in parallel over cameras.
  SampleVisibility Compute(const std::vector<vision::Camera>& cameras,
                           const geometry::Positions& control,
                           const geometry::Positions& sample_positions,
                           const geometry::Positions& sample_normals,
                           const std::vector<char>* coverage_of = nullptr) const;

  // The tessellated limit surface for `control` (what the z-buffer renders).
  geometry::TriangleMesh Tessellation(const geometry::Positions& control) const;

 private:
  const geometry::LoopHierarchy* hierarchy_;
  int level_;
  VisibilityOptions options_;
  geometry::LimitTessellation tessellation_;
  geometry::SparseMatrix tessellation_limit_;
};

}  // namespace subflow::solver
