#include "vision/dataset_import.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "vision/dataset.h"
#include "vision/dataset_writer.h"
#include "vision/import_media.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

// Video encoders code whole blocks of 16×16 pixels: a 1080-row video is coded as 1088 rows, and
// tools disagree on whether the padding is cut (a Qualisys calibration of 1088 columns, the
// same camera's video re-encoded with 1080).
constexpr int kCodecBlock = 16;

std::string Size(int width, int height) { return std::to_string(width) + "×" + std::to_string(height); }

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// The calibrated size against the decoded one (see the header): the scale s applied to K, or
// 1; `note` says what was assumed when the sizes differ.
double FitSizeToMedia(CalibratedCamera* camera, const CameraMedia& media, std::string* note) {
  if (camera->width <= 0 || camera->height <= 0) {
    camera->width = media.width;
    camera->height = media.height;
    return 1;
  }
  if (camera->width == media.width && camera->height == media.height) return 1;
  const std::string calibrated = Size(camera->width, camera->height), decoded = Size(media.width, media.height);
  const double sx = static_cast<double>(media.width) / camera->width;
  const double sy = static_cast<double>(media.height) / camera->height;
  if (std::abs(sx - sy) > 1e-9) {
    if (std::abs(media.width - camera->width) < kCodecBlock && std::abs(media.height - camera->height) < kCodecBlock) {
      *note = "camera \"" + camera->name + "\": its " + decoded + " frames read as the calibrated " + calibrated +
              " image cut or padded at the right and bottom edges (codec block padding), intrinsics unchanged";
      camera->width = media.width;
      camera->height = media.height;
      return 1;
    }
    const bool rotated = camera->width == media.height && camera->height == media.width;
    ThrowError(media.files.front(), "size",
               "expected " + calibrated + " (calibration of camera \"" + camera->name +
                   "\"), a uniform scaling of it, or it within " + std::to_string(kCodecBlock - 1) +
                   " pixels on each axis (codec padding), got " + decoded +
                   (rotated ? " (rotated by 90°: store the video as calibrated)" : ""));
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = S(1, 1) = sx;
  S(0, 2) = S(1, 2) = 0.5 * sx - 0.5;  // pixel centres: (c + ½) s − ½
  camera->K = S * camera->K;
  camera->width = media.width;
  camera->height = media.height;
  *note = "camera \"" + camera->name + "\": intrinsics scaled by " + std::to_string(sx) + " to its " + decoded +
          " frames";
  return sx;
}

void LinkFile(const fs::path& source, const fs::path& target, LinkMode mode) {
  std::error_code error;
  fs::create_directories(target.parent_path(), error);
  if (error) ThrowError(target.parent_path().string(), "", "cannot create directory: " + error.message());
  switch (mode) {
    case LinkMode::kSymlink: fs::create_symlink(source, target, error); break;
    case LinkMode::kHardLink: fs::create_hard_link(source, target, error); break;
    case LinkMode::kCopy: fs::copy_file(source, target, error); break;
  }
  if (error)
    ThrowError(target.string(), "",
               "cannot " + std::string(mode == LinkMode::kCopy ? "copy" : "link") + " " + source.string() + ": " +
                   error.message() + (mode == LinkMode::kHardLink ? " (across file systems, use --link copy)" : ""));
}

// The up axis of `floor` ("auto" → the calibration's), or none.
std::optional<Eigen::Vector3d> UpAxis(const std::string& floor, const Calibration& calibration) {
  if (floor == "none") return std::nullopt;
  if (floor == "auto") return calibration.up;
  const int axis = floor[1] - 'x';
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  up[axis] = floor[0] == '-' ? -1 : 1;
  return up;
}

Bounds DeriveBounds(const std::vector<Camera>& cameras, const DatasetImportOptions& options,
                    const Calibration& calibration, const std::string& source, std::string* origin) {
  Bounds box = EstimateWorkingVolume(cameras, options.working_volume, source);
  std::ostringstream text;
  text.precision(3);
  text << "seen by at least " << std::max(2, static_cast<int>(std::ceil(options.working_volume.min_camera_fraction *
                                                                        cameras.size())))
       << " of the " << cameras.size() << " cameras";
  const std::optional<Eigen::Vector3d> up = UpAxis(options.floor, calibration);
  if (up) {
    int axis = 0;
    up->cwiseAbs().maxCoeff(&axis);
    if (std::abs((*up)[axis]) == 1 && up->cwiseAbs().sum() == 1) {
      const char* names = "xyz";
      if ((*up)[axis] > 0) box.min[axis] = std::max(box.min[axis], 0.0);
      else box.max[axis] = std::min(box.max[axis], 0.0);
      if (!box.IsValid())
        ThrowError(source, "bounds", std::string("the volume the cameras see lies below the floor ") +
                                         ((*up)[axis] > 0 ? "+" : "-") + names[axis] +
                                         " = 0 (give --bounds or --floor none)");
      text << ", above the floor (" << ((*up)[axis] > 0 ? "+" : "-") << names[axis] << " up, floor at 0)";
    }
  }
  *origin = text.str();
  return box;
}

// The frame count every camera has (or --frames) and the common frame rate of videos, in
// `result`, with a note when the cameras differ in length.
void CountFrames(const std::vector<CameraMedia>& media, const DatasetImportOptions& options,
                 DatasetImportResult* result) {
  int available = media.front().frame_count, most = available;
  for (const CameraMedia& m : media) {
    if (m.frame_count <= 0)
      ThrowError(m.files.front(), "frame count", "unknown (the container does not report it)");
    available = std::min(available, m.frame_count);
    most = std::max(most, m.frame_count);
  }
  if (most != available)
    result->notes.push_back("cameras have " + std::to_string(available) + " to " + std::to_string(most) +
                            " frames; the first " + std::to_string(available) + " are used");
  if (options.frames && *options.frames > available)
    ThrowError("--frames", "", "expected at most the " + std::to_string(available) + " frames every camera has, got " +
                                   std::to_string(*options.frames));
  result->frame_count = options.frames ? *options.frames : available;
  if (media.front().video) {
    const double fps = media.front().fps;
    bool same = fps > 0;
    for (const CameraMedia& m : media) same = same && std::abs(m.fps - fps) <= 1e-3 * fps;
    if (same) result->fps = fps;
  }
}

}  // namespace

