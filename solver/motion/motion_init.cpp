#include "solver/motion/motion_init.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>


#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/task_errors.h"
#include "geometry/closest_point.h"
#include "geometry/mean_edge_length.h"
#include "geometry/multires_shape.h"
#include "solver/shape/surface_snapping.h"

namespace subflow::solver {

using geometry::Positions;

const char* ToString(GuessSource source) {
  switch (source) {
    case GuessSource::kTarget: return "target";
    case GuessSource::kPreviousStep: return "previous_step";
    case GuessSource::kZero: break;
  }
  return "zero";
}

GuessSource MotionFrameReport::guess_source() const {
  return step.guess_index >= 0 ? guesses_offered.at(step.guess_index) : GuessSource::kZero;
}

std::string MotionInitResult::BriefReport() const {
  double zero = 0, estimated = 0;
  int steps = 0;
  for (const MotionFrameReport& frame : frames) {
    if (frame.from_frame < 0) continue;
    zero += frame.step.photometric_rms_zero;
    estimated += frame.step.photometric_rms;
    ++steps;
  }
  return fmt::format("motion init: {} frames from reference {}, photometric RMS {:.4f} (zero motion) → {:.4f}, {:.1f} s",
                     frames.size(), reference_frame, steps ? zero / steps : 0.0, steps ? estimated / steps : 0.0,
                     seconds);
}

std::vector<int> MotionInitResult::FramesOffTarget(double fraction) const {
  std::vector<int> off;
  for (const MotionFrameReport& frame : frames)
    if (frame.corrected && frame.correction_unreached > fraction) off.push_back(frame.frame);
  std::sort(off.begin(), off.end());
  return off;
}

namespace {

// Every camera's image equal, pixel for pixel (a duplicated frame).
bool IdenticalImages(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b) {
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].size() != b[k].size() || a[k].type() != b[k].type() || cv::norm(a[k], b[k], cv::NORM_INF) != 0.0)
      return false;
  return !a.empty();
}

}  // namespace

void MotionInitOptions::Check() const {
  step.Check();
  if (!std::isfinite(hull_weight) || hull_weight < 0.0 || hull_weight > 1.0)
    ThrowError("motion init", "hull_weight", "expected a value in [0, 1]");
  if (!std::isfinite(hull_max_distance) || hull_max_distance < 0.0)
    ThrowError("motion init", "hull_max_distance", "expected a finite value ≥ 0 (0 = automatic)");
  if (hull_iterations < 1 || hull_iterations > 20)
    ThrowError("motion init", "hull_iterations", "expected 1..20");
  registration.Check();
  if (!(registration_min_unreached >= 0.0 && registration_min_unreached < 1.0))
    ThrowError("motion init", "registration_min_unreached", "expected a fraction in [0, 1) (0 = no such gate)");
}

namespace {

// Checks the inputs of InitializeMotion (throws subflow::Error naming the field); whether
// `initial_control` has one matrix per frame (else only the reference frame's).
bool CheckMotionInputs(const vision::ImageSequence& images, const geometry::LoopHierarchy& hierarchy,
                       const std::vector<Positions>& initial_control, int reference_frame,
                       const MotionInitOptions& options, const MotionLeadIn* lead_in) {
  options.Check();
  images.Check("motion init");
  const int frame_count = images.frame_count;
  if (frame_count < 1) ThrowError("motion init", "frame count", "expected at least one frame");
  if (reference_frame < 0 || reference_frame >= frame_count)
    ThrowError("motion init", "reference frame",
               std::to_string(reference_frame) + " is outside 0.." + std::to_string(frame_count - 1));
  const bool per_frame = static_cast<int>(initial_control.size()) == frame_count && frame_count > 1;
  if (!per_frame && initial_control.size() != 1)
    ThrowError("motion init", "initial control points",
               std::to_string(initial_control.size()) + " matrices, expected 1 (the reference "
               "frame's) or one per frame (" + std::to_string(frame_count) + ")");
  const Eigen::Index vertices = hierarchy.VertexCount(hierarchy.finest_level());
  const Positions& reference = per_frame ? initial_control[reference_frame] : initial_control[0];
  if (reference.rows() != vertices)
    ThrowError("motion init", "initial control points of the reference frame",
               std::to_string(reference.rows()) + " rows, expected #V(n) = " +
                   std::to_string(vertices));
  for (std::size_t f = 0; per_frame && f < initial_control.size(); ++f)
    if (initial_control[f].rows() != 0 && initial_control[f].rows() != vertices)
      ThrowError("motion init", "initial control points of frame " + std::to_string(f),
                 std::to_string(initial_control[f].rows()) + " rows, expected 0 or " +
                     std::to_string(vertices));
  if (lead_in && (std::abs(lead_in->direction) != 1 || lead_in->step.rows() != vertices || !lead_in->step.allFinite()))
    ThrowError("motion init", "lead-in step", "expected direction ±1 and #V(n) = " + std::to_string(vertices) +
                                                  " finite rows");
  return per_frame;
}

// A still: no step to estimate, nor anything to build for one.
MotionInitResult StillMotion(int reference_frame, const Positions& reference, const Stopwatch& start) {
  MotionInitResult still;
  still.reference_frame = reference_frame;
  still.control = {reference};
  still.frames.resize(1);
  still.seconds = start.Seconds();
  return still;
}

// The first pass's starts besides zero motion for a step from `control` (the step takes the
// one that matches the images best): towards the next frame's `target` (retrack), and the
// chain's `previous_step` (empty: none yet); `sources` says which is which.
std::vector<Positions> StepGuesses(const MotionInitOptions& options, const Positions& control, const Positions* target,
                                   const Positions& previous_step, std::vector<GuessSource>* sources) {
  std::vector<Positions> guesses;
  if (options.guess_from_targets && target) {
    guesses.push_back(*target - control);
    sources->push_back(GuessSource::kTarget);
  }
  if (options.guess_previous_step && previous_step.rows() > 0) {
    guesses.push_back(previous_step);
    sources->push_back(GuessSource::kPreviousStep);
  }
  return guesses;
}

// The displacement `shift` that a registration added at frame `to` built up since frame
// `anchor` (the previous one registered, or the reference): the frames between take it in
// proportion to their distance from the anchor, a steady motion instead of a jump at one
// frame.
void SpreadBack(const Positions& shift, int anchor, int to, std::vector<Positions>* control) {
  const int direction = to > anchor ? 1 : -1;
  const double span = std::abs(to - anchor);
  for (int g = anchor + direction; g != to; g += direction)
    (*control)[g] += (std::abs(g - anchor) / span) * shift;
}

}  // namespace

