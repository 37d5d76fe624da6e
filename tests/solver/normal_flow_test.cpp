// Normal-flow constraints (method eq. 24) and their robust sparse least-squares solution:
// samples about one per pixel, z-buffer visibility, image derivatives, constraints that the
// true motion satisfies on rendered images, exact recovery from exact constraints, and
// pruning of injected bad measurements.
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "solver/motion/constraint_collinearity.h"
#include "solver/observation/image_derivatives.h"
#include "solver/motion/normal_flow_constraints.h"
#include "solver/motion/normal_flow_solver.h"
#include "solver/observation/sample_visibility.h"
#include "solver/observation/surface_sampling.h"
#include "tests/solver/motion_test_scene.h"

namespace subflow::solver {
namespace {

using geometry::Positions;
using testing::MotionTestScene;

const MotionTestScene& Scene() {
  static const MotionTestScene scene = testing::MakeMotionTestScene();
  return scene;
}

double Rms(const Eigen::VectorXd& v) { return std::sqrt(v.squaredNorm() / v.size()); }

// Density m per face from the largest projected area A: m = ⌈√A⌉, so the samples per
// pixel² of each face's finest view are in [1, (1 + 1/√A)²] — at least one per pixel,
// and at most ~2 for faces of ≥ 25 px² (tolerance: the ceil's rounding).
TEST(SurfaceSampling, AboutOneSamplePerPixelOfTheFinestView) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const SurfaceSamples samples =
      SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  EXPECT_EQ(samples.limit.rows(), samples.size());
  EXPECT_EQ(samples.face_first_sample.back(), samples.size());
  // Every face has m² samples inside it, and positions L c lie on the limit surface: the
  // limit positions at the corners agree with LimitPositions (regression of the pattern).
  double total_pixels = 0.0;
  int faces_seen = 0;
  const Positions corners = scene.hierarchy.LimitPositions(n) * scene.control;
  for (int f = 0; f < scene.hierarchy.FaceCount(n); ++f) {
    const int m = samples.face_density[f];
    EXPECT_EQ(samples.face_first_sample[f + 1] - samples.face_first_sample[f], m * m);
    double largest = 0.0;
    for (const vision::Camera& camera : scene.cameras) {
      Eigen::Vector2d p[3];
      Eigen::Vector3d X[3];
      for (int k = 0; k < 3; ++k) {
        X[k] = corners.row(scene.hierarchy.LevelFaces(n)(f, k)).transpose();
        p[k] = camera.ProjectUndistorted(X[k]);
      }
      if ((X[1] - X[0]).cross(X[2] - X[0]).dot(camera.Center() - X[0]) <= 0) continue;
      const Eigen::Vector2d a = p[1] - p[0], b = p[2] - p[0];
      largest = std::max(largest, 0.5 * std::abs(a.x() * b.y() - a.y() * b.x()));
    }
    if (largest > 25.0) {
      ++faces_seen;
      total_pixels += largest;
      EXPECT_GE(m * m, largest - 1e-9);
      EXPECT_LE(m * m, std::pow(1.0 + 1.0 / std::sqrt(largest), 2) * largest + 1e-9);
    }
  }
  std::printf("%d samples on %d faces; %.2f samples per pixel on faces with > 25 px\n",
              samples.size(), scene.hierarchy.FaceCount(n),
              faces_seen ? samples.size() / total_pixels : 0.0);
  EXPECT_GT(faces_seen, scene.hierarchy.FaceCount(n) / 2);
}

// A sample is visible only from the side it faces, and on this convex-ish object nearly
// every sample facing a camera squarely (cos > 0.5) is visible there (≥ 97 %: bumps may
// hide a few).
TEST(SampleVisibility, BackFacingSamplesAreHiddenFrontFacingSeen) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const SurfaceSamples samples =
      SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  const VisibilityTester tester(scene.hierarchy, n);
  const Positions X = samples.SamplePositions(scene.control);
  const Positions normals = samples.SampleNormals(scene.control);
  const SampleVisibility visibility = tester.Compute(scene.cameras, scene.control, X, normals);
  int facing = 0, facing_visible = 0, back_visible = 0;
  for (int k = 0; k < visibility.camera_count(); ++k)
    for (int s = 0; s < samples.size(); ++s) {
      const Eigen::Vector3d ray = (scene.cameras[k].Center() - X.row(s).transpose()).normalized();
      const double cosine = normals.row(s).dot(ray.transpose());
      if (cosine < 0.0) back_visible += visibility.visible[k][s];
      if (cosine > 0.5 && scene.cameras[k].InImage(scene.cameras[k].ProjectUndistorted(X.row(s).transpose()), 3.0)) {
        ++facing;
        facing_visible += visibility.visible[k][s];
      }
    }
  EXPECT_EQ(back_visible, 0);
  EXPECT_GE(facing_visible, 0.97 * facing);
  EXPECT_GT(visibility.SamplesSeenBy(2), samples.size() / 2);
  const auto patch_cameras = visibility.CamerasSeeingFaces(samples);
  EXPECT_EQ(static_cast<int>(patch_cameras.size()), scene.hierarchy.FaceCount(n));
}

