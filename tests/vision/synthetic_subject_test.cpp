// Signed-distance subjects of `subflow synth` (vision/synthetic_subject.h): exact
// primitives, meshes that are valid by two independent self-intersection tests and have
// the advertised topology, thin plates that survive meshing, and deformations that move
// the material as declared.
#include "vision/synthetic_subject.h"

#include <cmath>
#include <map>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/mesh_validation.h"
#include "vision/synthetic_scene.h"

namespace subflow::vision {
namespace {

using Eigen::Vector3d;

// Each subject's rest mesh at the default voxel (1.5 mm), meshed once for all tests.
const geometry::TriangleMesh& RestMesh(const std::string& name) {
  static std::map<std::string, geometry::TriangleMesh> meshes;
  auto found = meshes.find(name);
  if (found == meshes.end()) found = meshes.emplace(name, MeshSdfSubject(MakeSdfSubject(name), SdfMeshOptions())).first;
  return found->second;
}

TEST(SdfPrimitives, GiveExactDistancesWhereTheyAreExact) {
  EXPECT_NEAR(SphereSdf({1, 0, 0}, 0.5)({3, 0, 0}), 1.5, 1e-15);
  EXPECT_NEAR(CapsuleSdf({0, 0, 0}, {0, 0, 1}, 0.1)({0.3, 0, 0.5}), 0.2, 1e-15);
  EXPECT_NEAR(CapsuleSdf({0, 0, 0}, {0, 0, 1}, 0.1)({0, 0, 1.5}), 0.4, 1e-15);
  const Sdf box = RoundBoxSdf({0, 0, 0}, {1, 2, 3}, AxisRotation(Vector3d::UnitZ(), 90.0), 0.25);
  EXPECT_NEAR(box({0, 0, 3.5}), 0.5, 1e-12);  // a face: rounding does not change it
  EXPECT_NEAR(box({2.5, 0, 0}), 0.5, 1e-12);  // the rotated y extent (2) now lies along x
  EXPECT_NEAR(box({0, 0, 0}), -1.0, 1e-12);   // inside: minus the distance to the nearest face
  EXPECT_NEAR(TorusSdf({0, 0, 0}, Vector3d::UnitY(), 1.0, 0.2)({1, 0, 0}), -0.2, 1e-15);
  EXPECT_NEAR(TorusSdf({0, 0, 0}, Vector3d::UnitY(), 1.0, 0.2)({0, 0.5, 0}), std::hypot(1.0, 0.5) - 0.2, 1e-15);
  EXPECT_NEAR(CylinderSdf({0, 0, 0}, {0, 0, 2}, 0.5, 0.1)({0, 0, 3}), 1.0, 1e-12);
  // A smooth union lies below both parts (a fillet) and equals min away from the seam.
  const Sdf a = SphereSdf({-1, 0, 0}, 1.0), b = SphereSdf({1, 0, 0}, 1.0);
  EXPECT_LT(SmoothUnion(a, b, 0.2)({0, 0.5, 0}), std::min(a({0, 0.5, 0}), b({0, 0.5, 0})));
  EXPECT_DOUBLE_EQ(SmoothUnion(a, b, 0.2)({-2.5, 0, 0}), a({-2.5, 0, 0}));
}

// The rest meshes are closed, outward, 2-manifold, free of self-intersections by CGAL's and
// TetGen's tests, have the declared components and genus (χ = 2·components − 2·genus), and
// their vertices lie on the SDF's zero set (Newton-projected: < 1 µm).
TEST(SdfSubjects, RestMeshesAreValidWithTheAdvertisedTopology) {
  for (const std::string& name : SdfSubjectNames()) {
    const SdfSubject subject = MakeSdfSubject(name);
    const geometry::TriangleMesh& mesh = RestMesh(name);
    const geometry::MeshValidationReport report = geometry::ValidateMesh(mesh);
    EXPECT_TRUE(report.valid()) << name << ":\n" << report.FullReport();
    EXPECT_TRUE(report.closed && report.outward_oriented) << name;
    EXPECT_EQ(report.component_count, subject.component_count) << name;
    EXPECT_EQ(report.genus, subject.genus * subject.component_count) << name;
    double worst = 0.0;
    for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
      worst = std::max(worst, std::abs(subject.sdf(mesh.V.row(v).transpose())));
    EXPECT_LT(worst, 1e-6) << name;
    std::printf("%s: %d vertices, %d faces, genus %d, %d components, |s| <= %.2g m (CGAL %.1f s, TetGen %.1f s)\n",
                name.c_str(), report.vertex_count, report.face_count, report.genus, report.component_count, worst,
                report.cgal.seconds, report.tetgen.seconds);
  }
}

// The bust's right ear is a plate 3 mm thick: near its centre, the mesh has two sheets at
// local x = ±1.5 mm and nothing in between (a meshing that swallowed or thickened it fails).
TEST(SdfSubjects, EarPlatesKeepTheirThreeMillimetres) {
  const SdfSubject subject = MakeSdfSubject("bust");
  const geometry::TriangleMesh& mesh = RestMesh("bust");
  const Eigen::Matrix3d to_local = AxisRotation(Vector3d::UnitZ(), -25.0).transpose();
  const Vector3d centre(0.074, 0.018, 0.012);
  int near = 0, inside = 0;
  double low = 0.0, high = 0.0;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const Vector3d q = to_local * (mesh.V.row(v).transpose() - centre);
    if (std::hypot(q.y() - 0.008, q.z()) > 0.008 || std::abs(q.x()) > 0.004) continue;  // rear half of the ear
    ++near;
    low = std::min(low, q.x());
    high = std::max(high, q.x());
    if (std::abs(q.x()) < 0.001) ++inside;
  }
  EXPECT_GT(near, 20);
  EXPECT_NEAR(low, -0.0015, 1e-4);
  EXPECT_NEAR(high, 0.0015, 1e-4);
  EXPECT_EQ(inside, 0);
}

// Deformed frames stay free of self-intersections at the largest articulations.
TEST(SdfSubjects, DeformedMeshesDoNotSelfIntersect) {
  // τ = 25 (the pair's legs and critter's tail at their extremes), 48 (the jaw fully open,
  // the arm half raised), 90 (the mug's bend, the pair's waist, the critter's legs … near
  // theirs): the motions have different periods, so these cover most extremes.
  for (const std::string& name : SdfSubjectNames()) {
    const SdfSubject subject = MakeSdfSubject(name);
    SdfMeshOptions coarse;  // the deformation, not the meshing, is under test
    coarse.voxel_size = 0.0025;
    const geometry::TriangleMesh rest = MeshSdfSubject(subject, coarse);
    for (double tau : {25.0, 48.0, 90.0}) {
      geometry::MeshValidationOptions validation;
      validation.check_self_intersections_tetgen = false;
      const geometry::TriangleMesh frame{subject.deformation.Apply(rest.V, tau), rest.F};
      const geometry::MeshValidationReport report = geometry::ValidateMesh(frame, validation);
      EXPECT_TRUE(report.cgal.ran);
      EXPECT_FALSE(report.cgal.found()) << name << " at τ " << tau << ": " << report.cgal.pair_count << " pairs";
    }
  }
}

TEST(Deformation, HingesRotateTheirRegionByTheBlendedAngle) {
  const SdfSubject bust = MakeSdfSubject("bust");
  const BlendedRotation& jaw = bust.deformation.rotations.at(0);
  ASSERT_EQ(jaw.name, "jaw");
  const Vector3d chin(0.0, -0.07, -0.07), crown(0.0, 0.0, 0.11);
  EXPECT_DOUBLE_EQ(jaw.Weight(chin), 1.0);
  EXPECT_DOUBLE_EQ(jaw.Weight(crown), 0.0);
  // At τ = 60 the head's yaw (sin(2π·60/120)) is 0 and the jaw's ramp is (1 − cos(2π·60/96))/2.
  const double tau = 60.0, angle = 14.0 * 0.5 * (1.0 - std::cos(2.0 * M_PI * tau / 96.0));
  const Vector3d expected =
      Eigen::AngleAxisd(angle * M_PI / 180.0, Vector3d::UnitX()) * (chin - jaw.pivot) + jaw.pivot;
  EXPECT_LT((bust.deformation.Apply(chin, tau) - expected).norm(), 1e-12);
  EXPECT_LT((bust.deformation.Apply(crown, tau) - crown).norm(), 1e-12);
  EXPECT_LT(expected.z(), chin.z() - 0.005);  // the jaw opens downwards
}

TEST(Deformation, RampWeightsTwistLinearlyAndSaturate) {
  BlendedRotation twist;
  twist.ramp_direction = Vector3d::UnitX();
  twist.ramp_half_length = 0.1;
  EXPECT_DOUBLE_EQ(twist.Weight({0.03, 0.5, 0}), 0.3);  // linear for |s| ≤ ½
  EXPECT_DOUBLE_EQ(twist.Weight({-0.03, 0, 0}), -0.3);
  EXPECT_DOUBLE_EQ(twist.Weight({0.15, 0, 0}), 1.0);  // saturated from |s| = 1.5
  EXPECT_DOUBLE_EQ(twist.Weight({-0.4, 0, 0}), -1.0);
  double previous = -2.0;
  for (double x = -0.2; x <= 0.2; x += 0.001) {
    const double w = twist.Weight({x, 0, 0});
    EXPECT_GE(w, previous - 1e-15);
    previous = w;
  }
}

TEST(Deformation, PivotsFollowTheRotationsBeforeThem) {
  // Rotation 0 turns everything +90° about z through the origin; rotation 1's pivot (1, 0, 0)
  // is then at (0, 1, 0), and it rotates only its own material (x > 0.5 at rest).
  Deformation d;
  BlendedRotation first;
  first.axis = Vector3d::UnitZ();
  first.amplitude_degrees = 90.0;
  first.wave = {Wave::Kind::kSine, 4.0, 0.0};  // sin(2π·1/4) = 1 at τ = 1
  BlendedRotation second = first;
  second.pivot = {1, 0, 0};
  second.region = {{{1, 0, 0}, 0.5, 0.01}};
  d.rotations = {first, second};
  // The point (2, 0, 0): after the first rotation (0, 2, 0); then +90° about z through the
  // moved pivot (0, 1, 0): (−1, 1, 0).
  EXPECT_LT((d.Apply(Vector3d(2, 0, 0), 1.0) - Vector3d(-1, 1, 0)).norm(), 1e-12);
  // Material outside the second region only takes the first rotation.
  EXPECT_LT((d.Apply(Vector3d(0.2, 0, 0), 1.0) - Vector3d(0, 0.2, 0)).norm(), 1e-12);
}

TEST(SdfSubjects, FramesKeepConnectivityAndAStillIsAnyFrame) {
  SyntheticSceneOptions options;
  options.scene = "mug";
  options.frame_count = 6;
  options.voxel_size = 0.003;  // coarse (the mug needs ≤ 3 mm): this test is about the frames
  const SyntheticScene scene = MakeSyntheticScene(options);
  ASSERT_EQ(scene.frame_count(), 6);
  for (int f = 1; f < 6; ++f) {
    ASSERT_EQ(scene.frames[f].rows(), scene.rest.rows());
    const double step = (scene.frames[f] - scene.frames[f - 1]).rowwise().norm().maxCoeff();
    EXPECT_GT(step, 1e-4);  // it moves …
    EXPECT_LT(step, 5e-3);  // … smoothly (< 5 mm a frame at motion 1)
  }
  options.frame_count = 1;
  options.start_frame = 5;
  const SyntheticScene still = MakeSyntheticScene(options);
  ASSERT_EQ(still.frame_count(), 1);
  EXPECT_EQ(still.F, scene.F);
  EXPECT_EQ((still.frames[0] - scene.frames[5]).cwiseAbs().maxCoeff(), 0.0);
}

TEST(SdfSubjects, RejectsUnknownSubjectsAndVoxels) {
  EXPECT_THROW(MakeSdfSubject("bunny"), Error);
  SyntheticSceneOptions options;
  options.scene = "bust";
  options.voxel_size = 0.5;
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace subflow::vision
