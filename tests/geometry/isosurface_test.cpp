#include "geometry/isosurface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/mesh_topology.h"

namespace subflow::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Ball {
  Eigen::Vector3d centre;
  double radius;
};

// Occupancy of voxel carving: 1 where the voxel centre lies inside one of the balls (and
// outside every hole), 0 elsewhere.
ScalarVolume SampleBalls(int n, double spacing, const Eigen::Vector3d& origin,
                         const std::vector<Ball>& balls, const std::vector<Ball>& holes = {}) {
  ScalarVolume volume(origin, spacing, n, n, n, 0.0f);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d p = volume.VoxelCenter(i, j, k);
        bool inside = false;
        for (const Ball& b : balls) inside |= (p - b.centre).norm() < b.radius;
        for (const Ball& b : holes) inside &= (p - b.centre).norm() >= b.radius;
        volume.at(i, j, k) = inside ? 1.0f : 0.0f;
      }
  return volume;
}

// Signed enclosed volume by the divergence theorem: Σ_f v0 · (v1 × v2) / 6, positive for a
// closed surface oriented counter-clockwise seen from outside.
double SignedVolume(const TriangleMesh& mesh, int face_begin = 0, int face_end = -1) {
  if (face_end < 0) face_end = mesh.face_count();
  double volume = 0.0;
  for (int f = face_begin; f < face_end; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

// Signed volume of each connected component (faces grouped by a union-find over vertices).
std::vector<double> ComponentVolumes(const TriangleMesh& mesh) {
  std::vector<int> parent(mesh.vertex_count());
  for (int v = 0; v < mesh.vertex_count(); ++v) parent[v] = v;
  const auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 1; k < 3; ++k) parent[find(mesh.F(f, k))] = find(mesh.F(f, 0));
  std::vector<int> component_of_root(mesh.vertex_count(), -1);
  std::vector<double> volumes;
  for (int f = 0; f < mesh.face_count(); ++f) {
    const int root = find(mesh.F(f, 0));
    if (component_of_root[root] < 0) {
      component_of_root[root] = static_cast<int>(volumes.size());
      volumes.push_back(0.0);
    }
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    volumes[component_of_root[root]] += a.dot(b.cross(c)) / 6.0;
  }
  return volumes;
}

// A 64³ grid of spacing 0.05 with a ball of radius 20 voxels: world units differ from voxels
// and the origin is not zero, so a mix-up of the two would show.
const double kSpacing = 0.05;
const Eigen::Vector3d kOrigin(-1.0, 2.0, 0.5);
Eigen::Vector3d GridPoint(double i, double j, double k) {
  return kOrigin + kSpacing * Eigen::Vector3d(i, j, k);
}

// Volume the extracted surface of a sampled ball of radius R (voxels) should enclose with
// the default options: the blur moves the 0.5 level inwards by σ²/R (σ = 1 voxel), and flat
// triangles of surface Delaunay radius up to ρ = facet_size = 2 voxels cut the cap of
// depth ≈ ρ²/(4R) off on average, a relative loss of 3ρ²/(4R²).
double ModelVolume(double radius_voxels) {
  const double r = radius_voxels;
  const double shrunk = r - 1.0 / r;
  return 4.0 / 3.0 * kPi * std::pow(shrunk * kSpacing, 3) * (1.0 - 3.0 * 4.0 / (4.0 * r * r));
}

TEST(Isosurface, SampledSphereGivesClosedOutwardManifoldOnTheSphere) {
  const Ball ball{GridPoint(31.3, 32.1, 30.7), 20.0 * kSpacing};
  const ScalarVolume volume = SampleBalls(64, kSpacing, kOrigin, {ball});
  IsosurfaceSummary summary;
  const TriangleMesh mesh = ExtractIsosurface(volume, IsosurfaceOptions(), &summary);

  const MeshTopology topology(mesh.F, mesh.vertex_count());  // throws if not a 2-manifold
  EXPECT_TRUE(topology.IsClosed());
  EXPECT_EQ(topology.ComponentCount(), 1);
  EXPECT_EQ(topology.UnreferencedVertexCount(), 0);
  EXPECT_EQ(summary.component_count, 1);
  EXPECT_EQ(summary.face_count, mesh.face_count());
  // Euler characteristic of a sphere.
  EXPECT_EQ(mesh.vertex_count() - topology.edge_count() + mesh.face_count(), 2);

  // Vertices lie on the 0.5 level of the blurred trilinear field, which runs half-way
  // between inside and outside voxel centres (≤ √3/2 voxel from the sphere before the
  // blur, which averages that staircase out) and is pulled in by ≈ σ²/R = 0.05 voxel:
  // every vertex within 1 voxel, the mean within 0.25 voxel.
  double max_error = 0.0, mean_error = 0.0;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const double error =
        std::abs((Eigen::Vector3d(mesh.V.row(v)) - ball.centre).norm() - ball.radius);
    max_error = std::max(max_error, error);
    mean_error += error / mesh.vertex_count();
  }
  EXPECT_LT(max_error, 1.0 * kSpacing);
  EXPECT_LT(mean_error, 0.25 * kSpacing);

  // Outward orientation gives a positive volume. Its error is ≈ 3·(mean radial offset)/R
  // (offsets ≤ 0.25 voxel → ≤ 3.75 %) plus the chordal loss of flat triangles of edge
  // ≤ ~3.5 voxels (sagitta ≤ e²/8R ≈ 0.08 voxel → ≤ 1.2 %): 3 % bounds the sum seen.
  const double true_volume = 4.0 / 3.0 * kPi * std::pow(ball.radius, 3);
  const double volume_of_mesh = SignedVolume(mesh);
  EXPECT_GT(volume_of_mesh, 0.0);
  EXPECT_NEAR(volume_of_mesh / true_volume, 1.0, 0.03);
  EXPECT_NEAR(volume_of_mesh / ModelVolume(20.0), 1.0, 0.02);  // see ModelVolume

  // Well-shaped: Mesh_3 refines every facet of the restricted Delaunay surface until it
  // meets the criteria, so every smallest angle is ≥ facet_angle_degrees = 30° (0.01° of
  // slack for rounding in the criterion's evaluation).
  double smallest_angle = 180.0;
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.V.row(mesh.F(f, k));
      const Eigen::Vector3d u = Eigen::Vector3d(mesh.V.row(mesh.F(f, (k + 1) % 3))) - p;
      const Eigen::Vector3d w = Eigen::Vector3d(mesh.V.row(mesh.F(f, (k + 2) % 3))) - p;
      smallest_angle =
          std::min(smallest_angle, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / kPi);
    }
  EXPECT_GE(smallest_angle, 30.0 - 0.01);
}

