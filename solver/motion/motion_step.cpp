#include "solver/motion/motion_step.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include <spdlog/fmt/fmt.h>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::solver {
namespace {

using geometry::Positions;

std::vector<SmoothedImage> SmoothAll(const std::vector<cv::Mat>& images, double sigma) {
  std::vector<SmoothedImage> smoothed(images.size());
  tbb::parallel_for(std::size_t{0}, images.size(),
                    [&](std::size_t k) { smoothed[k] = SmoothImage(images[k], sigma); });
  return smoothed;
}

// The images the constraints are written on: LogHighPass of each (σ > 0), else as given.
std::vector<cv::Mat> Structure(const std::vector<cv::Mat>& images, double highpass_sigma) {
  if (highpass_sigma <= 0.0) return images;
  std::vector<cv::Mat> structure(images.size());
  tbb::parallel_for(std::size_t{0}, images.size(),
                    [&](std::size_t k) { structure[k] = LogHighPass(images[k], highpass_sigma); });
  return structure;
}

double Rms(const Eigen::VectorXd& values) {
  return values.size() > 0 ? std::sqrt(values.squaredNorm() / values.size()) : 0.0;
}

}  // namespace

void MotionStepOptions::Check() const {
  sampling.Check();
  visibility.Check();
  solver.Check();
  if (image_sigmas.empty())
    ThrowError("motion step", "image_sigmas", "expected at least one σ (one per pass)");
  for (double sigma : image_sigmas)
    if (!std::isfinite(sigma) || sigma < 0.0 || sigma > 20.0)
      ThrowError("motion step", "image_sigmas", "expected values in [0, 20] pixels");
  if (!std::isfinite(highpass_sigma) || highpass_sigma < 0.0 || highpass_sigma > kMaxHighPassSigma)
    ThrowError("motion step", "highpass_sigma",
               fmt::format("expected a value in [0, {}] pixels (0 = off)", kMaxHighPassSigma));
  if (!std::isfinite(first_highpass_sigma) || first_highpass_sigma < 0.0 || first_highpass_sigma > 100.0)
    ThrowError("motion step", "first_highpass_sigma", "expected a value in [0, 100] pixels");
}

MotionStepEstimator::MotionStepEstimator(const geometry::LoopHierarchy& hierarchy,
                                         const std::vector<vision::Camera>& cameras,
                                         const Positions& reference_control,
                                         const MotionStepOptions& options)
    : hierarchy_(&hierarchy),
      cameras_(cameras),
      options_((options.Check(), options)),
      samples_(SampleLimitSurface(hierarchy, hierarchy.finest_level(), reference_control, cameras,
                                  options.sampling)),
      visibility_(hierarchy, hierarchy.finest_level(), options.visibility),
      solver_(hierarchy, samples_.limit, reference_control, options.solver) {
  if (cameras.empty()) ThrowError("motion step", "cameras", "need at least one camera");
}

