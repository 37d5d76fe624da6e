#include "solver/shape/shape_init.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/task_errors.h"
#include "geometry/closest_point.h"
#include "geometry/mean_edge_length.h"
#include "vision/plain_backdrop.h"
#include "vision/silhouettes.h"
#include "vision/working_scale.h"

namespace subflow::solver {
namespace {

// The store without a ShapeFrameStore: the hulls and control points in the result's frames.
class FramesStore : public ShapeFrameStore {
 public:
  FramesStore(std::vector<FrameShapeInit>* frames, int first) : frames_(frames), first_(first) {}
  void StoreHull(int frame, const geometry::TriangleMesh& hull) override { At(frame).hull = hull; }
  geometry::TriangleMesh LoadHull(int frame) const override { return frames_->at(frame - first_).hull; }
  void StoreControl(int frame, const geometry::LoopHierarchy&, const std::vector<geometry::Positions>& levels) override {
    At(frame).control = levels;
  }

 private:
  FrameShapeInit& At(int frame) { return frames_->at(frame - first_); }
  std::vector<FrameShapeInit>* frames_;
  int first_;
};

// Frames without evidence take the hull and carving figures of the nearest frame with
// evidence (the earlier one on a tie), with a warning; an error when no frame has any.
// all_empty[i]: every silhouette of frame i is empty and none is motion evidence (the
// object has left the volume).
void TakeHullsOfFramesWithoutEvidence(const vision::Dataset& dataset, const std::vector<bool>& has_evidence,
                                      const std::vector<bool>& all_empty, int min_cameras,
                                      std::vector<FrameShapeInit>* frames, ShapeFrameStore* store) {
  const int count = static_cast<int>(frames->size());
  const std::string frame_range =
      "frames " + std::to_string(frames->front().frame) + ".." + std::to_string(frames->back().frame);
  if (std::find(all_empty.begin(), all_empty.end(), false) == all_empty.end())
    ThrowError(dataset.directory(), frame_range, "every camera's silhouette is empty in every frame: cannot find the object");
  if (std::find(has_evidence.begin(), has_evidence.end(), true) == has_evidence.end())
    ThrowError(dataset.directory(),
               "frames " + std::to_string(frames->front().frame) + ".." + std::to_string(frames->back().frame),
               "no masks, no background, and no motion: cannot find the object (motion evidence in fewer than " +
                   std::to_string(min_cameras) + " camera(s) in every frame)");
  for (int i = 0; i < count; ++i) {
    if (has_evidence[i]) continue;
    int source = -1;
    for (int d = 1; source < 0; ++d) {
      if (i - d >= 0 && has_evidence[i - d]) source = i - d;
      else if (i + d < count && has_evidence[i + d]) source = i + d;
    }
    FrameShapeInit& frame = (*frames)[i];
    const FrameShapeInit& taken = (*frames)[source];
    frame.hull_from_frame = taken.frame;
    frame.carving = taken.carving;
    frame.carving.frame = frame.frame;
    frame.carving.warnings.clear();
    frame.isosurface = taken.isosurface;
    store->StoreHull(frame.frame, store->LoadHull(taken.frame));
    frame.hull_vertices = taken.hull_vertices;
    frame.hull_faces = taken.hull_faces;
    const std::string warning = all_empty[i] ?
        "frame " + std::to_string(frame.frame) + ": every camera's silhouette is empty (the object has left the "
        "working volume): hull of frame " + std::to_string(taken.frame) + " used" :
        "frame " + std::to_string(frame.frame) + ": no masks, no background, and motion evidence in fewer than " +
        std::to_string(min_cameras) + " camera(s) (nothing moves): hull of frame " + std::to_string(taken.frame) +
        " used";
    spdlog::warn("{}", warning);
    frame.carving.warnings.push_back(warning);
  }
}

// Every camera's gray image of `frame` at the size of its working camera.
std::vector<cv::Mat> WorkingGrayImages(const vision::Dataset& dataset, int frame,
                                       const std::vector<vision::Camera>& cameras) {
  std::vector<cv::Mat> gray(cameras.size());
  for (std::size_t k = 0; k < cameras.size(); ++k)
    gray[k] = vision::ResizeToCamera(dataset.Gray(static_cast<int>(k), frame), cameras[k]);
  return gray;
}

// The visual hull of every frame (FrameShapeInit's carving, hull and times) from the
// evidence of `silhouettes` (plus `standing`, when given), or from `still` for every frame
// when given; has_evidence / all_empty per frame as TakeHullsOfFramesWithoutEvidence
// reads them.
struct HullStage {
  const vision::Dataset& dataset;
  const vision::VoxelCarvingOptions& carving;
  const vision::ConcavityCarvingOptions& concavities;
  const geometry::IsosurfaceOptions& isosurface;
  const std::vector<vision::Camera>& cameras;  // the evidence's working cameras
  const std::vector<vision::EstimatedBackground>& estimated;
  const std::vector<vision::Silhouette>* standing = nullptr;
  int reference_frame = -1;  // the only frame whose concavities are carved unless every_frame

