#include "solver/reconstruction.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "vision/image_sequence.h"
#include "vision/working_scale.h"

namespace subflow::solver {

void ReconstructionOptions::Check() const {
  shape.Check();
  motion.Check();
  if (refine) refinement.Check();
  if (!(retrack_weight >= 0.0 && retrack_weight <= 1.0))
    ThrowError("reconstruction options", "retrack_weight", "must be in [0, 1]");
  if (!(image_edge_pixels == 0 || (image_edge_pixels >= 0.5 && image_edge_pixels <= 1000)))
    ThrowError("reconstruction options", "image_edge_pixels", "expected 0 (stored size) or a value in [0.5, 1000]");
}

MotionInitOptions ReconstructionOptions::RetrackOptions() const {
  MotionInitOptions retrack = motion;
  retrack.hull_weight = retrack_weight;
  return retrack;
}

std::string ReconstructionResult::BriefReport() const {
  std::string lines = shape.BriefReport() + "\n" + motion.BriefReport();
  if (refinement) lines += "\n" + refinement->BriefReport();
  if (retrack) lines += "\nretrack: " + retrack->BriefReport();
  return lines + "\n" + split.BriefReport();
}

geometry::Positions ReconstructionResult::Surface(int i) const {
  const geometry::LoopHierarchy& h = hierarchy();
  return h.LimitPositions(h.finest_level()) * control.at(i);
}

ReconstructionResult Reconstruct(const vision::Dataset& dataset, const ReconstructionOptions& options,
                                 Progress* progress) {
  options.Check();
  ReconstructionResult result;

  Stopwatch start;
  result.shape = InitializeShape(dataset, options.shape, progress);
  result.shape_seconds = start.Seconds();
  const geometry::LoopHierarchy& hierarchy = result.hierarchy();
  const int finest = hierarchy.finest_level();
  result.first_frame = result.shape.frames.front().frame;
  const int frames = static_cast<int>(result.shape.frames.size());
  std::vector<geometry::TriangleMesh> hulls;
  for (const FrameShapeInit& frame : result.shape.frames) hulls.push_back(frame.hull);
  const int reference = result.shape.reference_frame - result.first_frame;
  const geometry::Positions reference_surface =
      hierarchy.LimitPositions(finest) * result.shape.frames[reference].control.at(finest);
  result.image_scales.resize(dataset.camera_count());
  std::string scales;
  for (int k = 0; k < dataset.camera_count(); ++k) {
    double edge = 0;
    result.image_scales[k] = vision::SurfaceScale(dataset.camera(k), reference_surface,
                                                  hierarchy.LevelFaces(finest), options.image_edge_pixels, &edge);
    scales += fmt::format("{}{:.3f} ({:.1f} px)", k ? ", " : "", result.image_scales[k], edge);
  }
  spdlog::info("motion and refinement images at {} of the stored size (median finest edge)", scales);
  const std::vector<vision::Camera> working = vision::ScaledCameras(dataset.cameras(), result.image_scales);
  const vision::ImageSequence images = vision::DatasetImages(dataset, result.first_frame, frames,
                                                             options.shape.silhouettes.source, &hulls, &working);

  // Motion initialization from the reference frame's fit, corrected towards every frame's.
  start.Restart();
  std::vector<geometry::Positions> fitted(frames);
  for (int i = 0; i < frames; ++i) fitted[i] = result.shape.frames[i].control.at(finest);
  result.motion = InitializeMotion(images, hierarchy, fitted, reference, options.motion, progress);
  result.motion_seconds = start.Seconds();
  result.control = result.motion.control;

  if (options.refine) {
    start.Restart();
    result.refinement = RefineStereo(images, hierarchy, result.control, dataset.bounds(), options.refinement, progress);
    result.control = result.refinement->control;
    result.refinement_seconds = start.Seconds();
    if (options.retrack) {
      start.Restart();
      result.retrack =
          InitializeMotion(images, hierarchy, result.control, reference, options.RetrackOptions(), progress);
      result.control = result.retrack->control;
      result.retrack_seconds = start.Seconds();
    }
  }

  result.split = SplitRigidMotion(hierarchy, result.control);
  return result;
}

}  // namespace subflow::solver
