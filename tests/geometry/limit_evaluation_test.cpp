// Claims: LoopLimitEvaluator evaluates the Loop limit surface exactly — at face corners it
// gives Loop's limit masks, it is continuous (positions and tangent planes) across edges,
// and at dyadic interior points it equals the limit of CGAL's repeated Loop subdivision —
// on regular faces, on faces with one extraordinary corner of valence 3, 4, 5, 7, 9
// (Stam's method), on faces with several (local refinement) and on an open mesh (boundary
// rules, ghost-vertex box splines); its derivatives are those of the surface; L c = s.
//
// Independent reference: CGAL::Subdivision_method_3::Loop_subdivision refines the mesh; a
// dyadic point (i/2^l, j/2^l) of a face is a vertex of the l-times refined mesh (tracked
// through the refinements as the common new neighbour of its two lattice neighbours), and
// Loop's limit mask (written out here) applied to that vertex's 1-ring in CGAL's mesh is
// its exact limit position.
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/limit_evaluation.h"
#include "geometry/limit_tessellation.h"
#include "geometry/loop_box_spline.h"
#include "geometry/mesh_primitives.h"
#include "geometry/mesh_topology.h"
#include "tests/test_support.h"

namespace subflow::geometry {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
constexpr double kPi = 3.14159265358979323846;

// Positions are O(1) (unit-sphere primitives, perturbed by 0.1) and every evaluated point
// is a short affine combination (≤ ~40 weights of O(1)) from a few refinement steps, on
// both sides; 1e-12 leaves ~3 orders of magnitude over rounding, while any wrong weight
// or index moves a point by ≥ 1e-4.
constexpr double kExact = 1e-12;

using test::Perturbed;

// CGAL's Loop subdivision: levels[0] = mesh, levels[l] = l steps (old vertices keep their
// indices; CGAL appends one vertex per edge).
std::vector<TriangleMesh> CgalLevels(const TriangleMesh& mesh, int levels) {
  SurfaceMesh surface;
  std::vector<SurfaceMesh::Vertex_index> vertices;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
    vertices.push_back(surface.add_vertex(Kernel::Point_3(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2))));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    surface.add_face(vertices[mesh.F(f, 0)], vertices[mesh.F(f, 1)], vertices[mesh.F(f, 2)]);
  std::vector<TriangleMesh> result = {mesh};
  for (int l = 0; l < levels; ++l) {
    CGAL::Subdivision_method_3::Loop_subdivision(surface, CGAL::parameters::number_of_iterations(1));
    TriangleMesh refined;
    refined.V.resize(surface.number_of_vertices(), 3);
    for (const auto v : surface.vertices())
      refined.V.row(v.idx()) << surface.point(v).x(), surface.point(v).y(), surface.point(v).z();
    refined.F.resize(surface.number_of_faces(), 3);
    int f = 0;
    for (const auto face : surface.faces()) {
      int k = 0;
      for (const auto v : CGAL::vertices_around_face(surface.halfedge(face), surface))
        refined.F(f, k++) = static_cast<int>(v.idx());
      ++f;
    }
    result.push_back(std::move(refined));
  }
  return result;
}

// Loop's limit mask at vertex w (independent of the code under test).
Eigen::RowVector3d LimitMask(const TriangleMesh& mesh, const MeshTopology& topology, int w) {
  const IndexRange ring = topology.Ring(w);
  const int n = ring.size();
  if (topology.IsBoundaryVertex(w))
    return 2.0 / 3.0 * mesh.V.row(w) + (mesh.V.row(ring.front()) + mesh.V.row(ring.back())) / 6.0;
  const double t = 3.0 + 2.0 * std::cos(2.0 * kPi / n);
  const double beta = (5.0 / 8.0 - t * t / 64.0) / n;
  const double chi = 1.0 / (3.0 / (8.0 * beta) + n);
  Eigen::RowVector3d s = (1.0 - n * chi) * mesh.V.row(w);
  for (const int r : ring) s += chi * mesh.V.row(r);
  return s;
}