  // Frames go through three steps: evidence and carving (in frame order: video decoders
  // read forwards), the iso-surface (CGAL Mesh_3, one thread: frames side by side), and
  // storing the hull (in frame order). A frame's result does not depend on the others.
  void Run(const vision::SilhouetteOptions& silhouette_options, const std::vector<vision::Silhouette>* still,
           Progress* progress, std::vector<FrameShapeInit>* frames, std::vector<bool>* has_evidence,
           std::vector<bool>* all_empty, ShapeFrameStore* store) const {
    const int count = static_cast<int>(frames->size());
    std::vector<geometry::TriangleMesh> hulls(count);  // between extraction and the store
    int next = 0;
    ProgressBegin(progress, "visual hull", count);
    // A frame and whether it was carved (has_evidence's bits are shared: only the first
    // step writes or reads them).
    struct Token {  // trivial: TBB passes it by value between the steps
      int i;
      bool carved;
    };
    // No exception may reach TBB (core/task_errors.h): once a step threw, no frame enters
    // and the frames under way skip their remaining steps.
    TaskErrors errors;
    vision::CornerPixelCache corners;  // used by the first step alone, one frame at a time
    tbb::parallel_pipeline(
        static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()) + 1,
        tbb::make_filter<void, Token>(
            tbb::filter_mode::serial_in_order,
            [&](tbb::flow_control& control) {
              const int i = next++;
              if (i >= count || errors.failed() ||
                  !errors.Run([&] { Carve(silhouette_options, still, i, frames, has_evidence, all_empty, &corners); })) {
                control.stop();
                return Token{-1, false};
              }
              return Token{i, (*has_evidence)[i]};
            }) &
            tbb::make_filter<Token, Token>(tbb::filter_mode::parallel,
                                           [&](Token token) {
                                             if (token.carved && !errors.failed())
                                               errors.Run([&] { ExtractHull(&(*frames)[token.i], &hulls[token.i]); });
                                             return token;
                                           }) &
            tbb::make_filter<Token, void>(tbb::filter_mode::serial_in_order, [&](Token token) {
              if (errors.failed()) return;
              errors.Run([&] {
                if (token.carved) store->StoreHull((*frames)[token.i].frame, hulls[token.i]);
                hulls[token.i] = geometry::TriangleMesh();
                ProgressUpdate(progress, token.i + 1);
              });
            }));
    errors.RethrowFirst();
    ProgressEnd(progress);
  }

