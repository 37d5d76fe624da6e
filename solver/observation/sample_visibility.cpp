#include "solver/observation/sample_visibility.h"

#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/mean_edge_length.h"
#include "vision/zbuffer.h"

namespace subflow::solver {

using geometry::Positions;

void VisibilityOptions::Check() const {
  if (!std::isfinite(depth_tolerance) || depth_tolerance < 0.0)
    ThrowError("visibility", "depth_tolerance", "expected a finite value ≥ 0 (0 = automatic)");
  if (!std::isfinite(min_view_cosine) || min_view_cosine < 0.0 || min_view_cosine >= 1.0)
    ThrowError("visibility", "min_view_cosine", "expected a value in [0, 1)");
  if (!std::isfinite(image_margin) || image_margin < 0.0)
    ThrowError("visibility", "image_margin", "expected a finite value ≥ 0 (pixels)");
  if (tessellation_density < 1 || tessellation_density > 16)
    ThrowError("visibility", "tessellation_density",
               "expected 1..16, got " + std::to_string(tessellation_density));
}

std::vector<int> SampleVisibility::CamerasSeeing(int sample) const {
  std::vector<int> cameras;
  for (int k = 0; k < camera_count(); ++k)
    if (visible[k][sample]) cameras.push_back(k);
  return cameras;
}

int SampleVisibility::SamplesSeenBy(int min_cameras) const {
  if (visible.empty()) return 0;
  int count = 0;
  for (std::size_t s = 0; s < visible[0].size(); ++s) {
    int seen = 0;
    for (const auto& camera : visible) seen += camera[s];
    if (seen >= min_cameras) ++count;
  }
  return count;
}

std::vector<std::vector<int>> SampleVisibility::CamerasSeeingFaces(
    const SurfaceSamples& samples) const {
  const int face_count = static_cast<int>(samples.face_first_sample.size()) - 1;
  std::vector<std::vector<int>> cameras(std::max(face_count, 0));
  for (int f = 0; f < face_count; ++f)
    for (int k = 0; k < camera_count(); ++k)
      for (int s = samples.face_first_sample[f]; s < samples.face_first_sample[f + 1]; ++s)
        if (visible[k][s]) {
          cameras[f].push_back(k);
          break;
        }
  return cameras;
}

VisibilityTester::VisibilityTester(const geometry::LoopHierarchy& hierarchy, int level,
                                   const VisibilityOptions& options)
    : hierarchy_(&hierarchy), level_(level), options_(options) {
  options_.Check();
  if (level < 0 || level > hierarchy.finest_level())
    ThrowError("visibility", "level", "out of range: " + std::to_string(level));
  tessellation_ =
      geometry::TessellateLimitSurface(hierarchy.Topology(level), options_.tessellation_density);
  const geometry::LoopLimitEvaluator evaluator(hierarchy.Topology(level));
  tessellation_limit_ = evaluator.LimitMatrix(tessellation_.samples);
}

geometry::TriangleMesh VisibilityTester::Tessellation(const Positions& control) const {
  SUBFLOW_CHECK(control.rows() == tessellation_limit_.cols(), "control points of another level");
  return {tessellation_limit_ * control, tessellation_.faces};
}

SampleVisibility VisibilityTester::Compute(const std::vector<vision::Camera>& cameras,
                                           const Positions& control,
                                           const Positions& sample_positions,
                                           const Positions& sample_normals,
                                           const std::vector<char>* coverage_of) const {
  SUBFLOW_CHECK(sample_positions.rows() == sample_normals.rows(), "positions and normals differ");
  SUBFLOW_CHECK(!coverage_of || coverage_of->size() == cameras.size(), "one coverage flag per camera");
  const geometry::TriangleMesh mesh = Tessellation(control);
  SampleVisibility result;
  result.depth_tolerance = options_.depth_tolerance > 0.0 ? options_.depth_tolerance
                                                          : 0.5 * geometry::MeanEdgeLength(hierarchy_->Topology(level_), control);
  const int sample_count = static_cast<int>(sample_positions.rows());
  result.visible.assign(cameras.size(), std::vector<std::uint8_t>(sample_count, 0));
  result.coverage.resize(cameras.size());
  tbb::parallel_for(std::size_t{0}, cameras.size(), [&](std::size_t k) {
    const vision::Camera& camera = cameras[k];
    thread_local vision::ZBuffer zbuffer;  // its buffers reused from render to render
    vision::ZBufferOptions depth_only;
    depth_only.depth_only = true;
    zbuffer.Render(camera, mesh.V, mesh.F, depth_only);
    if (coverage_of && (*coverage_of)[k]) result.coverage[k] = zbuffer.Mask();
    const Eigen::Vector3d centre = camera.Center();
    std::vector<std::uint8_t>& visible = result.visible[k];
    for (int s = 0; s < sample_count; ++s) {
      const Eigen::Vector3d X = sample_positions.row(s).transpose();
      const Eigen::Vector3d to_camera = centre - X;
      const double distance = to_camera.norm();
      if (!(distance > 0.0)) continue;
      if (sample_normals.row(s).dot(to_camera.transpose()) < options_.min_view_cosine * distance)
        continue;
      double depth = 0.0;
      const Eigen::Vector2d pixel = camera.ProjectUndistorted(X, &depth);
      if (!(depth > 0.0) || !camera.InImage(pixel, options_.image_margin)) continue;
      visible[s] = zbuffer.IsVisible(X, result.depth_tolerance) ? 1 : 0;
    }
  });
  return result;
}

}  // namespace subflow::solver
