#include "solver/shape_init.h"

#include <chrono>

#include <spdlog/spdlog.h>

#include "geometry/closest_point.h"
#include "geometry/error.h"

namespace subflow::solver {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void ShapeInitOptions::Check() const {
  carving.Check();
  isosurface.Check();
  simplify.Check();
  fit.Check();
  if (levels < 0 || levels > 6) ThrowError("shape init options", "levels", "expected 0..6");
  if (first_frame < 0) ThrowError("shape init options", "first_frame", "expected ≥ 0");
  if (frame_count == 0 || frame_count < -1)
    ThrowError("shape init options", "frame_count", "expected > 0, or −1 for all frames");
}

ShapeInitResult InitializeShape(const vision::Dataset& dataset, const ShapeInitOptions& options,
                                Progress* progress) {
  options.Check();
  const int available = dataset.frame_count() - options.first_frame;
  if (available <= 0)
    ThrowError(dataset.directory(), "first_frame",
               "frame " + std::to_string(options.first_frame) + " is past the last frame (" +
                   std::to_string(dataset.frame_count()) + " frames)");
  const int count = options.frame_count < 0 ? available : std::min(options.frame_count, available);
  const int first = options.first_frame;
  const int reference = options.reference_frame < 0 ? first + count / 2 : options.reference_frame;
  if (reference < first || reference >= first + count)
    ThrowError(dataset.directory(), "reference_frame",
               "frame " + std::to_string(reference) + " is outside the frames processed [" +
                   std::to_string(first) + ", " + std::to_string(first + count) + ")");

  ShapeInitResult result;
  result.reference_frame = reference;
  result.frames.resize(count);

  // Visual hull of every frame.
  ProgressBegin(progress, "visual hull", count);
  for (int i = 0; i < count; ++i) {
    FrameShapeInit& frame = result.frames[i];
    frame.frame = first + i;
    auto start = std::chrono::steady_clock::now();
    frame.carving = vision::CarveFrame(dataset, frame.frame, options.silhouettes, options.carving);
    frame.carve_seconds = SecondsSince(start);
    start = std::chrono::steady_clock::now();
    frame.hull = geometry::ExtractIsosurface(frame.carving.occupancy, options.isosurface,
                                             &frame.isosurface,
                                             "occupancy of frame " + vision::FrameName(frame.frame));
    frame.isosurface_seconds = SecondsSince(start);
    frame.carving.occupancy = geometry::ScalarVolume();  // memory: keep the figures only
    ProgressUpdate(progress, i + 1);
  }
  ProgressEnd(progress);

  // Base mesh and hierarchy from the reference frame.
  auto start = std::chrono::steady_clock::now();
  const FrameShapeInit& reference_frame = result.frames[reference - first];
  result.base_mesh = geometry::SimplifyMesh(reference_frame.hull, options.simplify,
                                            &result.simplify,
                                            "visual hull of frame " + vision::FrameName(reference));
  result.simplify_seconds = SecondsSince(start);
  result.hierarchy = std::make_shared<const geometry::LoopHierarchy>(
      result.base_mesh.F, result.base_mesh.vertex_count(), options.levels, "base mesh");
  spdlog::info("base mesh: {} vertices, {} faces; {} levels, finest {} faces",
               result.base_mesh.vertex_count(), result.base_mesh.face_count(), options.levels,
               result.hierarchy->FaceCount(options.levels));

  // Fit the hierarchy to every frame's hull, outwards from the reference frame.
  ProgressBegin(progress, "fit subdivision surface", count);
  std::vector<int> order{reference - first};
  for (int d = 1; d < count; ++d) {
    if (reference - first - d >= 0) order.push_back(reference - first - d);
    if (reference - first + d < count) order.push_back(reference - first + d);
  }
  int done = 0;
  for (int i : order) {
    FrameShapeInit& frame = result.frames[i];
    start = std::chrono::steady_clock::now();
    const int neighbour = i < reference - first ? i + 1 : i - 1;
    const geometry::Positions& initial_base =
        i == reference - first ? result.base_mesh.V : result.frames[neighbour].control.front();
    const geometry::ClosestPointTree hull_tree(frame.hull, "visual hull of frame " +
                                                               vision::FrameName(frame.frame));
    frame.control = FitHierarchyToSurface(*result.hierarchy, initial_base, hull_tree,
                                          options.fit, &frame.fit);
    frame.shape = geometry::MultiresShape::Analyze(*result.hierarchy, frame.control.back());
    frame.fit_seconds = SecondsSince(start);
    ProgressUpdate(progress, ++done);
  }
  ProgressEnd(progress);
  return result;
}

}  // namespace subflow::solver