  // Frame i's evidence, has_evidence / all_empty, and its carving when it has evidence.
  // `corners`: the distorted cameras' voxel corners, kept from frame to frame.
  void Carve(const vision::SilhouetteOptions& silhouette_options, const std::vector<vision::Silhouette>* still,
             int i, std::vector<FrameShapeInit>* frames, std::vector<bool>* has_evidence,
             std::vector<bool>* all_empty, vision::CornerPixelCache* corners) const {
    FrameShapeInit& frame = (*frames)[i];
    const Stopwatch start;
    std::vector<vision::Silhouette> silhouettes;
    if (still) {
      silhouettes = *still;
    } else {
      silhouettes = vision::ComputeFrameEvidence(dataset, frame.frame, silhouette_options, &estimated, &cameras);
      if (standing) vision::AddStandingEvidence(*standing, &silhouettes);
    }
    (*has_evidence)[i] = !vision::LacksEvidence(silhouettes, carving.min_cameras);
    // Empty masks or background differences say the object is absent (motion evidence
    // only that nothing moves).
    (*all_empty)[i] = std::all_of(silhouettes.begin(), silhouettes.end(), [](const vision::Silhouette& s) {
      return s.empty && s.source != vision::EvidenceSource::kMotion;
    });
    if (!(*has_evidence)[i]) return;
    frame.carving = vision::CarveVoxels(cameras, silhouettes, dataset.bounds(), carving, frame.frame, corners);
    if (concavities.enabled && (concavities.every_frame || frame.frame == reference_frame))
      CarveFrameConcavities(&frame);
    frame.carve_seconds = start.Seconds();
  }

  // The frame's hull from its carving (whose occupancy is then released).
  void ExtractHull(FrameShapeInit* frame, geometry::TriangleMesh* hull) const {
    const Stopwatch start;
    *hull = geometry::ExtractIsosurface(frame->carving.occupancy, isosurface, &frame->isosurface,
                                        "occupancy of frame " + vision::FrameName(frame->frame));
    frame->isosurface_seconds = start.Seconds();
    frame->hull_vertices = hull->vertex_count();
    frame->hull_faces = hull->face_count();
    frame->carving.occupancy = geometry::ScalarVolume();  // memory: keep the figures only
  }