// The z-buffer of the level's own faces (density 1, the default) decides as a finer
// tessellation does: the facets' chord error is far below the depth tolerance.
TEST(SampleVisibility, OneTriangleAFaceDecidesAsAFinerTessellation) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const SurfaceSamples samples = SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  const Positions X = samples.SamplePositions(scene.control);
  const Positions normals = samples.SampleNormals(scene.control);
  VisibilityOptions fine;
  fine.tessellation_density = 4;
  const SampleVisibility coarse = VisibilityTester(scene.hierarchy, n).Compute(scene.cameras, scene.control, X, normals);
  const SampleVisibility reference =
      VisibilityTester(scene.hierarchy, n, fine).Compute(scene.cameras, scene.control, X, normals);
  int differ = 0, visible = 0;
  for (int k = 0; k < coarse.camera_count(); ++k)
    for (int s = 0; s < samples.size(); ++s) {
      differ += coarse.visible[k][s] != reference.visible[k][s];
      visible += reference.visible[k][s];
    }
  EXPECT_GT(visible, samples.size());
  EXPECT_LE(differ, 0.002 * visible) << differ << " of " << visible;
}

// The gradient SampleImage takes from the intensities at sampling time is, to the bit,
// the bilinear interpolation of OpenCV's central-difference planes (cv::filter2D, kernel
// (−½, 0, ½), replicated border), everywhere a sample is defined: inside and at the four
// borders, on a random image.
TEST(ImageDerivatives, GradientAtSamplingTimeIsFilter2DsPlanesToTheBit) {
  cv::Mat image(160, 200, CV_32FC1);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
  const SmoothedImage smoothed = SmoothImage(image, 0.8);
  cv::Mat gx, gy;
  const cv::Mat kx = (cv::Mat_<float>(1, 3) << -0.5f, 0.0f, 0.5f), ky = kx.t();
  cv::filter2D(smoothed.intensity, gx, CV_32F, kx, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  cv::filter2D(smoothed.intensity, gy, CV_32F, ky, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  const auto bilinear = [](const cv::Mat& plane, double x, double y) {  // as the planes were sampled
    double value = 0.0;
    EXPECT_TRUE(SampleScalar(plane, Eigen::Vector2d(x, y), &value));
    return value;
  };
  int sampled = 0, differing = 0;
  for (double y = 0.0; y < image.rows - 1.0; y += 0.37) {
    for (double x = 0.0; x < image.cols - 1.0; x += 0.41) {
      double intensity = 0.0;
      Eigen::Vector2d gradient;
      if (!SampleImage(smoothed, Eigen::Vector2d(x, y), &intensity, &gradient)) continue;
      ++sampled;
      differing += gradient.x() != bilinear(gx, x, y) || gradient.y() != bilinear(gy, x, y);
    }
  }
  EXPECT_GT(sampled, 4000);
  EXPECT_EQ(differing, 0);
  // A gradient that is not zero at the border: the replicated neighbour makes it one-sided.
  double intensity = 0.0;
  Eigen::Vector2d gradient;
  ASSERT_TRUE(SampleImage(smoothed, Eigen::Vector2d(0.0, 0.0), &intensity, &gradient));
  EXPECT_EQ(gradient.x(), 0.5f * (smoothed.intensity.at<float>(0, 1) - smoothed.intensity.at<float>(0, 0)));
}

// On a linear ramp I = a x + b y + c the smoothed gradient is exact (a Gaussian and a
// central difference preserve linear functions) away from the border, and I_t of a ramp
// shifted by d pixels per frame is −(a, b)·d (central and one-sided differences alike).
TEST(ImageDerivatives, RampGradientAndTemporalDerivativeAreExact) {
  const double a = 0.002, b = -0.0015;
  auto ramp = [&](double shift_x) {
    cv::Mat image(60, 80, CV_32FC1);
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x)
        image.at<float>(y, x) = static_cast<float>(0.4 + a * (x - shift_x) + b * y);
    return image;
  };
  const SmoothedImage smoothed = SmoothImage(ramp(0.0), 1.5);
  double intensity = 0.0;
  Eigen::Vector2d gradient;
  ASSERT_TRUE(SampleImage(smoothed, Eigen::Vector2d(40.3, 30.7), &intensity, &gradient));
  EXPECT_NEAR(intensity, 0.4 + a * 40.3 + b * 30.7, 1e-6);  // float images: 1e-6
  EXPECT_NEAR(gradient.x(), a, 1e-6);
  EXPECT_NEAR(gradient.y(), b, 1e-6);
  EXPECT_FALSE(SampleImage(smoothed, Eigen::Vector2d(79.2, 3.0), &intensity, &gradient));
  const SpatioTemporalDerivatives central =
      ComputeSpatioTemporalDerivatives(ramp(-0.7), ramp(0.0), ramp(0.7), 1.0);
  const SpatioTemporalDerivatives forward =
      ComputeSpatioTemporalDerivatives(cv::Mat(), ramp(0.0), ramp(0.7), 1.0);
  double it = 0.0;
  ASSERT_TRUE(SampleScalar(central.temporal, Eigen::Vector2d(40, 30), &it));
  EXPECT_NEAR(it, -a * 0.7, 1e-6);
  ASSERT_TRUE(SampleScalar(forward.temporal, Eigen::Vector2d(40, 30), &it));
  EXPECT_NEAR(it, -a * 0.7, 1e-6);
  EXPECT_THROW(ComputeSpatioTemporalDerivatives(cv::Mat(), ramp(0), cv::Mat(), 1.0), Error);
}

// Constraints from rendered images (8-bit, 3×3 supersampled, Lambertian, fixed lights) of
// the potato translated by 1.2 mm (≈ 0.85 px) are satisfied by the true displacement:
// RMS residual of the true motion ≤ 0.35 × RMS residual of zero motion in the linearized
// step form, ≤ 0.2 × after re-linearizing at the true motion (what remains: 8-bit
// quantization, anti-aliasing and interpolation). The frame form with central differences
// (frames −1, 0, +1) is satisfied likewise by the velocity.
TEST(NormalFlow, TrueMotionSatisfiesConstraintsOnExactImages) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const Eigen::Vector3d t(0.0009, -0.0006, 0.0005);
  testing::RigidTransform forward, backward;
  forward.t = t;
  backward.t = -t;
  const std::vector<cv::Mat> before = testing::RenderGray(scene, scene.mesh.V);
  const std::vector<cv::Mat> after = testing::RenderGray(scene, forward.Apply(scene.mesh.V));
  const std::vector<cv::Mat> previous = testing::RenderGray(scene, backward.Apply(scene.mesh.V));

  const SurfaceSamples samples =
      SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  const Positions X = samples.SamplePositions(scene.control);
  const SampleVisibility visibility = VisibilityTester(scene.hierarchy, n)
      .Compute(scene.cameras, scene.control, X, samples.SampleNormals(scene.control));
  Positions truth(X.rows(), 3);
  truth.rowwise() = t.transpose();
  const Positions zero = Positions::Zero(X.rows(), 3);

  std::vector<SmoothedImage> sb, sa;
  for (std::size_t k = 0; k < before.size(); ++k) {
    sb.push_back(SmoothImage(before[k], 1.0));
    sa.push_back(SmoothImage(after[k], 1.0));
  }
  const NormalFlowConstraints linear = BuildStepConstraints(scene.cameras, sb, sa, X, Positions(), visibility);
  const NormalFlowConstraints warped = BuildStepConstraints(scene.cameras, sb, sa, X, truth, visibility);
  ASSERT_GT(linear.size(), 20000);
  const double linear_ratio = Rms(linear.Residuals(truth)) / Rms(linear.Residuals(zero));
  const double warped_ratio = Rms(warped.Residuals(truth)) / Rms(linear.Residuals(zero));
  std::vector<SpatioTemporalDerivatives> derivatives;
  for (std::size_t k = 0; k < before.size(); ++k)
    derivatives.push_back(ComputeSpatioTemporalDerivatives(previous[k], before[k], after[k], 1.0));
  const NormalFlowConstraints frame = BuildFrameConstraints(scene.cameras, derivatives, X, visibility);
  const double frame_ratio = Rms(frame.Residuals(truth)) / Rms(frame.Residuals(zero));
  std::printf("%d constraints; residual ratio true/zero motion: step form %.3f, re-linearized "
              "%.3f, frame form (central differences) %.3f\n",
              linear.size(), linear_ratio, warped_ratio, frame_ratio);
  EXPECT_LT(linear_ratio, 0.35);
  EXPECT_LT(warped_ratio, 0.2);
  EXPECT_LT(frame_ratio, 0.35);
}