TEST(Isosurface, TwoSeparateSpheresGiveTwoOutwardComponents) {
  const Ball a{GridPoint(17.0, 32.0, 32.0), 14.0 * kSpacing};
  const Ball b{GridPoint(46.0, 30.0, 33.0), 9.0 * kSpacing};
  IsosurfaceSummary summary;
  const TriangleMesh mesh = ExtractIsosurface(SampleBalls(64, kSpacing, kOrigin, {a, b}),
                                              IsosurfaceOptions(), &summary);
  const MeshTopology topology(mesh.F, mesh.vertex_count());
  EXPECT_TRUE(topology.IsClosed());
  EXPECT_EQ(topology.ComponentCount(), 2);
  EXPECT_EQ(summary.component_count, 2);
  EXPECT_EQ(summary.cavity_count, 0);
  std::vector<double> volumes = ComponentVolumes(mesh);
  ASSERT_EQ(volumes.size(), 2u);
  std::sort(volumes.begin(), volumes.end());
  // Both positive (outward) and within 2 % of the model above; the residual is the
  // staircase of the sampling left after the blur (≈ 0.5 % on a ball of radius 20).
  EXPECT_NEAR(volumes[0] / ModelVolume(9.0), 1.0, 0.02);
  EXPECT_NEAR(volumes[1] / ModelVolume(14.0), 1.0, 0.02);
}

