// The Dataset-facing entry points of silhouettes and voxel carving (declared in
// vision/silhouettes.h and vision/voxel_carving.h), kept apart so that code using only
// the image-level functions does not link the dataset reader.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "vision/dataset.h"
#include "vision/silhouettes.h"
#include "vision/silhouettes_background.h"
#include "vision/voxel_carving.h"
#include "vision/working_scale.h"

namespace subflow::vision {

bool LacksEvidence(const std::vector<Silhouette>& silhouettes, int min_cameras) {
  int non_empty = 0;
  bool all_motion = true;
  for (const Silhouette& silhouette : silhouettes) {
    all_motion = all_motion && silhouette.source == EvidenceSource::kMotion;
    non_empty += !silhouette.empty;
  }
  // No camera sees the object (it has left the working volume): nothing to carve.
  if (non_empty == 0) return true;
  return all_motion && non_empty < min_cameras;
}

EvidenceSource AutomaticSource(const Dataset& dataset, int camera) {
  return dataset.has_masks()                                    ? EvidenceSource::kMask
         : std::filesystem::exists(dataset.BackgroundPath(camera)) ? EvidenceSource::kBackground
                                                                   : EvidenceSource::kMotion;
}

namespace {

// Whether camera `camera` would take motion evidence under options.source.
bool UsesMotion(const Dataset& dataset, int camera, const SilhouetteOptions& options) {
  const EvidenceSource source = options.source == EvidenceSource::kAuto ? AutomaticSource(dataset, camera)
                                                                         : options.source;
  return source == EvidenceSource::kMotion;
}

// The frames of one camera as the evidence sees them: the stored images, or resized to
// the working camera when `working` is given.
struct EvidenceImages {
  const Dataset& dataset;
  const std::vector<Camera>* working;

