// Simplification of a fine triangle mesh (the iso-surface) to the coarse base mesh T0 of
// the subdivision hierarchy (section 4.1, step 1: "simplify the triangle mesh
// representation down to a coarse base resolution").
//
// Method: CGAL edge collapse (Surface_mesh_simplification::edge_collapse) with the
// Garland–Heckbert plane quadrics for cost and placement: the cost of contracting edge
// (v0, v1) to the point p is pᵀ(Q0 + Q1)p, where Qv = Σ over the planes of the faces around
// v of the squared point–plane distance; p minimizes it. Collapses run cheapest first until
// the face count reaches `target_face_count`, or, with a distance bound (max_distance > 0),
// while the result stays within max_distance of the input both ways (the subject's detail
// sets the face count: simplify_bound_cgal.h). A collapse is refused when it would
//   - turn the normal of a surviving triangle of the star by more than
//     max_normal_change_degrees (this also refuses fold-overs),
//   - create a triangle whose smallest angle is below min_triangle_angle_degrees while
//     making that triangle's smallest angle worse than it was,
//   - give the merged vertex more than max_valence neighbours, or leave one of the two
//     vertices opposite the edge with fewer than min_valence.
// Valence bounds matter downstream: Loop subdivision and its limit evaluation behave best
// at valences 4–8 (extraordinary vertices of high valence converge slowly).
// Afterwards a pass of edge flips (optional) lowers Σ (valence − 6)² where a flip keeps the
// two triangles nearly coplanar and well-shaped; flips keep the face count.
// The result is checked for self-intersections; if there are some, the collapse is redone
// from the input with a target larger (a distance bound smaller) by `retry_growth`, up to
// `max_attempts` times.
//
// Input and output: V #V×3, F #F×3 counter-clockwise seen from outside (see
// triangle_mesh.h). The output keeps the orientation, the topology (genus and components:
// collapses that would change it are refused) and has no unreferenced vertices.
#pragma once

#include <map>
#include <string>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct SimplifyOptions {
  // Stop when the mesh has at most this many faces (≥ 4). A closed mesh ends at the target
  // or one face below (a collapse removes two faces); the filters below can stop it early
  // above the target (see SimplifySummary::face_count).
  int target_face_count = 400;
  // Distance bound, world units; 0 = none (stop at target_face_count). > 0: collapses (and
  // flips) are done only while every input vertex and face centroid stays within
  // max_distance of the result and every result vertex and face centroid within
  // max_distance of the input (simplify_bound_cgal.h), until no collapse keeps that or
  // min_face_count is reached: thin parts and sharp bends keep their faces, flat and gently
  // curved regions lose theirs. target_face_count is then not used.
  double max_distance = 0.0;
  int min_face_count = 100;
  // With a distance bound: where more faces remain, collapses go on by cost down to this
  // many (a cap on memory and time; the bound is then exceeded, SimplifySummary::bound_kept
  // is false).
  int max_face_count = 8000;
  // Refuse collapses that rotate a surviving face normal by more than this, degrees.
  double max_normal_change_degrees = 60.0;
  // Refuse collapses that create a triangle with a smaller angle than this, degrees,
  // unless that triangle was already worse before the collapse. 0 = no shape guard.
  double min_triangle_angle_degrees = 10.0;
  // Valence bounds enforced on collapses (see the header comment); 3 ≤ min ≤ 6 ≤ max.
  int max_valence = 9;
  int min_valence = 4;
  // Rounds of valence-improving edge flips after the collapses; 0 = none.
  int flip_rounds = 5;
  // A flip must keep the angle between the normals of its two triangles below this, degrees.
  double max_flip_dihedral_degrees = 30.0;
  // Self-intersection guard: retries with target·retry_growth when the result intersects.
  bool check_self_intersections = true;
  int max_attempts = 4;
  double retry_growth = 1.25;

  // Throws subflow::Error naming the field when an option is out of range.
  void Check() const;
};

struct SimplifySummary {
  int input_face_count = 0;
  int face_count = 0;
  int vertex_count = 0;
  int attempts = 0;           // collapses run (1 unless self-intersections forced a retry)
  // With a distance bound: the bound of the last attempt, the faces when it stopped the
  // collapses (before max_face_count), whether the result keeps it, and the largest
  // distance of an input sample to the result's face it is attributed to (≥ the sampled
  // input → result distance).
  double max_distance = 0.0;
  int bound_face_count = 0;
  bool bound_kept = true;
  double largest_sample_distance = 0.0;
  int flips = 0;              // edges flipped by the valence pass
  std::map<int, int> valence_histogram;  // valence → number of vertices
  double seconds = 0.0;
};

// Simplifies `mesh` (see the header comment). If the mesh already has at most
// target_face_count faces (with a distance bound: min_face_count) it is returned unchanged
// (after validation).
// Throws subflow::Error naming `source` when the mesh is not an oriented 2-manifold, has
// non-finite vertices or no faces, when the options are out of range (e.g. a target below
// 4), or when no attempt gives a mesh free of self-intersections.
TriangleMesh SimplifyMesh(const TriangleMesh& mesh, const SimplifyOptions& options,
                          SimplifySummary* summary = nullptr,
                          const std::string& source = "mesh");

}  // namespace subflow::geometry