// Vertex of levels[start + depth] at the dyadic point (i, j)/2^depth of face `face` of
// levels[start], for all i + j ≤ 2^depth.
std::map<std::pair<int, int>, int> DyadicVertices(const std::vector<TriangleMesh>& levels,
                                                  int start, int face, int depth) {
  std::map<std::pair<int, int>, int> lattice = {{{0, 0}, levels[start].F(face, 0)},
                                                {{1, 0}, levels[start].F(face, 1)},
                                                {{0, 1}, levels[start].F(face, 2)}};
  for (int l = 0; l < depth; ++l) {
    const TriangleMesh& fine = levels[start + l + 1];
    const MeshTopology topology(fine.F, static_cast<int>(fine.V.rows()));
    const int coarse_count = static_cast<int>(levels[start + l].V.rows());
    const int m = 1 << l;
    std::map<std::pair<int, int>, int> next;
    for (const auto& [p, v] : lattice) next[{2 * p.first, 2 * p.second}] = v;
    auto split = [&](std::pair<int, int> a, std::pair<int, int> b) {
      int found = -1, count = 0;
      for (const int x : topology.Ring(lattice.at(a)))
        for (const int y : topology.Ring(lattice.at(b)))
          if (x == y && x >= coarse_count) found = x, ++count;
      EXPECT_EQ(count, 1) << "edge midpoint not unique";
      next[{a.first + b.first, a.second + b.second}] = found;
    };
    for (int j = 0; j <= m; ++j)
      for (int i = 0; i + j <= m; ++i) {
        if (i + j < m) split({i, j}, {i + 1, j}), split({i, j}, {i, j + 1});
        if (i + j < m) split({i + 1, j}, {i, j + 1});
      }
    lattice = std::move(next);
  }
  return lattice;
}

struct Case {
  std::string name;
  TriangleMesh base;
};

std::vector<Case> Cases() {
  return {{"tetrahedron (valence 3)", Perturbed(Tetrahedron(), 0.1, 1)},
          {"octahedron (valence 4)", Perturbed(Octahedron(), 0.1, 2)},
          {"icosahedron (valence 5)", Perturbed(Icosahedron(), 0.1, 3)},
          {"bipyramid 7 (valences 7, 4)", Perturbed(Bipyramid(7), 0.1, 4)},
          {"bipyramid 9 (valences 9, 4)", Perturbed(Bipyramid(9), 0.1, 5)},
          {"open grid (boundary, valences 4, 8)", Perturbed(GridPatch(3, 3), 0.1, 6)}};
}

// (u, v) of the point at fraction t along half-edge h of its face.
FaceSample PointOnHalfedge(int h, double t) {
  double w[3] = {0, 0, 0};
  w[h % 3] = 1 - t;
  w[(h + 1) % 3] = t;
  return {h / 3, w[1], w[2]};
}

TEST(LoopBoxSpline, BasisIsAPartitionOfUnityWithLoopsLimitMaskAtCorners) {
  std::array<double, 12> b, du, dv;
  for (const auto& [u, v] : std::vector<std::pair<double, double>>{{0.2, 0.3}, {0.7, 0.1}, {0, 0}}) {
    LoopBoxSplineBasis(u, v, &b, &du, &dv);
    double sum = 0, sum_du = 0, sum_dv = 0;
    for (int i = 0; i < 12; ++i) sum += b[i], sum_du += du[i], sum_dv += dv[i];
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_NEAR(sum_du, 0.0, 1e-15);
    EXPECT_NEAR(sum_dv, 0.0, 1e-15);
  }
  LoopBoxSplineBasis(0, 0, &b, &du, &dv);  // corner C0 = control point 3, its ring 0,1,2,4,6,7
  for (int i = 0; i < 12; ++i) {
    const bool ring = i == 0 || i == 1 || i == 2 || i == 4 || i == 6 || i == 7;
    EXPECT_NEAR(b[i], i == 3 ? 0.5 : ring ? 1.0 / 12 : 0.0, 1e-15) << i;
  }
}