TEST(Isosurface, HollowBallHasInwardFacingCavity) {
  const Eigen::Vector3d centre = GridPoint(32.0, 32.0, 32.0);
  const Ball outer{centre, 22.0 * kSpacing}, inner{centre, 12.0 * kSpacing};
  IsosurfaceSummary summary;
  const TriangleMesh mesh =
      ExtractIsosurface(SampleBalls(64, kSpacing, kOrigin, {outer}, {inner}),
                        IsosurfaceOptions(), &summary);
  const MeshTopology topology(mesh.F, mesh.vertex_count());
  EXPECT_TRUE(topology.IsClosed());
  EXPECT_EQ(topology.ComponentCount(), 2);
  EXPECT_EQ(summary.component_count, 1);
  EXPECT_EQ(summary.cavity_count, 1);
  std::vector<double> volumes = ComponentVolumes(mesh);
  ASSERT_EQ(volumes.size(), 2u);
  std::sort(volumes.begin(), volumes.end());
  // The cavity's normals point into the hole (out of the material): negative volume. The
  // blur moves a level set towards its centres of curvature (it is a step of mean
  // curvature flow), so the hole, too, shrinks to radius R − σ²/R: ModelVolume applies.
  EXPECT_NEAR(volumes[0] / -ModelVolume(12.0), 1.0, 0.02);
  EXPECT_NEAR(volumes[1] / ModelVolume(22.0), 1.0, 0.02);
}

TEST(Isosurface, ObjectTouchingTheBorderIsCappedAndClosed) {
  // A ball centred on the x = origin face of the grid: the volume holds only its half.
  const Ball ball{GridPoint(0.0, 32.0, 32.0), 18.0 * kSpacing};
  const ScalarVolume volume = SampleBalls(64, kSpacing, kOrigin, {ball});
  const TriangleMesh mesh = ExtractIsosurface(volume, IsosurfaceOptions());
  const MeshTopology topology(mesh.F, mesh.vertex_count());
  EXPECT_TRUE(topology.IsClosed());
  EXPECT_EQ(topology.ComponentCount(), 1);
  // The cap lies half a voxel outside the border samples (0.5 level between the last
  // occupied sample and the zero padding), rounded by the blur: within [−1.5, 0] voxels.
  const double min_x = mesh.V.col(0).minCoeff();
  EXPECT_GT(min_x, kOrigin.x() - 1.5 * kSpacing);
  EXPECT_LT(min_x, kOrigin.x());
  // Volume: the half ball plus the slab of half a voxel in front of the border samples.
  const double half_ball = 2.0 / 3.0 * kPi * std::pow(ball.radius, 3);
  const double slab = kPi * ball.radius * ball.radius * 0.5 * kSpacing;
  EXPECT_NEAR(SignedVolume(mesh) / (half_ball + slab), 1.0, 0.04);
}

TEST(Isosurface, SameInputGivesTheSameMesh) {
  const ScalarVolume volume =
      SampleBalls(40, kSpacing, kOrigin, {{GridPoint(20.0, 19.0, 21.0), 12.0 * kSpacing}});
  const TriangleMesh first = ExtractIsosurface(volume, IsosurfaceOptions());
  const TriangleMesh second = ExtractIsosurface(volume, IsosurfaceOptions());
  ASSERT_EQ(first.vertex_count(), second.vertex_count());
  ASSERT_EQ(first.face_count(), second.face_count());
  EXPECT_EQ(first.V, second.V);
  EXPECT_EQ(first.F, second.F);
}

