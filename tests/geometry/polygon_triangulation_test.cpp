// Claims about polygon faces (geometry/polygon_triangulation.h and the readers): a closed
// cube of six quads, in OBJ and in PLY (ascii, binary of either byte order), reads as a
// closed, consistently oriented manifold of 12 triangles enclosing volume 1; non-convex
// planar polygons are tiled exactly (k − 2 triangles of the polygon's orientation whose
// areas add up to the polygon's, checked against the shoelace formula on random star
// polygons); degenerate polygons still give k − 2 triangles on their own corners.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/mesh_io.h"
#include "geometry/mesh_topology.h"
#include "geometry/mesh_validation.h"
#include "geometry/obj_io.h"
#include "geometry/ply_io.h"
#include "geometry/polygon_triangulation.h"

namespace subflow::geometry {
namespace {

const char* kCubeVertices[8] = {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"};
const int kCubeQuads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

std::string CubeObj() {
  std::string text = "# unit cube, outward quads\n";
  for (const char* v : kCubeVertices) text += std::string("v ") + v + "\n";
  for (const auto& quad : kCubeQuads)
    text += "f " + std::to_string(quad[0] + 1) + "/1 " + std::to_string(quad[1] + 1) + "/1 " +
            std::to_string(quad[2] + 1) + "/1 " + std::to_string(quad[3] + 1) + "/1\n";
  return text;
}

std::string CubePly(const std::string& format) {
  std::string text = "ply\nformat " + format +
                     " 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 6\nproperty list uchar int vertex_indices\nend_header\n";
  const bool big = format == "binary_big_endian";
  auto append = [&](const void* value, int size) {
    unsigned char raw[4];
    std::memcpy(raw, value, size);
    for (int i = 0; i < size; ++i) text += static_cast<char>(raw[big ? size - 1 - i : i]);
  };
  for (const char* v : kCubeVertices) {
    if (format == "ascii") {
      text += std::string(v) + "\n";
      continue;
    }
    for (int axis = 0; axis < 3; ++axis) {
      const float coordinate = static_cast<float>(v[2 * axis] - '0');
      append(&coordinate, 4);
    }
  }
  for (const auto& quad : kCubeQuads) {
    if (format == "ascii") {
      text += "4 " + std::to_string(quad[0]) + " " + std::to_string(quad[1]) + " " +
              std::to_string(quad[2]) + " " + std::to_string(quad[3]) + "\n";
      continue;
    }
    text += static_cast<char>(4);
    for (int k = 0; k < 4; ++k) {
      const std::int32_t index = quad[k];
      append(&index, 4);
    }
  }
  return text;
}

void ExpectClosedUnitCube(const TriangleMesh& mesh, const std::string& what) {
  ASSERT_EQ(mesh.face_count(), 12) << what;
  ASSERT_EQ(mesh.vertex_count(), 8) << what;
  MeshValidationOptions options;
  options.check_self_intersections_tetgen = false;
  const MeshValidationReport report = ValidateMesh(mesh, options, what);
  EXPECT_TRUE(report.valid()) << what << "\n" << report.FullReport();
  EXPECT_TRUE(MeshTopology(mesh.F, mesh.vertex_count(), what).IsClosed()) << what;
  double volume = 0;  // divergence theorem: Σ v0 · (v1 × v2) / 6, positive when outward
  for (int f = 0; f < mesh.face_count(); ++f)
    volume += Eigen::Vector3d(mesh.V.row(mesh.F(f, 0)))
                  .dot(Eigen::Vector3d(mesh.V.row(mesh.F(f, 1))).cross(Eigen::Vector3d(mesh.V.row(mesh.F(f, 2))))) / 6;
  EXPECT_NEAR(volume, 1.0, 1e-12) << what;  // exact up to rounding of small integers
}

TEST(PolygonFaces, ClosedQuadCubeReadsAsAClosedOutwardTriangleMeshInObjAndPly) {
  ExpectClosedUnitCube(ParseObj(CubeObj(), "cube.obj"), "cube.obj");
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"})
    ExpectClosedUnitCube(ParsePly(CubePly(format), "cube.ply"), "cube.ply " + format);
}

double SignedArea(const std::vector<Eigen::Vector2d>& polygon) {
  double area = 0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& p = polygon[i];
    const Eigen::Vector2d& q = polygon[(i + 1) % polygon.size()];
    area += (p.x() * q.y() - p.y() * q.x()) / 2;
  }
  return area;
}

// A random star-shaped polygon (non-convex) in a random plane of space; triangulation must
// tile it: k − 2 triangles whose (signed, in the plane's orientation) areas add up to the
// shoelace area and are each positive.
TEST(PolygonFaces, RandomNonConvexPlanarPolygonsAreTiledExactly) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> radius(0.2, 1.0), unit(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int k = 4 + trial % 29;
    std::vector<Eigen::Vector2d> polygon(k);
    for (int i = 0; i < k; ++i) {
      const double angle = 2 * M_PI * (i + 0.4 * unit(random)) / k;
      polygon[i] = radius(random) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    const bool clockwise = trial % 2 == 1;  // either winding keeps its orientation
    if (clockwise) std::reverse(polygon.begin(), polygon.end());
    const Eigen::Matrix3d frame =
        Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized().toRotationMatrix();
    Positions V(k, 3);
    for (int i = 0; i < k; ++i) V.row(i) = frame * Eigen::Vector3d(polygon[i].x(), polygon[i].y(), 0.0);
    PolygonFaces faces;
    std::vector<int> corners(k);
    for (int i = 0; i < k; ++i) corners[i] = i;
    faces.Add(corners.data(), k);
    int polygons = 0;
    const Faces F = TriangulatePolygons(faces, V, &polygons);
    ASSERT_EQ(F.rows(), k - 2) << trial;
    EXPECT_EQ(polygons, 1);
    const Eigen::Vector3d normal = frame.col(2);
    double area = 0;
    for (int t = 0; t < F.rows(); ++t) {
      const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
      const double signed_area = (b - a).cross(c - a).dot(normal) / 2;
      EXPECT_GT(signed_area * (clockwise ? -1 : 1), 0) << "trial " << trial << " triangle " << t;
      area += signed_area;
    }
    EXPECT_NEAR(area, SignedArea(polygon), 1e-12) << trial;
  }
}

TEST(PolygonFaces, DegeneratePolygonsKeepEveryCorner) {
  // Collinear corners (zero area), a repeated position, a non-planar quad.
  Positions V(6, 3);
  V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 0, 1, 0.3, 1, 1, -0.3;
  PolygonFaces faces;
  const int collinear[4] = {0, 1, 2, 3}, repeated[5] = {0, 1, 1, 5, 4}, skew[4] = {0, 1, 5, 4};
  faces.Add(collinear, 4);
  faces.Add(repeated, 5);
  faces.Add(skew, 4);
  const Faces F = TriangulatePolygons(faces, V);
  ASSERT_EQ(F.rows(), 2 + 3 + 2);
  EXPECT_TRUE((F.array() >= 0).all() && (F.array() < 6).all());
  // Every corner of each polygon appears in its triangles.
  for (int v : {0, 1, 2, 3}) EXPECT_TRUE((F.topRows(2).array() == v).any()) << v;
  for (int v : {0, 1, 4, 5}) EXPECT_TRUE((F.bottomRows(2).array() == v).any()) << v;
}

TEST(PolygonFaces, TooFewOrTooManyCornersAreRefusedNamingTheFace) {
  try {
    ParseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n", "two.obj");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "two.obj: line 5 (face 1): has 2 vertices; expected a polygon of at least 3");
  }
  std::string big = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i <= kMaxPolygonCorners; ++i) big += " " + std::to_string(1 + i % 3);
  EXPECT_THROW(ParseObj(big + "\n", "big.obj"), Error);
}

}  // namespace
}  // namespace subflow::geometry