// Exact synthetic constraints of the rank-2 structure of real ones (g_k = ∇ρ + λ_k n per
// sample, 4 views, b = gᵀ u_true) for a translation plus a small rotation (0.57°): the
// solver recovers the control displacement to 1e-3 of its magnitude (measured 8e-6; CG
// stops at a relative residual of 1e-4 per level). The smoothness term acts on the motion
// minus its rigid part; the plain umbrella Laplacian of the velocities biases the rotation
// (measured 1.5e-3 at the default smoothness 0.003, 1.3e-2 at 0.1), which the second
// solve shows (> 10× the error).
struct SyntheticConstraints {
  NormalFlowConstraints constraints;
  Positions true_displacement;
};

SyntheticConstraints MakeSyntheticConstraints(const MotionTestScene& scene,
                                              const SurfaceSamples& samples, unsigned seed) {
  testing::RigidTransform motion;
  motion.R = Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.2, 0.4, 0.9).normalized()).toRotationMatrix();
  motion.t = Eigen::Vector3d(0.001, -0.0005, 0.0008);
  motion.centre = testing::Centroid(scene.control);
  SyntheticConstraints result;
  result.true_displacement = motion.Apply(scene.control) - scene.control;
  const Positions X = samples.SamplePositions(scene.control);
  const Positions normals = samples.SampleNormals(scene.control);
  const Positions u = samples.limit * result.true_displacement;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  SampleVisibility all;
  all.visible.assign(4, std::vector<std::uint8_t>(samples.size(), 1));
  std::vector<int> sample_ids;
  std::vector<Eigen::Vector3d> gradients;
  std::vector<double> rhs;
  for (int s = 0; s < samples.size(); ++s) {
    const Eigen::Vector3d n = normals.row(s).transpose();
    Eigen::Vector3d texture(normal(rng), normal(rng), normal(rng));
    texture = 30.0 * (texture - texture.dot(n) * n);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d g = texture + 20.0 * normal(rng) * n;
      sample_ids.push_back(s);
      gradients.push_back(g);
      rhs.push_back(g.dot(u.row(s).transpose()));
    }
  }
  NormalFlowConstraints& c = result.constraints;
  c.sample = sample_ids;
  c.camera.assign(sample_ids.size(), 0);
  c.gradient.resize(static_cast<Eigen::Index>(sample_ids.size()), 3);
  c.rhs.resize(static_cast<Eigen::Index>(sample_ids.size()));
  c.photometric = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(sample_ids.size()));
  for (std::size_t i = 0; i < sample_ids.size(); ++i) {
    c.gradient.row(static_cast<Eigen::Index>(i)) = gradients[i].transpose();
    c.rhs(static_cast<Eigen::Index>(i)) = rhs[i];
  }
  return result;
}

