// Validation of a triangle mesh (V, F): the figures `subflow check` prints and the
// verdict every stage that needs a clean surface relies on.
//
// Definitions (faces that repeat a vertex index are counted and left out of the rest):
//   edge          an unordered vertex pair used by at least one face; E = #edges.
//   boundary edge an edge used by one face; closed ⇔ no boundary edge. Boundary loops are
//                 the connected components of the boundary edges.
//   manifold      every edge has ≤ 2 faces and the faces around every vertex form one fan
//                 (a disk or half-disk): no fins, no bowties. MeshTopology's own verdict
//                 (which also requires consistent orientation) is kept as its message.
//   consistently oriented  every 2-face edge is traversed in opposite directions.
//   components    connected components of faces sharing edges.
//   χ = V' − E + F with V' the vertices used by some face; for an orientable manifold,
//   genus g = (2·components − χ − boundary loops) / 2 (summed over components).
//   signed volume Σ_f (v0 − o)·((v1 − o) × (v2 − o)) / 6, o = bounding-box centre: the
//                 enclosed volume, > 0 when a closed mesh's faces are counter-clockwise seen
//                 from outside (outward normals, the convention of triangle_mesh.h).
//   degenerate    area < degenerate_area_tolerance · (mean edge length)².
//   valid         finite coordinates, manifold, consistently oriented, outward if closed,
//                 and no self-intersection found by either test (self_intersections.h).
//                 Open boundaries, degenerate faces and unreferenced vertices are warnings.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/self_intersections.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct MeshValidationOptions {
  // CGAL's self-intersection test (box intersection + exact predicates). Skip for speed.
  bool check_self_intersections_cgal = true;
  // TetGen's -d test, an independent second opinion. Skip for speed.
  bool check_self_intersections_tetgen = true;
  // A face is degenerate when its area < this × (mean edge length)²; dimensionless.
  double degenerate_area_tolerance = 1e-10;
  // How many intersecting face pairs the report lists (the count is always complete).
  int max_example_pairs = 10;

  bool Validate(std::string* why) const;
};

struct MeshValidationReport {
  // Counts.
  int vertex_count = 0;
  int face_count = 0;
  int edge_count = 0;
  int unreferenced_vertex_count = 0;
  int non_finite_vertex_count = 0;     // vertices with a NaN or infinite coordinate
  int repeated_vertex_face_count = 0;  // faces naming one vertex twice

  // Topology.
  int boundary_edge_count = 0;
  int boundary_loop_count = 0;
  bool closed = false;
  int non_manifold_edge_count = 0;    // edges with more than two faces
  int non_manifold_vertex_count = 0;  // vertices whose faces form more than one fan
  bool manifold = false;
  std::string topology_message;     // MeshTopology's error, empty when it accepts the mesh
  int inconsistent_edge_count = 0;  // 2-face edges traversed twice in the same direction
  bool consistently_oriented = false;
  int component_count = 0;
  int euler_characteristic = 0;
  int genus = -1;  // −1 when undefined (non-manifold or non-orientable)

  // Geometry (NaN when coordinates are not finite).
  double signed_volume = 0.0;     // meaningful for closed meshes
  bool outward_oriented = false;  // closed and signed_volume > 0
  double surface_area = 0.0;
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
  double min_edge_length = 0.0;
  double mean_edge_length = 0.0;
  double max_edge_length = 0.0;
  int degenerate_face_count = 0;

  // Self-intersections (ran = false when skipped by the options or not applicable).
  SelfIntersectionResult cgal;
  SelfIntersectionResult tetgen;
  bool self_intersection_checks_agree = false;  // both ran and reached the same verdict
  bool self_intersecting_faces_agree = false;   // ... and found the same faces

  std::vector<std::string> problems;  // why the mesh is not valid; empty ⇔ valid
  std::vector<std::string> warnings;  // notable facts that do not invalidate the mesh

  bool valid() const { return problems.empty(); }
  // The figures, one topic per line, for people.
  std::string FullReport() const;
  // The figures as a JSON object (pretty-printed with `indent` spaces; −1 = one line).
  std::string ToJson(int indent = 2) const;
};

// Measures `mesh` and judges it (see the definitions above). Throws subflow::Error
// (naming `source`) only when a face index is out of range or the options are invalid;
// every other defect is reported.
MeshValidationReport ValidateMesh(const TriangleMesh& mesh,
                                  const MeshValidationOptions& options = {},
                                  const std::string& source = "mesh");

}  // namespace subflow::geometry
