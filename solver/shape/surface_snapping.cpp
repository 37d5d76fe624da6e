#include "solver/shape/surface_snapping.h"

#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "geometry/local_frames.h"

namespace subflow::solver {
namespace {

using geometry::Positions;

// Signed normal distances of the limit points of `control` to the target; rows without a
// hit get 0 and are counted.
Eigen::VectorXd NormalDistances(const geometry::LoopHierarchy& hierarchy, int level,
                                const Positions& control, const geometry::ClosestPointTree& target,
                                double max_distance, Positions* normals, int* misses) {
  const Positions limit = hierarchy.LimitPositions(level) * control;
  *normals = geometry::LimitNormals(hierarchy, level, control);
  const std::vector<geometry::RayHit> hits =
      target.NearestHitsOnLines(limit, *normals, max_distance);
  Eigen::VectorXd distance = Eigen::VectorXd::Zero(limit.rows());
  *misses = 0;
  for (Eigen::Index v = 0; v < limit.rows(); ++v) {
    if (hits[v].hit && normals->row(v).squaredNorm() > 0.0)
      distance(v) = hits[v].t;
    else
      ++*misses;
  }
  return distance;
}

double Rms(const Eigen::VectorXd& values) {
  return values.size() > 0 ? std::sqrt(values.squaredNorm() / values.size()) : 0.0;
}

}  // namespace

void SurfaceSnapOptions::Check() const {
  if (!std::isfinite(weight) || weight < 0.0 || weight > 1.0)
    ThrowError("surface snapping", "weight", "expected a value in [0, 1]");
  if (!(max_distance > 0.0))
    ThrowError("surface snapping", "max_distance", "expected a value > 0");
  if (iterations < 1 || iterations > 100)
    ThrowError("surface snapping", "iterations", "expected 1..100");
}

double UnreachedFraction(const geometry::LoopHierarchy& hierarchy, int level, const Positions& control,
                         const geometry::ClosestPointTree& target, double max_distance) {
  if (control.rows() == 0) return 0.0;
  Positions normals;
  int misses = 0;
  NormalDistances(hierarchy, level, control, target, max_distance, &normals, &misses);
  return static_cast<double>(misses) / static_cast<double>(control.rows());
}

Positions SnapToSurface(const geometry::LoopHierarchy& hierarchy, int level,
                        const Positions& control, const geometry::ClosestPointTree& target,
                        const SurfaceSnapOptions& options, SurfaceSnapReport* report) {
  options.Check();
  if (level < 0 || level > hierarchy.finest_level())
    ThrowError("surface snapping", "level", "out of range: " + std::to_string(level));
  if (control.rows() != hierarchy.VertexCount(level))
    ThrowError("surface snapping", "control points",
               std::to_string(control.rows()) + " rows, expected " +
                   std::to_string(hierarchy.VertexCount(level)));
  Positions snapped = control;
  Positions normals;
  int misses = 0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const Eigen::VectorXd distance =
        NormalDistances(hierarchy, level, snapped, target, options.max_distance, &normals, &misses);
    if (iteration == 0 && report) {
      report->rms_distance_before = Rms(distance);
      report->vertices_without_hit = misses;
    }
    snapped += (normals.array().colwise() * distance.array()).matrix();
  }
  Positions result = control + options.weight * (snapped - control);
  if (report) report->rms_correction = Rms((result - control).rowwise().norm());
  if (report && options.measure_after) {
    int unused = 0;
    report->rms_distance_after =
        Rms(NormalDistances(hierarchy, level, result, target, options.max_distance, &normals, &unused));
  }
  return result;
}

}  // namespace subflow::solver
