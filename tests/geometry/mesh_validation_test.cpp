#include "geometry/mesh_validation.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "geometry/mesh_io.h"

namespace subflow::geometry {
namespace {

// Axis-aligned box, 8 vertices (index x + 2y + 4z), 12 faces counter-clockwise seen
// from outside.
TriangleMesh Box(const Eigen::Vector3d& corner, const Eigen::Vector3d& size) {
  TriangleMesh mesh;
  mesh.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    for (int axis = 0; axis < 3; ++axis)
      mesh.V(i, axis) = corner(axis) + size(axis) * ((i >> axis) & 1);
  mesh.F.resize(12, 3);
  mesh.F << 0, 2, 3, 0, 3, 1,  // z = 0
      4, 5, 7, 4, 7, 6,        // z = 1
      0, 1, 5, 0, 5, 4,        // y = 0
      2, 6, 7, 2, 7, 3,        // y = 1
      0, 4, 6, 0, 6, 2,        // x = 0
      1, 3, 7, 1, 7, 5;        // x = 1
  return mesh;
}

TriangleMesh UnitCube() { return Box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()); }

TriangleMesh Union(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh mesh;
  mesh.V.resize(a.vertex_count() + b.vertex_count(), 3);
  mesh.V << a.V, b.V;
  mesh.F.resize(a.face_count() + b.face_count(), 3);
  mesh.F << a.F, (b.F.array() + a.vertex_count()).matrix();
  return mesh;
}

// Torus (R, r) sampled on an nu × nv grid, faces counter-clockwise seen from outside.
TriangleMesh Torus(int nu, int nv, double R, double r) {
  TriangleMesh mesh;
  mesh.V.resize(nu * nv, 3);
  mesh.F.resize(2 * nu * nv, 3);
  auto index = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
      mesh.V.row(index(i, j)) << (R + r * std::cos(v)) * std::cos(u),
          (R + r * std::cos(v)) * std::sin(u), r * std::sin(v);
      mesh.F.row(2 * index(i, j)) << index(i, j), index(i + 1, j), index(i + 1, j + 1);
      mesh.F.row(2 * index(i, j) + 1) << index(i, j), index(i + 1, j + 1), index(i, j + 1);
    }
  return mesh;
}

bool Mentions(const std::vector<std::string>& messages, const std::string& fragment) {
  for (const std::string& message : messages)
    if (message.find(fragment) != std::string::npos) return true;
  return false;
}

TEST(MeshValidation, UnitCubeFiguresAreExact) {
  const MeshValidationReport report = ValidateMesh(UnitCube());
  EXPECT_EQ(report.vertex_count, 8);
  EXPECT_EQ(report.face_count, 12);
  EXPECT_EQ(report.edge_count, 18);
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.manifold);
  EXPECT_TRUE(report.consistently_oriented);
  EXPECT_TRUE(report.outward_oriented);
  EXPECT_EQ(report.component_count, 1);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_EQ(report.genus, 0);
  // Sums of a dozen exactly representable terms: rounding error only (1e-14).
  EXPECT_NEAR(report.signed_volume, 1.0, 1e-14);
  EXPECT_NEAR(report.surface_area, 6.0, 1e-14);
  EXPECT_NEAR(report.min_edge_length, 1.0, 1e-15);
  EXPECT_NEAR(report.max_edge_length, std::sqrt(2.0), 1e-15);
  EXPECT_EQ(report.bbox_max, Eigen::Vector3d::Ones());
  EXPECT_EQ(report.degenerate_face_count, 0);
  EXPECT_TRUE(report.cgal.ran);
  EXPECT_TRUE(report.tetgen.ran) << report.tetgen.note;
  EXPECT_FALSE(report.cgal.found());
  EXPECT_FALSE(report.tetgen.found());
  EXPECT_TRUE(report.self_intersecting_faces_agree);
  EXPECT_TRUE(report.valid()) << report.FullReport();
  EXPECT_TRUE(report.warnings.empty()) << report.FullReport();
}