Positions CorrectTowardsFit(const geometry::LoopHierarchy& hierarchy, const SurfaceRegistration& registration,
                            const Positions& control, const geometry::ClosestPointTree& fit,
                            const MotionInitOptions& options, double max_correction, MotionFrameReport* report,
                            Positions* registration_shift) {
  const int n = hierarchy.finest_level();
  Positions corrected = control;
  if (registration_shift) *registration_shift = Positions();
  bool lost = true;
  if (options.registration.enabled && options.registration_min_unreached > 0.0) {
    report->unreached_before_registration = UnreachedFraction(hierarchy, n, control, fit, max_correction);
    lost = report->unreached_before_registration > options.registration_min_unreached;
  }
  if (options.registration.enabled && lost) {
    geometry::MultiresShape shape = geometry::MultiresShape::Analyze(hierarchy, control);
    Positions registered = registration.Register(shape.base(), fit, &report->registration);
    if (report->registration.applied) {
      shape.base() = std::move(registered);
      corrected = shape.Synthesize(hierarchy, n);
      if (registration_shift) *registration_shift = corrected - control;
    }
  }
  SurfaceSnapOptions snap;
  snap.weight = options.hull_weight;
  snap.max_distance = max_correction;
  snap.iterations = options.hull_iterations;
  snap.measure_after = false;
  SurfaceSnapReport snap_report;
  corrected = SnapToSurface(hierarchy, n, corrected, fit, snap, &snap_report);
  report->corrected = true;
  report->correction_rms_before = snap_report.rms_distance_before;
  report->correction_rms_applied = snap_report.rms_correction;
  report->correction_unreached = control.rows() > 0 ? static_cast<double>(snap_report.vertices_without_hit) /
                                                          static_cast<double>(control.rows())
                                                    : 0.0;
  return corrected;
}