double RelativeError(const Positions& estimate, const Positions& truth) {
  return std::sqrt((estimate - truth).squaredNorm() / truth.squaredNorm());
}

TEST(NormalFlowSolver, RecoversAKnownMotionFromExactConstraints) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const SurfaceSamples samples =
      SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  const SyntheticConstraints synthetic = MakeSyntheticConstraints(scene, samples, 7);
  NormalFlowSolverOptions options;
  const NormalFlowSolver solver(scene.hierarchy, samples.limit, scene.control, options);
  const NormalFlowSolution solution = solver.Solve(synthetic.constraints, scene.control);
  const double error = RelativeError(solution.displacement, synthetic.true_displacement);
  std::printf("exact constraints: relative error %.2e, %d CG iterations, %d pruned of %d\n",
              error, solution.cg_iterations, solution.pruned, synthetic.constraints.size());
  EXPECT_LT(error, 1e-3);
  NormalFlowSolverOptions plain_laplacian;
  plain_laplacian.rigid_invariant_smoothness = false;
  const double biased = RelativeError(
      NormalFlowSolver(scene.hierarchy, samples.limit, scene.control, plain_laplacian)
          .Solve(synthetic.constraints, scene.control).displacement,
      synthetic.true_displacement);
  std::printf("plain umbrella smoothness: relative error %.2e\n", biased);
  EXPECT_GT(biased, 10.0 * error);
  // Base first: the base level alone already carries most of the motion.
  ASSERT_EQ(solution.levels.size(), static_cast<std::size_t>(n + 1));
  const Positions base_only =
      scene.hierarchy.Refine(solution.level_motion[0], 0, n);
  EXPECT_LT(RelativeError(base_only, synthetic.true_displacement), 0.1);
  EXPECT_EQ(LocalDetailMotion(scene.hierarchy, scene.control, solution, 0)[n].rows(),
            scene.hierarchy.VertexCount(n));
}