TEST(MeshValidation, BlobGroundTruthIsAClosedGenusZeroSurfaceOfTheExpectedVolume) {
  const std::string path =
      std::string(SUBFLOW_SHARED_DIR) + "/data/blob/groundtruth/mesh/000000.ply";
  const TriangleMesh mesh = ReadMesh(path);
  const MeshValidationReport report = ValidateMesh(mesh, {}, path);
  EXPECT_EQ(report.vertex_count, 10242);
  EXPECT_EQ(report.face_count, 20480);
  EXPECT_EQ(report.edge_count, 30720);
  EXPECT_TRUE(report.closed);
  EXPECT_TRUE(report.manifold);
  EXPECT_TRUE(report.outward_oriented);
  EXPECT_EQ(report.genus, 0);
  EXPECT_EQ(report.component_count, 1);
  ASSERT_TRUE(report.cgal.ran);
  ASSERT_TRUE(report.tetgen.ran) << report.tetgen.note;
  EXPECT_FALSE(report.cgal.found());
  EXPECT_FALSE(report.tetgen.found());
  EXPECT_TRUE(report.valid()) << report.FullReport();
  // A sphere of radius r = 0.1 m displaced along its normals by travelling sinusoids,
  // |h| ≤ 8 mm (data/blob/README.md): V / V_sphere = <(1 + h/r)³> over the sphere. With
  // |k|·r ≥ 2.8 the sinusoids nearly average out, leaving 3<h²>/r² ≤ 3·0.08²/2 ≈ 1 %, and
  // the inscribed icosphere loses ~0.2 %: 3 % covers both.
  const double sphere_volume = 4.0 / 3.0 * M_PI * std::pow(0.1, 3);
  EXPECT_NEAR(report.signed_volume / sphere_volume, 1.0, 0.03);
  // Tighter, from the data itself: the vertices of the (near-uniform) icosphere sample the
  // solid angle evenly, so V ≈ (4π/3)·mean(ρ³), ρ = distance to the vertex centroid. The
  // uneven icosphere cells and the polyhedral deficit stay below 0.5 %.
  const Eigen::RowVector3d centroid = mesh.V.colwise().mean();
  const double mean_cube = (mesh.V.rowwise() - centroid).rowwise().norm().array().cube().mean();
  EXPECT_NEAR(report.signed_volume / (4.0 / 3.0 * M_PI * mean_cube), 1.0, 0.005);
}

TEST(MeshValidation, InterpenetratingBoxesAreFoundByCgalAndTetgen) {
  // Generic offset: no coplanar faces, no vertex on another box's face.
  const TriangleMesh mesh =
      Union(UnitCube(), Box(Eigen::Vector3d(0.5, 0.37, 0.29), Eigen::Vector3d(1.0, 1.1, 0.9)));
  const MeshValidationReport report = ValidateMesh(mesh);
  EXPECT_TRUE(report.manifold);
  EXPECT_EQ(report.component_count, 2);
  ASSERT_TRUE(report.cgal.ran);
  ASSERT_TRUE(report.tetgen.ran) << report.tetgen.note;
  EXPECT_TRUE(report.cgal.found());
  EXPECT_TRUE(report.tetgen.found());
  EXPECT_GT(report.cgal.pair_count, 0);
  EXPECT_TRUE(report.self_intersection_checks_agree);
  EXPECT_TRUE(report.self_intersecting_faces_agree)
      << report.cgal.reported_face_count << " vs " << report.tetgen.reported_face_count;
  // Every reported pair mixes one face of each box.
  for (const auto& [i, j] : report.cgal.example_pairs)
    EXPECT_TRUE(i < 12 && j >= 12) << i << " " << j;
  EXPECT_FALSE(report.valid());
  EXPECT_TRUE(Mentions(report.problems, "intersecting faces found by CGAL")) << report.FullReport();
  EXPECT_TRUE(Mentions(report.problems, "found by TetGen")) << report.FullReport();

  // Separated boxes do not intersect.
  const MeshValidationReport apart = ValidateMesh(
      Union(UnitCube(), Box(Eigen::Vector3d(1.5, 0.37, 0.29), Eigen::Vector3d::Ones())));
  EXPECT_FALSE(apart.cgal.found());
  EXPECT_FALSE(apart.tetgen.found());
  EXPECT_TRUE(apart.valid()) << apart.FullReport();
}

