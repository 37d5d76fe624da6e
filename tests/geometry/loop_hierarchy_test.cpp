// Claims about LoopHierarchy: nested connectivity, errors on bad base meshes, and the
// limit masks (positions, tangents, normals) against repeated refinement.
#include "geometry/loop_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/local_frames.h"
#include "geometry/mesh_primitives.h"
#include "tests/test_support.h"

namespace subflow::geometry {
namespace {

using test::Perturbed;

// Half-disk fan: centre 0 on the boundary with `faces` triangles, rim 1..faces+1.
TriangleMesh HalfFan(int faces) {
  TriangleMesh mesh;
  mesh.V.resize(faces + 2, 3);
  mesh.V.row(0) << 0, 0, 0;
  for (int i = 0; i <= faces; ++i)
    mesh.V.row(1 + i) << std::cos(M_PI * i / faces), std::sin(M_PI * i / faces), 0.0;
  mesh.F.resize(faces, 3);
  for (int i = 0; i < faces; ++i) mesh.F.row(i) << 0, 1 + i, 2 + i;
  return mesh;
}

template <typename Function>
std::string ErrorMessage(Function&& function) {
  try {
    function();
  } catch (const subflow::Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(LoopHierarchy, LevelsAreNestedWithOddVerticesOnParentEdges) {
  const TriangleMesh base = MakeIcosphere(0);
  const LoopHierarchy hierarchy(base.F, base.vertex_count(), 3);
  ASSERT_EQ(hierarchy.finest_level(), 3);
  for (int level = 0; level <= 3; ++level) {
    const MeshTopology& topology = hierarchy.Topology(level);
    EXPECT_EQ(hierarchy.FaceCount(level), 20 << (2 * level));
    EXPECT_EQ(hierarchy.VertexCount(level), 10 * (1 << (2 * level)) + 2);
    EXPECT_TRUE(topology.IsClosed());
    EXPECT_EQ(topology.vertex_count() - topology.edge_count() + topology.face_count(), 2);
  }
  for (int level = 1; level <= 3; ++level) {
    const MeshTopology& coarse = hierarchy.Topology(level - 1);
    const MeshTopology& fine = hierarchy.Topology(level);
    EXPECT_EQ(hierarchy.VertexCount(level), coarse.vertex_count() + coarse.edge_count());
    for (int v = coarse.vertex_count(); v < fine.vertex_count(); ++v) {
      ASSERT_TRUE(hierarchy.IsOddVertex(level, v));
      const auto [a, b] = hierarchy.ParentEdge(level, v);
      // The parents are neighbours on the coarse level and both neighbours of v on the
      // fine level (the edge was split at v); odd vertices of a closed mesh have valence 6.
      const IndexRange coarse_ring = coarse.Ring(a);
      EXPECT_NE(std::find(coarse_ring.begin(), coarse_ring.end(), b), coarse_ring.end());
      const IndexRange ring = fine.Ring(v);
      EXPECT_EQ(ring.size(), 6);
      EXPECT_NE(std::find(ring.begin(), ring.end(), a), ring.end());
      EXPECT_NE(std::find(ring.begin(), ring.end(), b), ring.end());
    }
    for (int v = 0; v < coarse.vertex_count(); ++v) {
      EXPECT_FALSE(hierarchy.IsOddVertex(level, v));
      EXPECT_EQ(fine.Valence(v), coarse.Valence(v));  // even vertices keep their valence
    }
    // Child faces: corner child k holds the parent's corner k at position k; the centre
    // child's corner k is the odd vertex on the parent's edge (k, k+1).
    const Faces& parents = hierarchy.LevelFaces(level - 1);
    const Faces& children = hierarchy.LevelFaces(level);
    for (int f = 0; f < parents.rows(); ++f) {
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(children(LoopHierarchy::ChildFace(f, k), k), parents(f, k));
      for (int k = 0; k < 3; ++k) {
        const auto edge = hierarchy.ParentEdge(level, children(LoopHierarchy::ChildFace(f, 3), k));
        const std::array<int, 2> expected = {parents(f, k), parents(f, (k + 1) % 3)};
        EXPECT_TRUE(edge == expected || (edge[0] == expected[1] && edge[1] == expected[0]));
      }
    }
  }
}

TEST(LoopHierarchy, ChildBarycentricsMapToParentAndBack) {
  // Exact in binary floating point for these dyadic coordinates.
  const Eigen::Vector3d points[] = {{0.7, 0.2, 0.1}, {0.1, 0.8, 0.1}, {0.05, 0.25, 0.7},
                                    {0.3, 0.3, 0.4}, {1.0, 0.0, 0.0}, {0.25, 0.25, 0.5}};
  for (const Eigen::Vector3d& u : points) {
    Eigen::Vector3d w;
    const int child = LoopHierarchy::ParentToChildBarycentric(u, &w);
    EXPECT_NEAR(w.sum(), 1.0, 1e-15);
    EXPECT_GE(w.minCoeff(), -1e-15) << "child " << child;
    EXPECT_LT((LoopHierarchy::ChildToParentBarycentric(child, w) - u).norm(), 1e-15);
  }
  // The centre child's corners are the parent's edge midpoints (0,1), (1,2), (2,0).
  EXPECT_LT((LoopHierarchy::ChildToParentBarycentric(3, {1, 0, 0}) -
             Eigen::Vector3d(0.5, 0.5, 0)).norm(), 1e-15);
  EXPECT_LT((LoopHierarchy::ChildToParentBarycentric(3, {0, 0, 1}) -
             Eigen::Vector3d(0.5, 0, 0.5)).norm(), 1e-15);
}

TEST(LoopHierarchy, RejectsBadBaseMeshes) {
  const TriangleMesh tetrahedron = Tetrahedron();
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(tetrahedron.F, 4, -1, "t.ply"); })
                .find("t.ply: levels"), std::string::npos);
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(tetrahedron.F, 5, 1, "t.ply"); })
                .find("t.ply: vertex 4: referenced by no face"), std::string::npos);
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(Faces(0, 3), 0, 1, "t.ply"); })
                .find("t.ply: faces"), std::string::npos);
  Faces fin(3, 3);  // an edge shared by three faces
  fin << 0, 1, 2, 1, 0, 3, 1, 0, 4;
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(fin, 5, 1, "fin.ply"); }).find("non-manifold"),
            std::string::npos);
  Faces bowtie(2, 3);  // two triangles sharing only vertex 0
  bowtie << 0, 1, 2, 0, 3, 4;
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(bowtie, 5, 1, "bowtie.ply"); })
                .find("bowtie.ply: vertex 0: non-manifold vertex"), std::string::npos);
  Faces pillow(2, 3);  // closed, but interior vertices of valence 2
  pillow << 0, 1, 2, 0, 2, 1;
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(pillow, 3, 1, "pillow.ply"); })
                .find("interior vertex with 2 neighbours"), std::string::npos);
  EXPECT_NE(ErrorMessage([&] { LoopHierarchy(tetrahedron.F, 4, 16, "t.ply"); })
                .find("exceed 2^31 faces"), std::string::npos);
}