// The V-cycle preconditioner (multigrid_preconditioner.h) changes how the CG gets to each
// level's solution, not the solution: the same displacement within the CG tolerance's
// reach, in fewer iterations.
TEST(NormalFlowSolver, MultigridGivesTheSameMotionInFewerIterations) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const SurfaceSamples samples = SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  const SyntheticConstraints synthetic = MakeSyntheticConstraints(scene, samples, 7);
  NormalFlowSolverOptions plain, cycled;
  plain.multigrid = false;
  cycled.multigrid = true;
  cycled.multigrid_min_vertices = 0;  // the scene's levels are smaller than the default's
  const NormalFlowSolution a =
      NormalFlowSolver(scene.hierarchy, samples.limit, scene.control, plain).Solve(synthetic.constraints, scene.control);
  const NormalFlowSolution b =
      NormalFlowSolver(scene.hierarchy, samples.limit, scene.control, cycled).Solve(synthetic.constraints, scene.control);
  std::printf("CG iterations: block Jacobi %d, V-cycle %d; relative difference %.2e\n", a.cg_iterations,
              b.cg_iterations, RelativeError(b.displacement, a.displacement));
  EXPECT_LT(RelativeError(b.displacement, a.displacement), 1e-3);
  EXPECT_LT(RelativeError(b.displacement, synthetic.true_displacement), 1e-3);
  EXPECT_LT(b.cg_iterations, a.cg_iterations);
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (std::size_t l = 0; l < a.levels.size(); ++l) EXPECT_LE(b.levels[l].cg_error, plain.cg_tolerance);
}

