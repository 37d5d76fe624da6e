// Claim: LoopHierarchy's refinement operators C(i) reproduce CGAL's
// Subdivision_method_3::Loop_subdivision vertex for vertex (after matching indices) and
// face for face, on closed meshes with valences 3, 4, 5, 8 and on an open mesh with
// boundary vertices of 1 to 4 faces.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>
#include <gtest/gtest.h>

#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/mesh_primitives.h"
#include "tests/test_support.h"

namespace subflow::geometry {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

// Tolerance: both sides compute each new point as a short weighted sum (≤ 11 terms) of
// O(1) coordinates, per level; their rounding differs by a few ulps, so 1e-12 leaves two
// orders of magnitude of margin while any wrong weight (≥ 1e-3 of an edge) fails.
constexpr double kTolerance = 1e-12;

// Generic (non-symmetric) geometry, so that no two refined vertices coincide and a
// wrong stencil cannot hide behind symmetry.
using test::Perturbed;

SurfaceMesh ToSurfaceMesh(const TriangleMesh& mesh) {
  SurfaceMesh surface;
  std::vector<SurfaceMesh::Vertex_index> vertices;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
    vertices.push_back(surface.add_vertex(Kernel::Point_3(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2))));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const auto face = surface.add_face(vertices[mesh.F(f, 0)], vertices[mesh.F(f, 1)],
                                       vertices[mesh.F(f, 2)]);
    EXPECT_NE(face, SurfaceMesh::null_face()) << "CGAL refused face " << f;
  }
  return surface;
}

TriangleMesh FromSurfaceMesh(const SurfaceMesh& surface) {
  TriangleMesh mesh;
  mesh.V.resize(surface.number_of_vertices(), 3);
  for (const auto v : surface.vertices()) {
    const auto& p = surface.point(v);
    mesh.V.row(v.idx()) << p.x(), p.y(), p.z();
  }
  mesh.F.resize(surface.number_of_faces(), 3);
  int f = 0;
  for (const auto face : surface.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(surface.halfedge(face), surface))
      mesh.F(f, k++) = static_cast<int>(v.idx());
    ++f;
  }
  return mesh;
}

// A face as its vertex triple rotated so the smallest index comes first (keeps orientation).
std::array<int, 3> Canonical(int a, int b, int c) {
  if (b < a && b < c) return {b, c, a};
  if (c < a && c < b) return {c, a, b};
  return {a, b, c};
}

// Refines `base` `levels` times with LoopHierarchy and with CGAL and compares: positions
// after matching every CGAL vertex to the nearest of ours (which must be a bijection),
// and the faces as oriented triples under that matching.
void ExpectMatchesCgal(const TriangleMesh& base, int levels) {
  const LoopHierarchy hierarchy(base.F, base.vertex_count(), levels);
  const Positions ours = hierarchy.Refine(base.V, 0, levels);

  SurfaceMesh surface = ToSurfaceMesh(base);
  CGAL::Subdivision_method_3::Loop_subdivision(
      surface, CGAL::parameters::number_of_iterations(levels));
  const TriangleMesh theirs = FromSurfaceMesh(surface);

  ASSERT_EQ(theirs.vertex_count(), hierarchy.VertexCount(levels));
  ASSERT_EQ(theirs.face_count(), hierarchy.FaceCount(levels));

  // Nearest neighbour by brute force (meshes here have at most a few thousand vertices).
  std::vector<int> ours_of_theirs(theirs.vertex_count(), -1);
  std::vector<int> used(ours.rows(), 0);
  double worst = 0.0;
  for (int t = 0; t < theirs.vertex_count(); ++t) {
    double best = std::numeric_limits<double>::infinity();
    int best_index = -1;
    for (Eigen::Index o = 0; o < ours.rows(); ++o) {
      const double distance = (ours.row(o) - theirs.V.row(t)).norm();
      if (distance < best) best = distance, best_index = static_cast<int>(o);
    }
    ours_of_theirs[t] = best_index;
    ++used[best_index];
    worst = std::max(worst, best);
  }
  EXPECT_LT(worst, kTolerance) << "largest distance between matched vertices";
  EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](int n) { return n == 1; }))
      << "the nearest-vertex matching is not one-to-one";

  std::set<std::array<int, 3>> our_faces, their_faces;
  const Faces& F = hierarchy.LevelFaces(levels);
  for (Eigen::Index f = 0; f < F.rows(); ++f) our_faces.insert(Canonical(F(f, 0), F(f, 1), F(f, 2)));
  for (Eigen::Index f = 0; f < theirs.F.rows(); ++f)
    their_faces.insert(Canonical(ours_of_theirs[theirs.F(f, 0)], ours_of_theirs[theirs.F(f, 1)],
                                 ours_of_theirs[theirs.F(f, 2)]));
  EXPECT_EQ(our_faces, their_faces) << "faces differ after vertex matching";
}

TEST(LoopHierarchy, RefinementMatchesCgalLoopSubdivisionOnIcosahedron) {
  ExpectMatchesCgal(Perturbed(MakeIcosphere(0), 0.1, 1), 3);  // valence 5 (and 6)
}

TEST(LoopHierarchy, RefinementMatchesCgalLoopSubdivisionOnOctahedron) {
  ExpectMatchesCgal(Perturbed(Octahedron(), 0.1, 2), 3);  // valence 4
}

TEST(LoopHierarchy, RefinementMatchesCgalLoopSubdivisionWithValenceThree) {
  ExpectMatchesCgal(Perturbed(Tetrahedron(), 0.1, 3), 3);         // every vertex valence 3
  ExpectMatchesCgal(Perturbed(Bipyramid(3, 1.5), 0.1, 4), 2);     // apexes of valence 3
}

TEST(LoopHierarchy, RefinementMatchesCgalLoopSubdivisionWithHighValence) {
  ExpectMatchesCgal(Perturbed(Bipyramid(8), 0.1, 5), 2);   // apexes of valence 8
  ExpectMatchesCgal(Perturbed(Bipyramid(11), 0.1, 6), 2);  // apexes of valence 11
}

TEST(LoopHierarchy, RefinementMatchesCgalLoopSubdivisionOnOpenMesh) {
  // Interior valences 4 and 8, boundary vertices with 1, 2 and 4 faces.
  ExpectMatchesCgal(Perturbed(GridPatch(4, 3), 0.2, 7), 3);
}

TEST(LoopHierarchy, RefinementMatchesCgalLoopSubdivisionOnOpenFan) {
  // A disk of 7 triangles around an interior vertex of valence 7 (rim vertices with 2
  // faces), then the half-disk: its centre is a boundary vertex with 5 faces.
  TriangleMesh disk;
  disk.V.resize(8, 3);
  disk.V.row(0) << 0, 0, 0.3;
  for (int i = 0; i < 7; ++i)
    disk.V.row(1 + i) << std::cos(2 * M_PI * i / 7), std::sin(2 * M_PI * i / 7), 0.0;
  disk.F.resize(7, 3);
  for (int i = 0; i < 7; ++i) disk.F.row(i) << 0, 1 + i, 1 + (i + 1) % 7;
  ExpectMatchesCgal(Perturbed(disk, 0.1, 8), 3);

  TriangleMesh half;
  half.V = disk.V.topRows(7);
  half.F = disk.F.topRows(5);
  ExpectMatchesCgal(Perturbed(half, 0.1, 9), 3);
}

}  // namespace
}  // namespace subflow::geometry