// Stam's structure: the subdivision matrix of a patch with one extraordinary corner of
// valence N has Loop's spectrum 1, 5/8 − α(N), 3/8 + cos(2πk/N)/4 (k = 1…N−1) from the
// 1-ring, and 1/8 (×3), 1/16 (×2) from the 5 outer control points.
TEST(StamPatch, SubdivisionMatrixHasLoopsSpectrumAndIsDefectiveForValenceThree) {
  for (int n = 3; n <= 12; ++n) {
    if (n == 6) continue;  // a regular corner: box spline, no Stam patch
    // Faces around C0 = 0 (ring 1…n, C1 = 1, C2 = 2) and around C1 and C2; others open.
    Faces f(n + 7, 3);
    for (int k = 1; k <= n; ++k) f.row(k - 1) << 0, k, k % n + 1;
    const int v6 = n + 1, v10 = n + 2, v11 = n + 3, v12 = n + 4, v9 = n + 5;
    f.row(n) << 1, n, v6;
    f.row(n + 1) << 1, v6, v10;
    f.row(n + 2) << 1, v10, v11;
    f.row(n + 3) << 1, v11, 2;
    f.row(n + 4) << 2, v11, v12;
    f.row(n + 5) << 2, v12, v9;
    f.row(n + 6) << 2, v9, 3;
    const MeshTopology topology(f, n + 6);
    const LoopLimitEvaluator evaluator(topology);
    ASSERT_EQ(evaluator.PatchKind(0), LimitPatchKind::kStam) << "valence " << n;
    const Eigen::MatrixXd& a = evaluator.StamPatchOf(0).subdivision;
    ASSERT_EQ(a.rows(), n + 6);

    const double t = 3 + 2 * std::cos(2 * kPi / n);
    std::vector<double> expected = {1.0, 5.0 / 8 - (5.0 / 8 - t * t / 64), 0.125, 0.125, 0.125,
                                    0.0625, 0.0625};
    for (int k = 1; k < n; ++k) expected.push_back(3.0 / 8 + std::cos(2 * kPi * k / n) / 4);
    Eigen::EigenSolver<Eigen::MatrixXd> solver(a);
    std::vector<double> actual;
    for (int i = 0; i < a.rows(); ++i) {
      EXPECT_LT(std::abs(solver.eigenvalues()[i].imag()), 1e-7) << "valence " << n;
      actual.push_back(solver.eigenvalues()[i].real());
    }
    std::sort(expected.begin(), expected.end());
    std::sort(actual.begin(), actual.end());
    // Repeated eigenvalues of a non-normal matrix are computed to ~sqrt(eps) (N = 3's
    // defective 1/16 to ~eps^(1/3)); 1e-4 still separates every distinct value.
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_NEAR(actual[i], expected[i], 1e-4) << "valence " << n << " eigenvalue " << i;
    // A V = V Λ for the computed eigenpairs.
    const Eigen::MatrixXcd v = solver.eigenvectors();
    EXPECT_LT((a.cast<std::complex<double>>() * v - v * solver.eigenvalues().asDiagonal()).norm(), 1e-12);
    // Why Stam's A^(n−1) = V Λ^(n−1) V⁻¹ is not used: for N = 3 the eigenvalue 1/16 has
    // algebraic multiplicity 3 but only 2 eigenvectors (rank(A − I/16) = K − 2).
    if (n == 3) {
      Eigen::FullPivLU<Eigen::MatrixXd> lu(a - Eigen::MatrixXd::Identity(9, 9) / 16);
      lu.setThreshold(1e-10);
      EXPECT_EQ(9 - lu.rank(), 2);
    }
  }
}

