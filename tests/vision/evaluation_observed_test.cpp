// Observed-surface scoring (vision/evaluation.h): figures restricted to the true surface
// that enough cameras see, on a case whose visibility is known by construction.
#include "vision/evaluation.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "vision/camera_rig.h"

namespace subflow::vision {
namespace {

using geometry::Faces;
using geometry::Positions;
using geometry::TriangleMesh;

// The square [−0.1, 0.1]² at z = 0 as an n × n grid of quads, facing +z.
TriangleMesh Plane(int n = 40) {
  TriangleMesh mesh;
  mesh.V.resize((n + 1) * (n + 1), 3);
  mesh.F.resize(2 * n * n, 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.V.row(j * (n + 1) + i) << -0.1 + 0.2 * i / n, -0.1 + 0.2 * j / n, 0.0;
  int f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      mesh.F.row(f++) << a, a + 1, a + n + 2;
      mesh.F.row(f++) << a, a + n + 2, a + n + 1;
    }
  return mesh;
}

// Cameras 0.5 m above the plane looking straight down: two narrow ones (f = 500 px,
// 100 × 200 px) above x = 0.05 that see exactly the half x ≥ 0 (their image spans
// x ∈ [0, 0.1]), and one wide one (f = 250, 100 × 100) above the centre that sees it all.
// Pixel footprints: depth / f = 0.5 / 500 = 1 mm and 0.5 / 250 = 2 mm.
std::vector<Camera> HalfSeeingCameras() {
  return {LookAtCamera("narrow0", 100, 200, 500.0, {0.05, 0.0, 0.5}, {0.05, 0.0, 0.0}),
          LookAtCamera("narrow1", 100, 200, 500.0, {0.05, 0.0, 0.5}, {0.05, 0.0, 0.0}),
          LookAtCamera("wide", 100, 100, 250.0, {0.0, 0.0, 0.5}, {0.0, 0.0, 0.0})};
}

struct PlaneCase {
  std::vector<TriangleMesh> truth, result;
  std::vector<Positions> motion;
};

// Truth: the plane translating 1 mm per frame along +x (2 frames). Result: the same,
// except that the hidden half (x < 0) is lifted 5 mm and its motion is 2 mm off along z.
PlaneCase MakePlaneCase() {
  PlaneCase c;
  const TriangleMesh plane = Plane();
  for (int f = 0; f < 2; ++f) {
    TriangleMesh truth = plane;
    truth.V.col(0).array() += 0.001 * f;
    TriangleMesh result = truth;
    Positions motion = Positions::Zero(plane.V.rows(), 3);
    motion.col(0).setConstant(0.001);
    for (Eigen::Index i = 0; i < plane.V.rows(); ++i) {
      if (plane.V(i, 0) < -1e-9) {
        result.V(i, 2) += 0.005;
        motion(i, 2) = 0.002;
      }
    }
    c.truth.push_back(truth);
    c.result.push_back(result);
    c.motion.push_back(motion);
  }
  return c;
}

EvaluationReport EvaluatePlane(const PlaneCase& c, int min_views) {
  EvaluationOptions options;
  options.samples = 20000;
  options.min_views = min_views;
  return EvaluateSequence(
      2, [&](int f) { return c.truth[f]; },
      [&](int f) { return EvaluationFrame{c.result[f], c.motion[f]}; }, options, nullptr, "truth", "result",
      HalfSeeingCameras());
}

TEST(ObservedEvaluation, ErrorsOnTheHalfNoTwoCamerasSeeAreLeftOut) {
  const PlaneCase c = MakePlaneCase();
  const EvaluationReport report = EvaluatePlane(c, 2);
  const FrameScores& all = report.overall;
  ASSERT_TRUE(all.observed.evaluated);
  EXPECT_EQ(report.camera_count, 3);
  // Half of the (area-weighted) true samples lie in x ≥ 0; the boundary column of the
  // ±1 px image border is measure zero: 2 % slack for the sampling.
  EXPECT_NEAR(all.observed.observed_fraction, 0.5, 0.02);
  // The whole surface: the lifted half is 5 mm off (> the 2.8 mm completeness threshold).
  EXPECT_GT(all.surface.accuracy, 0.004);
  EXPECT_NEAR(all.surface.completeness, 0.5, 0.05);
  // The observed surface is exact: samples on the very triangles of the truth (rounding).
  EXPECT_LT(all.observed.surface.accuracy, 1e-9);
  EXPECT_DOUBLE_EQ(all.observed.surface.completeness, 1.0);
  // Flow: wrong (2 mm) only on the hidden half.
  ASSERT_TRUE(all.flow.evaluated && all.observed.flow.evaluated);
  EXPECT_GT(all.flow.epe_mean, 0.0005);
  EXPECT_LT(all.observed.flow.epe_mean, 1e-9);
  EXPECT_NEAR(all.observed.flow.true_motion_mean, 0.001, 1e-9);
  // Observed points are seen by the two narrow cameras (1 mm) and the wide one (2 mm).
  EXPECT_NEAR(all.observed.pixel_footprint, (0.001 + 0.001 + 0.002) / 3.0, 1e-9);
  EXPECT_NEAR(report.frames[0].observed.pixel_footprint, (0.001 + 0.001 + 0.002) / 3.0, 1e-9);
}

TEST(ObservedEvaluation, OneViewCountsTheWholePlaneAsObserved) {
  const EvaluationReport report = EvaluatePlane(MakePlaneCase(), 1);
  EXPECT_NEAR(report.overall.observed.observed_fraction, 1.0, 0.005);
  EXPECT_NEAR(report.overall.observed.surface.accuracy, report.overall.surface.accuracy, 1e-12);
  EXPECT_NEAR(report.overall.observed.flow.epe_mean, report.overall.flow.epe_mean, 1e-4);
}

TEST(ObservedEvaluation, AccuracyInPixelsIsAccuracyOverFootprint) {
  PlaneCase c = MakePlaneCase();
  for (TriangleMesh& result : c.result) result.V.col(2).array() += 0.0004;  // 0.4 mm everywhere
  const EvaluationReport report = EvaluatePlane(c, 2);
  const ObservedScores& o = report.overall.observed;
  EXPECT_NEAR(o.surface.accuracy, 0.0004, 1e-7);
  EXPECT_NEAR(o.accuracy_px, 0.0004 / ((0.001 + 0.001 + 0.002) / 3.0), 1e-3);
}

TEST(ObservedEvaluation, SurfacesOnlyModeAcceptsChangingTopology) {
  // Visual hulls have their own mesh per frame: with score_flow off, frame 1 may have
  // other vertices and faces; no flow is reported.
  const TriangleMesh coarse = Plane(10), fine = Plane(30);
  EvaluationOptions options;
  options.samples = 5000;
  options.score_flow = false;
  const EvaluationReport report = EvaluateSequence(
      2, [&](int) { return fine; }, [&](int f) { return EvaluationFrame{f == 0 ? coarse : fine, std::nullopt}; },
      options, nullptr, "truth", "hull", HalfSeeingCameras());
  EXPECT_EQ(report.flow_source, "none");
  EXPECT_FALSE(report.overall.flow.evaluated);
  EXPECT_FALSE(report.overall.observed.flow.evaluated);
  EXPECT_LT(report.overall.surface.accuracy, 1e-9);
  // With flow scored, the same input is refused.
  options.score_flow = true;
  EXPECT_THROW(EvaluateSequence(
                   2, [&](int) { return fine; },
                   [&](int f) { return EvaluationFrame{f == 0 ? coarse : fine, std::nullopt}; }, options),
               Error);
}

TEST(ObservedEvaluation, RejectsNonsenseOptions) {
  EvaluationOptions options;
  options.min_views = 0;
  EXPECT_THROW(options.Check(), Error);
  options.min_views = 2;
  options.visibility_tolerance = -1.0;
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace subflow::vision
