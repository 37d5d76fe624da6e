// Moving control points so that their limit surface approaches a target surface along
// its normals: the per-frame normal correction of motion initialization (against that
// frame's visual hull or fitted surface, so that drift does not build up), and a simple
// way to fit a hierarchy's control points to a mesh (tests, benchmarks).
//
// One iteration, for the control points c of `level` (#V×3):
//   s = LimitPositions(level) c, n = LimitNormals(level, c)          (per vertex)
//   t = signed distance along n from s to the target (ClosestPointTree::NearestHitOnLine,
//       |t| ≤ max_distance; vertices without a hit are left where they are)
//   c ← c + t n
// The limit operator is a local average, so for a smooth t the limit points move by ≈ t n
// and a few iterations converge (each removes most of the remaining normal distance).
// The result is blended: c_out = c_in + weight · (c_snapped − c_in). Only the normal
// component is corrected; the tangential position (the correspondence) is left alone up to
// the second-order effect of the normals' variation.
#pragma once

#include <limits>

#include "geometry/closest_point.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"

namespace subflow::solver {

struct SurfaceSnapOptions {
  double weight = 1.0;  // blend in [0, 1]: 0 = unchanged, 1 = fully on the target
  // Largest |t| accepted (world units); farther hits are ignored.
  double max_distance = std::numeric_limits<double>::infinity();
  int iterations = 3;
  // Cast once more after the last pass to measure rms_distance_after (a third more ray
  // casts at the default iterations). Motion initialization, which snaps every frame
  // step, reports the applied correction instead (rms_correction, free).
  bool measure_after = true;

  void Check() const;  // throws subflow::Error naming the field
};

struct SurfaceSnapReport {
  double rms_distance_before = 0.0;  // of the limit points to the target along n, first pass
  double rms_distance_after = 0.0;   // measured once more after the last pass (measure_after; else 0)
  double rms_correction = 0.0;       // RMS of |result − control| over the control points
  int vertices_without_hit = 0;      // in the first pass
};

geometry::Positions SnapToSurface(const geometry::LoopHierarchy& hierarchy, int level,
                                  const geometry::Positions& control,
                                  const geometry::ClosestPointTree& target,
                                  const SurfaceSnapOptions& options,
                                  SurfaceSnapReport* report = nullptr);

// Fraction of the limit points of `control` (level `level`) whose normal line meets `target`
// nowhere within `max_distance`: surface that a snap along the normals cannot bring back
// (SnapToSurface's first pass counts the same, as vertices_without_hit).
double UnreachedFraction(const geometry::LoopHierarchy& hierarchy, int level, const geometry::Positions& control,
                         const geometry::ClosestPointTree& target, double max_distance);

}  // namespace subflow::solver
