// CGAL is confined to this file (heavy headers).
#include <algorithm>
#include <iterator>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "core/stopwatch.h"
#include "geometry/self_intersections.h"

namespace subflow::geometry {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

// Builds the Surface_mesh with vertex i and face f keeping their indices; false when
// a face cannot be added (the mesh is not an oriented 2-manifold there).
bool ToSurfaceMesh(const TriangleMesh& mesh, SurfaceMesh* surface, int* failed_face) {
  surface->reserve(mesh.vertex_count(), 3 * mesh.face_count() / 2 + 3, mesh.face_count());
  for (int v = 0; v < mesh.vertex_count(); ++v)
    surface->add_vertex(Kernel::Point_3(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)));
  for (int f = 0; f < mesh.face_count(); ++f) {
    const SurfaceMesh::Face_index face = surface->add_face(SurfaceMesh::Vertex_index(mesh.F(f, 0)),
                                                           SurfaceMesh::Vertex_index(mesh.F(f, 1)),
                                                           SurfaceMesh::Vertex_index(mesh.F(f, 2)));
    if (face == SurfaceMesh::null_face()) {
      *failed_face = f;
      return false;
    }
  }
  return true;
}

}  // namespace

SelfIntersectionResult FindSelfIntersectionsCgal(const TriangleMesh& mesh, int max_example_pairs) {
  const Stopwatch stopwatch;
  SelfIntersectionResult result;
  result.method = "CGAL";
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= mesh.vertex_count()) {
        result.note = "not run: face " + std::to_string(f) + " has a vertex index out of range";
        return result;
      }
  for (int f = 0; f < mesh.face_count(); ++f)
    if (mesh.F(f, 0) == mesh.F(f, 1) || mesh.F(f, 1) == mesh.F(f, 2) ||
        mesh.F(f, 0) == mesh.F(f, 2)) {
      result.note = "not run: face " + std::to_string(f) + " repeats a vertex";
      return result;
    }
  if (!mesh.V.allFinite()) {
    result.note = "not run: the mesh has non-finite coordinates";
    return result;
  }
  SurfaceMesh surface;
  int failed_face = -1;
  if (!ToSurfaceMesh(mesh, &surface, &failed_face)) {
    result.note = "not run: face " + std::to_string(failed_face) +
                  " cannot join a halfedge mesh (CGAL needs an oriented 2-manifold)";
    return result;
  }
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(surface, std::back_inserter(pairs));

  result.ran = true;
  result.pair_count = 0;
  for (const auto& [a, b] : pairs) {
    const int i = static_cast<int>(a.idx()), j = static_cast<int>(b.idx());
    if (i == j) {  // CGAL reports a degenerate face as the pair (f, f)
      ++result.degenerate_face_count;
      continue;
    }
    ++result.pair_count;
    if (static_cast<int>(result.example_pairs.size()) < max_example_pairs)
      result.example_pairs.emplace_back(std::min(i, j), std::max(i, j));
    result.intersecting_faces.push_back(i);
    result.intersecting_faces.push_back(j);
  }
  std::sort(result.intersecting_faces.begin(), result.intersecting_faces.end());
  result.intersecting_faces.erase(
      std::unique(result.intersecting_faces.begin(), result.intersecting_faces.end()),
      result.intersecting_faces.end());
  result.reported_face_count = static_cast<int>(result.intersecting_faces.size());
  result.seconds = stopwatch.Seconds();
  return result;
}

}  // namespace subflow::geometry
