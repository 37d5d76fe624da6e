// Motion initialization (method §4.2) on rendered images with known motion: one frame step
// recovers a translation and a small rotation, and a sequence is propagated forward and
// backward from a reference frame on one hierarchy with the rigid motion of every step.
#include "solver/motion/motion_init.h"

#include <cmath>
#include <cstdio>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/mean_edge_length.h"
#include "geometry/multires_shape.h"
#include "solver/reconstruction.h"
#include "solver/rigid/rigid_motion.h"
#include "solver/rigid/rigid_split.h"
#include "tests/solver/motion_test_scene.h"

namespace subflow::solver {
namespace {

using geometry::Positions;
using testing::MotionTestScene;
using testing::RigidTransform;

constexpr double kDegree = M_PI / 180.0;

const MotionTestScene& Scene() {
  static const MotionTestScene scene = testing::MakeMotionTestScene();
  return scene;
}

// Frames 0..frame_count−1 of vision's "rigid" scene on the test scene's mesh (subdivisions 4).
vision::SyntheticScene RigidSequence(int frame_count) {
  vision::SyntheticSceneOptions options;
  options.scene = "rigid";
  options.frame_count = frame_count;
  options.subdivisions = 4;
  return vision::MakeSyntheticScene(options);
}

// Mean |u_est − u_true| / mean |u_true| over the samples that at least two cameras see
// (elsewhere only the smoothness term speaks).
double SampleMotionError(const MotionStepEstimator& estimator, const Positions& control,
                         const Positions& estimate, const Positions& truth) {
  const SurfaceSamples& samples = estimator.samples();
  const SampleVisibility visibility = estimator.visibility().Compute(
      estimator.cameras(), control, samples.SamplePositions(control), samples.SampleNormals(control));
  const Positions u = samples.limit * estimate, u_true = samples.limit * truth;
  double error = 0.0, magnitude = 0.0;
  for (int s = 0; s < samples.size(); ++s) {
    if (visibility.CamerasSeeing(s).size() < 2) continue;
    error += (u.row(s) - u_true.row(s)).norm();
    magnitude += u_true.row(s).norm();
  }
  return error / magnitude;
}

// One translation `t` of the scene, estimated from zero and from the guess that the
// translation is `guess_t`; Error() is SampleMotionError against the true motion.
struct TranslationStepsWithGuess {
  TranslationStepsWithGuess(const Eigen::Vector3d& t, const Eigen::Vector3d& guess_t)
      : before(testing::RenderGray(scene, scene.mesh.V)),
        after(testing::RenderGray(scene, Translated(scene.mesh.V, t))),
        truth(Translated(scene.control, t) - scene.control),
        guess(Translated(scene.control, guess_t) - scene.control),
        from_zero(estimator.Estimate(scene.control, before, after)),
        from_guess(estimator.Estimate(scene.control, before, after, {guess})) {}
  double Error(const Positions& displacement) const {
    return SampleMotionError(estimator, scene.control, displacement, truth);
  }
  static Positions Translated(const Positions& points, const Eigen::Vector3d& t) {
    RigidTransform motion;
    motion.t = t;
    return motion.Apply(points);
  }