MotionInitResult InitializeMotion(const vision::ImageSequence& images,
                                  const geometry::LoopHierarchy& hierarchy,
                                  const std::vector<Positions>& initial_control,
                                  int reference_frame, const MotionInitOptions& options,
                                  Progress* progress, const MotionLeadIn* lead_in) {
  const Stopwatch start;
  const bool per_frame = CheckMotionInputs(images, hierarchy, initial_control, reference_frame, options, lead_in);
  const std::vector<vision::Camera>& cameras = images.cameras;
  const int frame_count = images.frame_count;
  const int n = hierarchy.finest_level();
  const Positions& reference = per_frame ? initial_control[reference_frame] : initial_control[0];
  if (frame_count == 1) return StillMotion(reference_frame, reference, start);
  auto fitted = [&](int frame) -> const Positions* {
    if (!per_frame || initial_control[frame].rows() == 0) return nullptr;
    return &initial_control[frame];
  };

  const MotionStepEstimator estimator(hierarchy, cameras, reference, options.step);
  const double max_correction = options.hull_max_distance > 0.0
                                    ? options.hull_max_distance
                                    : 3.0 * geometry::MeanEdgeLength(hierarchy.Topology(n), reference);

  // Distances of the registration's gate in the reference frame's base edges.
  const geometry::MultiresShape reference_shape = geometry::MultiresShape::Analyze(hierarchy, reference);
  const SurfaceRegistration registration(
      hierarchy, options.registration, geometry::MeanEdgeLength(hierarchy.Topology(0), reference_shape.base()));

  MotionInitResult result;
  result.reference_frame = reference_frame;
  result.control.assign(frame_count, Positions());
  result.control[reference_frame] = reference;
  result.frames.resize(frame_count);
  for (int f = 0; f < frame_count; ++f) result.frames[f].frame = f;

  auto load = [&](int frame) {
    std::vector<cv::Mat> loaded(cameras.size());
    for (std::size_t k = 0; k < cameras.size(); ++k) loaded[k] = images.gray(static_cast<int>(k), frame);
    return loaded;
  };
  std::mutex progress_mutex;  // the two chains report one count
  int done = 0;
  ProgressBegin(progress, "motion initialization", static_cast<std::size_t>(frame_count - 1));
  // Returns the registration's displacement of `to` when it was registered and
  // options.spread_registration is set (else empty).
  auto propagate = [&](int from, int to, const std::vector<cv::Mat>& from_images,
                       const std::vector<cv::Mat>& to_images, Positions* previous_step) {
    Positions shift;
    const Positions* target = fitted(to);
    std::vector<GuessSource> sources;
    const std::vector<Positions> guesses = StepGuesses(options, result.control[from], target, *previous_step, &sources);
    const MotionStep step = estimator.Estimate(result.control[from], from_images, to_images, guesses);
    *previous_step = step.displacement;
    Positions control = result.control[from] + step.displacement;
    MotionFrameReport& report = result.frames[to];
    report.from_frame = from;
    report.step = step.report;
    report.guesses_offered = std::move(sources);
    report.identical_images = IdenticalImages(from_images, to_images);
    if (report.identical_images)
      spdlog::warn("motion init: frame {} is identical to frame {} in every camera (a repeated frame, as capture "
                   "software writes for a dropped one?): no image motion between them, so the surface stands "
                   "still there and the motion of the dropped frame lands in the next step",
                   images.first_frame + to, images.first_frame + from);
    if (target && options.hull_weight > 0.0) {
      const geometry::ClosestPointTree tree(estimator.visibility().Tessellation(*target),
                                            "fitted surface of frame " + std::to_string(to));
      control = CorrectTowardsFit(hierarchy, registration, control, tree, options, max_correction, &report,
                                  options.spread_registration ? &shift : nullptr);
    }
    result.control[to] = std::move(control);
    spdlog::debug("motion init: frame {} -> {}: {} constraints, {} pruned, photometric rms {:.4f} "
                  "-> {:.4f}, mean |dc| {:.3g}, {:.2f} s",
                  from, to, step.report.constraints, step.report.pruned,
                  step.report.photometric_rms_zero, step.report.photometric_rms,
                  step.report.mean_displacement, step.report.seconds);
    {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      ProgressUpdate(progress, static_cast<std::size_t>(++done));
    }
    return shift;
  };
  const std::vector<cv::Mat> reference_images = load(reference_frame);
  // The chain from the reference frame to the last frame (+1) or the first (-1); see below.
  auto chain = [&](int direction, const TaskErrors* group) {
    std::vector<cv::Mat> current = reference_images;
    int anchor = reference_frame;  // the last frame registered (or the reference)
    // The chain's last step: none yet, or the one of the chain this one continues.
    Positions previous_step = lead_in && lead_in->direction == direction ? lead_in->step : Positions();
    for (int f = reference_frame; f + direction >= 0 && f + direction < frame_count; f += direction) {
      if (group && group->failed()) return;
      std::vector<cv::Mat> next = load(f + direction);
      const int to = f + direction;
      const Positions shift = propagate(f, to, current, next, &previous_step);
      if (shift.rows() > 0) {
        SpreadBack(shift, anchor, to, &result.control);
        anchor = to;
      }
      current = std::move(next);
    }
  };
  // The chains after and before the reference frame share only its images, and each step
  // is computed as it would be alone (every parallel sum in the step has a fixed order):
  // side by side, one chain's serial parts (the solver's level loop, ray casts, decoding)
  // overlap the other's parallel ones. An exception in one (an interrupt, a bad frame) is
  // rethrown here once the other has stopped too, at its next frame (core/task_errors.h).
  if (options.concurrent_chains) {
    RunSideBySide([&](const TaskErrors& g) { chain(+1, &g); }, [&](const TaskErrors& g) { chain(-1, &g); });
  } else {
    chain(+1, nullptr);
    chain(-1, nullptr);
  }
  ProgressEnd(progress);

  result.seconds = start.Seconds();
  return result;
}

}  // namespace subflow::solver