  cv::Mat Fit(int camera, cv::Mat image, bool mask = false) const {
    return working ? ResizeToCamera(image, (*working)[camera], mask) : image;
  }
  cv::Mat Image(int camera, int frame) const { return Fit(camera, dataset.Image(camera, frame)); }
  cv::Mat Gray(int camera, int frame) const { return Fit(camera, dataset.Gray(camera, frame)); }
  cv::Mat Mask(int camera, int frame) const { return Fit(camera, dataset.Mask(camera, frame), true); }
  cv::Mat Background(int camera) const { return Fit(camera, dataset.Background(camera)); }
  cv::Mat BackgroundGray(int camera) const { return Fit(camera, dataset.BackgroundGray(camera)); }
  const Camera& CameraAt(int camera) const { return working ? (*working)[camera] : dataset.camera(camera); }
  int Width(int camera) const { return CameraAt(camera).width(); }
  int Height(int camera) const { return CameraAt(camera).height(); }
  // The pixels that cannot show the object (outside the projected working volume).
  cv::Mat SurelyBackground(int camera, const SilhouetteOptions& options) const {
    const Camera& view = CameraAt(camera);
    return OutsideWorkingVolume(view, dataset.bounds(), options.working_volume_margin * std::hypot(view.width(), view.height()));
  }
};

void CheckWorkingCameras(const Dataset& dataset, const std::vector<Camera>* working) {
  SUBFLOW_CHECK(!working || static_cast<int>(working->size()) == dataset.camera_count(),
                "one working camera per camera of the dataset");
}

}  // namespace

std::vector<EstimatedBackground> EstimateBackgrounds(const Dataset& dataset, const SilhouetteOptions& options,
                                                    const std::vector<Camera>* working) {
  options.Check();
  CheckWorkingCameras(dataset, working);
  const EvidenceImages evidence{dataset, working};
  const int frame_count = dataset.frame_count();
  if (!options.estimate_background || options.source != EvidenceSource::kAuto ||
      frame_count < options.background_estimate_min_frames)
    return {};
  constexpr int kMaxFrames = 64;
  const int used = std::min(frame_count, kMaxFrames);
  std::vector<int> frames(used);
  for (int i = 0; i < used; ++i)
    frames[i] = used == frame_count ? i : static_cast<int>(std::lround(i * (frame_count - 1.0) / (used - 1)));
  const int camera_count = dataset.camera_count();
  std::vector<EstimatedBackground> estimated(camera_count);
  bool any = false;
  for (int c = 0; c < camera_count; ++c) any = any || UsesMotion(dataset, c, options);
  if (!any) return {};
  tbb::parallel_for(0, camera_count, [&](int c) {
    if (!UsesMotion(dataset, c, options)) return;
    std::vector<cv::Mat> images, gray;
    for (int g : frames) {
      images.push_back(evidence.Image(c, g));
      gray.push_back(evidence.Gray(c, g));
    }
    estimated[c] = EstimateBackground(images, gray, options);
  });
  return estimated;
}

Silhouette BackgroundImageSilhouette(const Dataset& dataset, int camera, int frame, const SilhouetteOptions& options,
                                     const std::vector<Camera>* working) {
  const EvidenceImages evidence{dataset, working};
  // Colour when both images have colour (distance in colour separates better), else gray.
  cv::Mat image = evidence.Image(camera, frame), background = evidence.Background(camera);
  if (image.type() != background.type()) {
    image = evidence.Gray(camera, frame);
    background = evidence.BackgroundGray(camera);
  }
  Silhouette silhouette =
      SilhouetteFromBackground(image, background, options, evidence.SurelyBackground(camera, options));
  silhouette.outline = options.background_outlines;
  return silhouette;
}

std::vector<Silhouette> ComputeFrameEvidence(const Dataset& dataset, int frame,
                                             const SilhouetteOptions& options,
                                             const std::vector<EstimatedBackground>* estimated,
                                             const std::vector<Camera>* working) {
  options.Check();
  CheckWorkingCameras(dataset, working);
  const EvidenceImages evidence{dataset, working};
  const std::string& source_name = dataset.directory();
  if (frame < 0 || frame >= dataset.frame_count())
    ThrowError(source_name, "frame",
               "expected a frame in [0, " + std::to_string(dataset.frame_count() - 1) + "], got " +
                   std::to_string(frame));
  if (options.source == EvidenceSource::kMask && !dataset.has_masks())
    ThrowError(source_name, "masks/", "evidence source \"mask\" asked for, but the dataset has no masks");
  if (options.source == EvidenceSource::kStill)
    ThrowError(source_name, "evidence source",
               "\"still\" is photo-consistency over every camera's image, computed by shape initialization "
               "(vision/still_evidence.h), not per camera");
  if (options.source == EvidenceSource::kMotion && dataset.frame_count() < 2)
    ThrowError(source_name, "frame_count",
               "evidence source \"motion\" needs at least 2 frames, the dataset has 1");

  const int camera_count = dataset.camera_count();
  std::vector<EvidenceSource> sources(camera_count, options.source);
  for (int c = 0; c < camera_count; ++c) {
    if (options.source == EvidenceSource::kBackground && !std::filesystem::exists(dataset.BackgroundPath(c)))
      ThrowError(dataset.BackgroundPath(c), "background",
                 "evidence source \"background\" asked for, but this file does not exist");
    if (options.source == EvidenceSource::kAuto) sources[c] = AutomaticSource(dataset, c);
  }

  std::vector<Silhouette> silhouettes(camera_count);
  tbb::parallel_for(0, camera_count, [&](int c) {
    if (sources[c] == EvidenceSource::kMotion && options.source == EvidenceSource::kAuto && estimated != nullptr &&
        c < static_cast<int>(estimated->size()) && (*estimated)[c].valid()) {
      silhouettes[c] = SilhouetteFromEstimatedBackground(evidence.Image(c, frame), (*estimated)[c], options);
      return;
    }
    switch (sources[c]) {
      case EvidenceSource::kMask:
        silhouettes[c] = SilhouetteFromMask(evidence.Mask(c, frame), options);
        break;
      case EvidenceSource::kBackground:
        silhouettes[c] = BackgroundImageSilhouette(dataset, c, frame, options, working);
        break;
      default: {
        if (dataset.frame_count() < 2) {
          Silhouette none = ThresholdAndClean(
              cv::Mat::zeros(evidence.Height(c), evidence.Width(c), CV_32F),
              0.0, options);
          none.source = EvidenceSource::kMotion;
          silhouettes[c] = none;
          break;
        }
        const int first = std::max(0, frame - options.motion_window - 1);
        const int last = std::min(dataset.frame_count() - 1, frame + options.motion_window + 1);
        std::vector<cv::Mat> gray;
        for (int g = first; g <= last; ++g) gray.push_back(evidence.Gray(c, g));
        silhouettes[c] = SilhouetteFromMotion(gray, frame - first, options);
      }
    }
  });

  return silhouettes;
}

std::vector<Silhouette> ComputeSilhouettes(const Dataset& dataset, int frame,
                                           const SilhouetteOptions& options) {
  std::vector<Silhouette> silhouettes = ComputeFrameEvidence(dataset, frame, options);
  const bool all_empty = std::all_of(silhouettes.begin(), silhouettes.end(), [](const Silhouette& silhouette) {
    return silhouette.empty && silhouette.source != EvidenceSource::kMotion;
  });
  if (LacksEvidence(silhouettes))
    ThrowError(dataset.directory(), "frame " + std::to_string(frame),
               all_empty
                   ? "every camera's silhouette is empty: cannot find the object"
                   : "no masks, no background, and no motion: cannot find the object");
  return silhouettes;
}

CarvingResult CarveFrame(const Dataset& dataset, int frame, const SilhouetteOptions& silhouette_options,
                         const VoxelCarvingOptions& carving_options) {
  carving_options.Check();
  const std::vector<Silhouette> silhouettes = ComputeSilhouettes(dataset, frame, silhouette_options);
  return CarveVoxels(dataset.cameras(), silhouettes, dataset.bounds(),
                     ResolveCarvingOptions(dataset.cameras(), dataset.bounds(), carving_options), frame);
}

}  // namespace subflow::vision