  const MotionTestScene& scene = Scene();
  const MotionStepEstimator estimator{scene.hierarchy, scene.cameras, scene.control};
  const std::vector<cv::Mat> before, after;
  const Positions truth, guess;
  const MotionStep from_zero, from_guess;
};

// A translation of 1.5 mm (≈ 1 px in these 320×240 views, the blob's per-frame motion) is
// recovered within 10 % (sample motion, mean over the samples seen twice) and the fitted
// rigid translation within 10 % of its length.
TEST(MotionStep, RecoversAKnownTranslation) {
  const MotionTestScene& scene = Scene();
  RigidTransform motion;
  motion.t = Eigen::Vector3d(0.0012, -0.0007, 0.0006);
  const MotionStepEstimator estimator(scene.hierarchy, scene.cameras, scene.control);
  const MotionStep step = estimator.Estimate(scene.control, testing::RenderGray(scene, scene.mesh.V),
                                             testing::RenderGray(scene, motion.Apply(scene.mesh.V)));
  const Positions truth = motion.Apply(scene.control) - scene.control;
  const double error = SampleMotionError(estimator, scene.control, step.displacement, truth);
  const RigidMotion rigid = FitRigidMotion(scene.control + 0.5 * step.displacement, step.displacement);
  std::printf("translation |t| = %.2f mm: sample motion error %.1f %%, rigid v error %.1f %%, "
              "rotation %.3f°, photometric RMS %.4f → %.4f, %d constraints (%d pruned), %.2f s\n",
              motion.t.norm() * 1e3, 100 * error, 100 * (rigid.v - motion.t).norm() / motion.t.norm(),
              rigid.RotationAngle() / kDegree, step.report.photometric_rms_zero,
              step.report.photometric_rms, step.report.constraints, step.report.pruned,
              step.report.seconds);
  EXPECT_LT(error, 0.10);
  EXPECT_LT((rigid.v - motion.t).norm(), 0.10 * motion.t.norm());
  EXPECT_LT(rigid.RotationAngle(), 0.5 * kDegree);
  EXPECT_LT(step.report.photometric_rms, 0.6 * step.report.photometric_rms_zero);
}

// A translation of 8 mm (≈ 5 px) is far outside the linear range of the image passes (σ 1.5
// then 1 px): from zero the passes recover it to ~4 % (sample motion). Started at a guess
// 1.4 mm (≈ 1 px) off — what the retrack pass has in the refined trajectories — the same
// passes recover it several times closer (~0.3 %).
TEST(MotionStep, AGuessNearTheMotionIsFollowedCloserThanAStartFromZero) {
  const Eigen::Vector3d t(0.006, -0.004, 0.003);
  const TranslationStepsWithGuess steps(t, t + Eigen::Vector3d(0.001, 0.0008, -0.0006));
  const double error_zero = steps.Error(steps.from_zero.displacement);
  const double error_guess = steps.Error(steps.from_guess.displacement);
  const double error_of_guess = steps.Error(steps.guess);
  std::printf("translation |t| = %.1f mm: sample motion error from zero %.1f %%, guess itself %.1f %%, "
              "from the guess %.1f %%\n",
              t.norm() * 1e3, 100 * error_zero, 100 * error_of_guess, 100 * error_guess);
  EXPECT_LT(error_zero, 0.10);
  EXPECT_LT(error_guess, 0.25 * error_zero);
  EXPECT_LT(error_guess, 0.1 * error_of_guess);
  EXPECT_TRUE(steps.from_guess.report.guess_used);
  EXPECT_LT(steps.from_guess.report.guess_rms, steps.from_guess.report.guess_rms_zero);
  const Positions wrong = Positions::Zero(3, 3);
  EXPECT_THROW(steps.estimator.Estimate(steps.scene.control, steps.before, steps.after, {steps.guess, wrong}), Error);
}

// Of several guesses the first pass starts at the one that matches the images best: a guess
// 12 mm the wrong way beside the one near the motion changes nothing, to the bit.
TEST(MotionStep, TheBestOfSeveralGuessesIsTheStart) {
  const TranslationStepsWithGuess steps(Eigen::Vector3d(0.006, -0.004, 0.003), Eigen::Vector3d(0.007, -0.0032, 0.0024));
  const Positions wrong = TranslationStepsWithGuess::Translated(steps.scene.control, Eigen::Vector3d(-0.008, 0.007, -0.006)) -
                          steps.scene.control;
  for (const std::vector<Positions>& guesses : {std::vector<Positions>{wrong, steps.guess},
                                                std::vector<Positions>{steps.guess, wrong}}) {
    const MotionStep step = steps.estimator.Estimate(steps.scene.control, steps.before, steps.after, guesses);
    EXPECT_TRUE(step.report.guess_used);
    EXPECT_EQ(step.report.guess_index, guesses[0].isApprox(wrong) ? 1 : 0);
    EXPECT_EQ(step.displacement, steps.from_guess.displacement);
  }
}

// A guess that matches the images worse than no motion (refined shapes that jump from frame
// to frame, as on a real take whose tracking drifted: 12 mm, ≈ 8 px, the wrong way) is not a
// start: the step is the one from zero, to the bit, and recovers the motion as well.
TEST(MotionStep, AGuessWorseThanNoMotionIsIgnored) {
  const TranslationStepsWithGuess steps(Eigen::Vector3d(0.0012, -0.0007, 0.0006), Eigen::Vector3d(-0.008, 0.007, -0.006));
  const MotionStepReport& report = steps.from_guess.report;
  const double error = steps.Error(steps.from_guess.displacement);
  std::printf("guess 12 mm the wrong way: photometric RMS %.4f (guess) vs %.4f (zero), sample motion error %.1f %%\n",
              report.guess_rms, report.guess_rms_zero, 100 * error);
  EXPECT_FALSE(report.guess_used);
  EXPECT_GT(report.guess_rms, report.guess_rms_zero);
  EXPECT_EQ(steps.from_guess.displacement, steps.from_zero.displacement);
  EXPECT_LT(error, 0.10);
}

// A rotation of 2° about a tilted axis through the object's centre (≤ 1.5 mm, ≤ 1 px at
// the surface) is recovered within 0.5° (|ω_est − ω_true| as an angle), its sample motion
// within 15 %.
TEST(MotionStep, RecoversAKnownSmallRotation) {
  const MotionTestScene& scene = Scene();
  RigidTransform motion;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.2, 0.93).normalized();
  motion.R = Eigen::AngleAxisd(2.0 * kDegree, axis).toRotationMatrix();
  motion.centre = testing::Centroid(scene.mesh.V);
  const MotionStepEstimator estimator(scene.hierarchy, scene.cameras, scene.control);
  const MotionStep step = estimator.Estimate(scene.control, testing::RenderGray(scene, scene.mesh.V),
                                             testing::RenderGray(scene, motion.Apply(scene.mesh.V)));
  const Positions truth = motion.Apply(scene.control) - scene.control;
  const double error = SampleMotionError(estimator, scene.control, step.displacement, truth);
  const RigidMotion fitted = FitRigidMotion(scene.control + 0.5 * step.displacement, step.displacement);
  const RigidMotion exact = FitRigidMotion(scene.control + 0.5 * truth, truth);
  const double omega_error = (fitted.omega - exact.omega).norm();
  std::printf("rotation 2°: estimated %.3f°, |ω error| %.3f°, sample motion error %.1f %%, "
              "%.2f s\n",
              fitted.RotationAngle() / kDegree, omega_error / kDegree, 100 * error,
              step.report.seconds);
  EXPECT_NEAR(exact.RotationAngle(), 2.0 * kDegree, 1e-12);
  EXPECT_LT(omega_error, 0.5 * kDegree);
  EXPECT_LT(error, 0.15);
}

// A camera whose exposure changes between two frames (auto exposure, mains flicker on a fast
// shutter): every pixel of the second image is 12 % brighter. On the intensities
// (highpass_sigma 0, the first motion pass's default) that change reads as motion; on the
// images' fine structure (LogHighPass, the retrack's default: 0.7 px after a first pass at
// 8 px, see motion_step.h), where a gain is an offset that the high-pass removes, the step
// recovers the motion as without the change.
TEST(MotionStep, AnExposureChangeIsNotTakenForMotion) {
  const MotionTestScene& scene = Scene();
  RigidTransform motion;
  motion.t = Eigen::Vector3d(0.0012, -0.0007, 0.0006);
  const std::vector<cv::Mat> before = testing::RenderGray(scene, scene.mesh.V);
  const std::vector<cv::Mat> after = testing::RenderGray(scene, motion.Apply(scene.mesh.V));
  std::vector<cv::Mat> brighter(after.size());
  for (std::size_t k = 0; k < after.size(); ++k) after[k].convertTo(brighter[k], -1, 1.12);
  const Positions truth = motion.Apply(scene.control) - scene.control;
  auto error = [&](double highpass_sigma, const std::vector<cv::Mat>& second) {
    MotionStepOptions options = ReconstructionOptions().RetrackOptions().step;  // the retrack's
    options.highpass_sigma = highpass_sigma;
    const MotionStepEstimator estimator(scene.hierarchy, scene.cameras, scene.control, options);
    return SampleMotionError(estimator, scene.control, estimator.Estimate(scene.control, before, second).displacement,
                             truth);
  };
  const double sigma = ReconstructionOptions().RetrackOptions().step.highpass_sigma;
  ASSERT_GT(sigma, 0.0) << "the retrack's default is the fine structure";
  const double raw_same = error(0.0, after), raw_brighter = error(0.0, brighter);
  const double structure_same = error(sigma, after), structure_brighter = error(sigma, brighter);
  std::printf("translation 1.5 mm, sample motion error: intensities %.1f %% (12 %% brighter: %.1f %%), fine "
              "structure %.1f %% (12 %% brighter: %.1f %%)\n",
              100 * raw_same, 100 * raw_brighter, 100 * structure_same, 100 * structure_brighter);
  EXPECT_LT(structure_same, 0.10);
  EXPECT_LT(structure_brighter, 1.5 * structure_same);
  EXPECT_LT(structure_brighter, 0.5 * raw_brighter);
}

// Frames 0..2 of vision's "rigid" scene (2° per frame about a tilted axis + 1.5 mm), from
// reference frame 1 forward and backward, with each frame's exact shape as its "hull":
// every frame is on the hierarchy, the rigid motion of both steps is within 0.5° and
// 10 % of the truth, and the non-rigid part of the control flow is small (mean < 20 % of
// the mean flow: the normal correction, the smoothness term and the image noise are all
// that is not rigid).
TEST(MotionInit, PropagatesForwardAndBackwardOnOneHierarchy) {
  const MotionTestScene& scene = Scene();
  const vision::SyntheticScene sequence = RigidSequence(3);
  ASSERT_LT((sequence.frames[0] - scene.mesh.V).cwiseAbs().maxCoeff(), 1e-12);
  std::vector<std::vector<cv::Mat>> images;
  std::vector<RigidMotion> truth;
  std::vector<Positions> fitted = {scene.control};
  for (int f = 0; f < 3; ++f) images.push_back(testing::RenderGray(scene, sequence.frames[f]));
  for (int f = 0; f < 2; ++f) {
    truth.push_back(FitRigidMotion(0.5 * (sequence.frames[f] + sequence.frames[f + 1]),
                                   sequence.frames[f + 1] - sequence.frames[f]));
    ASSERT_LT(truth.back().rms_residual, 1e-12);  // the scene is rigid
    // Cayley: x' = x + v + w × (x + x')/2 ⇔ (I − W/2) x' = (I + W/2) x + v.
    Eigen::Matrix3d W;
    const Eigen::Vector3d w = truth.back().omega;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    const Eigen::Matrix3d A = Eigen::Matrix3d::Identity() - 0.5 * W;
    Positions next(scene.control.rows(), 3);
    for (Eigen::Index i = 0; i < next.rows(); ++i)
      next.row(i) = A.partialPivLu().solve((Eigen::Matrix3d::Identity() + 0.5 * W) * fitted.back().row(i).transpose() +
                            truth.back().v).transpose();
    fitted.push_back(next);
  }
  vision::ImageSequence images_of_frames{scene.cameras, 0, 3, [&](int camera, int frame) { return images[frame][camera]; }, {}, {}};
  MotionInitOptions init;
  const MotionInitResult result = InitializeMotion(images_of_frames, scene.hierarchy, fitted, 1, init);
  ASSERT_EQ(result.control.size(), 3u);
  const RigidSplit split = SplitRigidMotion(scene.hierarchy, result.control);
  ASSERT_EQ(split.trajectory.size(), 3u);
  ASSERT_EQ(split.rigid.size(), 2u);
  EXPECT_EQ(result.frames[1].from_frame, -1);
  EXPECT_EQ(result.frames[0].from_frame, 1);
  EXPECT_EQ(result.frames[2].from_frame, 1);
  EXPECT_TRUE(result.frames[0].corrected && result.frames[2].corrected);
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(result.control[f].rows(), scene.hierarchy.VertexCount(2));
    EXPECT_EQ(split.trajectory[f].base().rows(), scene.hierarchy.VertexCount(0));
  }
  for (int f = 0; f < 2; ++f) {
    const double omega_error = (split.rigid[f].omega - truth[f].omega).norm();
    const double v_error = (split.rigid[f].v - truth[f].v).norm() / truth[f].v.norm();
    std::printf("step %d→%d: rotation %.3f° (true %.3f°), |ω error| %.3f°, v error %.1f %%, "
                "%.2f s\n",
                f, f + 1, split.rigid[f].RotationAngle() / kDegree,
                truth[f].RotationAngle() / kDegree, omega_error / kDegree, 100 * v_error,
                result.frames[f == 0 ? 0 : 2].step.seconds);
    EXPECT_LT(omega_error, 0.5 * kDegree);
    EXPECT_LT(v_error, 0.10);
  }
  const FlowAnalysis flow = AnalyzeFlow(result.control, split.rigid);
  const double mean_flow = flow.motion_energy.mean() / 2.0;
  const double mean_non_rigid = flow.non_rigid_energy.mean() / 2.0;
  std::printf("mean |flow| %.3f mm, mean |non-rigid flow| %.3f mm\n", 1e3 * mean_flow,
              1e3 * mean_non_rigid);
  EXPECT_LT(mean_non_rigid, 0.2 * mean_flow);