// (1) corners = Loop's limit mask; after 8 CGAL steps the corner's control point is
// exactly S + ρ^8 (c⁰ − S), ρ = 5/8 − α(K) the rate of its only non-tangent mode.
TEST(LoopLimitEvaluator, CornersAreLimitPositionsAndCgalConvergesToThemAtLoopsRate) {
  for (const Case& c : Cases()) {
    const std::vector<TriangleMesh> levels = CgalLevels(c.base, 1);
    for (int level = 0; level <= 1; ++level) {
      const TriangleMesh& mesh = levels[level];
      const MeshTopology topology(mesh.F, static_cast<int>(mesh.V.rows()));
      const LoopLimitEvaluator evaluator(topology);
      for (int f = 0; f < topology.face_count(); ++f)
        for (int k = 0; k < 3; ++k) {
          const LimitPoint p = evaluator.Evaluate(f, k == 1, k == 2, mesh.V);
          EXPECT_LT((p.position - LimitMask(mesh, topology, mesh.F(f, k))).norm(), kExact)
              << c.name << " level " << level << " face " << f << " corner " << k;
        }
    }
  }
  const TriangleMesh base = Perturbed(Tetrahedron(), 0.1, 7);
  const std::vector<TriangleMesh> levels = CgalLevels(base, 8);
  const MeshTopology topology(base.F, 4);
  const LoopLimitEvaluator evaluator(topology);
  const double t = 3 + 2 * std::cos(2 * kPi / 3);
  const double rho = t * t / 64;  // 5/8 − α(3) = 1/16
  for (int f = 0; f < 4; ++f) {
    const Eigen::RowVector3d s = evaluator.Evaluate(f, 0, 0, base.V).position;
    const Eigen::RowVector3d predicted = s + std::pow(rho, 8) * (base.V.row(base.F(f, 0)) - s);
    // 8 levels of CGAL rounding on O(1) coordinates: ~1e-15.
    EXPECT_LT((levels[8].V.row(base.F(f, 0)) - predicted).norm(), 1e-13) << "face " << f;
  }
}

// (3) interior dyadic points equal the limit of the densely refined CGAL mesh.
TEST(LoopLimitEvaluator, DyadicPointsEqualLimitOfCgalRefinement) {
  constexpr int kDepth = 3;  // points (i, j)/8
  for (const Case& c : Cases()) {
    const std::vector<TriangleMesh> levels = CgalLevels(c.base, 1 + kDepth);
    for (int level = 0; level <= 1; ++level) {
      const TriangleMesh& mesh = levels[level];
      const MeshTopology topology(mesh.F, static_cast<int>(mesh.V.rows()));
      const LoopLimitEvaluator evaluator(topology);
      const TriangleMesh& fine = levels[level + kDepth];
      const MeshTopology fine_topology(fine.F, static_cast<int>(fine.V.rows()));
      std::map<LimitPatchKind, int> kinds;
      for (int f = 0; f < topology.face_count(); ++f) {
        ++kinds[evaluator.PatchKind(f)];
        for (const auto& [ij, w] : DyadicVertices(levels, level, f, kDepth)) {
          const double u = ij.first / 8.0, v = ij.second / 8.0;
          EXPECT_LT((evaluator.Evaluate(f, u, v, mesh.V).position - LimitMask(fine, fine_topology, w)).norm(),
                    kExact)
              << c.name << " level " << level << " face " << f << " (u, v) = (" << u << ", " << v << ")";
        }
      }
      if (level == 1 && c.name.rfind("open", 0) != 0) {  // closed level 1: Stam + regular only
        EXPECT_GT(kinds[LimitPatchKind::kStam], 0) << c.name;
        EXPECT_EQ(kinds[LimitPatchKind::kLocalRefinement], 0) << c.name;
      }
    }
  }
}

