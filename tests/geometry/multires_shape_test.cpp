// Claims about the multi-resolution shape (method §3.2–3.4): analysis and synthesis are
// exact inverses; details in local frames follow rigid motions of the coarse mesh while
// details in world coordinates do not.
#include "geometry/multires_shape.h"

#include <cmath>
#include <random>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/local_frames.h"
#include "geometry/mesh_primitives.h"

namespace subflow::geometry {
namespace {

Positions AddNoise(Positions V, double amplitude, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-amplitude, amplitude);
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    for (int k = 0; k < 3; ++k) V(v, k) += offset(random);
  return V;
}

// A bumpy closed shape at level 3 of a perturbed icosahedron: the refined control mesh
// plus noise, so every level has non-zero details.
struct Bumpy {
  TriangleMesh base = MakeIcosphere(0);
  LoopHierarchy hierarchy{base.F, base.vertex_count(), 3};
  Positions finest = AddNoise(hierarchy.Refine(AddNoise(base.V, 0.1, 1), 0, 3), 0.03, 2);
};

// Rigid motion x ↦ R x + t applied to rows.
Positions Moved(const Positions& V, const Eigen::Matrix3d& R, const Eigen::RowVector3d& t) {
  Positions moved = V * R.transpose();
  moved.rowwise() += t;
  return moved;
}

const Eigen::Matrix3d kRotation =
    Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
const Eigen::RowVector3d kTranslation(0.5, -2.0, 1.25);

// Analysis then synthesis is exact up to rounding: a few sparse products and 3×3 frame
// transforms per level on O(1) coordinates give errors of ~1e-15; 1e-10 is the issue's
// bound.
TEST(MultiresShape, AnalysisThenSynthesisReproducesTheFinestControlMesh) {
  const Bumpy bumpy;
  const MultiresShape shape = MultiresShape::Analyze(bumpy.hierarchy, bumpy.finest);
  ASSERT_EQ(shape.detail_levels(), 3);
  EXPECT_EQ(shape.base().rows(), 12);
  for (int level = 1; level <= 3; ++level) {
    EXPECT_EQ(shape.Detail(level).rows(), bumpy.hierarchy.VertexCount(level));
    EXPECT_GT(shape.Detail(level).cwiseAbs().maxCoeff(), 1e-3) << "level " << level;
  }
  const Positions synthesized = shape.Synthesize(bumpy.hierarchy, 3);
  EXPECT_LT((synthesized - bumpy.finest).cwiseAbs().maxCoeff(), 1e-10);

  // The same on an open mesh (boundary frames and boundary smoothing).
  const TriangleMesh patch = GridPatch(4, 3);
  const LoopHierarchy open(patch.F, patch.vertex_count(), 3);
  const Positions finest = AddNoise(open.Refine(AddNoise(patch.V, 0.2, 3), 0, 3), 0.05, 4);
  const MultiresShape open_shape = MultiresShape::Analyze(open, finest);
  EXPECT_LT((open_shape.Synthesize(open, 3) - finest).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(MultiresShape, EveryLevelIsTheRefinedCoarserLevelPlusItsFramedDetails) {
  const Bumpy bumpy;
  const MultiresShape shape = MultiresShape::Analyze(bumpy.hierarchy, bumpy.finest);
  const std::vector<Positions> levels = shape.SynthesizeLevels(bumpy.hierarchy, 3);
  std::vector<LocalFrames> frames;
  const Positions finest = shape.Synthesize(bumpy.hierarchy, 3, &frames);
  ASSERT_EQ(levels.size(), 4u);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ((levels[3] - finest).cwiseAbs().maxCoeff(), 0.0);
  for (int level = 1; level <= 3; ++level) {
    const Positions predicted = bumpy.hierarchy.Refinement(level - 1) * levels[level - 1];
    const LocalFrames expected = ComputeLocalFrames(bumpy.hierarchy, level, predicted);
    // (Synthesis applies C with the stencil, a different summation order: rounding only.)
    EXPECT_LT((frames[level - 1].normal - expected.normal).cwiseAbs().maxCoeff(), 1e-14);
    const Positions detail = frames[level - 1].ToWorld(shape.Detail(level));
    EXPECT_LT((levels[level] - predicted - detail).cwiseAbs().maxCoeff(), 1e-14);
    // The analysis' coarse levels are the Taubin-smoothed finer levels.
    if (level < 3) continue;
    EXPECT_LT((bumpy.hierarchy.Coarsening(3) * bumpy.finest - levels[2]).cwiseAbs().maxCoeff(),
              1e-10);
  }
}

TEST(MultiresShape, ZeroDetailsGivePlainRefinementAndPartialDetailsRefineAboveTheirLevel) {
  const Bumpy bumpy;
  const MultiresShape smooth(bumpy.hierarchy, bumpy.base.V);
  EXPECT_EQ(smooth.detail_levels(), 3);
  EXPECT_LT((smooth.Synthesize(bumpy.hierarchy, 3) - bumpy.hierarchy.Refine(bumpy.base.V, 0, 3))
                .cwiseAbs().maxCoeff(), 1e-15);

  MultiresShape partial(bumpy.hierarchy, bumpy.base.V, 1);
  partial.Detail(1) = AddNoise(Positions::Zero(bumpy.hierarchy.VertexCount(1), 3), 0.05, 5);
  const Positions level1 = partial.Synthesize(bumpy.hierarchy, 1);
  EXPECT_GT((level1 - bumpy.hierarchy.Refine(bumpy.base.V, 0, 1)).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT((partial.Synthesize(bumpy.hierarchy, 3) - bumpy.hierarchy.Refine(level1, 1, 3))
                .cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LocalFrames, AreOrthonormalRightHandedAndRotateWithTheControlPoints) {
  const Bumpy bumpy;
  const LocalFrames frames = ComputeLocalFrames(bumpy.hierarchy, 3, bumpy.finest);
  const LocalFrames moved =
      ComputeLocalFrames(bumpy.hierarchy, 3, Moved(bumpy.finest, kRotation, kTranslation));
  for (int v = 0; v < frames.vertex_count(); ++v) {
    const Eigen::Vector3d n = frames.normal.row(v), r = frames.r.row(v), q = frames.q.row(v);
    Eigen::Matrix3d F;
    F << n, r, q;
    EXPECT_LT((F.transpose() * F - Eigen::Matrix3d::Identity()).norm(), 1e-14) << v;
    EXPECT_NEAR(F.determinant(), 1.0, 1e-14) << v;
    Eigen::Matrix3d G;
    G << moved.normal.row(v).transpose(), moved.r.row(v).transpose(), moved.q.row(v).transpose();
    EXPECT_LT((G - kRotation * F).norm(), 1e-12) << v;
  }
  // ToLocal is the inverse of ToWorld.
  const Positions local = AddNoise(Positions::Zero(frames.vertex_count(), 3), 1.0, 6);
  EXPECT_LT((frames.ToLocal(frames.ToWorld(local)) - local).cwiseAbs().maxCoeff(), 1e-14);
}

// The point of local frames (method §3.4, Fig. 6): moving the base control points rigidly
// and re-synthesizing with the same details moves the whole fine mesh by that motion,
// to rounding (1e-10). With details in world coordinates (D = I, eq. 19–20) the fine mesh
// does not follow: each detail keeps its world direction, so the error is of the order of
// |R d − d| ≈ 2 sin(θ/2)|d| for rotation angle θ.
TEST(MultiresShape, LocalDetailsFollowARigidMotionOfTheBaseAndWorldDetailsDoNot) {
  const Bumpy bumpy;
  const LoopHierarchy& hierarchy = bumpy.hierarchy;
  MultiresShape shape = MultiresShape::Analyze(hierarchy, bumpy.finest);
  const std::vector<Positions> levels = shape.SynthesizeLevels(hierarchy, 3);
  shape.base() = Moved(shape.base(), kRotation, kTranslation);
  const Positions expected = Moved(bumpy.finest, kRotation, kTranslation);
  const double local_error = (shape.Synthesize(hierarchy, 3) - expected).cwiseAbs().maxCoeff();
  EXPECT_LT(local_error, 1e-10);

  // Global encoding: d(i) = c(i) − C c(i−1) in world coordinates.
  Positions c = Moved(levels[0], kRotation, kTranslation);
  double largest_detail = 0.0;
  for (int level = 1; level <= 3; ++level) {
    const Positions world_detail = levels[level] - hierarchy.Refinement(level - 1) * levels[level - 1];
    largest_detail = std::max(largest_detail, world_detail.rowwise().norm().maxCoeff());
    c = hierarchy.Refinement(level - 1) * c + world_detail;
  }
  const double global_error = (c - expected).rowwise().norm().maxCoeff();
  // θ = 0.7 rad: 2 sin(0.35) = 0.69; demand a third of the largest detail.
  EXPECT_GT(global_error, largest_detail / 3.0);
  EXPECT_GT(global_error, 1e6 * local_error);
  std::printf("rigid motion of c0: fine-mesh error %.3g with local details, %.3g with world "
              "details (largest detail %.3g)\n",
              local_error, global_error, largest_detail);
}

TEST(MultiresShape, TrajectoriesAnalyzeAndSynthesizeEveryFrame) {
  const Bumpy bumpy;
  std::vector<Positions> frames;
  for (int t = 0; t < 4; ++t)
    frames.push_back(Moved(AddNoise(bumpy.finest, 0.01, 10 + t),
                           Eigen::AngleAxisd(0.1 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                           Eigen::RowVector3d(0.1 * t, 0, 0)));
  const Trajectory trajectory = AnalyzeTrajectory(bumpy.hierarchy, frames);
  ASSERT_EQ(trajectory.size(), frames.size());
  const std::vector<Positions> synthesized = SynthesizeTrajectory(bumpy.hierarchy, trajectory, 3);
  for (size_t t = 0; t < frames.size(); ++t) {
    EXPECT_LT((synthesized[t] - frames[t]).cwiseAbs().maxCoeff(), 1e-10) << "frame " << t;
    const MultiresShape alone = MultiresShape::Analyze(bumpy.hierarchy, frames[t]);
    EXPECT_EQ((alone.base() - trajectory[t].base()).cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(MultiresShape, RejectsControlPointsOfTheWrongSize) {
  const Bumpy bumpy;
  auto message = [](auto&& function) -> std::string {
    try {
      function();
    } catch (const subflow::Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_NE(message([&] { MultiresShape::Analyze(bumpy.hierarchy, bumpy.base.V); })
                .find("finest control points: has 12 rows, expected 642"), std::string::npos);
  EXPECT_NE(message([&] { MultiresShape(bumpy.hierarchy, bumpy.finest); })
                .find("base control points: has 642 rows, expected 12"), std::string::npos);
  EXPECT_NE(message([&] { MultiresShape(bumpy.hierarchy, bumpy.base.V, 4); })
                .find("detail levels"), std::string::npos);
  MultiresShape shape(bumpy.hierarchy, bumpy.base.V);
  shape.Detail(2) = Positions::Zero(5, 3);
  EXPECT_NE(message([&] { shape.Synthesize(bumpy.hierarchy, 3); })
                .find("detail level 2: has 5 rows, expected 162"), std::string::npos);
}

// The hot path (RefineAndAddDetails: tangents of the predicted points from the coarse
// points, synthesis_plan.h) agrees with refining, then framing the predicted points, on a
// closed mesh with valence-5 vertices and on an open one (general rows at the boundary),
// in each instruction set the CPU offers. The two paths round differently (sums in another
// order, fused multiply-adds on AVX2): ~1e-15 on these O(1) coordinates, 1e-13 leaves room.
TEST(MultiresShape, FusedSynthesisMatchesRefineThenFrame) {
  const Bumpy bumpy;
  const TriangleMesh patch = GridPatch(4, 3);
  const LoopHierarchy open(patch.F, patch.vertex_count(), 3);
  const Positions open_finest = AddNoise(open.Refine(AddNoise(patch.V, 0.2, 3), 0, 3), 0.05, 4);
  for (const SynthesisKernel kernel : {SynthesisKernel::kBaseline, SynthesisKernel::kAvx2Fma}) {
    if (!SynthesisKernelAvailable(kernel)) continue;
    for (const auto& [hierarchy, finest] :
         {std::pair<const LoopHierarchy*, const Positions*>{&bumpy.hierarchy, &bumpy.finest},
          std::pair<const LoopHierarchy*, const Positions*>{&open, &open_finest}}) {
      const MultiresShape shape = MultiresShape::Analyze(*hierarchy, *finest);
      Positions c = shape.base();
      for (int level = 1; level <= 3; ++level) {
        Positions predicted, expected, fused;
        hierarchy->RefinementStencil(level - 1).Apply(c, &predicted);
        AddDetailsInLocalFrames(*hierarchy, level, predicted, shape.Detail(level), &expected);
        RefineAndAddDetails(*hierarchy, level, c, shape.Detail(level), &fused, kernel);
        EXPECT_LT((fused - expected).cwiseAbs().maxCoeff(), 1e-13)
            << "level " << level << ", kernel " << static_cast<int>(kernel);
        c = expected;
      }
    }
  }
}

// The baseline (SSE2) and AVX2+FMA kernels of the synthesis step compute the same thing:
// on a finer mesh (4 levels, 40962 vertices, so that the step runs in parallel blocks too)
// they agree to 1e-12 relative to the coordinates' size (rounding only: FMA rounds once
// where the baseline rounds twice). With zero details both give plain refinement exactly:
// the predicted points are rounded as PointStencil::Apply rounds them, in both.
TEST(MultiresShape, SynthesisKernelsAgree) {
  if (!SynthesisKernelAvailable(SynthesisKernel::kAvx2Fma))
    GTEST_SKIP() << "this CPU has no AVX2+FMA; only the baseline kernel runs";
  const TriangleMesh base = MakeIcosphere(2);
  const LoopHierarchy hierarchy(base.F, base.vertex_count(), 4);
  const Positions finest =
      AddNoise(hierarchy.Refine(AddNoise(base.V, 0.05, 6), 0, 4), 0.01, 7);
  const MultiresShape shape = MultiresShape::Analyze(hierarchy, finest);
  const MultiresShape smooth(hierarchy, base.V);
  for (const MultiresShape* s : {&shape, &smooth}) {
    Positions baseline = s->base(), avx2 = s->base(), next;
    for (int level = 1; level <= 4; ++level) {
      RefineAndAddDetails(hierarchy, level, baseline, s->Detail(level), &next,
                          SynthesisKernel::kBaseline);
      baseline.swap(next);
      RefineAndAddDetails(hierarchy, level, avx2, s->Detail(level), &next,
                          SynthesisKernel::kAvx2Fma);
      avx2.swap(next);
    }
    const double scale = baseline.cwiseAbs().maxCoeff();
    if (s == &smooth) {
      EXPECT_EQ((baseline - avx2).cwiseAbs().maxCoeff(), 0.0);
      EXPECT_EQ((baseline - hierarchy.Refine(base.V, 0, 4)).cwiseAbs().maxCoeff(), 0.0);
    } else {
      EXPECT_LT((baseline - avx2).cwiseAbs().maxCoeff(), 1e-12 * scale);
      EXPECT_LT((baseline - finest).cwiseAbs().maxCoeff(), 1e-10);
    }
  }
}

}  // namespace
}  // namespace subflow::geometry