  // The chains after and before the reference frame side by side (the default) or one after
  // the other: the same numbers, to the bit.
  MotionInitOptions serial = init;
  serial.concurrent_chains = false;
  ASSERT_TRUE(init.concurrent_chains);
  const MotionInitResult one_after_the_other = InitializeMotion(images_of_frames, scene.hierarchy, fitted, 1, serial);
  for (int f = 0; f < 3; ++f)
    EXPECT_EQ((one_after_the_other.control[f] - result.control[f]).cwiseAbs().maxCoeff(), 0.0) << "frame " << f;
}

// A take that moves fast and steadily: 8 mm (≈ 5 px) a frame, far beyond the image passes'
// linear range, for 4 frames. From zero motion every step recovers it to a few per cent;
// started at the previous step (a constant velocity), the steps after the first land several
// times closer, and report that start.
TEST(MotionInit, AConstantVelocityStartsEachStepAtThePreviousOne) {
  const MotionTestScene& scene = Scene();
  const Eigen::Vector3d t(0.006, -0.004, 0.003);
  std::vector<std::vector<cv::Mat>> frames;
  for (int f = 0; f < 4; ++f)
    frames.push_back(testing::RenderGray(scene, TranslationStepsWithGuess::Translated(scene.mesh.V, f * t)));
  const vision::ImageSequence images{scene.cameras, 0, 4, [&](int camera, int frame) { return frames[frame][camera]; },
                                     {}, {}};
  const Positions truth = TranslationStepsWithGuess::Translated(scene.control, t) - scene.control;
  const MotionStepEstimator measure(scene.hierarchy, scene.cameras, scene.control);
  auto step_error = [&](const MotionInitResult& r, int f) {  // the step f → f + 1
    const Positions at = r.control[f];
    return SampleMotionError(measure, at, r.control[f + 1] - at, truth);
  };
  MotionInitOptions options;
  ASSERT_TRUE(options.guess_previous_step);
  const MotionInitResult velocity = InitializeMotion(images, scene.hierarchy, {scene.control}, 0, options);
  options.guess_previous_step = false;
  const MotionInitResult zero = InitializeMotion(images, scene.hierarchy, {scene.control}, 0, options);
  for (int f = 0; f < 3; ++f)
    std::printf("step %d→%d: sample motion error from zero %.2f %%, with the previous step as a start %.2f %%\n", f,
                f + 1, 100 * step_error(zero, f), 100 * step_error(velocity, f));
  EXPECT_EQ(step_error(velocity, 0), step_error(zero, 0));  // no previous step yet
  EXPECT_EQ(velocity.frames[1].guess_source(), GuessSource::kZero);
  for (int f = 1; f < 3; ++f) {
    EXPECT_EQ(velocity.frames[f + 1].guess_source(), GuessSource::kPreviousStep) << "frame " << f + 1;
    EXPECT_LT(step_error(zero, f), 0.10) << "step " << f;
    EXPECT_LT(step_error(velocity, f), 0.3 * step_error(zero, f)) << "step " << f;
  }

  // A chain that continues another (a plan's chunk seeded at frame 1, docs/cluster.md): with
  // the step into its reference frame as its lead-in, its first step starts there too. A
  // lead-in of the other direction is not this chain's.
  const vision::ImageSequence rest{scene.cameras, 0, 3,
                                   [&](int camera, int frame) { return frames[frame + 1][camera]; }, {}, {}};
  options.guess_previous_step = true;
  MotionLeadIn lead_in{+1, velocity.control[1] - velocity.control[0]};
  const MotionInitResult continued =
      InitializeMotion(rest, scene.hierarchy, {velocity.control[1]}, 0, options, nullptr, &lead_in);
  EXPECT_EQ(continued.frames[1].guess_source(), GuessSource::kPreviousStep);
  EXPECT_LT(step_error(continued, 0), 0.3 * step_error(zero, 1));
  lead_in.direction = -1;
  const MotionInitResult other =
      InitializeMotion(rest, scene.hierarchy, {velocity.control[1]}, 0, options, nullptr, &lead_in);
  EXPECT_EQ(other.frames[1].guess_source(), GuessSource::kZero);
  lead_in.step = Positions::Zero(3, 3);
  EXPECT_THROW(InitializeMotion(rest, scene.hierarchy, {velocity.control[1]}, 0, options, nullptr, &lead_in), Error);
}