  // The frame's hull carved where its images see through it (vision/concavity_carving.h).
  void CarveFrameConcavities(FrameShapeInit* frame) const {
    frame->concavities = vision::CarveConcavities(cameras, WorkingGrayImages(dataset, frame->frame, cameras),
                                                  concavities, &frame->carving.occupancy);
    const vision::ConcavityCarvingReport& report = frame->concavities;
    if (!report.skipped.empty() && report.carved_voxels > 0) {
      const std::string warning = "frame " + std::to_string(frame->frame) + ": concavity carving not applied: " +
                                  report.skipped;
      spdlog::warn("{}", warning);
      frame->carving.warnings.push_back(warning);
    }
    spdlog::debug("frame {}: concavities carved {} of {} hull voxels ({} removed with cleaning), {} trusted "
                  "depths, {:.2f} s",
                  frame->frame, report.carved_voxels, report.hull_voxels, report.removed_voxels,
                  report.trusted_pixels, report.seconds);
  }
};

// The standing silhouette of every camera with an estimated background (none when the
// option is off or nothing was estimated).
std::vector<vision::Silhouette> StandingSilhouettes(const std::vector<vision::EstimatedBackground>& estimated,
                                                    const ShapeInitOptions& options) {
  if (!options.standing.enabled || estimated.empty()) return {};
  std::vector<vision::Silhouette> standing(estimated.size());
  for (std::size_t k = 0; k < estimated.size(); ++k)
    standing[k] = vision::StandingSilhouette(estimated[k], options.silhouettes, options.standing);
  return standing;
}

// The silhouettes of a still set against a plain backdrop (vision/plain_backdrop.h): every
// camera's image of `reference` compared with its backdrop's colour as with a background
// image, with two differences (docs/shape.md, "Still sets on a plain backdrop"):
//  - the threshold is the difference histogram's (no surely-background pixels given), not
//    the backdrop's noise: against a backdrop that noiseless, the noise threshold also takes
//    in the dim props beside the object (the Middlebury dino's dark stand), which differ
//    from it by a few levels where the object differs by far more;
//  - no shadow test: on a backdrop without texture, a part of the object darker than the
//    backdrop fits a shadow's gain as well as a shadow does, and was carved away (a
//    sphere's shaded side); a shadow cast on the backdrop now stays in the silhouette,
//    which only makes the hull larger.
// Against a plain backdrop whatever differs is the object, so each silhouette is its
// outline (Silhouette::outline, result->outlines): the hull is carved as from masks, and
// the refinement draws the surface's rim onto it.
// Empty when some camera's backdrop is not plain, or when some camera's silhouette is empty
// (result->backdrops has every camera's figures either way).
std::vector<vision::Silhouette> BackdropSilhouettes(const vision::Dataset& dataset, int reference,
                                                    const std::vector<vision::Camera>& cameras,
                                                    const ShapeInitOptions& options, ShapeInitResult* result) {
  const vision::PlainBackdropOptions& backdrop = options.still.backdrop;
  if (!backdrop.enabled) return {};
  const Stopwatch start;
  std::vector<cv::Mat> images(cameras.size());
  result->backdrops.assign(cameras.size(), vision::PlainBackdrop());
  tbb::parallel_for(0, static_cast<int>(cameras.size()), [&](int k) {
    images[k] = vision::ResizeToCamera(dataset.Image(k, reference), cameras[k]);
    result->backdrops[k] = vision::MeasureBackdrop(images[k], vision::BorderBand(images[k].size(), backdrop), backdrop);
  });
  const auto plain = [](const vision::PlainBackdrop& b) { return b.plain; };
  const auto widest = std::max_element(result->backdrops.begin(), result->backdrops.end(),
                                       [](const auto& a, const auto& b) { return a.spread < b.spread; });
  if (!std::all_of(result->backdrops.begin(), result->backdrops.end(), plain)) {
    spdlog::info("no plain backdrop (plain in {} of {} cameras; widest spread {:.3f} > {:.3f} in camera {})",
                 std::count_if(result->backdrops.begin(), result->backdrops.end(), plain), cameras.size(),
                 widest->spread, backdrop.max_spread, dataset.camera(widest - result->backdrops.begin()).name());
    return {};
  }
  vision::SilhouetteOptions plain_options = options.silhouettes;
  plain_options.background_shadow_test = false;
  std::vector<vision::Silhouette> silhouettes(cameras.size());
  tbb::parallel_for(0, static_cast<int>(cameras.size()), [&](int k) {
    silhouettes[k] = vision::SilhouetteFromBackground(
        images[k], vision::BackdropImage(images[k], result->backdrops[k]), plain_options);
    silhouettes[k].source = vision::EvidenceSource::kStill;
    silhouettes[k].outline = true;
  });
  result->backdrop_seconds = start.Seconds();
  const auto empty = std::find_if(silhouettes.begin(), silhouettes.end(), [](const auto& s) { return s.empty; });
  if (empty != silhouettes.end()) {  // an object of the backdrop's colour (dark on black velvet)?
    spdlog::info("nothing differs from the plain backdrop in camera {}: photo-consistency instead",
                 dataset.camera(empty - silhouettes.begin()).name());
    return {};
  }
  result->used_backdrop = true;
  result->outlines.resize(silhouettes.size());
  for (std::size_t k = 0; k < silhouettes.size(); ++k) result->outlines[k] = silhouettes[k].mask;
  spdlog::info("no masks, no background and nothing moves: frame {} against a plain backdrop in every camera "
               "(widest spread {:.3f})",
               reference, widest->spread);
  return silhouettes;
}

// The still evidence of the reference frame as silhouettes of source kStill, on the
// evidence's working cameras: against a plain backdrop when every camera has one, else
// the photo-consistency (vision/still_evidence.h).
std::vector<vision::Silhouette> StillSilhouettes(const vision::Dataset& dataset, int reference,
                                                 const std::vector<vision::Camera>& cameras, int resolution,
                                                 const ShapeInitOptions& options, ShapeInitResult* result) {
  result->used_still = true;
  std::vector<vision::Silhouette> silhouettes = BackdropSilhouettes(dataset, reference, cameras, options, result);
  if (!silhouettes.empty()) return silhouettes;
  result->still = vision::ComputeStillEvidence(cameras, WorkingGrayImages(dataset, reference, cameras),
                                               dataset.bounds(), resolution, options.still);
  silhouettes.resize(cameras.size());
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    silhouettes[k] = vision::SilhouetteFromMask(result->still.silhouettes[k], options.silhouettes);
    silhouettes[k].source = vision::EvidenceSource::kStill;
  }
  for (cv::Mat& silhouette : result->still.silhouettes) silhouette.release();  // memory: keep the figures
  result->still.fused.occupancy = geometry::ScalarVolume();
  spdlog::info("no masks, no background and nothing moves: photo-consistency of frame {} ({} voxels, support "
               "plane {}, {:.1f} s)",
               reference, result->still.fused.occupied_voxels,
               result->still.support.found ? "removed" : "not found", result->still.seconds);
  return silhouettes;
}

