// The distance bound of SimplifyOptions::max_distance (geometry/simplify.h), internal to the
// simplification (simplify_cgal.cpp): which collapses and flips keep the simplified mesh
// within a distance ε of its input, both ways.
//
// Samples of the input surface (its vertices and its face centroids) are each attributed to
// one face of the mesh being simplified: at the start the face they lie on (a vertex: one
// of its faces). A collapse of the edge (v0, v1) to the point p is allowed only when
//   (a) every sample attributed to a face around v0 or v1 lies within ε of one of the faces
//       that surround p after the collapse, and
//   (b) p and the centroids of those faces lie within ε of the input surface;
// after it, the samples of the old star are attributed to their nearest face of the new
// star. An edge flip is held to the same two rules for its two faces. By induction every
// sample stays within ε of the simplified surface (input → result, up to the sample
// spacing), and every vertex and face centroid of the result within ε of the input
// (result → input): a sampled two-sided bound, where a Garland–Heckbert cost alone sums
// squared plane distances that grow with the number of merged faces and says nothing
// about a thin part eroded from its rim (collapsing across a 3 mm plate costs about as
// much as merging a few faces of a gently curved cheek).
#pragma once

#include <memory>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "geometry/closest_point.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry::simplify_internal {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using VertexIndex = SurfaceMesh::Vertex_index;
using FaceIndex = SurfaceMesh::Face_index;
using HalfedgeIndex = SurfaceMesh::Halfedge_index;

class DistanceBound {
 public:
  // `mesh` is the copy of `input` that will be simplified (same vertices and faces); it
  // must outlive the bound. `max_distance` > 0, world units.
  DistanceBound(const TriangleMesh& input, SurfaceMesh* mesh, double max_distance);

  // Rules (a) and (b) for collapsing the edge v0 → v1 to p (v0, v1 still in the mesh).
  bool AllowsCollapse(VertexIndex v0, VertexIndex v1, const Point& p) const;
  // Before the collapse of (v0, v1): takes the samples of their faces.
  void BeforeCollapse(VertexIndex v0, VertexIndex v1);
  // After it: gives them to the nearest face around the kept vertex.
  void AfterCollapse(VertexIndex kept);

  // Rules (a) and (b) for flipping the edge of h: faces (a, b, c) and (b, a, d) become
  // (a, d, c) and (d, b, c) (a = source(h), b = target(h)).
  bool AllowsFlip(HalfedgeIndex h) const;
  // Flips the edge of h (CGAL::Euler::flip_edge) and re-attributes the two faces' samples.
  void Flip(HalfedgeIndex h);

  // The largest distance of a sample to the surface of `result` (≤ ε up to rounding when
  // every collapse and flip kept the bound).
  double LargestSampleDistance(const ClosestPointTree& result) const;

 private:
  struct Triangle {
    Point a, b, c;
  };
  double DistanceToInput(const Point& p) const;
  static double Distance(const Point& p, const Triangle& t);
  // The smallest distance of `p` to the triangles; the index of the nearest in *nearest.
  static double Nearest(const Point& p, const std::vector<Triangle>& triangles, std::size_t* nearest);
  // Rule (a) for the samples of `faces` (successor[i]: the triangle face i becomes, −1 if
  // none), rule (b) for the triangles (whose corners include p).
  bool Keeps(const std::vector<FaceIndex>& faces, const std::vector<int>& successor,
             const std::vector<Triangle>& triangles) const;
  void Attribute(const std::vector<int>& samples, const std::vector<FaceIndex>& faces);

  SurfaceMesh* mesh_;
  double max_distance_;
  std::unique_ptr<ClosestPointTree> input_tree_;
  std::vector<Point> samples_;
  SurfaceMesh::Property_map<FaceIndex, std::vector<int>> attributed_;
  std::vector<int> pending_;  // samples between BeforeCollapse and AfterCollapse
};

}  // namespace subflow::geometry::simplify_internal