// A duplicated frame (capture software repeats a frame when it drops one): frames 0, 1, 1
// of the rigid scene as frames 0, 1, 2. The step onto the repeat is flagged and stands
// still (no image motion: the surface moves by < 2 % of a true step); the other is not
// flagged and moves the surface by about the true step.
TEST(MotionInit, FlagsADuplicatedFrameAndKeepsTheSurfaceStill) {
  const MotionTestScene& scene = Scene();
  const vision::SyntheticScene sequence = RigidSequence(2);
  const std::vector<cv::Mat> first = testing::RenderGray(scene, sequence.frames[0]);
  const std::vector<cv::Mat> second = testing::RenderGray(scene, sequence.frames[1]);
  const vision::ImageSequence images{scene.cameras, 0, 3, [&](int camera, int frame) {
                                       return frame == 0 ? first[camera] : second[camera].clone();
                                     }, {}, {}};
  const MotionInitResult result = InitializeMotion(images, scene.hierarchy, {scene.control}, 0, MotionInitOptions());
  ASSERT_EQ(result.control.size(), 3u);
  EXPECT_FALSE(result.frames[0].identical_images);  // the reference frame
  EXPECT_FALSE(result.frames[1].identical_images);
  EXPECT_TRUE(result.frames[2].identical_images);
  const double true_step = (sequence.frames[1] - sequence.frames[0]).rowwise().norm().mean();
  const double moved = (result.control[1] - result.control[0]).rowwise().norm().mean();
  const double repeated = (result.control[2] - result.control[1]).rowwise().norm().mean();
  std::printf("true step %.3f mm, estimated %.3f mm, onto the repeat %.4f mm\n", 1e3 * true_step, 1e3 * moved,
              1e3 * repeated);
  EXPECT_GT(moved, 0.5 * true_step);
  EXPECT_LT(repeated, 0.02 * true_step);
}