// Fits the hierarchy to every frame's hull (FrameShapeInit::fit and fit_seconds; the
// control points of levels 0..n to `store`), outwards from the reference frame. A frame
// starts from its neighbour's fitted base, the frame fitted last on its side of the
// reference frame. The two sides share only the reference frame's base: they run side by
// side (each frame's fit is what it would be alone), the store's calls one at a time.
// Returns the reference frame's finest control points.
geometry::Positions FitEveryFrame(const ShapeInitOptions& options, ShapeFrameStore* store, Progress* progress,
                                  ShapeInitResult* result) {
  const int count = static_cast<int>(result->frames.size());
  const int reference_index = result->reference_frame - result->frames.front().frame;
  const SurfaceRegistration registration(
      *result->hierarchy, options.registration,
      geometry::MeanEdgeLength(result->hierarchy->Topology(0), result->base_mesh.V));
  std::mutex store_mutex;  // the store and the progress
  int done = 0;
  // Fits frame i from `initial_base`; returns its control points of levels 0..n.
  auto fit = [&](int i, const geometry::Positions& initial_base) {
    FrameShapeInit& frame = result->frames[i];
    const Stopwatch start;
    geometry::TriangleMesh hull;
    {
      const std::lock_guard<std::mutex> lock(store_mutex);
      hull = store->LoadHull(frame.frame);
    }
    const geometry::ClosestPointTree hull_tree(hull, "visual hull of frame " + vision::FrameName(frame.frame));
    // The reference frame's base is its own hull simplified: nothing to follow there.
    const geometry::Positions registered = i == reference_index
                                               ? initial_base
                                               : registration.Register(initial_base, hull_tree, &frame.registration);
    std::vector<geometry::Positions> control =
        FitHierarchyToSurface(*result->hierarchy, registered, hull_tree, options.fit, &frame.fit);
    frame.fit_seconds = start.Seconds();
    const std::lock_guard<std::mutex> lock(store_mutex);
    store->StoreControl(frame.frame, *result->hierarchy, control);
    ProgressUpdate(progress, static_cast<std::size_t>(++done));
    return control;
  };
  ProgressBegin(progress, "fit subdivision surface", count);
  const std::vector<geometry::Positions> reference = fit(reference_index, result->base_mesh.V);
  // The frames after the reference frame (direction +1) or before it (-1); a side stops
  // early once the other has thrown.
  auto side = [&](int direction, const TaskErrors& group) {
    geometry::Positions base = reference.front();
    for (int i = reference_index + direction; i >= 0 && i < count && !group.failed(); i += direction)
      base = fit(i, base).front();
  };
  RunSideBySide([&](const TaskErrors& group) { side(+1, group); },  // core/task_errors.h
                [&](const TaskErrors& group) { side(-1, group); });
  ProgressEnd(progress);
  return reference.back();
}

}  // namespace

