#include "solver/reconstruction.h"


#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "vision/zbuffer.h"

namespace subflow::solver {
namespace {

}  // namespace

void ReconstructionOptions::Check() const {
  shape.Check();
  motion.Check();
  if (refine) refinement.Check();
  if (!(retrack_weight >= 0.0 && retrack_weight <= 1.0))
    ThrowError("reconstruction options", "retrack_weight", "must be in [0, 1]");
}

geometry::Positions ReconstructionResult::Surface(int i) const {
  const geometry::LoopHierarchy& h = hierarchy();
  return h.LimitPositions(h.finest_level()) * control.at(i);
}

RefinementImageLoader SilhouetteLoader(const vision::Dataset& dataset, const ShapeInitResult& shape) {
  const int first = shape.frames.empty() ? 0 : shape.frames.front().frame;
  if (dataset.has_masks()) {
    return [&dataset, first](int camera, int frame) {
      const vision::Camera& cam = dataset.camera(camera);
      const cv::Mat mask = dataset.Mask(camera, first + frame);
      return cam.HasDistortion() ? cam.UndistortImage(mask, cv::INTER_NEAREST) : mask;
    };
  }
  return [&dataset, &shape](int camera, int frame) {
    const geometry::TriangleMesh& hull = shape.frames.at(frame).hull;
    if (hull.F.rows() == 0) return cv::Mat();
    return vision::ZBuffer(dataset.camera(camera), hull.V, hull.F).Mask();
  };
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

  // Motion initialization from the reference frame's fit, corrected towards every frame's.
  start.Restart();
  std::vector<geometry::Positions> fitted(frames);
  for (int i = 0; i < frames; ++i) fitted[i] = result.shape.frames[i].control.at(finest);
  const int first = result.first_frame;
  const GrayImageLoader gray = [&dataset, first](int camera, int frame) {
    const vision::Camera& cam = dataset.camera(camera);
    cv::Mat image = dataset.Gray(camera, first + frame);
    return cam.HasDistortion() ? cam.UndistortImage(image) : image;
  };
  result.motion = InitializeMotion(dataset.cameras(), frames, gray, hierarchy, fitted,
                                   result.shape.reference_frame - first, options.motion, progress);
  result.motion_seconds = start.Seconds();
  result.control = result.motion.control;

  if (options.refine) {
    start.Restart();
    result.refinement = RefineStereo(dataset.cameras(), gray, SilhouetteLoader(dataset, result.shape),
                                     hierarchy, result.control, dataset.bounds(), options.refinement,
                                     progress);
    result.control = result.refinement->control;
    result.refinement_seconds = start.Seconds();
    if (options.retrack) {
      start.Restart();
      MotionInitOptions retrack = options.motion;
      retrack.hull_weight = options.retrack_weight;
      result.retrack = InitializeMotion(dataset.cameras(), frames, gray, hierarchy, result.control,
                                        result.shape.reference_frame - first, retrack, progress);
      result.control = result.retrack->control;
      result.retrack_seconds = start.Seconds();
    }
  }

  start.Restart();
  result.trajectory = geometry::AnalyzeTrajectory(hierarchy, result.control);
  std::vector<geometry::Positions> bases;
  for (const geometry::MultiresShape& shape : result.trajectory) bases.push_back(shape.base());
  result.rigid = FitRigidMotions(bases);
  result.analysis_seconds = start.Seconds();
  return result;
}

}  // namespace subflow::solver
