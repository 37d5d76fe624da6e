#include "solver/observation/surface_sampling.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::solver {

using geometry::Positions;

void SurfaceSamplingOptions::Check() const {
  if (!std::isfinite(samples_per_pixel) || samples_per_pixel <= 0.0)
    ThrowError("surface sampling", "samples_per_pixel", "expected a finite value > 0");
  if (max_density < 1 || max_density > 64)
    ThrowError("surface sampling", "max_density",
               "expected 1..64, got " + std::to_string(max_density));
}

Positions SurfaceSamples::SamplePositions(const Positions& control) const {
  SUBFLOW_CHECK(control.rows() == limit.cols(), "control points do not match the samples' level");
  return limit * control;
}

Positions SurfaceSamples::SampleNormals(const Positions& control) const {
  SUBFLOW_CHECK(control.rows() == limit.cols(), "control points do not match the samples' level");
  const geometry::Positions du = limit_du * control, dv = limit_dv * control;
  geometry::Positions normals(du.rows(), 3);
  for (Eigen::Index s = 0; s < du.rows(); ++s) {
    const Eigen::RowVector3d n = du.row(s).cross(dv.row(s));
    const double length = n.norm();
    normals.row(s) = length > 0.0 ? Eigen::RowVector3d(n / length) : Eigen::RowVector3d::Zero();
  }
  return normals;
}

void AppendFaceSamplePattern(int face, int density, std::vector<geometry::FaceSample>* samples) {
  SUBFLOW_CHECK(density >= 1, "density must be positive");
  const double m = density;
  for (int j = 0; j < density; ++j)
    for (int i = 0; i + j <= density - 1; ++i)
      samples->push_back({face, (i + 1.0 / 3.0) / m, (j + 1.0 / 3.0) / m});
  for (int j = 0; j < density - 1; ++j)
    for (int i = 0; i + j <= density - 2; ++i)
      samples->push_back({face, (i + 2.0 / 3.0) / m, (j + 2.0 / 3.0) / m});
}

std::vector<int> FaceSampleDensities(const geometry::LoopHierarchy& hierarchy, int level,
                                     const Positions& control,
                                     const std::vector<vision::Camera>& cameras,
                                     const SurfaceSamplingOptions& options) {
  options.Check();
  if (level < 0 || level > hierarchy.finest_level())
    ThrowError("surface sampling", "level", "out of range: " + std::to_string(level));
  if (control.rows() != hierarchy.VertexCount(level))
    ThrowError("surface sampling", "control points",
               std::to_string(control.rows()) + " rows, expected " +
                   std::to_string(hierarchy.VertexCount(level)));
  const Positions corners = hierarchy.LimitPositions(level) * control;
  const geometry::Faces& F = hierarchy.LevelFaces(level);
  std::vector<int> density(F.rows(), 1);
  tbb::parallel_for(Eigen::Index{0}, F.rows(), [&](Eigen::Index f) {
    Eigen::Vector3d X[3];
    for (int k = 0; k < 3; ++k) X[k] = corners.row(F(f, k)).transpose();
    const Eigen::Vector3d normal = (X[1] - X[0]).cross(X[2] - X[0]);
    const Eigen::Vector3d centroid = (X[0] + X[1] + X[2]) / 3.0;
    double largest_area = 0.0;
    for (const vision::Camera& camera : cameras) {
      if (normal.dot(camera.Center() - centroid) <= 0.0) continue;
      Eigen::Vector2d p[3];
      bool in_front = true, in_image = false;
      for (int k = 0; k < 3; ++k) {
        double depth = 0.0;
        p[k] = camera.ProjectUndistorted(X[k], &depth);
        in_front = in_front && depth > 0.0;
        in_image = in_image || camera.InImage(p[k]);
      }
      if (!in_front || !in_image) continue;
      const Eigen::Vector2d a = p[1] - p[0], b = p[2] - p[0];
      largest_area = std::max(largest_area, 0.5 * std::abs(a.x() * b.y() - a.y() * b.x()));
    }
    const double m = std::ceil(std::sqrt(options.samples_per_pixel * largest_area));
    density[f] = static_cast<int>(std::clamp(m, 1.0, static_cast<double>(options.max_density)));
  });
  return density;
}

SurfaceSamples SampleLimitSurface(const geometry::LoopHierarchy& hierarchy, int level,
                                  const Positions& control,
                                  const std::vector<vision::Camera>& cameras,
                                  const SurfaceSamplingOptions& options) {
  SurfaceSamples result;
  result.level = level;
  result.face_density = FaceSampleDensities(hierarchy, level, control, cameras, options);
  const int face_count = hierarchy.FaceCount(level);
  result.face_first_sample.reserve(face_count + 1);
  for (int f = 0; f < face_count; ++f) {
    result.face_first_sample.push_back(static_cast<int>(result.samples.size()));
    AppendFaceSamplePattern(f, result.face_density[f], &result.samples);
  }
  result.face_first_sample.push_back(static_cast<int>(result.samples.size()));
  const geometry::LoopLimitEvaluator evaluator(hierarchy.Topology(level));
  result.limit = evaluator.LimitMatrix(result.samples, &result.limit_du, &result.limit_dv);
  return result;
}

}  // namespace subflow::solver