std::string ShapeInitResult::BriefReport() const {
  double iou = 0;
  int with_iou = 0;
  for (const FrameShapeInit& frame : frames)
    if (std::isfinite(frame.carving.mean_silhouette_iou)) iou += frame.carving.mean_silhouette_iou, ++with_iou;
  const int levels = hierarchy ? hierarchy->finest_level() : 0;
  return fmt::format("shape init: {} frames ({}–{}), reference {}, base mesh {} vertices / {} faces, {} levels "
                     "(finest {} faces), mean silhouette IoU {:.4f}, {:.1f} s",
                     frames.size(), frames.empty() ? 0 : frames.front().frame, frames.empty() ? 0 : frames.back().frame,
                     reference_frame, base_mesh.vertex_count(), base_mesh.face_count(), levels,
                     hierarchy ? hierarchy->FaceCount(levels) : 0, with_iou ? iou / with_iou : 0.0, this->seconds);
}

void ShapeInitOptions::Check() const {
  silhouettes.Check();
  standing.Check();
  still.Check();
  carving.Check();
  concavities.Check();
  isosurface.Check();
  simplify.Check();
  registration.Check();
  fit.Check();
  if (levels < -1 || levels > 6) ThrowError("shape init options", "levels", "expected 0..6, or −1 for automatic");
  if (!(base_distance_voxels >= 0 && base_distance_voxels <= 100))
    ThrowError("shape init options", "base_distance_voxels", "expected 0 (by count) or a distance in (0, 100] voxels");
  if (!(finest_edge_pixels >= 0.25 && finest_edge_pixels <= 1000))
    ThrowError("shape init options", "finest_edge_pixels", "expected a length in [0.25, 1000] pixels");
  if (max_finest_faces < 4) ThrowError("shape init options", "max_finest_faces", "expected at least 4");
  if (first_frame < 0) ThrowError("shape init options", "first_frame", "expected ≥ 0");
  if (frame_count == 0 || frame_count < -1)
    ThrowError("shape init options", "frame_count", "expected > 0, or −1 for all frames");
  if (!(image_edge_pixels == 0 || (image_edge_pixels >= 0.5 && image_edge_pixels <= 1000)))
    ThrowError("shape init options", "image_edge_pixels", "expected 0 (stored size) or a value in [0.5, 1000]");
}