TEST(Isosurface, PaddingKeepsWorldPositionsAndBlurKeepsMass) {
  ScalarVolume volume(kOrigin, kSpacing, 5, 6, 7, 0.0f);
  volume.at(4, 5, 6) = 1.0f;  // a corner sample: the blur must not lose it to the border
  volume.at(0, 0, 0) = 0.5f;  // the opposite corner, beyond the kernel of the first
  const ScalarVolume padded = PadAndSmoothVolume(volume, 4, 1.0);
  EXPECT_EQ(padded.nx, 13);
  EXPECT_EQ(padded.ny, 14);
  EXPECT_EQ(padded.nz, 15);
  EXPECT_TRUE(padded.VoxelCenter(4, 4, 4).isApprox(volume.VoxelCenter(0, 0, 0)));
  double mass = 0.0;
  for (float x : padded.values) mass += x;
  // The normalized kernel (radius 3 < padding 4) conserves the sum up to float rounding.
  EXPECT_NEAR(mass, 1.5, 1e-5);
  // Symmetric blur: the peak stays on the sample.
  EXPECT_GT(padded.at(8, 9, 10), padded.at(7, 9, 10));
  EXPECT_NEAR(padded.at(7, 9, 10), padded.at(9, 9, 10), 1e-7);
}

void ExpectErrorMentioning(const ScalarVolume& volume, const IsosurfaceOptions& options,
                           const std::string& words) {
  try {
    ExtractIsosurface(volume, options, nullptr, "frame 7 occupancy");
    ADD_FAILURE() << "expected subflow::Error mentioning '" << words << "'";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
  }
}

TEST(Isosurface, BadInputsGiveClearErrors) {
  const IsosurfaceOptions defaults;
  ExpectErrorMentioning(ScalarVolume(kOrigin, kSpacing, 16, 16, 16, 0.0f), defaults,
                        "frame 7 occupancy: values: no voxel is occupied");
  ExpectErrorMentioning(ScalarVolume(kOrigin, kSpacing, 16, 16, 16, 1.0f), defaults,
                        "frame 7 occupancy: values: every voxel is occupied");
  ScalarVolume with_nan(kOrigin, kSpacing, 16, 16, 16, 0.0f);
  with_nan.at(8, 8, 8) = 1.0f;
  with_nan.at(3, 4, 5) = std::numeric_limits<float>::quiet_NaN();
  ExpectErrorMentioning(with_nan, defaults, "value at voxel (3, 4, 5): expected a finite");
  ScalarVolume wrong_size(kOrigin, kSpacing, 16, 16, 16, 0.0f);
  wrong_size.values.pop_back();
  ExpectErrorMentioning(wrong_size, defaults, "values: expected nx·ny·nz = 4096 samples");
  ScalarVolume bad_spacing(kOrigin, 0.0, 16, 16, 16, 0.0f);
  ExpectErrorMentioning(bad_spacing, defaults, "spacing: expected a finite voxel size > 0");
  // A single occupied voxel is thinner than the blur: reported as empty, not as a crash.
  ScalarVolume speck(kOrigin, kSpacing, 16, 16, 16, 0.0f);
  speck.at(8, 8, 8) = 1.0f;
  ExpectErrorMentioning(speck, defaults, "thinner than the blur");

  IsosurfaceOptions bad = defaults;
  bad.facet_size_voxels = 0.0;
  ExpectErrorMentioning(with_nan, bad, "IsosurfaceOptions: facet_size_voxels");
  bad = defaults;
  bad.facet_angle_degrees = 40.0;
  ExpectErrorMentioning(with_nan, bad, "IsosurfaceOptions: facet_angle_degrees");
  bad = defaults;
  bad.smoothing_sigma_voxels = -1.0;
  ExpectErrorMentioning(with_nan, bad, "IsosurfaceOptions: smoothing_sigma_voxels");
}

}  // namespace
}  // namespace subflow::geometry
