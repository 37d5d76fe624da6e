// Self-intersection tests of a triangle mesh by two independent implementations, so that
// each can vouch for the other (geometry/mesh_validation.h runs both and compares).
//
// Two faces intersect when their triangles share a point that is not a vertex or an edge
// common to both faces: neighbours meeting along their shared edge or at their shared
// vertex do not intersect. The two tests differ on coincident vertices with different
// indices: CGAL reports faces touching there, TetGen merges such vertices first and does
// not; a mesh with coincident vertices can therefore make them disagree.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct SelfIntersectionResult {
  std::string method;  // "CGAL" or "TetGen"
  bool ran = false;    // false: skipped or failed, and `note` says why
  std::string note;
  // Number of intersecting face pairs, or −1 when the method does not count pairs
  // (TetGen reports the faces involved, not the pairs).
  long long pair_count = -1;
  std::vector<std::pair<int, int>> example_pairs;  // the first few pairs (i < j), CGAL only
  std::vector<int> intersecting_faces;             // sorted, distinct faces in some pair
  // Faces the method reports as intersecting; equals intersecting_faces.size() unless some
  // reported face could not be matched to an input face (see `note`).
  int reported_face_count = 0;
  int degenerate_face_count = 0;  // faces CGAL finds degenerate (collinear corners), CGAL only
  double seconds = 0.0;           // wall time of the test, including the conversion

  bool found() const { return ran && reported_face_count > 0; }
};

// CGAL::Polygon_mesh_processing::self_intersections on the mesh converted once to
// CGAL::Surface_mesh<Epick::Point_3> (exact predicates). The conversion needs an oriented
// 2-manifold; for any other mesh ran = false. Degenerate faces are counted separately,
// not as intersections. At most `max_example_pairs` pairs are kept in example_pairs.
SelfIntersectionResult FindSelfIntersectionsCgal(const TriangleMesh& mesh,
                                                 int max_example_pairs = 10);

// TetGen's detection of intersecting facets (switches "pdQ": read the faces as a
// piecewise linear complex, -d detect self-intersections, quiet). Works on any triangle
// soup; faces that repeat a vertex index are left out. TetGen stops with an error code
// on some degenerate input; then ran = false and `note` gives the code.
SelfIntersectionResult FindSelfIntersectionsTetgen(const TriangleMesh& mesh);

}  // namespace subflow::geometry
