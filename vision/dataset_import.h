// `subflow import`: a calibration (vision/import_*.h) and the cameras' videos or images
// become a dataset in the layout of ../shared/DATASET.md (docs/import.md):
//
//   <out>/cameras.json                 the cameras in metres (when the format has units),
//                                      fps and frame_count, and the working volume
//   <out>/videos/<camera>.<ext>        a link to (or copy of) the camera's video, or
//   <out>/images/<camera>/<frame>.<ext>  links to its images, renamed 000000.<ext>, ...
//
// Frames are never re-encoded. Sizes: a calibrated size equal to the decoded one is kept;
// a decoded size that is the calibrated one times s (the same s on both axes, e.g. a
// binned or downscaled video) rescales K (fx, fy by s; cx' = s (cx + ½) − ½, pixel-centre
// convention); a decoded size within 15 pixels of the calibrated one on each axis (codec
// block padding, cut or added: 1080 against 1088) is the same pixel grid cut or padded at
// the right and bottom edges, K unchanged, with a note; any other size is an error; an
// unknown calibrated size is the decoded one.
//
// Working volume ("bounds"): the one given, else the box of the region that at least
// min_camera_fraction of the cameras see (vision/working_volume.h), clipped to the half
// space above the floor where the format (or `floor`) gives an up axis.
//
// cameras.json is written last (through a temporary file): a directory without it is
// not a dataset, so an interrupted import never looks finished.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "vision/calibration_import.h"
#include "vision/working_volume.h"

namespace subflow::vision {

enum class LinkMode { kSymlink, kHardLink, kCopy };

struct DatasetImportOptions {
  std::string videos;  // folder of one video per camera, or
  std::string images;  // folder of per-camera image folders (or one still per camera)
  std::string name_pattern;  // regex naming the camera in a file name (vision/import_media.h)
  LinkMode link = LinkMode::kSymlink;  // how videos / images enter the dataset
  // Drop the calibration's cameras that have no video / images (listed in the result)
  // instead of failing.
  bool skip_unmatched = false;
  std::optional<int> frames;     // frame_count to write (≤ the frames available); default all
  std::optional<Bounds> bounds;  // the working volume in metres (world units); default derived
  std::string units;             // the calibration's translation unit (m, cm, mm); "" = the format's
  // Up axis whose plane through the origin is the floor: "auto" (the format's, if any),
  // "none", or "+x", "-x", "+y", "-y", "+z", "-z".
  std::string floor = "auto";
  WorkingVolumeOptions working_volume;  // for a derived volume
  bool overwrite = false;  // replace the dataset entries of a non-empty <out>

  void Check() const;  // throws subflow::Error naming the option
};

struct ImportedCameraSummary {
  std::string name;
  int width = 0, height = 0;
  double rescaled = 1;  // s when the calibration was rescaled to the media
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  std::string media;  // the video, or the first image
  int media_frames = 0;
};

struct DatasetImportResult {
  std::vector<ImportedCameraSummary> cameras;
  int frame_count = 0;  // 0 without media
  std::optional<double> fps;
  Bounds bounds;
  std::string bounds_origin;  // how the volume was obtained, one sentence
  std::string units;          // "meters" or "" (no metric scale)
  std::vector<std::string> skipped_cameras;  // without media (skip_unmatched)
  std::vector<std::string> unused_entries;   // media folder entries matching no camera
  std::vector<std::string> notes;            // the calibration's and the import's
};

// Writes the dataset to `out`. Throws subflow::Error naming the file, the field and what
// was expected (malformed calibration, missing or ambiguous media, sizes that disagree,
// an existing non-empty `out` without overwrite, a link that cannot be made).
DatasetImportResult ImportDataset(const Calibration& calibration, const std::string& out,
                                  const DatasetImportOptions& options, Progress* progress = nullptr);

}  // namespace subflow::vision