TEST(MeshValidation, FlatPatchesAreCheckedByBothTests) {
  // TetGen aborts on a bounding box that is flat along an axis unless it is lifted; the
  // planar patch must be checked, not crash the process.
  TriangleMesh square;
  square.V.resize(4, 3);
  square.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;
  square.F.resize(2, 3);
  square.F << 0, 1, 2, 1, 3, 2;
  const MeshValidationReport flat = ValidateMesh(square);
  ASSERT_TRUE(flat.tetgen.ran) << flat.tetgen.note;
  EXPECT_FALSE(flat.tetgen.found());
  EXPECT_FALSE(flat.cgal.found());
  EXPECT_TRUE(flat.valid()) << flat.FullReport();

  // Two coplanar triangles overlapping in the plane z = 0.
  TriangleMesh overlap;
  overlap.V.resize(6, 3);
  overlap.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0, 1.2, 0.2, 0, 0.2, 1.2, 0;
  overlap.F.resize(2, 3);
  overlap.F << 0, 1, 2, 3, 4, 5;
  const MeshValidationReport report = ValidateMesh(overlap);
  EXPECT_EQ(report.cgal.pair_count, 1);
  EXPECT_EQ(report.tetgen.reported_face_count, 2);
  EXPECT_TRUE(report.self_intersecting_faces_agree);
}

TEST(MeshValidation, InwardOrientationGivesNegativeVolumeAndIsInvalid) {
  TriangleMesh mesh = UnitCube();
  mesh.F.col(1).swap(mesh.F.col(2));
  const MeshValidationReport report = ValidateMesh(mesh);
  EXPECT_TRUE(report.consistently_oriented);
  EXPECT_NEAR(report.signed_volume, -1.0, 1e-14);
  EXPECT_FALSE(report.outward_oriented);
  EXPECT_FALSE(report.valid());
  EXPECT_TRUE(Mentions(report.problems, "oriented inward"));
}

TEST(MeshValidation, OneFlippedFaceIsAnOrientationError) {
  TriangleMesh mesh = UnitCube();
  std::swap(mesh.F(5, 1), mesh.F(5, 2));
  const MeshValidationReport report = ValidateMesh(mesh);
  EXPECT_TRUE(report.manifold);
  EXPECT_EQ(report.inconsistent_edge_count, 3);  // each edge of the flipped face
  EXPECT_FALSE(report.consistently_oriented);
  EXPECT_EQ(report.genus, -1);
  EXPECT_FALSE(report.topology_message.empty());  // MeshTopology requires orientation
  EXPECT_FALSE(report.cgal.ran);
  EXPECT_FALSE(report.valid());
}

TEST(MeshValidation, OpenMeshReportsItsBoundaryAndStaysValid) {
  TriangleMesh cube = UnitCube();
  TriangleMesh open;
  open.V = cube.V;
  open.F = cube.F.bottomRows(10);  // without the two faces at z = 0
  const MeshValidationReport report = ValidateMesh(open);
  EXPECT_FALSE(report.closed);
  EXPECT_EQ(report.boundary_edge_count, 4);
  EXPECT_EQ(report.boundary_loop_count, 1);
  EXPECT_EQ(report.edge_count, 17);
  EXPECT_EQ(report.euler_characteristic, 1);  // a disk
  EXPECT_EQ(report.genus, 0);
  EXPECT_FALSE(report.outward_oriented);
  EXPECT_TRUE(report.valid()) << report.FullReport();
  EXPECT_TRUE(Mentions(report.warnings, "boundary edges 4, boundary loops 1"));
}

TEST(MeshValidation, TorusHasGenusOne) {
  const MeshValidationReport report = ValidateMesh(Torus(24, 12, 1.0, 0.4));
  EXPECT_TRUE(report.closed);
  EXPECT_EQ(report.euler_characteristic, 0);
  EXPECT_EQ(report.genus, 1);
  // Inscribed polyhedron: volume a little below 2π²Rr² (12 samples around the tube lose
  // ~4.5 % of the cross-section, 24 around the axis ~1 %).
  EXPECT_NEAR(report.signed_volume / (2 * M_PI * M_PI * 0.16), 0.95, 0.03);
  EXPECT_TRUE(report.valid()) << report.FullReport();
}

