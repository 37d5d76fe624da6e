// The z-buffer against independent references: CGAL ray casting through pixel centres,
// the analytic outline of a sphere, exact tie handling on a pixel-aligned grid, and the
// masks that Blender rendered for ../shared/data/blob.
#include "vision/zbuffer.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "geometry/closest_point.h"
#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/mesh_io.h"
#include "vision/camera_rig.h"
#include "vision/dataset.h"
#include "vision/mask_agreement.h"

namespace subflow::vision {
namespace {

using geometry::Faces;
using geometry::Positions;
using geometry::TriangleMesh;

// A bumpy closed surface (so that it self-occludes) around `centre`.
TriangleMesh BumpySphere(int subdivisions, const Eigen::Vector3d& centre) {
  TriangleMesh mesh = geometry::MakeIcosphere(subdivisions, 0.1);
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    const Eigen::Vector3d x = mesh.V.row(i);
    const double r = 1.0 + 0.15 * std::sin(40.0 * x.x()) * std::cos(35.0 * x.y() + 20.0 * x.z());
    mesh.V.row(i) = (r * x + centre).transpose();
  }
  return mesh;
}

Camera TestCamera(int width = 320, int height = 240) {
  // Off-axis, tilted: exercises a general R and t.
  return LookAtCamera("test", width, height, 420.0 * width / 320.0, Eigen::Vector3d(0.35, -0.45, 0.2),
                      Eigen::Vector3d(0.01, -0.02, 0.015));
}

TEST(ZBuffer, PixelCentreRaysHitTheFaceAndBarycentricsTheZBufferReports) {
  // Reference: CGAL's AABB ray casting through the centre of every 3rd pixel. The z-buffer
  // must report the same face, barycentrics and depth. Tolerances: barycentrics are
  // stored as float (1e-7 relative) of triangles ~5 px wide → 2e-5; depth float → 1e-6 m.
  const TriangleMesh mesh = BumpySphere(4, Eigen::Vector3d(0.01, -0.02, 0.015));
  const Camera camera = TestCamera();
  const ZBuffer zbuffer(camera, mesh.V, mesh.F);
  const geometry::ClosestPointTree tree(mesh);
  int hits = 0, edge_ties = 0;
  for (int y = 0; y < camera.height(); y += 3) {
    for (int x = 0; x < camera.width(); x += 3) {
      const Eigen::Vector3d direction = camera.BackProjectUndistorted(Eigen::Vector2d(x, y));
      const geometry::RayHit hit = tree.FirstHit(camera.Center(), direction);
      if (!hit.hit) {
        EXPECT_FALSE(zbuffer.Covered(x, y)) << "pixel " << x << "," << y;
        continue;
      }
      ASSERT_TRUE(zbuffer.Covered(x, y)) << "pixel " << x << "," << y;
      ++hits;
      const Eigen::Vector3d point = zbuffer.SurfacePoint(x, y, mesh.V, mesh.F);
      EXPECT_LT((point - hit.point).norm(), 1e-6) << "pixel " << x << "," << y;
      EXPECT_NEAR(zbuffer.Depth(x, y), camera.ToCamera(hit.point).z(), 1e-6);
      if (zbuffer.Face(x, y) != hit.face) {
        // Only where the ray passes through an edge or vertex shared by both faces.
        ++edge_ties;
        const Eigen::Vector2d uv = hit.barycentric;
        EXPECT_LT(std::min({uv.x(), uv.y(), 1.0 - uv.x() - uv.y()}), 1e-5);
        continue;
      }
      EXPECT_NEAR(zbuffer.Barycentric(x, y).x(), hit.barycentric.x(), 2e-5);
      EXPECT_NEAR(zbuffer.Barycentric(x, y).y(), hit.barycentric.y(), 2e-5);
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_LE(edge_ties, 2);
}

TEST(ZBuffer, SurfacePointOfEveryCoveredPixelProjectsOntoThatPixelCentre) {
  // The inverse claim: the 3D point the z-buffer reports at pixel (x, y) is a point of
  // its face that ProjectUndistorted maps to (x, y). Tolerance 1e-3 px: float
  // barycentrics on triangles up to ~10 px.
  const TriangleMesh mesh = BumpySphere(4, Eigen::Vector3d::Zero());
  const Camera camera = TestCamera();
  const ZBuffer zbuffer(camera, mesh.V, mesh.F);
  double worst = 0.0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      if (!zbuffer.Covered(x, y)) continue;
      const Eigen::Vector2f uv = zbuffer.Barycentric(x, y);
      EXPECT_GE(std::min({uv.x(), uv.y(), 1.0f - uv.x() - uv.y()}), -1e-5f);
      double depth = 0.0;
      const Eigen::Vector2d p = camera.ProjectUndistorted(zbuffer.SurfacePoint(x, y, mesh.V, mesh.F), &depth);
      worst = std::max(worst, (p - Eigen::Vector2d(x, y)).norm());
      EXPECT_NEAR(depth, zbuffer.Depth(x, y), 1e-6);
    }
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(zbuffer.CoveredPixelCount(), 5000);
}

// Whether the ray through image point (x, y) meets the sphere (centre c, radius r).
bool RayMeetsSphere(const Camera& camera, double x, double y, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d d = camera.BackProjectUndistorted(Eigen::Vector2d(x, y));
  const Eigen::Vector3d to_centre = c - camera.Center();
  const double along = d.dot(to_centre);
  return along > 0.0 && to_centre.squaredNorm() - along * along <= r * r;
}

TEST(ZBuffer, SphereSilhouetteMatchesItsAnalyticOutline) {
  // The analytic silhouette of a sphere is the conic where the viewing cone touches it.
  // An icosphere with 5 levels is inscribed in the sphere with a sagitta ≤ 2e-4 r
  // (≈ 0.015 px here): pixels may differ only where the true outline passes through the
  // pixel (its four corners disagree), and only by the raster being inside. A half-pixel
  // convention error would differ on the whole outline (~500 pixels).
  const Eigen::Vector3d centre(0.03, 0.02, -0.01);
  const double radius = 0.1;
  TriangleMesh sphere = geometry::MakeIcosphere(5, radius);
  sphere.V.rowwise() += centre.transpose();
  const Camera camera = TestCamera();
  const ZBuffer zbuffer(camera, sphere.V, sphere.F);
  int analytic_count = 0, boundary = 0, differing = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const bool analytic = RayMeetsSphere(camera, x, y, centre, radius);
      analytic_count += analytic;
      int corners = 0;
      for (double dy : {-0.5, 0.5})
        for (double dx : {-0.5, 0.5}) corners += RayMeetsSphere(camera, x + dx, y + dy, centre, radius);
      const bool on_outline = corners != 0 && corners != 4;
      boundary += on_outline;
      if (analytic == zbuffer.Covered(x, y)) continue;
      ++differing;
      EXPECT_TRUE(on_outline) << "pixel " << x << "," << y << " away from the outline differs";
      EXPECT_TRUE(analytic) << "pixel " << x << "," << y << " covered outside the sphere";
    }
  }
  EXPECT_GT(analytic_count, 10000);
  EXPECT_GT(boundary, 300);
  EXPECT_LE(differing, boundary / 20) << differing << " of " << boundary << " outline pixels differ";
}