// (2) continuity: the two faces of an edge give the same point, the same derivative along
// the edge and the same tangent plane.
TEST(LoopLimitEvaluator, SurfaceIsContinuousWithContinuousTangentPlaneAcrossEdges) {
  for (const Case& c : Cases()) {
    const std::vector<TriangleMesh> levels = CgalLevels(c.base, 1);
    for (int level = 0; level <= 1; ++level) {
      const TriangleMesh& mesh = levels[level];
      const MeshTopology topology(mesh.F, static_cast<int>(mesh.V.rows()));
      const LoopLimitEvaluator evaluator(topology);
      for (int h = 0; h < 3 * topology.face_count(); ++h) {
        const int twin = topology.HalfedgeTwin(h);
        if (twin < h) continue;  // boundary, or seen from the other side
        // 2^−30 (near a corner, possibly extraordinary) has an exact complement 1 − t, so
        // both faces are asked for the same point.
        for (const double t : {std::ldexp(1.0, -30), 0.1, 0.37, 0.5, 0.875}) {
          const FaceSample a = PointOnHalfedge(h, t), b = PointOnHalfedge(twin, 1 - t);
          const LimitPoint pa = evaluator.Evaluate(a.face, a.u, a.v, mesh.V);
          const LimitPoint pb = evaluator.Evaluate(b.face, b.u, b.v, mesh.V);
          EXPECT_LT((pa.position - pb.position).norm(), kExact) << c.name << " h " << h << " t " << t;
          // d/dt along the half-edge: corner k → k+1 is (1,0), (−1,1), (0,−1) in (u, v).
          auto along = [](const LimitPoint& p, int k) -> Eigen::RowVector3d {
            return k == 0 ? p.du : k == 1 ? Eigen::RowVector3d(p.dv - p.du) : Eigen::RowVector3d(-p.dv);
          };
          const Eigen::RowVector3d ta = along(pa, h % 3), tb = along(pb, twin % 3);
          EXPECT_LT((ta + tb).norm(), 1e-10 * ta.norm()) << c.name << " h " << h << " t " << t;
          EXPECT_GT(pa.Normal().dot(pb.Normal()), 1 - 1e-12) << c.name << " h " << h << " t " << t;
        }
      }
    }
  }
}

// (4) derivatives = central differences of positions (h = 1e-6: truncation ~h²·|s'''| and
// rounding ~1e-16/h are both ~1e-10 of |du|, so 1e-7 relative is a clear margin).
TEST(LoopLimitEvaluator, DerivativesMatchFiniteDifferences) {
  const double h = 1e-6;
  for (const Case& c : Cases()) {
    const std::vector<TriangleMesh> levels = CgalLevels(c.base, 1);
    for (int level = 0; level <= 1; ++level) {
      const TriangleMesh& mesh = levels[level];
      const MeshTopology topology(mesh.F, static_cast<int>(mesh.V.rows()));
      const LoopLimitEvaluator evaluator(topology);
      for (int f = 0; f < topology.face_count(); ++f)
        for (const auto& [u, v] : std::vector<std::pair<double, double>>{
                 {0.3, 0.25}, {0.1, 0.13}, {0.6, 0.2}, {0.05, 0.02}, {0.2, 0.7}}) {
          const LimitPoint p = evaluator.Evaluate(f, u, v, mesh.V);
          const Eigen::RowVector3d fd_u = (evaluator.Evaluate(f, u + h, v, mesh.V).position -
                                           evaluator.Evaluate(f, u - h, v, mesh.V).position) / (2 * h);
          const Eigen::RowVector3d fd_v = (evaluator.Evaluate(f, u, v + h, mesh.V).position -
                                           evaluator.Evaluate(f, u, v - h, mesh.V).position) / (2 * h);
          const double scale = p.du.norm() + p.dv.norm();
          EXPECT_LT((p.du - fd_u).norm(), 1e-7 * scale) << c.name << " level " << level << " face " << f;
          EXPECT_LT((p.dv - fd_v).norm(), 1e-7 * scale) << c.name << " level " << level << " face " << f;
        }
    }
  }
}

}  // namespace
}  // namespace subflow::geometry
