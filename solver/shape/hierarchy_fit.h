// Fitting a Loop subdivision hierarchy to a target surface (method §4.1, steps 2–4):
// starting from base control points, at every level i = 0..n the control points are
// displaced along the limit normals until the LIMIT surface of level i lies on the
// target (the iso-surface of the visual hull), then refined to level i + 1.
//
// Each level is snapped with SnapToSurface (solver/surface_snapping.h): limit points are
// moved along their limit normals onto the target, `iterations_per_level` times.
#pragma once

#include <string>
#include <vector>

#include "geometry/closest_point.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"

namespace subflow::solver {

struct HierarchyFitOptions {
  // Snap iterations per level (each removes most of the remaining normal distance).
  int iterations_per_level = 3;
  // Largest |t| accepted along a normal line, world units; ≤ 0 = automatic: 10 % of the
  // target's bounding-box diagonal.
  double max_snap_distance = 0.0;
  void Check() const;  // throws subflow::Error naming the field
};

// Figures of the last snap step of one level.
struct LevelFitSummary {
  int level = 0;
  int vertex_count = 0;
  int misses = 0;                  // limit points whose normal line missed the target
  double mean_distance = 0.0;      // mean |limit point − target| after the level's steps
  double max_distance = 0.0;       // (closest-point distances, world units)
};

// Throws subflow::Error (naming `source`) unless `base_control_points` has one finite row
// per vertex of level 0.
void CheckBaseControlPoints(const geometry::LoopHierarchy& hierarchy, const geometry::Positions& base_control_points,
                            const std::string& source);

// Fits levels 0..n of `hierarchy` to `target` from `base_control_points` (#V(0)×3) and
// returns the fitted control points of every level (element i is #V(i)×3). `summaries`
// (optional) receives one entry per level.
std::vector<geometry::Positions> FitHierarchyToSurface(
    const geometry::LoopHierarchy& hierarchy, const geometry::Positions& base_control_points,
    const geometry::ClosestPointTree& target, const HierarchyFitOptions& options,
    std::vector<LevelFitSummary>* summaries = nullptr);

}  // namespace subflow::solver