TEST(LoopHierarchy, OperatorRowsReproduceConstantsAndTangentsAnnihilateThem) {
  const TriangleMesh base = Perturbed(GridPatch(3, 3), 0.1, 11);
  const LoopHierarchy hierarchy(base.F, base.vertex_count(), 2);
  for (int level = 0; level <= 2; ++level) {
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(hierarchy.VertexCount(level));
    if (level < 2) {
      const Eigen::VectorXd refined = hierarchy.Refinement(level) * ones;
      EXPECT_LT((refined.array() - 1.0).abs().maxCoeff(), 1e-15);
    }
    EXPECT_LT(((hierarchy.LimitPositions(level) * ones).array() - 1.0).abs().maxCoeff(), 1e-14);
    EXPECT_LT((hierarchy.TaubinSmoothing(level) * ones - ones).norm(), 1e-13);
    for (int which = 0; which < 2; ++which)
      EXPECT_LT((hierarchy.LimitTangent(level, which) * ones).norm(), 1e-13);
  }
}

constexpr int kRefinements = 8;

// Open disk of `faces` triangles around an interior centre 0 of valence `faces` (rim
// vertices: boundary, 2 faces each), the centre lifted so the fan is not flat.
TriangleMesh Fan(int faces) {
  TriangleMesh mesh;
  mesh.V.resize(faces + 1, 3);
  mesh.V.row(0) << 0, 0, 0.4;
  for (int i = 0; i < faces; ++i)
    mesh.V.row(1 + i) << std::cos(2 * M_PI * i / faces), std::sin(2 * M_PI * i / faces), 0.0;
  mesh.F.resize(faces, 3);
  for (int i = 0; i < faces; ++i) mesh.F.row(i) << 0, 1 + i, 1 + (i + 1) % faces;
  return mesh;
}

// The meshes the limit claims are checked on, refined kRefinements times once for all
// tests (65536 times as many faces: the meshes are kept tiny). Interior vertices of
// valence 3, 4, 5, 8; boundary vertices with 1, 2, 3, 4 and 6 faces. The limit masks of a
// vertex only read its 1-ring, which refinement maps onto itself, so a fan around the
// vertex is as good a test as any larger mesh.
//
// Only what the tests read is kept (the 8-level hierarchies are large and dropped):
// level-0 operators, and the level-8 quantities at the base vertices (their indices are
// kept by refinement).
struct LimitCase {
  TriangleMesh base;
  LoopHierarchy coarse;          // level 0 only: the masks applied to the base mesh
  Positions refined;             // base vertices' control points after 8 refinements
  Positions fine_limit;          // LimitPositions(8) × c_8 at the base vertices
  Positions fine_tangents[2];    // LimitTangent(8, which) × c_8 at the base vertices
  Positions fine_normals;        // LimitNormals at level 8, at the base vertices
  Positions ring_normals;        // area-weighted normals of their faces at level 8
};