void DatasetImportOptions::Check() const {
  if (!videos.empty() && !images.empty())
    ThrowError("--videos / --images", "", "expected one source of frames, got both");
  if (frames && *frames <= 0) ThrowError("--frames", "", "expected a positive frame count, got " + std::to_string(*frames));
  if (bounds && !bounds->IsValid()) ThrowError("--bounds", "", "expected finite min < max on every axis");
  if (!units.empty()) MetresPerUnit(units, "--units");
  static const char* const kFloors[] = {"auto", "none", "+x", "-x", "+y", "-y", "+z", "-z"};
  if (std::find(std::begin(kFloors), std::end(kFloors), floor) == std::end(kFloors))
    ThrowError("--floor", "", "expected auto, none, +x, -x, +y, -y, +z or -z, got \"" + floor + "\"");
  working_volume.Check();
}

DatasetImportResult ImportDataset(const Calibration& source_calibration, const std::string& out,
                                  const DatasetImportOptions& options, Progress* progress) {
  options.Check();
  Calibration calibration = source_calibration;
  CheckCameraNames(calibration, calibration.format);
  DatasetImportResult result;
  result.notes = calibration.notes;
  const std::string units = options.units.empty() ? calibration.units : options.units;
  const double metres_per_unit = units.empty() ? 1.0 : MetresPerUnit(units, "--units");
  result.units = units.empty() ? "" : "meters";
  if (!options.units.empty() && !calibration.units.empty() && options.units != calibration.units)
    result.notes.push_back("translations read in " + options.units + " (--units), not the format's " + calibration.units);

  // Media, matched to the cameras; sizes reconciled.
  std::vector<CameraMedia> media;
  const bool has_media = !options.videos.empty() || !options.images.empty();
  ProgressBegin(progress, "probing videos / images", calibration.cameras.size());
  if (has_media) {
    MediaSearch search = FindCameraMedia(calibration, options.videos, options.images, options.name_pattern);
    result.unused_entries = search.unused;
    std::vector<CalibratedCamera> kept;
    std::string missing;
    for (std::size_t c = 0; c < calibration.cameras.size(); ++c) {
      if (search.media[c].files.empty()) {
        result.skipped_cameras.push_back(calibration.cameras[c].name);
        missing += (missing.empty() ? "" : ", ") + calibration.cameras[c].name;
        continue;
      }
      kept.push_back(calibration.cameras[c]);
      media.push_back(search.media[c]);
    }
    if (!missing.empty() && !options.skip_unmatched) {
      std::string unused;
      for (const std::string& entry : search.unused) unused += (unused.empty() ? "" : ", ") + entry;
      ThrowError(options.videos.empty() ? options.images : options.videos, "",
                 "no " + std::string(options.videos.empty() ? "images" : "video") + " for camera(s) " + missing +
                     (unused.empty() ? "" : " (entries matching no camera: " + unused + ")") +
                     "; expected one per camera (see --name-pattern, --skip-unmatched)");
    }
    calibration.cameras = kept;
    if (calibration.cameras.empty()) ThrowError(calibration.format, "cameras", "none left with media");
  }
  std::vector<double> rescaled(calibration.cameras.size(), 1.0);
  for (std::size_t c = 0; c < media.size(); ++c) {
    std::string note;
    rescaled[c] = FitSizeToMedia(&calibration.cameras[c], media[c], &note);
    if (!note.empty()) result.notes.push_back(note);
    ProgressUpdate(progress, c + 1);
  }
  ProgressEnd(progress);
  const std::vector<Camera> cameras = ToCameras(calibration, metres_per_unit);

  if (has_media) CountFrames(media, options, &result);

  // Working volume.
  if (options.bounds) {
    result.bounds = *options.bounds;
    result.bounds_origin = "given (--bounds)";
  } else {
    result.bounds = DeriveBounds(cameras, options, calibration, calibration.format, &result.bounds_origin);
  }

  // The dataset: frames linked first, cameras.json last.
  PrepareDatasetDirectory(out, options.overwrite);
  const fs::path root(out);
  ProgressBegin(progress, "linking frames", media.size());
  for (std::size_t c = 0; c < media.size(); ++c) {
    const CameraMedia& m = media[c];
    if (m.video) {
      LinkFile(m.files.front(), root / "videos" / (cameras[c].name() + Lower(fs::path(m.files.front()).extension().string())),
               options.link);
    } else {
      for (int f = 0; f < result.frame_count; ++f)
        LinkFile(m.files[f], root / "images" / cameras[c].name() / (FrameName(f) + Lower(fs::path(m.files[f]).extension().string())),
                 options.link);
    }
    ProgressUpdate(progress, c + 1);
  }
  ProgressEnd(progress);
  WriteCamerasJson((root / "cameras.json").string(), cameras, result.fps,
                   has_media ? std::optional<int>(result.frame_count) : std::nullopt, result.bounds, result.units);

  for (std::size_t c = 0; c < cameras.size(); ++c) {
    ImportedCameraSummary summary;
    summary.name = cameras[c].name();
    summary.width = cameras[c].width();
    summary.height = cameras[c].height();
    summary.rescaled = rescaled[c];
    summary.centre = cameras[c].Center();
    if (c < media.size()) {
      summary.media = media[c].files.front();
      summary.media_frames = media[c].frame_count;
    }
    result.cameras.push_back(summary);
  }
  return result;
}

}  // namespace subflow::vision