ShapeInitResult InitializeShape(const vision::Dataset& dataset, const ShapeInitOptions& options,
                                Progress* progress, ShapeFrameStore* store) {
  options.Check();
  const Stopwatch stage_start;
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
  for (int i = 0; i < count; ++i) result.frames[i].frame = result.frames[i].hull_from_frame = first + i;
  FramesStore in_frames(&result.frames, first);
  if (!store) store = &in_frames;

  // Evidence on images reduced to what the voxel grid resolves (vision/working_scale.h),
  // the grid's resolution and morphology fixed first on the stored images, so that they do
  // not follow the reduced cameras.
  const vision::VoxelCarvingOptions carving =
      vision::ResolveCarvingOptions(dataset.cameras(), dataset.bounds(), options.carving);
  const double voxel_size = dataset.bounds().Size().maxCoeff() / carving.resolution;
  result.evidence_scales.resize(dataset.camera_count());
  for (int k = 0; k < dataset.camera_count(); ++k)
    result.evidence_scales[k] =
        vision::EvidenceScale(dataset.camera(k), dataset.bounds(), voxel_size, options.carving.max_pixels_per_voxel);
  const std::vector<vision::Camera> evidence_cameras = vision::ScaledCameras(dataset.cameras(), result.evidence_scales);
  std::string scales;
  for (double scale : result.evidence_scales) scales += fmt::format("{}{:.3f}", scales.empty() ? "" : " ", scale);
  const auto radius = [](int r) { return r < 0 ? std::string("automatic") : std::to_string(r); };
  spdlog::info("evidence images at {} of the stored size (voxels of {:.4g}, {} along the longest axis; closing "
               "and opening radii {} and {})",
               scales, voxel_size, carving.resolution, radius(carving.closing_radius), radius(carving.opening_radius));

  // Without masks and background images: backgrounds estimated from the video.
  Stopwatch estimate_start;
  result.estimated_backgrounds = vision::EstimateBackgrounds(dataset, options.silhouettes, &evidence_cameras);
  result.estimate_background_seconds = estimate_start.Seconds();
  for (const vision::EstimatedBackground& estimated : result.estimated_backgrounds)
    if (estimated.valid()) {
      spdlog::info("no masks, no background: background estimated from {} frames per camera ({:.1f} s)",
                   estimated.frames, result.estimate_background_seconds);
      break;
    }

  // Visual hull of every frame with evidence; when no frame has any, of the still set.
  std::vector<bool> has_evidence(count, false), all_empty(count, false);
  result.standing = StandingSilhouettes(result.estimated_backgrounds, options);
  const HullStage stage{dataset,          carving, options.concavities, options.isosurface, evidence_cameras,
                        result.estimated_backgrounds, result.standing.empty() ? nullptr : &result.standing,
                        reference};
  const bool still_forced = options.silhouettes.source == vision::EvidenceSource::kStill;
  std::vector<vision::Silhouette> still;
  if (still_forced) still = StillSilhouettes(dataset, reference, evidence_cameras, carving.resolution, options, &result);
  stage.Run(options.silhouettes, still_forced ? &still : nullptr, progress, &result.frames, &has_evidence,
            &all_empty, store);
  const bool none = std::find(has_evidence.begin(), has_evidence.end(), true) == has_evidence.end();
  if (!still_forced && none && options.still.enabled && options.silhouettes.source == vision::EvidenceSource::kAuto &&
      std::find(all_empty.begin(), all_empty.end(), false) != all_empty.end()) {
    still = StillSilhouettes(dataset, reference, evidence_cameras, carving.resolution, options, &result);
    stage.Run(options.silhouettes, &still, progress, &result.frames, &has_evidence, &all_empty, store);
  }
  std::vector<const vision::CarvingResult*> carvings;
  for (int i = 0; i < count; ++i)
    if (has_evidence[i]) carvings.push_back(&result.frames[i].carving);
  for (const std::string& line : vision::SummarizeBorderContacts(carvings))  // one line per side, not per frame
    spdlog::warn("{}", line);
  for (vision::EstimatedBackground& estimated : result.estimated_backgrounds)  // memory: keep the figures
    estimated.image.release(), estimated.known.release(), estimated.instability.release();
  for (vision::Silhouette& standing : result.standing)
    standing.evidence.release(), standing.mask.release(), standing.measure.release();
  if (result.used_still && std::find(has_evidence.begin(), has_evidence.end(), true) == has_evidence.end())
    ThrowError(dataset.directory(), "evidence",
               std::string("no masks, no background, nothing moves, and ") +
                   (result.used_backdrop ? "the differences to the plain backdrop carve the whole volume"
                                         : "the photo-consistency of the still set found no surface either") +
                   " (evidence \"still\"): cannot find the object (give masks or background images)");
  TakeHullsOfFramesWithoutEvidence(dataset, has_evidence, all_empty, options.carving.min_cameras, &result.frames,
                                   store);

  // Base mesh and hierarchy from the reference frame.
  Stopwatch start;
  result.resolution = ChooseBaseResolution(store->LoadHull(reference), dataset.cameras(), voxel_size, options,
                                           "visual hull of frame " + vision::FrameName(reference));
  result.base_mesh = std::move(result.resolution.base);
  result.simplify = result.resolution.simplify;
  result.simplify_seconds = start.Seconds();
  const int levels = result.resolution.levels;
  result.hierarchy = std::make_shared<const geometry::LoopHierarchy>(
      result.base_mesh.F, result.base_mesh.vertex_count(), levels, "base mesh");
  spdlog::info("base mesh: {} vertices, {} faces; {} levels, finest {} faces",
               result.base_mesh.vertex_count(), result.base_mesh.face_count(), levels,
               result.hierarchy->FaceCount(levels));

  result.reference_control = FitEveryFrame(options, store, progress, &result);
  result.seconds = stage_start.Seconds();
  return result;
}

}  // namespace subflow::solver