const std::vector<LimitCase>& LimitCases() {
  static const std::vector<LimitCase> cases = [] {
    const TriangleMesh meshes[] = {Perturbed(Tetrahedron(), 0.1, 21), Perturbed(Fan(4), 0.1, 22),
                                   Perturbed(Fan(5), 0.1, 23),        Perturbed(Fan(8), 0.1, 24),
                                   Perturbed(HalfFan(3), 0.2, 25),    Perturbed(HalfFan(4), 0.2, 26),
                                   Perturbed(HalfFan(6), 0.2, 27)};
    std::vector<LimitCase> built;
    for (const TriangleMesh& mesh : meshes) {
      const int n = mesh.vertex_count();
      const LoopHierarchy hierarchy(mesh.F, n, kRefinements);
      const Positions refined = hierarchy.Refine(mesh.V, 0, kRefinements);
      const MeshTopology& fine = hierarchy.Topology(kRefinements);
      const Faces& F = hierarchy.LevelFaces(kRefinements);
      Positions ring_normals = Positions::Zero(n, 3);
      for (int v = 0; v < n; ++v) {
        for (int f : fine.RingFaces(v)) {
          const Eigen::Vector3d a = refined.row(F(f, 0)), b = refined.row(F(f, 1)),
                                c = refined.row(F(f, 2));
          ring_normals.row(v) += (b - a).cross(c - a).transpose();
        }
      }
      built.push_back(
          {mesh, LoopHierarchy(mesh.F, n, 0), refined.topRows(n),
           (hierarchy.LimitPositions(kRefinements) * refined).topRows(n),
           {(hierarchy.LimitTangent(kRefinements, 0) * refined).topRows(n),
            (hierarchy.LimitTangent(kRefinements, 1) * refined).topRows(n)},
           LimitNormals(hierarchy, kRefinements, refined).topRows(n), ring_normals});
    }
    return built;
  }();
  return cases;
}

// Each vertex's 1-ring is closed under refinement, and in it the vertex's control point
// follows c_m = s + r^m (c_0 − s) EXACTLY, s the limit point, r the eigenvalue of the
// rotation-invariant mode: (3 + 2cos(2π/K))²/64 = 5/8 − α(K) inside, 1/4 on the
// boundary. So after 8 refinements c_8 − s must equal r^8 (c_0 − s) up to rounding
// (1e-12 for O(1) coordinates), a tight check of the limit mask — an error δ in s shows
// up as (1 − r^8) δ ≈ δ.
TEST(LoopHierarchy, LimitPositionsAreWhereRepeatedRefinementConverges) {
  for (const LimitCase& limit_case : LimitCases()) {
    const TriangleMesh& base = limit_case.base;
    const Positions& refined = limit_case.refined;
    const Positions limit = limit_case.coarse.LimitPositions(0) * base.V;
    const MeshTopology& topology = limit_case.coarse.Topology(0);
    for (int v = 0; v < base.vertex_count(); ++v) {
      const double c = 3.0 + 2.0 * std::cos(2.0 * M_PI / topology.Valence(v));
      const double rate = topology.IsBoundaryVertex(v) ? 0.25 : c * c / 64.0;
      const Eigen::RowVector3d expected =
          std::pow(rate, kRefinements) * (base.V.row(v) - limit.row(v));
      EXPECT_LT((refined.row(v) - limit.row(v) - expected).norm(), 1e-12)
          << "vertex " << v << " valence " << topology.Valence(v)
          << (topology.IsBoundaryVertex(v) ? " (boundary)" : "");
    }
    // The limit mask must give the same point whichever level it is applied on.
    EXPECT_LT((limit_case.fine_limit - limit).norm(), 1e-12);
  }
}