// 5 % of the constraints get a wrong temporal derivative (b off by ±(5..15) × the RMS of b):
// with the collinearity test and IRLS, ≥ 95 % of them end with weight 0, the solution stays
// within 1 % of the clean one's error budget (relative error < 0.02), while plain least
// squares is thrown off by more than 5 %.
// Each sample has 4 views, so a single bad view is identified by the collinearity test and
// removed alone; only samples with 2 bad views (~1.4 %) lose all their constraints —
// hence "fewer than 2 × as many pruned as injected".
TEST(NormalFlowSolver, PruningRemovesInjectedBadMeasurements) {
  const MotionTestScene& scene = Scene();
  const int n = scene.hierarchy.finest_level();
  const SurfaceSamples samples =
      SampleLimitSurface(scene.hierarchy, n, scene.control, scene.cameras, {});
  SyntheticConstraints synthetic = MakeSyntheticConstraints(scene, samples, 11);
  NormalFlowConstraints& c = synthetic.constraints;
  const double rms_b = Rms(c.rhs);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<int> bad;
  for (int i = 0; i < c.size(); ++i)
    if (uniform(rng) < 0.05) {
      c.rhs(i) += (uniform(rng) < 0.5 ? -1.0 : 1.0) * (5.0 + 10.0 * uniform(rng)) * rms_b;
      bad.push_back(i);
    }
  const NormalFlowSolution robust =
      NormalFlowSolver(scene.hierarchy, samples.limit, scene.control, {}).Solve(c, scene.control);
  NormalFlowSolverOptions plain_options;
  plain_options.reweighting_iterations = 0;
  plain_options.collinearity_pruning = false;
  const NormalFlowSolution plain =
      NormalFlowSolver(scene.hierarchy, samples.limit, scene.control, plain_options).Solve(c, scene.control);
  int bad_removed = 0;
  for (int i : bad) bad_removed += robust.weights(i) == 0.0;
  const double robust_error = RelativeError(robust.displacement, synthetic.true_displacement);
  const double plain_error = RelativeError(plain.displacement, synthetic.true_displacement);
  std::printf("%zu bad of %d: %d pruned (%d by collinearity, %d in all); error robust %.2e, "
              "plain %.2e\n",
              bad.size(), c.size(), bad_removed, robust.collinearity_pruned, robust.pruned,
              robust_error, plain_error);
  EXPECT_GE(bad_removed, 0.95 * bad.size());
  EXPECT_LT(robust.pruned, 2.0 * bad.size());  // few good rows are lost
  EXPECT_LT(robust_error, 0.02);
  EXPECT_GT(plain_error, 0.05);
}

// The collinearity test on one sample: five consistent planes through one 3D normal-flow
// line (g_k = ∇ρ + λ_k n, b_k = g_kᵀ V) keep weight 1; one wrong b is removed alone; with
// three views and one wrong b the bad view cannot be told apart, the sample is pruned.
TEST(ConstraintCollinearity, RemovesTheOneInconsistentPlaneOrTheWholeSample) {
  const Eigen::Vector3d n(0, 0, 1), texture(30, -10, 0), V(0.001, 0.0005, -0.0008);
  // Sample 0 carries the case under test; samples 1..39 are clean (they fix σ at the
  // noise floor, as the many good samples of a real step do).
  constexpr int kSamples = 40;
  auto make = [&](int views, int bad_view) {
    NormalFlowConstraints c;
    c.gradient.resize(kSamples * views, 3);
    c.rhs.resize(kSamples * views);
    c.photometric = Eigen::VectorXd::Zero(kSamples * views);
    for (int s = 0; s < kSamples; ++s)
      for (int k = 0; k < views; ++k) {
        const int row = s * views + k;
        const Eigen::Vector3d g = texture + (20.0 * k - 35.0) * n;
        c.sample.push_back(s);
        c.camera.push_back(k);
        c.gradient.row(row) = g.transpose();
        c.rhs(row) = g.dot(V) + (s == 0 && k == bad_view ? 0.2 : 0.0);
      }
    return c;
  };
  const CollinearityOptions options;
  const CollinearityResult clean = CollinearityWeights(make(5, -1), kSamples, options);
  EXPECT_EQ(clean.pruned, 0);
  EXPECT_NEAR(clean.weights.minCoeff(), 1.0, 1e-6);
  const CollinearityResult one_bad = CollinearityWeights(make(5, 2), kSamples, options);
  EXPECT_EQ(one_bad.pruned, 1);
  EXPECT_EQ(one_bad.weights(2), 0.0);
  EXPECT_EQ(one_bad.removed_single, 1);
  const CollinearityResult three_views = CollinearityWeights(make(3, 1), kSamples, options);
  EXPECT_EQ(three_views.pruned, 3);
  EXPECT_EQ(three_views.pruned_samples, 1);
  EXPECT_NEAR(TukeyWeight(0.5), 0.5625, 1e-15);
  EXPECT_EQ(TukeyWeight(1.0), 0.0);
  EXPECT_NEAR(RobustScale({1.0, -2.0, 3.0}, 0.0), 1.4826 * 2.0, 1e-12);
  EXPECT_EQ(RobustScale({1e-9, -1e-9, 0.0}, 0.002), 0.002);
}

}  // namespace
}  // namespace subflow::solver