// A frame whose target has moved away (a limb the chain left behind: the images here stand
// still, the target of the last frame is the surface shifted by 0.8 base edges) is
// registered; with spread_registration, the displacement that the registration adds at that
// frame is shared out over the frames since the reference in proportion to their distance
// (1/3 and 2/3 of it), a steady motion instead of a jump. The registered frame itself is the
// same either way.
TEST(MotionInit, ARegistrationIsSpreadOverTheFramesSinceTheLastOne) {
  const MotionTestScene& scene = Scene();
  const std::vector<cv::Mat> still = testing::RenderGray(scene, scene.mesh.V);
  const vision::ImageSequence images{scene.cameras, 0, 4, [&](int camera, int) { return still[camera].clone(); },
                                     {}, {}};
  const geometry::MultiresShape shape = geometry::MultiresShape::Analyze(scene.hierarchy, scene.control);
  const double base_edge = geometry::MeanEdgeLength(scene.hierarchy.Topology(0), shape.base());
  const Eigen::RowVector3d shift(0.8 * base_edge, 0.0, 0.0);
  std::vector<Positions> targets(4, scene.control);
  targets[3].rowwise() += shift;
  MotionInitOptions options;
  options.registration.enabled = true;
  const MotionInitResult jump = InitializeMotion(images, scene.hierarchy, targets, 0, options);
  options.spread_registration = true;
  const MotionInitResult spread = InitializeMotion(images, scene.hierarchy, targets, 0, options);
  ASSERT_TRUE(spread.frames[3].registration.applied);
  for (int f = 1; f < 3; ++f) EXPECT_FALSE(spread.frames[f].registration.applied) << "frame " << f;
  EXPECT_EQ((spread.control[3] - jump.control[3]).cwiseAbs().maxCoeff(), 0.0);

  auto mean_step = [](const MotionInitResult& r, int f) {
    return (r.control[f + 1] - r.control[f]).rowwise().norm().mean();
  };
  std::printf("mean step (mm), registration at frame 3 as a jump: %.3f %.3f %.3f; spread: %.3f %.3f %.3f\n",
              1e3 * mean_step(jump, 0), 1e3 * mean_step(jump, 1), 1e3 * mean_step(jump, 2),
              1e3 * mean_step(spread, 0), 1e3 * mean_step(spread, 1), 1e3 * mean_step(spread, 2));
  // As a jump: the registered frame moves by most of the shift at once, the others hardly.
  EXPECT_GT(mean_step(jump, 2), 0.5 * shift.norm());
  EXPECT_LT(mean_step(jump, 0), 0.05 * shift.norm());
  // Spread: the frames in between carry 1/3 and 2/3 of the same displacement, three equal steps.
  const Positions third = spread.control[1] - jump.control[1];
  EXPECT_LT((spread.control[2] - jump.control[2] - 2.0 * third).cwiseAbs().maxCoeff(), 1e-12);
  for (int f = 0; f < 3; ++f) {
    EXPECT_GT(mean_step(spread, f), 0.2 * shift.norm()) << "step " << f;
    EXPECT_LT(mean_step(spread, f), 0.5 * shift.norm()) << "step " << f;
  }
}