TEST(MeshValidation, FinAndBowtieAreNonManifoldAndReportedWithoutThrowing) {
  TriangleMesh fin;
  fin.V.resize(5, 3);
  fin.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  fin.F.resize(3, 3);
  fin.F << 0, 1, 2, 1, 0, 3, 1, 0, 4;
  const MeshValidationReport fin_report = ValidateMesh(fin);
  EXPECT_EQ(fin_report.non_manifold_edge_count, 1);
  EXPECT_FALSE(fin_report.manifold);
  EXPECT_NE(fin_report.topology_message.find("edge (1, 0)"), std::string::npos)
      << fin_report.topology_message;
  EXPECT_FALSE(fin_report.cgal.ran);
  EXPECT_TRUE(fin_report.tetgen.ran) << fin_report.tetgen.note;
  EXPECT_FALSE(fin_report.valid());

  TriangleMesh bowtie;
  bowtie.V.resize(5, 3);
  bowtie.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
  bowtie.F.resize(2, 3);
  bowtie.F << 0, 1, 2, 0, 3, 4;
  const MeshValidationReport bowtie_report = ValidateMesh(bowtie);
  EXPECT_EQ(bowtie_report.non_manifold_edge_count, 0);
  EXPECT_EQ(bowtie_report.non_manifold_vertex_count, 1);
  EXPECT_FALSE(bowtie_report.manifold);
  EXPECT_TRUE(Mentions(bowtie_report.problems, "bowtie"));
}

TEST(MeshValidation, DegenerateAndRepeatedVertexFacesAreCounted) {
  TriangleMesh mesh = UnitCube();
  mesh.V.conservativeResize(10, 3);
  mesh.V.row(8) << 2, 0, 0;
  mesh.V.row(9) << 4, 0, 0;  // 1, 8, 9 are collinear
  mesh.F.conservativeResize(14, 3);
  mesh.F.row(12) << 1, 8, 9;
  mesh.F.row(13) << 8, 8, 9;
  const MeshValidationReport report = ValidateMesh(mesh);
  EXPECT_EQ(report.degenerate_face_count, 1);
  EXPECT_EQ(report.repeated_vertex_face_count, 1);
  EXPECT_FALSE(report.valid());
  EXPECT_THROW(ValidateMesh(TriangleMesh{mesh.V, (mesh.F.array() + 5).matrix()}), Error);
}

TEST(MeshValidation, NonFiniteCoordinatesAreReportedAndSkipGeometry) {
  TriangleMesh mesh = UnitCube();
  mesh.V(3, 1) = std::nan("");
  const MeshValidationReport report = ValidateMesh(mesh);
  EXPECT_EQ(report.non_finite_vertex_count, 1);
  EXPECT_TRUE(std::isnan(report.signed_volume));
  EXPECT_FALSE(report.cgal.ran);
  EXPECT_FALSE(report.tetgen.ran);
  EXPECT_FALSE(report.valid());
}

TEST(MeshValidation, OptionsSkipTheIntersectionTestsAndJsonCarriesTheFigures) {
  MeshValidationOptions options;
  options.check_self_intersections_cgal = false;
  options.check_self_intersections_tetgen = false;
  const MeshValidationReport report = ValidateMesh(UnitCube(), options);
  EXPECT_FALSE(report.cgal.ran);
  EXPECT_FALSE(report.tetgen.ran);
  EXPECT_TRUE(report.valid());
  const nlohmann::json json = nlohmann::json::parse(report.ToJson());
  EXPECT_EQ(json["valid"], true);
  EXPECT_EQ(json["counts"]["edges"], 18);
  EXPECT_EQ(json["topology"]["genus"], 0);
  EXPECT_NEAR(json["geometry"]["signed_volume"].get<double>(), 1.0, 1e-14);
  EXPECT_EQ(json["self_intersections"]["cgal"]["ran"], false);
  EXPECT_NE(report.FullReport().find("verdict: valid"), std::string::npos);

  options.max_example_pairs = -1;
  EXPECT_THROW(ValidateMesh(UnitCube(), options), Error);
}

}  // namespace
}  // namespace subflow::geometry