// The tangent masks are left eigenvectors of refinement: T C^m c = λ^m T c, with
// λ = 3/8 + cos(2π/K)/4 inside; on the boundary 1/2 along, and across 1/4 (k = 1) or
// 3/8 + cos(π/k)/4 (k ≥ 2). Hence the normal of the refined control points at level 8 is
// exactly the normal at level 0 (rounding: 1e-12 relative to |λ^m T c|).
TEST(LoopHierarchy, LimitTangentsAreEigenvectorsOfRefinement) {
  for (const LimitCase& limit_case : LimitCases()) {
    const TriangleMesh& base = limit_case.base;
    const MeshTopology& topology = limit_case.coarse.Topology(0);
    for (int which = 0; which < 2; ++which) {
      const Positions coarse_tangent = limit_case.coarse.LimitTangent(0, which) * base.V;
      const Positions& fine_tangent = limit_case.fine_tangents[which];
      for (int v = 0; v < base.vertex_count(); ++v) {
        const int valence = topology.Valence(v);
        double eigenvalue = 0.375 + 0.25 * std::cos(2.0 * M_PI / valence);
        if (topology.IsBoundaryVertex(v)) {
          const int k = valence - 1;
          eigenvalue = which == 0 ? 0.5 : k == 1 ? 0.25 : 0.375 + 0.25 * std::cos(M_PI / k);
        }
        const Eigen::RowVector3d expected = std::pow(eigenvalue, kRefinements) * coarse_tangent.row(v);
        EXPECT_LT((fine_tangent.row(v) - expected).norm(), 1e-12 * (1.0 + expected.norm()))
            << "tangent " << which << " vertex " << v << " valence " << valence
            << (topology.IsBoundaryVertex(v) ? " (boundary)" : "");
      }
    }
    const Positions coarse_normals = LimitNormals(limit_case.coarse, 0, base.V);
    EXPECT_LT((limit_case.fine_normals - coarse_normals).norm(), 1e-9);
  }
}

// Geometric check of the normals, independent of the masks: the area-weighted normal of
// a vertex's faces after m refinements. In the closed 1-ring, the ring's modes j = 1..K−1
// decay as μ_j^m (μ_j = 3/8 + cos(2πj/K)/4); the face normal sums cross products of modes
// j and K − j, so its direction converges to the limit normal (modes 1 and K − 1) with
// relative error of the order of (μ_2/μ_1)^{2m}, times the ratio of the mode amplitudes
// (< 1 here: the rings are perturbed regular polygons). The tolerance is (μ_2/μ_1)^{2m}
// itself: after 8 levels 2e-8 for K = 4, 2e-7 for K = 5, 2e-3 for K = 8; K = 3 has only
// the modes 1 and 2 = K − 1, so its ring normal is exact (1e-10 for rounding).
TEST(LoopHierarchy, LimitNormalsMatchTheRefinedMeshAtInteriorVertices) {
  for (const LimitCase& limit_case : LimitCases()) {
    const Positions normals = LimitNormals(limit_case.coarse, 0, limit_case.base.V);
    const MeshTopology& topology = limit_case.coarse.Topology(0);
    for (int v = 0; v < limit_case.base.vertex_count(); ++v) {
      if (topology.IsBoundaryVertex(v)) continue;
      const Eigen::Vector3d area_normal = limit_case.ring_normals.row(v).transpose();
      const int valence = topology.Valence(v);
      const double mu1 = 0.375 + 0.25 * std::cos(2.0 * M_PI / valence);
      const double mu2 = 0.375 + 0.25 * std::cos(4.0 * M_PI / valence);
      const double bound =
          valence == 3 ? 1e-10 : std::pow(mu2 / mu1, 2 * kRefinements) + 1e-10;
      const double angle =
          std::atan2(area_normal.cross(normals.row(v).transpose()).norm(),
                     area_normal.dot(normals.row(v).transpose()));
      EXPECT_LT(angle, bound) << "vertex " << v << " valence " << valence;
    }
  }
}

TEST(LoopHierarchy, LimitNormalsPointOutwardsAndAreExactOnPlanarPatches) {
  const TriangleMesh sphere = Perturbed(MakeIcosphere(1), 0.05, 31);
  const LoopHierarchy closed(sphere.F, sphere.vertex_count(), 1);
  const Positions normals = LimitNormals(closed, 0, sphere.V);
  const Positions limit = closed.LimitPositions(0) * sphere.V;
  for (int v = 0; v < sphere.vertex_count(); ++v)
    EXPECT_GT(normals.row(v).dot(limit.row(v).normalized()), 0.9) << "vertex " << v;

  // A planar patch, counter-clockwise seen from +z: every normal, boundary or not, is +z.
  TriangleMesh patch = GridPatch(4, 3);
  for (Eigen::Index v = 0; v < patch.V.rows(); ++v)  // in-plane jitter keeps it planar
    patch.V.row(v) += Eigen::RowVector3d(0.1 * std::sin(3.0 * v), 0.1 * std::cos(5.0 * v), 0.0);
  const LoopHierarchy open(patch.F, patch.vertex_count(), 1);
  const Positions patch_normals = LimitNormals(open, 0, patch.V);
  for (int v = 0; v < patch.vertex_count(); ++v)
    EXPECT_LT((patch_normals.row(v) - Eigen::RowVector3d(0, 0, 1)).norm(), 1e-12)
        << "vertex " << v << (open.Topology(0).IsBoundaryVertex(v) ? " (boundary)" : "");
}

}  // namespace
}  // namespace subflow::geometry