// A still (one frame) has no step: its trajectory is the reference control points, exactly,
// and no image is read (the loader would throw).
TEST(MotionInit, OneFrameIsTheReferenceShapeAndReadsNoImage) {
  const MotionTestScene& scene = Scene();
  const vision::ImageSequence images{scene.cameras, 0, 1, [](int, int) -> cv::Mat {
                                       throw std::runtime_error("an image of a still was read");
                                     }, {}, {}};
  const MotionInitResult result = InitializeMotion(images, scene.hierarchy, {scene.control}, 0, MotionInitOptions());
  ASSERT_EQ(result.control.size(), 1u);
  EXPECT_EQ(result.control[0], scene.control);
  ASSERT_EQ(result.frames.size(), 1u);
  EXPECT_EQ(result.frames[0].frame, 0);
  EXPECT_EQ(result.frames[0].from_frame, -1);
  EXPECT_EQ(result.reference_frame, 0);
}

TEST(MotionInit, RejectsInconsistentInputs) {
  const MotionTestScene& scene = Scene();
  const vision::ImageSequence images{scene.cameras, 0, 3, [](int, int) { return cv::Mat(); }, {}, {}};
  const MotionInitOptions options;
  EXPECT_THROW(InitializeMotion(images, scene.hierarchy, {scene.control}, 3, options),
               Error);
  EXPECT_THROW(InitializeMotion(images, scene.hierarchy,
                                {scene.control, scene.control}, 0, options),
               Error);
  EXPECT_THROW(InitializeMotion(images, scene.hierarchy,
                                {Positions::Zero(5, 3)}, 0, options),
               Error);
  MotionInitOptions bad = options;
  bad.hull_weight = 1.5;
  EXPECT_THROW(InitializeMotion(images, scene.hierarchy, {scene.control}, 0, bad),
               Error);
}

}  // namespace
}  // namespace subflow::solver
