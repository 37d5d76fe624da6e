// Non-rigid registration of a subdivision surface's base control points to a target
// surface: how shape initialization carries one frame's fitted surface to the next frame's
// visual hull when the subject has moved by more than a snap along the normals can follow
// (a leg swung, an arm raised: the hull's limb is beside the surface's, not under it).
//
// Non-rigid ICP (Amberg, Romdhani & Vetter, "Optimal Step Nonrigid ICP Algorithms for
// Surface Registration", CVPR 2007) of the LIMIT surface, with the base control points c
// as unknowns. s = L c are the limit points of level e = min(1, finest) (L =
// LimitPositions(e) · Refinement(0) when e = 1), a triangle mesh with level e's faces:
// level 0's triangles are chords a base edge long, whose sag would push the surface
// outwards. Each iteration finds the correspondences again and solves one sparse linear
// least-squares problem:
//
//   E(c) = 1/|S| Σ_i∈S  [ (n_i·(s_i − p_i))² + β |s_i − p_i|² ]          surface → target
//        + 1/|Q| Σ_j∈Q  [ (n_j·(s_(j) − q_j))² + β |s_(j) − q_j|² ]     target → surface
//        + α_k /|E| Σ_(a,b)∈E |(c_a − c_b) − (c⁰_a − c⁰_b)|²             stiffness
//        + δ/|V| Σ_v |c_v − c⁰_v|²                                       (δ = 1e-4: keeps
//                                                   what no correspondence reaches in place)
//
//   S: limit points s_i, p_i their closest target point, n_i the target's face normal;
//   Q: target vertices q_j (every k-th, about |S| of them; normal n_j), s_(j) the corner
//      with the largest barycentric weight of the closest face of the limit mesh (the
//      term is mostly point-to-plane, so the offset along that face hardly matters, and
//      each point's equations stay a 3×3 block);
//   a correspondence counts only when it is nearer than `max_distance_edges` mean
//   base edges and both normals agree within acos(min_normal_cosine) (so that a surface
//   is not pulled onto the other side of a thin part);
//   E: the base mesh's edges; c⁰ the starting control points. The stiffness α_k falls
//   geometrically from stiffness_start to stiffness_end over the iterations: the surface
//   first moves as a whole, then follows the parts. The iterations stop early once no
//   control point moves by more than 1 % of the correspondence distance (2 % of a mean
//   base edge at the default).
//
// The two-sided data term is what moves the surface into a limb that it lacks (target →
// surface) without dragging it across space the target does not hold (surface → target).
// The result is a starting point for FitHierarchyToSurface, which snaps every level onto
// the target along the normals.
#pragma once

#include <memory>

#include "geometry/closest_point.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"

namespace subflow::solver {

struct SurfaceRegistrationOptions {
  bool enabled = true;
  int iterations = 6;                // ICP iterations (0 = off)
  double stiffness_start = 10.0;     // α of the first iteration
  double stiffness_end = 0.5;        // α of the last
  double point_weight = 0.1;         // β: point-to-point beside point-to-plane
  double max_distance_edges = 2.0;   // correspondences nearer than this many mean base edges
  double min_normal_cosine = 0.5;    // normals within 60°
  // Registered only when the target samples within the correspondence distance are on
  // average farther than this many mean base edges from the start surface: a surface
  // already on its target is left to the snapping (and parts of the target out of reach,
  // clutter in a hull, do not trip it).
  // The data terms have a bias of a few % of an edge (the level-1 chords' sag, the nearest
  // corner); a quarter edge is well above it. On the synthetic scenes and the shared blob
  // consecutive frames start 0.02–0.21 edges apart (nothing registered, results
  // unchanged); on pose2sim_multiperson 0.09–0.58 (median 0.26: 53 of 100 frames).
  double min_start_distance_edges = 0.25;

  void Check() const;  // throws subflow::Error naming the field
};

// Distances between the level-0 limit surface and the target, before and after.
struct SurfaceRegistrationReport {
  bool applied = false;  // false: disabled, or the start was already within the gate
  int iterations = 0;
  double mean_surface_distance_before = 0.0;  // limit points → target
  double mean_surface_distance_after = 0.0;
  double mean_target_distance_before = 0.0;   // target vertices → limit mesh
  double mean_target_distance_after = 0.0;
  // Mean over the target samples within the correspondence distance (what the gate reads:
  // parts of the target beyond it, such as clutter in a hull, cannot be registered to).
  double reachable_target_distance_before = 0.0;
  double seconds = 0.0;
};

// The operators of one hierarchy, built once (the evaluation operator L and the fixed
// sparsity pattern of the normal equations), for the registration of every frame.
class SurfaceRegistration {
 public:
  // Keeps a reference to `hierarchy`, which must outlive this object. `edge_length`: the
  // mean base edge that the options' distances are counted in (world units), e.g. the
  // reference frame's base mesh's, so that the gate does not follow a start whose edges a
  // bad fit stretched; ≤ 0 = each start's own mean base edge.
  SurfaceRegistration(const geometry::LoopHierarchy& hierarchy, const SurfaceRegistrationOptions& options,
                      double edge_length = 0.0);
  ~SurfaceRegistration();
  SurfaceRegistration(const SurfaceRegistration&) = delete;
  SurfaceRegistration& operator=(const SurfaceRegistration&) = delete;

  // The registered base control points (#V(0)×3). Throws subflow::Error on a size
  // mismatch or non-finite input. Disabled (enabled false, 0 iterations) or with the start
  // already within min_start_distance_edges of the target, returns `base_control_points`
  // unchanged (the report still measures the distances).
  geometry::Positions Register(const geometry::Positions& base_control_points,
                               const geometry::ClosestPointTree& target,
                               SurfaceRegistrationReport* report = nullptr) const;

 private:
  struct Impl;
  std::unique_ptr<const Impl> impl_;
};

// SurfaceRegistration(hierarchy, options).Register(...), for one registration.
geometry::Positions RegisterToSurface(const geometry::LoopHierarchy& hierarchy,
                                      const geometry::Positions& base_control_points,
                                      const geometry::ClosestPointTree& target,
                                      const SurfaceRegistrationOptions& options,
                                      SurfaceRegistrationReport* report = nullptr);

}  // namespace subflow::solver
