// Claims: the limit matrices L, L_u, L_v of LoopLimitEvaluator are affine (rows sum to 1,
// 0, 0) and reproduce Evaluate; Stam's method and local refinement give the same
// stencils on patches with one extraordinary corner, down to u + v = 1e−30; normals from
// du × dv at corners are Loop's limit normals (interior tangent masks; boundary left
// eigenvectors of the 1-ring subdivision matrix, computed here); the limit tessellation
// is a watertight mesh with the control mesh's topology. (CGAL comparisons:
// limit_evaluation_test.cpp.)
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/limit_evaluation.h"
#include "geometry/limit_tessellation.h"
#include "geometry/mesh_primitives.h"
#include "geometry/mesh_topology.h"
#include "tests/test_support.h"

namespace subflow::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::Perturbed;

// 1→4 split of every face (edge midpoints, perturbed): old vertices keep their valence,
// new ones have valence 6, so extraordinary vertices become isolated.
TriangleMesh MidpointSplit(const TriangleMesh& mesh, unsigned seed) {
  const MeshTopology topology(mesh.F, static_cast<int>(mesh.V.rows()));
  const int n = static_cast<int>(mesh.V.rows());
  TriangleMesh split;
  split.V.resize(n + topology.edge_count(), 3);
  split.V.topRows(n) = mesh.V;
  for (int e = 0; e < topology.edge_count(); ++e)
    split.V.row(n + e) = (mesh.V.row(topology.EdgeVertex(e, 0)) + mesh.V.row(topology.EdgeVertex(e, 1))) / 2;
  split.F.resize(4 * mesh.F.rows(), 3);
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int ab = n + topology.FaceEdge(f, 0), bc = n + topology.FaceEdge(f, 1), ca = n + topology.FaceEdge(f, 2);
    split.F.row(4 * f) << a, ab, ca;
    split.F.row(4 * f + 1) << ab, b, bc;
    split.F.row(4 * f + 2) << ca, bc, c;
    split.F.row(4 * f + 3) << ab, bc, ca;
  }
  return Perturbed(split, 0.1, seed);
}

// The first four have isolated extraordinary vertices of valence 3, 4, 7 (and 4), 9 (and
// 4); the bipyramid's apexes of valence 8 touch equator vertices of valence 4; the grid
// is open (boundary vertices with 1 to 4 faces, interior valences 4 and 8).
std::vector<TriangleMesh> Meshes() {
  return {MidpointSplit(Tetrahedron(), 1), MidpointSplit(Octahedron(), 2),
          MidpointSplit(Bipyramid(7), 3),  MidpointSplit(Bipyramid(9), 4),
          Perturbed(Bipyramid(8), 0.1, 5), Perturbed(GridPatch(3, 3), 0.1, 6)};
}
constexpr int kIsolatedMeshCount = 4;

// Dense weights over all vertices of a stencil (position, du, dv stacked as rows).
Eigen::MatrixXd Dense(const LimitStencil& s, int vertex_count) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(3, vertex_count);
  for (int i = 0; i < s.size(); ++i) {
    d(0, s.vertices[i]) += s.position[i];
    d(1, s.vertices[i]) += s.du[i];
    d(2, s.vertices[i]) += s.dv[i];
  }
  return d;
}