TEST(ZBuffer, SharedEdgesThroughPixelCentresAreCoveredExactlyOnce) {
  // A flat grid whose vertices project exactly onto pixel centres (f = 64, K and the
  // plane chosen so every coordinate is a dyadic rational), diagonals alternating: every
  // edge passes through pixel centres. Rendering each triangle alone and counting, a
  // centre strictly inside the grid must be claimed by exactly one triangle.
  Eigen::Matrix3d K;
  K << 64.0, 0.0, 16.0, 0.0, 64.0, 16.0, 0.0, 0.0, 1.0;
  const Camera camera("grid", 32, 32, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const int n = 6, step = 4, origin = 4;  // grid of n×n squares of 4 px from pixel (4, 4)
  TriangleMesh grid;
  grid.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      grid.V.row(j * (n + 1) + i) << (origin + step * i - 16) / 64.0, (origin + step * j - 16) / 64.0, 1.0;
  grid.F.resize(2 * n * n, 3);
  for (int j = 0, f = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      if ((i + j) % 2 == 0) {
        grid.F.row(f++) << a, b, d;
        grid.F.row(f++) << a, d, c;
      } else {
        grid.F.row(f++) << a, b, c;
        grid.F.row(f++) << b, d, c;
      }
    }
  }
  std::vector<int> count(32 * 32, 0);
  for (int f = 0; f < grid.face_count(); ++f) {
    const Faces single = grid.F.row(f);
    const ZBuffer zbuffer(camera, grid.V, single);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) count[y * 32 + x] += zbuffer.Covered(x, y);
  }
  const int last = origin + step * n;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      const int c = count[y * 32 + x];
      if (x > origin && x < last && y > origin && y < last) {
        EXPECT_EQ(c, 1) << "pixel " << x << "," << y;
      } else if (x < origin || x > last || y < origin || y > last) {
        EXPECT_EQ(c, 0) << "pixel " << x << "," << y;
      } else {
        EXPECT_LE(c, 1) << "outer edge pixel " << x << "," << y;
      }
    }
  }
  // The whole grid at once: no cracks inside.
  const ZBuffer whole(camera, grid.V, grid.F);
  for (int y = origin + 1; y < last; ++y)
    for (int x = origin + 1; x < last; ++x) EXPECT_TRUE(whole.Covered(x, y));
}

