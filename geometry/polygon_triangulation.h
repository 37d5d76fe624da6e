// Polygon faces → triangles, as the mesh readers need them: most tools export quads and
// n-gons, subflow works on triangles.
//
// A polygon of k ≥ 3 corners (given in its winding order) becomes k − 2 triangles with
// the same winding, by ear clipping in the polygon's plane: the plane is the one of the
// Newell normal n = Σᵢ (pᵢ − pᵢ₊₁) × (pᵢ + pᵢ₊₁) / 2 (exact for planar polygons, a best
// fit for slightly non-planar ones, as in Assimp and Blender); corners are projected
// along n's largest axis, oriented so that the polygon turns counter-clockwise. An ear is
// a strictly convex corner whose triangle contains no other corner; when none exists (a
// self-intersecting or degenerate polygon, e.g. collinear corners) the most convex corner
// is clipped, so every polygon is triangulated and no corner is dropped. A planar simple
// polygon (convex or not) gives triangles that tile it exactly. O(k²) per polygon.
#pragma once

#include <vector>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Polygons beyond this many corners are refused by the readers (absurd for a mesh face,
// and the quadratic ear clipping must stay fast on any input).
inline constexpr int kMaxPolygonCorners = 4096;

// Faces as corner lists: face f has corners[starts[f] .. starts[f + 1]) (vertex indices).
struct PolygonFaces {
  std::vector<int> corners;
  std::vector<int> starts{0};

  int face_count() const { return static_cast<int>(starts.size()) - 1; }
  int size(int face) const { return starts[face + 1] - starts[face]; }
  void Add(const int* face_corners, int count) {
    corners.insert(corners.end(), face_corners, face_corners + count);
    starts.push_back(static_cast<int>(corners.size()));
  }
};

// The triangles of every face, in face order (a triangle stays as it is). Every corner
// must index a row of V and every face have ≥ 3 corners (the readers check both first).
// `polygons` (optional) receives the number of faces with more than three corners.
Faces TriangulatePolygons(const PolygonFaces& faces, const Positions& V, int* polygons = nullptr);

}  // namespace subflow::geometry