// Stam's method (powers of A) and local refinement are two exact evaluations of the same
// patch; they agree to rounding. Derivative weights grow or shrink like (2λ₁)^n near the
// extraordinary corner, so they are compared relative to their size.
TEST(LoopLimitEvaluator, StamPatchesAgreeWithLocalRefinement) {
  LimitEvaluatorOptions refine_only;
  refine_only.use_stam_patches = false;
  const std::vector<TriangleMesh> meshes = Meshes();
  for (size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    const int n = static_cast<int>(mesh.V.rows());
    const MeshTopology topology(mesh.F, n);
    const LoopLimitEvaluator stam(topology), refinement(topology, refine_only);
    int stam_faces = 0;
    for (int f = 0; f < topology.face_count(); ++f) {
      if (stam.PatchKind(f) != LimitPatchKind::kStam) continue;
      ++stam_faces;
      for (const auto& [u, v] : std::vector<std::pair<double, double>>{
               {0, 0}, {1, 0}, {0, 1}, {0.3, 0.3}, {0.6, 0.1}, {0.1, 0.85}, {1e-3, 2e-3},
               {1e-9, 0}, {0, 1e-12}, {1e-30, 1e-30}, {0.5, 0.5 - 1e-14}, {1 - 1e-13, 0}}) {
        const Eigen::MatrixXd a = Dense(stam.Stencil(f, u, v), n);
        const Eigen::MatrixXd b = Dense(refinement.Stencil(f, u, v), n);
        EXPECT_LT((a.row(0) - b.row(0)).norm(), 1e-13) << "face " << f << " (" << u << ", " << v << ")";
        for (int r = 1; r < 3; ++r)
          EXPECT_LT((a.row(r) - b.row(r)).norm(), 1e-11 * b.row(r).norm())
              << "face " << f << " (" << u << ", " << v << ") derivative " << r;
      }
    }
    // Every face touching an isolated extraordinary vertex is a Stam patch, and patches
    // of the same valence share one subdivision matrix.
    if (static_cast<int>(m) < kIsolatedMeshCount) {
      int expected = 0;
      std::set<int> valences;
      for (int v = 0; v < n; ++v)
        if (topology.Valence(v) != 6) expected += topology.Valence(v), valences.insert(topology.Valence(v));
      EXPECT_EQ(stam_faces, expected) << "mesh " << m;
      EXPECT_EQ(stam.StamPatchCount(), static_cast<int>(valences.size())) << "mesh " << m;
    } else {
      EXPECT_EQ(stam_faces, 0) << "mesh " << m;
    }
  }
}

