#include "solver/reconstruction.h"

#include <algorithm>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "vision/working_scale.h"

namespace subflow::solver {

void ReconstructionOptions::Check() const {
  shape.Check();
  motion.Check();
  if (refine) refinement.Check();
  if (!(retrack_weight >= 0.0 && retrack_weight <= 1.0))
    ThrowError("reconstruction options", "retrack_weight", "must be in [0, 1]");
  if (!(retrack_highpass >= 0.0 && retrack_highpass <= kMaxHighPassSigma))
    ThrowError("reconstruction options", "retrack_highpass",
               fmt::format("expected a value in [0, {}] pixels (0 = off)", kMaxHighPassSigma));
}

MotionInitOptions ReconstructionOptions::RetrackOptions() const {
  MotionInitOptions retrack = motion;
  retrack.hull_weight = retrack_weight;
  retrack.step.highpass_sigma = retrack_highpass;
  // Each step starts at the refined trajectories' own step (blob, 24 frames: end-point error
  // 0.0422 → 0.0402 relative, accuracy P90 0.4357 → 0.4313 mm, same time; bust_front and
  // pair_dome, 8 frames: 0.0576 → 0.0564, 0.1806 → 0.1799). A single pass at σ = 1 from that
  // start was measured too and is worse (0.0580): the coarse pass stays.
  retrack.guess_from_targets = true;
  // A frame whose surface has lost its refined shape (more than kLostTargetFraction of it out
  // of the snap's reach) is registered to it, and the registration's displacement is spread
  // over the frames since the last one registered (docs/shape.md, "The retrack registers the
  // frames that lost their refined surface").
  retrack.registration.enabled = retrack_register;
  retrack.registration_min_unreached = kLostTargetFraction;
  retrack.spread_registration = true;
  return retrack;
}

const char* StageName(Stage stage) {
  switch (stage) {
    case Stage::kShape: return "shape";
    case Stage::kMotion: return "motion";
    case Stage::kRefine: return "refine";
    case Stage::kRetrack: return "retrack";
  }
  return "?";
}

std::vector<Stage> StagesOf(const ReconstructionOptions& options) {
  std::vector<Stage> stages{Stage::kShape, Stage::kMotion};
  if (options.refine) stages.push_back(Stage::kRefine);
  if (options.refine && options.retrack) stages.push_back(Stage::kRetrack);
  return stages;
}

void StageState::Check(const std::string& source) const {
  if (!hierarchy) ThrowError(source, "hierarchy", "missing");
  if (control.empty()) ThrowError(source, "control", "expected at least one frame");
  if (hulls.size() != control.size())
    ThrowError(source, "hull", "expected one per frame (" + std::to_string(control.size()) + "), found " +
                                   std::to_string(hulls.size()));
  const int vertices = hierarchy->VertexCount(hierarchy->finest_level());
  for (int i = 0; i < frame_count(); ++i)
    if (control[i].rows() != vertices || control[i].cols() != 3)
      ThrowError(source, "control of frame " + std::to_string(first_frame + i),
                 "expected " + std::to_string(vertices) + " × 3 control points of level " +
                     std::to_string(hierarchy->finest_level()));
  if (reference_index() < 0 || reference_index() >= frame_count())
    ThrowError(source, "reference_frame",
               std::to_string(reference_frame) + " is outside the frames [" + std::to_string(first_frame) + ", " +
                   std::to_string(first_frame + frame_count()) + ")");
}

geometry::Positions StageState::Surface(int i) const {
  return hierarchy->LimitPositions(hierarchy->finest_level()) * control.at(i);
}

vision::ImageSequence StageImages(const vision::Dataset& dataset, const StageState& state) {
  std::vector<vision::Camera> working;
  if (!state.image_scales.empty()) {
    if (static_cast<int>(state.image_scales.size()) != dataset.camera_count())
      ThrowError("stage state", "image_scales",
                 "expected one per camera (" + std::to_string(dataset.camera_count()) + "), found " +
                     std::to_string(state.image_scales.size()));
    working = vision::ScaledCameras(dataset.cameras(), state.image_scales);
  }
  return vision::DatasetImages(dataset, state.first_frame, state.frame_count(), state.evidence, &state.hulls,
                               working.empty() ? nullptr : &working, &state.outlines,
                               state.background_outlines ? &*state.background_outlines : nullptr);
}

namespace {

// Per camera, the scale at which the finest level's edges of the reference frame's
// surface project to about `edge_pixels` (vision::SurfaceScale; never enlarged).
std::vector<double> WorkingImageScales(const vision::Dataset& dataset, const geometry::LoopHierarchy& hierarchy,
                                       const geometry::Positions& reference_control, double edge_pixels) {
  if (edge_pixels == 0) return {};
  const geometry::Faces& faces = hierarchy.LevelFaces(hierarchy.finest_level());
  const geometry::Positions reference_surface = hierarchy.LimitPositions(hierarchy.finest_level()) * reference_control;
  std::vector<double> scales(dataset.camera_count());
  std::string line;
  for (int k = 0; k < dataset.camera_count(); ++k) {
    double edge = 0;
    scales[k] = vision::SurfaceScale(dataset.camera(k), reference_surface, faces, edge_pixels, &edge);
    line += fmt::format("{}{:.3f} ({:.1f} px)", k ? ", " : "", scales[k], edge);
  }
  spdlog::info("motion and refinement images at {} of the stored size (median finest edge)", line);
  return scales;
}

}  // namespace

StageState RunShapeStage(const vision::Dataset& dataset, const ShapeInitOptions& options, Progress* progress,
                         ShapeInitResult* figures, ShapeFrameStore* store) {
  *figures = InitializeShape(dataset, options, progress, store);
  StageState state;
  state.hierarchy = figures->hierarchy;
  state.base_mesh = figures->base_mesh;
  state.first_frame = figures->frames.front().frame;
  state.reference_frame = figures->reference_frame;
  state.evidence = options.silhouettes.source;
  const int finest = state.hierarchy->finest_level();
  if (!store)
    for (FrameShapeInit& frame : figures->frames) {
      state.hulls.push_back(std::move(frame.hull));  // moved: the figures keep its size
      state.control.push_back(frame.control.at(finest));
    }
  state.image_scales =
      WorkingImageScales(dataset, state.Hierarchy(), figures->reference_control, options.image_edge_pixels);
  state.outlines = figures->outlines;
  bool any_background_image = false;
  for (int k = 0; k < dataset.camera_count(); ++k)
    any_background_image =
        any_background_image || vision::AutomaticSource(dataset, k) == vision::EvidenceSource::kBackground;
  if (options.silhouettes.background_outlines && options.silhouettes.source == vision::EvidenceSource::kAuto &&
      any_background_image)
    state.background_outlines = options.silhouettes;
  return state;
}

StageState RunMotionStage(const vision::Dataset& dataset, const StageState& in, const MotionInitOptions& options,
                          Progress* progress, MotionInitResult* figures) {
  in.Check("motion stage input");
  const vision::ImageSequence images = StageImages(dataset, in);
  *figures = InitializeMotion(images, in.Hierarchy(), in.control, in.reference_index(), options, progress,
                              in.lead_in ? &*in.lead_in : nullptr);
  StageState out = in;
  out.control = figures->control;
  out.lead_in.reset();  // the input's, used
  return out;
}

StageState RunRefineStage(const vision::Dataset& dataset, const StageState& in,
                          const StereoRefinementOptions& options, Progress* progress, RefinementResult* figures) {
  in.Check("refine stage input");
  const vision::ImageSequence images = StageImages(dataset, in);
  *figures = RefineStereo(images, in.Hierarchy(), in.control, dataset.bounds(), options, progress);
  StageState out = in;
  out.control = figures->control;
  return out;
}

RigidSplit RunSplitStage(const StageState& in) {
  in.Check("split stage input");
  return SplitRigidMotion(in.Hierarchy(), in.control);
}

}  // namespace subflow::solver