TEST(ZBuffer, TrianglesCrossingTheNearPlaneAreClipped) {
  // A large floor triangle reaching behind the camera: pixels whose ray hits it in front
  // of the near plane (CGAL ray casting) are covered with the right depth; nothing
  // behind the camera is drawn.
  Eigen::Matrix3d K;
  K << 100.0, 0.0, 31.5, 0.0, 100.0, 23.5, 0.0, 0.0, 1.0;
  const Camera camera("floor", 64, 48, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  TriangleMesh floor;
  floor.V.resize(3, 3);
  floor.V << -4.0, 0.03, -1.0, 4.0, 0.03, -1.0, 0.0, 0.03, 5.0;  // y = 0.03 (below), z from −1 to 5
  floor.F.resize(1, 3);
  floor.F << 0, 2, 1;
  ZBufferOptions options;
  options.near = 0.5;  // the clip line z = 0.5 projects to row 29.5, inside the image
  const ZBuffer zbuffer(camera, floor.V, floor.F, options);
  const geometry::ClosestPointTree tree(floor);
  int covered = 0;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const geometry::RayHit hit = tree.FirstHit(camera.Center(), camera.BackProjectUndistorted({x, y}));
      const bool expected = hit.hit && hit.point.z() >= options.near;
      EXPECT_EQ(zbuffer.Covered(x, y), expected) << "pixel " << x << "," << y;
      if (!expected || !zbuffer.Covered(x, y)) continue;
      ++covered;
      EXPECT_NEAR(zbuffer.Depth(x, y), hit.point.z(), 1e-5 * hit.point.z());
      EXPECT_LT((zbuffer.SurfacePoint(x, y, floor.V, floor.F) - hit.point).norm(), 1e-5 * hit.point.z());
    }
  }
  EXPECT_GT(covered, 200);
}

TEST(ZBuffer, BackFaceCullingChangesNothingOnAClosedSurface) {
  const TriangleMesh mesh = BumpySphere(4, Eigen::Vector3d::Zero());
  const Camera camera = TestCamera();
  ZBufferOptions cull;
  cull.cull_back_faces = true;
  const ZBuffer all(camera, mesh.V, mesh.F), culled(camera, mesh.V, mesh.F, cull);
  EXPECT_EQ(all.faces(), culled.faces());
}

TEST(ZBuffer, DepthOnlyRenderKeepsTheDepthsAndCoverageAndReusesItsBuffers) {
  const TriangleMesh mesh = BumpySphere(4, Eigen::Vector3d(0.01, -0.02, 0.015));
  const Camera camera = TestCamera();
  const ZBuffer full(camera, mesh.V, mesh.F);
  ZBufferOptions depth_only;
  depth_only.depth_only = true;
  ZBuffer depth(TestCamera(160, 120), mesh.V, mesh.F);  // a full render of another size first
  depth.Render(camera, mesh.V, mesh.F, depth_only);
  EXPECT_EQ(depth.depth(), full.depth());
  EXPECT_TRUE(depth.faces().empty());
  EXPECT_TRUE(depth.barycentrics().empty());
  EXPECT_EQ(depth.CoveredPixelCount(), full.CoveredPixelCount());
  EXPECT_GT(full.CoveredPixelCount(), 1000);
  EXPECT_EQ(cv::countNonZero(depth.Mask() != full.Mask()), 0);
  int agree = 0;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    const Eigen::Vector3d X = mesh.V.row(i).transpose();
    EXPECT_EQ(depth.IsVisible(X, 1e-3), full.IsVisible(X, 1e-3));
    agree += full.IsVisible(X, 1e-3);
  }
  EXPECT_GT(agree, 100);
}