// (6) s = L c: rows of L sum to 1, of L_u and L_v to 0; L c equals Evaluate.
TEST(LoopLimitEvaluator, LimitMatricesAreAffineAndReproduceEvaluate) {
  std::mt19937 random(11);
  for (const TriangleMesh& mesh : Meshes()) {
    const int n = static_cast<int>(mesh.V.rows());
    const MeshTopology topology(mesh.F, n);
    const LoopLimitEvaluator evaluator(topology);
    std::vector<FaceSample> samples;
    std::uniform_real_distribution<double> unit(0, 1);
    for (int f = 0; f < topology.face_count(); ++f)
      for (int s = 0; s < 5; ++s) {
        double u = unit(random), v = unit(random);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        samples.push_back({f, u, v});
      }
    samples.push_back({0, 0, 0});
    SparseMatrix l_u, l_v;
    const SparseMatrix l = evaluator.LimitMatrix(samples, &l_u, &l_v);
    ASSERT_EQ(l.rows(), static_cast<Eigen::Index>(samples.size()));
    ASSERT_EQ(l.cols(), n);
    const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
    EXPECT_LT(((l * ones).array() - 1).abs().maxCoeff(), 1e-13);
    EXPECT_LT((l_u * ones).cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_LT((l_v * ones).cwiseAbs().maxCoeff(), 1e-11);
    const Positions s = l * mesh.V, s_u = l_u * mesh.V, s_v = l_v * mesh.V;
    for (size_t i = 0; i < samples.size(); ++i) {
      const LimitPoint p = evaluator.Evaluate(samples[i].face, samples[i].u, samples[i].v, mesh.V);
      EXPECT_LT((s.row(i) - p.position).norm(), 1e-13);
      EXPECT_LT((s_u.row(i) - p.du).norm(), 1e-12 * (1 + p.du.norm()));
      EXPECT_LT((s_v.row(i) - p.dv).norm(), 1e-12 * (1 + p.dv.norm()));
    }
    for (int r = 0; r < l.outerSize(); ++r)  // columns sorted and distinct within a row
      for (int k = l.outerIndexPtr()[r] + 1; k < l.outerIndexPtr()[r + 1]; ++k)
        EXPECT_LT(l.innerIndexPtr()[k - 1], l.innerIndexPtr()[k]);
  }
}

// (5) normals at corners: du × dv ∥ Loop's limit normal. Interior: tangent masks
// Σ cos/sin(2πk/K) r_k. Boundary vertex with k ≠ 3 faces: along = r_0 − r_k and the left
// eigenvector of its 1-ring subdivision matrix S for µ = 3/8 + cos(π/k)/4 (1/4 if k = 1),
// computed here from S (the code solves for it in closed form).
TEST(LoopLimitEvaluator, CornerNormalsAreLoopsLimitNormals) {
  for (const TriangleMesh& mesh : Meshes()) {
    const int n = static_cast<int>(mesh.V.rows());
    const MeshTopology topology(mesh.F, n);
    const LoopLimitEvaluator evaluator(topology);
    for (int f = 0; f < topology.face_count(); ++f)
      for (int corner = 0; corner < 3; ++corner) {
        const int w = mesh.F(f, corner);
        const IndexRange ring = topology.Ring(w);
        const int size = ring.size();
        const Eigen::RowVector3d normal = evaluator.Evaluate(f, corner == 1, corner == 2, mesh.V).Normal();
        Eigen::RowVector3d expected;
        if (!topology.IsBoundaryVertex(w)) {
          Eigen::RowVector3d t1 = Eigen::RowVector3d::Zero(), t2 = Eigen::RowVector3d::Zero();
          for (int k = 0; k < size; ++k) {
            t1 += std::cos(2 * kPi * k / size) * mesh.V.row(ring[k]);
            t2 += std::sin(2 * kPi * k / size) * mesh.V.row(ring[k]);
          }
          expected = t1.cross(t2).normalized();
        } else {
          const int faces = size - 1;
          if (faces == 3) continue;  // regular: the ghost-vertex box spline, tested elsewhere
          Eigen::MatrixXd s = Eigen::MatrixXd::Zero(size + 1, size + 1);  // index 0 = w
          s(0, 0) = 0.75, s(0, 1) += 0.125, s(0, size) += 0.125;
          s(1, 0) = s(1, 1) = 0.5;
          s(size, 0) = s(size, size) = 0.5;
          for (int i = 2; i < size; ++i)
            s(i, 0) = s(i, i) = 0.375, s(i, i - 1) = s(i, i + 1) = 0.125;
          const double mu = faces == 1 ? 0.25 : 0.375 + std::cos(kPi / faces) / 4;
          Eigen::FullPivLU<Eigen::MatrixXd> lu(s.transpose() - mu * Eigen::MatrixXd::Identity(size + 1, size + 1));
          ASSERT_EQ(lu.kernel().cols(), 1);
          const Eigen::VectorXd l = lu.kernel().col(0);
          Eigen::RowVector3d across = l[0] * mesh.V.row(w), along = mesh.V.row(ring[0]) - mesh.V.row(ring[size - 1]);
          for (int i = 0; i < size; ++i) across += l[i + 1] * mesh.V.row(ring[i]);
          expected = along.cross(across).normalized();
          // Orientation: like the face's own normal.
          const Eigen::RowVector3d face_normal = (mesh.V.row(mesh.F(f, 1)) - mesh.V.row(mesh.F(f, 0)))
                                                     .cross(mesh.V.row(mesh.F(f, 2)) - mesh.V.row(mesh.F(f, 0)));
          if (expected.dot(face_normal) < 0) expected = -expected;
        }
        EXPECT_GT(normal.dot(expected), 1 - 1e-12) << "face " << f << " corner " << corner;
      }
  }
}

// Near an extraordinary corner (u = v = 2^−40, sub-patch level 41) the normal du × dv has
// converged to the limit normal: the error decays like (λ₂/λ₁)^n, λ₁ the subdominant
// eigenvalue and λ₂ the next; < 1e−5 for every valence here (K = 9: (0.418/0.567)^40 ≈ 5e−6).
TEST(LoopLimitEvaluator, NormalsNearExtraordinaryCornersConvergeToTheLimitNormal) {
  for (const TriangleMesh& mesh : Meshes()) {
    const MeshTopology topology(mesh.F, static_cast<int>(mesh.V.rows()));
    const LoopLimitEvaluator evaluator(topology);
    for (int f = 0; f < topology.face_count(); ++f) {
      if (topology.IsBoundaryVertex(mesh.F(f, 0)) || topology.Valence(mesh.F(f, 0)) == 6) continue;
      const double d = std::ldexp(1.0, -40);
      const Eigen::RowVector3d at = evaluator.Evaluate(f, 0, 0, mesh.V).Normal();
      const Eigen::RowVector3d near = evaluator.Evaluate(f, d, d, mesh.V).Normal();
      EXPECT_GT(at.dot(near), 1 - 1e-10) << "face " << f << " valence " << topology.Valence(mesh.F(f, 0));
    }
  }
}

TEST(TessellateLimitSurface, IsAWatertightMeshWithTheControlMeshTopology) {
  for (const TriangleMesh& mesh :
       {Perturbed(MakeIcosphere(1), 0.1, 7), Perturbed(GridPatch(3, 2), 0.1, 8)}) {
    const int n = static_cast<int>(mesh.V.rows());
    const MeshTopology topology(mesh.F, n);
    const LoopLimitEvaluator evaluator(topology);
    for (const int m : {1, 2, 5}) {
      const LimitTessellation t = TessellateLimitSurface(topology, m);
      const int expected = n + topology.edge_count() * (m - 1) + topology.face_count() * (m - 1) * (m - 2) / 2;
      ASSERT_EQ(static_cast<int>(t.samples.size()), expected);
      ASSERT_EQ(t.faces.rows(), topology.face_count() * m * m);
      const MeshTopology fine(t.faces, expected, "tessellation");  // throws if non-manifold
      EXPECT_EQ(fine.UnreferencedVertexCount(), 0);
      EXPECT_EQ(fine.ComponentCount(), topology.ComponentCount());
      EXPECT_EQ(fine.BoundaryEdgeCount(), m * topology.BoundaryEdgeCount());
      EXPECT_EQ(expected - fine.edge_count() + fine.face_count(),
                n - topology.edge_count() + topology.face_count());  // Euler characteristic
      const Positions s = evaluator.LimitMatrix(t.samples) * mesh.V;
      for (int v = 0; v < n; ++v)  // vertex samples: the limit points of the control vertices
        EXPECT_EQ(t.vertex_sample[v], v);
      // Each small triangle is oriented like its control face (no flips on this smooth surface).
      for (int f = 0; f < t.faces.rows(); ++f) {
        const int control_face = f / (m * m);
        const Eigen::RowVector3d nf = (s.row(t.faces(f, 1)) - s.row(t.faces(f, 0))).cross(s.row(t.faces(f, 2)) - s.row(t.faces(f, 0)));
        const Eigen::RowVector3d nc = (mesh.V.row(mesh.F(control_face, 1)) - mesh.V.row(mesh.F(control_face, 0)))
                                          .cross(mesh.V.row(mesh.F(control_face, 2)) - mesh.V.row(mesh.F(control_face, 0)));
        EXPECT_GT(nf.dot(nc), 0) << "m " << m << " triangle " << f;
      }
    }
  }
}

TEST(LoopLimitEvaluator, RejectsBadInput) {
  const TriangleMesh mesh = Octahedron();
  const MeshTopology topology(mesh.F, 6);
  const LoopLimitEvaluator evaluator(topology);
  EXPECT_THROW(evaluator.Stencil(-1, 0.2, 0.2), Error);
  EXPECT_THROW(evaluator.Stencil(8, 0.2, 0.2), Error);
  EXPECT_THROW(evaluator.Stencil(0, -0.1, 0.2), Error);
  EXPECT_THROW(evaluator.Stencil(0, 0.6, 0.5), Error);
  EXPECT_THROW(evaluator.Stencil(0, std::nan(""), 0.5), Error);
  EXPECT_NO_THROW(evaluator.Stencil(0, 0.6, 0.4 + 1e-15));  // rounding-level excess is accepted
  EXPECT_THROW(evaluator.Evaluate(0, 0.2, 0.2, Positions::Zero(5, 3)), Error);
  EXPECT_THROW(TessellateLimitSurface(topology, 0), Error);
  Faces pillow(2, 3);  // two triangles glued along all edges: interior valence 2
  pillow << 0, 1, 2, 0, 2, 1;
  const MeshTopology pillow_topology(pillow, 3);
  EXPECT_THROW(LoopLimitEvaluator{pillow_topology}, Error);
}

}  // namespace
}  // namespace subflow::geometry