MotionStep MotionStepEstimator::Estimate(const Positions& control,
                                         const std::vector<cv::Mat>& before,
                                         const std::vector<cv::Mat>& after,
                                         const std::vector<Positions>& guesses) const {
  const auto start = std::chrono::steady_clock::now();
  const int n = hierarchy_->finest_level();
  if (control.rows() != hierarchy_->VertexCount(n))
    ThrowError("motion step", "control points",
               std::to_string(control.rows()) + " rows, expected #V(n) = " +
                   std::to_string(hierarchy_->VertexCount(n)));
  if (before.size() != cameras_.size() || after.size() != cameras_.size())
    ThrowError("motion step", "images",
               "expected one image per camera (" + std::to_string(cameras_.size()) + ") per frame");
  for (std::size_t k = 0; k < cameras_.size(); ++k)
    for (const cv::Mat* image : {&before[k], &after[k]})
      if (image->cols != cameras_[k].width() || image->rows != cameras_[k].height())
        ThrowError("motion step", "image of camera " + cameras_[k].name(),
                   "size differs from the camera's " + std::to_string(cameras_[k].width()) + "×" +
                       std::to_string(cameras_[k].height()));

  const Positions positions = samples_.SamplePositions(control);
  const SampleVisibility visibility =
      visibility_.Compute(cameras_, control, positions, samples_.SampleNormals(control));

  MotionStep step;
  step.report.samples = samples_.size();
  step.report.visible_samples = visibility.SamplesSeenBy(1);
  step.report.multi_view_samples = visibility.SamplesSeenBy(2);
  step.displacement = Positions::Zero(control.rows(), 3);
  Positions sample_motion;  // empty: zero guess on the first pass
  for (const Positions& guess : guesses) {
    if (guess.rows() != control.rows() || guess.cols() != 3 || !guess.allFinite())
      ThrowError("motion step", "guess", "expected #V(n) = " + std::to_string(control.rows()) + " finite rows");
  }
  const int passes = static_cast<int>(options_.image_sigmas.size());
  // The first of several passes on a coarser high-pass: its wider linear range brings a
  // motion of a few pixels within the fine structure's.
  const auto pass_highpass = [&](int pass) {
    return pass == 0 && passes > 1 && options_.highpass_sigma > 0.0
               ? std::max(options_.highpass_sigma, options_.first_highpass_sigma)
               : options_.highpass_sigma;
  };
  std::vector<SmoothedImage> smoothed_before, smoothed_after;
  // The high-pass of this pass; kept for the next pass when it uses the same, else freed.
  std::vector<cv::Mat> structure_before, structure_after;
  for (int pass = 0; pass < passes; ++pass) {
    const double highpass = pass_highpass(pass);
    if (structure_before.empty()) {
      structure_before = Structure(before, highpass);
      structure_after = Structure(after, highpass);
    }
    smoothed_before = SmoothAll(structure_before, options_.image_sigmas[pass]);
    smoothed_after = SmoothAll(structure_after, options_.image_sigmas[pass]);
    if (pass + 1 == passes || pass_highpass(pass + 1) != highpass) structure_before = structure_after = {};
    if (pass == 0 && !guesses.empty()) {
      // A guess is a start, not a given: where it matches the images worse than no motion
      // does (trajectories that jump from frame to frame), the step starts from zero.
      step.report.guess_rms_zero = Rms(StepPhotometricDifferences(cameras_, smoothed_before, smoothed_after,
                                                                  positions, Positions(), visibility));
      for (std::size_t g = 0; g < guesses.size(); ++g) {
        Positions motion = solver_.SampleMotion(guesses[g]);
        const double rms = Rms(StepPhotometricDifferences(cameras_, smoothed_before, smoothed_after, positions,
                                                          motion, visibility));
        if (g == 0 || rms < step.report.guess_rms) {
          step.report.guess_rms = rms;
          step.report.guess_index = static_cast<int>(g);
          sample_motion = std::move(motion);
        }
      }
      step.report.guess_used = step.report.guess_rms < step.report.guess_rms_zero;
      if (!step.report.guess_used) {
        sample_motion = Positions();
        step.report.guess_index = -1;
      }
    }
    const NormalFlowConstraints constraints = BuildStepConstraints(
        cameras_, smoothed_before, smoothed_after, positions, sample_motion, visibility);
    if (pass == passes - 1) {
      // Photometric error of zero motion at the finest σ.
      step.report.photometric_rms_zero = Rms(StepPhotometricDifferences(
          cameras_, smoothed_before, smoothed_after, positions, Positions(), visibility));
    }
    step.solution = solver_.Solve(constraints, control, pass > 0 ? &step.solution : nullptr);
    step.displacement = step.solution.displacement;
    sample_motion = solver_.SampleMotion(step.displacement);
    step.report.cg_iterations += step.solution.cg_iterations;
    step.report.constraints = constraints.size();
    step.report.pruned = step.solution.pruned;
    step.report.collinearity_pruned = step.solution.collinearity_pruned;
  }
  step.report.photometric_rms = Rms(StepPhotometricDifferences(
      cameras_, smoothed_before, smoothed_after, positions, sample_motion, visibility));
  step.report.mean_displacement = step.displacement.rowwise().norm().mean();
  step.report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return step;
}

}  // namespace subflow::solver
