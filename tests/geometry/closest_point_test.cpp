// ClosestPointTree against closed-form answers on an icosphere and a single triangle, and
// its Embree ray casts against CGAL's exact-predicate traversal.
#include "geometry/closest_point.h"

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"

namespace subflow::geometry {
namespace {

TEST(ClosestPoint, SingleTriangleGivesTheOrthogonalProjectionAndItsBarycentrics) {
  TriangleMesh triangle;
  triangle.V.resize(3, 3);
  triangle.V << 0, 0, 0, 2, 0, 0, 0, 1, 0;
  triangle.F.resize(1, 3);
  triangle.F << 0, 1, 2;
  const ClosestPointTree tree(triangle);
  // Interior: straight down onto the plane z = 0; (u, v) = (x/2, y).
  const SurfacePoint inside = tree.Closest(Eigen::Vector3d(0.5, 0.25, 0.7));
  EXPECT_EQ(inside.face, 0);
  EXPECT_NEAR((inside.point - Eigen::Vector3d(0.5, 0.25, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(inside.distance, 0.7, 1e-15);
  EXPECT_NEAR(inside.barycentric.x(), 0.25, 1e-15);
  EXPECT_NEAR(inside.barycentric.y(), 0.25, 1e-15);
  EXPECT_NEAR((FacePoint(triangle.V, triangle.F, 0, inside.barycentric) - inside.point).norm(), 0.0, 1e-15);
  // Beyond a corner: the corner itself.
  const SurfacePoint corner = tree.Closest(Eigen::Vector3d(3.0, -1.0, 0.0));
  EXPECT_NEAR((corner.point - Eigen::Vector3d(2, 0, 0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(corner.barycentric.x(), 1.0, 1e-15);
  // Rays: hit from above, miss sideways, both directions on a line.
  const RayHit down = tree.FirstHit(Eigen::Vector3d(0.2, 0.2, 1.0), Eigen::Vector3d(0, 0, -2));
  ASSERT_TRUE(down.hit);
  EXPECT_NEAR(down.t, 1.0, 1e-15);  // t is a distance: direction normalized
  EXPECT_NEAR(down.barycentric.x(), 0.1, 1e-15);
  EXPECT_FALSE(tree.FirstHit(Eigen::Vector3d(0.2, 0.2, 1.0), Eigen::Vector3d(0, 0, 1)).hit);
  EXPECT_FALSE(tree.FirstHit(Eigen::Vector3d(0.2, 0.2, 1.0), Eigen::Vector3d(0, 0, -1), 0.5).hit);
  const RayHit line = tree.NearestHitOnLine(Eigen::Vector3d(0.2, 0.2, 1.0), Eigen::Vector3d(0, 0, 1));
  ASSERT_TRUE(line.hit);
  EXPECT_NEAR(line.t, -1.0, 1e-15);
}

TEST(ClosestPoint, IcosphereQueriesAgreeWithTheSphere) {
  // Icosphere of radius 1 with 4 levels: inscribed, sagitta ≤ 1.2e-3, so the distance
  // to the mesh of a point at radius ρ is |ρ − 1| within 1.2e-3.
  const TriangleMesh sphere = MakeIcosphere(4, 1.0);
  const ClosestPointTree tree(sphere);
  std::mt19937 generator(3);
  std::normal_distribution<double> normal;
  Positions queries(500, 3);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d direction = Eigen::Vector3d(normal(generator), normal(generator), normal(generator)).normalized();
    queries.row(i) = ((i % 2 ? 1.5 : 0.6) * direction).transpose();
  }
  const std::vector<SurfacePoint> closest = tree.ClosestPoints(queries);
  const Eigen::VectorXd distances = tree.Distances(queries);
  const std::vector<RayHit> hits = tree.NearestHitsOnLines(queries, queries);  // radial lines
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d q = queries.row(i);
    const double expected = std::abs(q.norm() - 1.0);
    EXPECT_NEAR(closest[i].distance, expected, 1.2e-3);
    EXPECT_NEAR(distances[i], closest[i].distance, 1e-14);
    const Eigen::Vector2d uv = closest[i].barycentric;
    EXPECT_GE(std::min({uv.x(), uv.y(), 1.0 - uv.x() - uv.y()}), -1e-12);
    EXPECT_NEAR((FacePoint(sphere.V, sphere.F, closest[i].face, uv) - closest[i].point).norm(), 0.0, 1e-14);
    ASSERT_TRUE(hits[i].hit);
    EXPECT_NEAR(std::abs(hits[i].t), expected, 1.2e-3);
    EXPECT_EQ(hits[i].t < 0.0, q.norm() > 1.0);  // outside points snap back along −q
    EXPECT_EQ(tree.IsInside(q), q.norm() < 1.0);
    EXPECT_EQ(tree.SignedDistance(q) < 0.0, q.norm() < 1.0);
  }
  EXPECT_EQ(tree.Side(Eigen::Vector3d(5, 0, 0)), PointSide::kOutside);
}

// A bounded cast stops at the first box beyond the bound instead of walking the whole
// ray: every hit within the bound must be exactly (point, face, t) the unbounded cast's,
// and none beyond it may be reported. Rays from points near and far from a bumpy sphere in
// random directions, bounds from a tenth of an edge to the diameter.
TriangleMesh BumpySphere() {
  TriangleMesh bumpy = MakeIcosphere(4, 1.0);
  for (Eigen::Index v = 0; v < bumpy.V.rows(); ++v) {
    const Eigen::Vector3d p = bumpy.V.row(v);
    bumpy.V.row(v) *= 1.0 + 0.15 * std::sin(5 * p.x()) * std::cos(4 * p.y() + p.z());
  }
  return bumpy;
}

class BoundedRayCasts : public testing::TestWithParam<RayEngine> {};

TEST_P(BoundedRayCasts, FindExactlyTheHitsOfUnboundedOnes) {
  const RayEngine engine = GetParam();
  const ClosestPointTree tree(BumpySphere());
  std::mt19937 generator(11);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> radius(0.5, 1.6);
  int hits = 0, compared = 0;
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3d origin =
        radius(generator) * Eigen::Vector3d(normal(generator), normal(generator), normal(generator)).normalized();
    const Eigen::Vector3d direction(normal(generator), normal(generator), normal(generator));
    const double unbounded = std::numeric_limits<double>::infinity();
    const RayHit line = tree.NearestHitOnLine(origin, direction, unbounded, engine);
    const RayHit ray = tree.FirstHit(origin, direction, unbounded, engine);
    for (double bound : {0.005, 0.05, 0.3, 2.0}) {
      const RayHit bounded_line = tree.NearestHitOnLine(origin, direction, bound, engine);
      const RayHit bounded_ray = tree.FirstHit(origin, direction, bound, engine);
      const bool line_within = line.hit && std::abs(line.t) <= bound;
      ASSERT_EQ(bounded_line.hit, line_within) << "ray " << i << ", bound " << bound << ", t " << line.t;
      ASSERT_EQ(bounded_ray.hit, ray.hit && ray.t <= bound) << i << " " << bound;
      if (line_within) {
        EXPECT_EQ(bounded_line.t, line.t);
        EXPECT_EQ(bounded_line.face, line.face);
        EXPECT_EQ(bounded_line.point, line.point);
        ++hits;
      }
      ++compared;
    }
  }
  EXPECT_GT(hits, compared / 4);
}

INSTANTIATE_TEST_SUITE_P(ClosestPoint, BoundedRayCasts, testing::Values(RayEngine::kEmbree, RayEngine::kCgal),
                         [](const testing::TestParamInfo<RayEngine>& info) {
                           return info.param == RayEngine::kEmbree ? "Embree" : "Cgal";
                         });

// Embree intersects in float; the hit's parameter is then recomputed in double on the
// triangle it chose. Against CGAL's exact-predicate traversal, on a bumpy sphere 2 mm
// across placed 1 km from the origin (where float's spacing is 61 µm, thirty thousand
// times the sphere's own rounding): every line finds the same face and the same point
// within 2e-12 / |cos θ| (θ between the line and the face's normal: both intersect a line
// and a plane in double, each rounding coordinates near 1,000 to 1.1e-13; float's
// parameter alone would be ~6e-5 off), unless CGAL's hit lies within 1e-5 of a face's edge, where
// the two may pick either neighbour (counted, and bounded).
TEST(ClosestPoint, EmbreeCastsAgreeWithCgalsExactTraversal) {
  TriangleMesh mesh = BumpySphere();
  const double scale = 1e-3;
  const Eigen::RowVector3d offset(1000.0, -700.0, 250.0);
  mesh.V = (mesh.V * scale).rowwise() + offset;
  const ClosestPointTree tree(mesh);
  std::mt19937 generator(5);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> radius(0.5, 1.6);
  int agreed = 0, near_edges = 0, misses = 0;
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3d origin =
        offset.transpose() +
        scale * radius(generator) * Eigen::Vector3d(normal(generator), normal(generator), normal(generator)).normalized();
    const Eigen::Vector3d direction(normal(generator), normal(generator), normal(generator));
    const double bound = i % 2 ? std::numeric_limits<double>::infinity() : 0.3 * scale;
    const RayHit exact = tree.NearestHitOnLine(origin, direction, bound, RayEngine::kCgal);
    const RayHit fast = tree.NearestHitOnLine(origin, direction, bound, RayEngine::kEmbree);
    if (exact.hit && std::min({exact.barycentric.x(), exact.barycentric.y(),
                               1.0 - exact.barycentric.x() - exact.barycentric.y()}) < 1e-5) {
      ++near_edges;
      continue;
    }
    ASSERT_EQ(fast.hit, exact.hit) << "line " << i << ", t " << exact.t;
    if (!exact.hit) {
      ++misses;
      continue;
    }
    EXPECT_EQ(fast.face, exact.face) << "line " << i;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(exact.face, 0)), b = mesh.V.row(mesh.F(exact.face, 1)),
                          c = mesh.V.row(mesh.F(exact.face, 2));
    const double cosine = std::abs((b - a).cross(c - a).normalized().dot(direction.normalized()));
    const double tolerance = 2e-12 / std::max(cosine, 0.01);
    EXPECT_NEAR(fast.t, exact.t, tolerance) << "line " << i;
    EXPECT_NEAR((fast.point - exact.point).norm(), 0.0, tolerance) << "line " << i;
    EXPECT_NEAR((fast.barycentric - exact.barycentric).norm(), 0.0, tolerance / 1e-5) << "line " << i;  // edges ≈ 0.1 mm
    ++agreed;
  }
  EXPECT_GT(agreed, 1500) << misses << " misses, " << near_edges << " near edges";
  EXPECT_GT(misses, 1000);  // the bounded half: most lines pass the sphere farther than 0.3 radii
  EXPECT_LT(near_edges, 40);
}

TEST(ClosestPoint, DegenerateFacesAreSkippedAndBadIndicesRejected) {
  TriangleMesh mesh = MakeIcosphere(1, 1.0);
  mesh.F.conservativeResize(mesh.F.rows() + 1, 3);
  mesh.F.row(mesh.F.rows() - 1) << 0, 0, 1;  // zero area
  const ClosestPointTree tree(mesh);
  EXPECT_LT(tree.Closest(mesh.V.row(0).transpose() * 2.0).face, mesh.F.rows() - 1);
  mesh.F(0, 0) = 999;
  EXPECT_THROW(ClosestPointTree{mesh}, Error);
}

}  // namespace
}  // namespace subflow::geometry
