#include "solver/shape/hierarchy_fit.h"

#include <string>

#include "core/error.h"
#include "geometry/local_frames.h"
#include "solver/shape/surface_snapping.h"

namespace subflow::solver {

using geometry::Positions;

void HierarchyFitOptions::Check() const {
  if (iterations_per_level < 1)
    ThrowError("hierarchy fit options", "iterations_per_level", "expected ≥ 1");
}

void CheckBaseControlPoints(const geometry::LoopHierarchy& hierarchy, const Positions& base_control_points,
                            const std::string& source) {
  if (base_control_points.rows() != hierarchy.VertexCount(0))
    ThrowError(source, "base control points",
               "expected " + std::to_string(hierarchy.VertexCount(0)) + " rows, got " +
                   std::to_string(base_control_points.rows()));
  if (!base_control_points.allFinite()) ThrowError(source, "base control points", "expected finite coordinates");
}

namespace {

LevelFitSummary Measure(const geometry::LoopHierarchy& hierarchy, int level, const Positions& c,
                        const geometry::ClosestPointTree& target, double max_distance) {
  LevelFitSummary summary;
  summary.level = level;
  summary.vertex_count = static_cast<int>(c.rows());
  const Positions limit = hierarchy.LimitPositions(level) * c;
  const Positions normals = geometry::LimitNormals(hierarchy, level, c);
  for (const auto& hit : target.NearestHitsOnLines(limit, normals, max_distance))
    summary.misses += hit.hit ? 0 : 1;
  const Eigen::VectorXd distances = target.Distances(limit);
  summary.mean_distance = distances.size() ? distances.mean() : 0.0;
  summary.max_distance = distances.size() ? distances.maxCoeff() : 0.0;
  return summary;
}

}  // namespace

std::vector<Positions> FitHierarchyToSurface(const geometry::LoopHierarchy& hierarchy,
                                             const Positions& base_control_points,
                                             const geometry::ClosestPointTree& target,
                                             const HierarchyFitOptions& options,
                                             std::vector<LevelFitSummary>* summaries) {
  options.Check();
  CheckBaseControlPoints(hierarchy, base_control_points, "hierarchy fit");
  const auto& V = target.mesh().V;
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  const double max_distance =
      options.max_snap_distance > 0.0 ? options.max_snap_distance : 0.1 * diagonal;

  std::vector<Positions> levels;
  levels.reserve(hierarchy.finest_level() + 1);
  Positions c = base_control_points;
  if (summaries) summaries->clear();
  for (int level = 0; level <= hierarchy.finest_level(); ++level) {
    if (level > 0) c = hierarchy.Refinement(level - 1) * levels.back();
    SurfaceSnapOptions snap;
    snap.iterations = options.iterations_per_level;
    snap.max_distance = max_distance;
    c = SnapToSurface(hierarchy, level, c, target, snap);
    if (summaries) summaries->push_back(Measure(hierarchy, level, c, target, max_distance));
    levels.push_back(c);
  }
  return levels;
}

}  // namespace subflow::solver