TEST(ZBuffer, VisibilityOfSurfacePoints) {
  // Vertices of a sphere: visible iff on the camera's side of the tangent cone
  // (n · (C − X) > 0). Near the outline (|facing| < 0.2) the discrete silhouette decides,
  // so those are skipped. Tolerance 1 mm: 1/z interpolated bilinearly is exact on planes;
  // the sphere's curvature over the ≤ 7 mm of surface one pixel spans at facing 0.2
  // bends it by < 0.5 mm, while hidden points with facing < −0.2 lie ≥ 2 cm behind.
  TriangleMesh sphere = geometry::MakeIcosphere(4, 0.1);
  const Camera camera = TestCamera();
  const ZBuffer zbuffer(camera, sphere.V, sphere.F);
  const std::vector<std::uint8_t> visible = zbuffer.VisibleSamples(sphere.V, 1e-3);
  int checked = 0;
  for (Eigen::Index i = 0; i < sphere.V.rows(); ++i) {
    const Eigen::Vector3d X = sphere.V.row(i);
    const double facing = X.normalized().dot((camera.Center() - X).normalized());
    if (std::abs(facing) < 0.2) continue;
    ++checked;
    EXPECT_EQ(visible[i] != 0, facing > 0.0) << "vertex " << i << " facing " << facing;
  }
  EXPECT_GT(checked, 1500);
  // A tighter tolerance still holds well inside the visible cap (facing > 0.6).
  for (Eigen::Index i = 0; i < sphere.V.rows(); ++i) {
    const Eigen::Vector3d X = sphere.V.row(i);
    if (X.normalized().dot((camera.Center() - X).normalized()) > 0.6) {
      EXPECT_TRUE(zbuffer.IsVisible(X, 1e-4)) << "vertex " << i;
    }
  }
  // Outside the image: not visible; empty pixel in front of nothing: visible.
  EXPECT_FALSE(zbuffer.IsVisible(camera.Center() + 0.5 * camera.BackProjectUndistorted({-20.0, 10.0}), 1e-4));
  EXPECT_TRUE(zbuffer.IsVisible(camera.Center() + 0.5 * camera.BackProjectUndistorted({2.0, 2.0}), 1e-4));
  EXPECT_FALSE(zbuffer.IsVisible(camera.Center() - camera.ViewDirection(), 1e-4));  // behind
}

TEST(ZBuffer, RejectsFacesIndexingMissingVertices) {
  TriangleMesh mesh = geometry::MakeIcosphere(1, 0.1);
  mesh.F(3, 1) = mesh.vertex_count();
  try {
    ZBuffer(TestCamera(), mesh.V, mesh.F);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
}

TEST(ZBuffer, BlobGroundTruthMatchesBlenderMasks) {
  // ../shared/data/blob was rendered by Blender (Cycles, masks = Cryptomatte coverage
  // > 0.5). Our cameras + z-buffer on its ground-truth meshes must reproduce every mask:
  // IoU ≥ 0.99 per camera (the README's own check finds ≥ 0.999) and a mean centroid
  // offset below 0.15 px per camera (a half-pixel convention error would give 0.5).
  const Dataset dataset(SUBFLOW_SHARED_DIR "/data/blob");
  ASSERT_EQ(dataset.camera_count(), 10);
  ASSERT_TRUE(dataset.has_masks());
  const std::vector<int> frames = {0, 8, 16, 23};
  std::vector<double> min_iou(dataset.camera_count(), 1.0);
  std::vector<Eigen::Vector2d> offset_sum(dataset.camera_count(), Eigen::Vector2d::Zero());
  for (int frame : frames) {
    const TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(frame));
    const std::vector<ZBuffer> zbuffers = RenderZBuffers(dataset.cameras(), mesh.V, mesh.F);
    for (int c = 0; c < dataset.camera_count(); ++c) {
      const MaskAgreement agreement = CompareMasks(zbuffers[c].Mask(), dataset.Mask(c, frame));
      min_iou[c] = std::min(min_iou[c], agreement.iou);
      offset_sum[c] += agreement.centroid_offset;
    }
  }
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const Eigen::Vector2d offset = offset_sum[c] / static_cast<double>(frames.size());
    std::printf("blob %s: min IoU %.4f, mean centroid offset (%+.4f, %+.4f) px\n",
                dataset.camera(c).name().c_str(), min_iou[c], offset.x(), offset.y());
    EXPECT_GE(min_iou[c], 0.99) << dataset.camera(c).name();
    EXPECT_LT(offset.norm(), 0.15) << dataset.camera(c).name();
  }
}

}  // namespace
}  // namespace subflow::vision
