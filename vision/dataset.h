// A multi-view video dataset in the layout of ../shared/DATASET.md (version 1):
//
//   <dataset>/cameras.json                  cameras (see vision/camera.h for the convention)
//   <dataset>/images/<camera>/<frame>.png   or  <dataset>/videos/<camera>.<ext>
//   <dataset>/masks/<camera>/<frame>.png    optional, non-zero = object
//   <dataset>/background/<camera>.png       optional, the empty scene
//   <dataset>/groundtruth/mesh/<frame>.ply  optional, evaluation only
//
// <frame> is the zero-based index with six digits (000000.png). Cameras are indexed
// 0..camera_count()-1 in the order of cameras.json; frames 0..frame_count()-1.
//
// Opening validates the whole layout (cameras.json fields, folder names, every camera
// having every frame, PNG headers' sizes) and throws subflow::Error naming the file, the
// field and what was expected. Pixels are read lazily: Image/Gray/Mask decode on demand
// and keep the most recently used ones in a bounded LRU cache (DatasetOptions), so
// memory grows with the window of frames in use, not with the sequence.
//
// Thread safety: all const member functions may be called concurrently from several
// threads (the cache and the video readers are guarded by mutexes inside the Dataset).
// Returned cv::Mat are deep copies owned by the caller.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/camera.h"
#include "vision/working_volume.h"

namespace subflow::vision {

inline constexpr const char* kDatasetFormat = "multiview-video/1";
// The most frames a dataset may have (frame_count, a video's reported count): ~9 hours at
// 30 fps. Larger counts are refused before anything per frame is allocated.
inline constexpr int kMaxFrameCount = 1000000;

struct DatasetOptions {
  // Decoded images held in memory, counted in frames: at most cache_frames × camera_count
  // entries (an entry = one camera's image, gray image or mask at one frame). 0 disables
  // the cache.
  int cache_frames = 4;
  // Read every PNG header at Open() to check each frame's size against its camera (cheap:
  // 24 bytes per file), so a wrong-sized frame is reported before any work starts. Images
  // are always checked again when decoded.
  bool check_image_headers = true;
  // Used only when cameras.json has no "bounds".
  WorkingVolumeOptions working_volume;

  void Check() const;  // throws subflow::Error on nonsense
};

// Fields of cameras.json besides the cameras.
struct DatasetInfo {
  std::optional<double> fps;
  std::optional<int> frame_count;
  std::optional<Bounds> bounds;
  std::string units;  // "" when absent
};

// Parses and validates cameras.json (format "multiview-video/1"). Every camera needs
// name (unique, non-empty, no '/'), width, height (positive integers), K (3×3), R (3×3
// near-rotation, re-orthonormalized: vision/rotation.h), t (3-vector); "distortion" is
// optional with 0, 4 (k1 k2 p1 p2), 5 (k1 k2 p1 p2 k3) or 8 (OpenCV's rational model k1 k2
// p1 p2 k3 k4 k5 k6) values, or 4 (k1 k2 k3 k4) with "distortion_model": "fisheye"
// (docs/dataset.md: extensions of the layout). Optional: fps
// (> 0), frame_count (positive integer), units (string), bounds ({min: [3], max: [3]},
// min < max). Unknown top-level or camera keys are errors.
std::vector<Camera> ReadCamerasJson(const std::string& path, DatasetInfo* info = nullptr);

class Dataset {
 public:
  // Opens and validates the dataset in `directory` (see the file comment).
  explicit Dataset(const std::string& directory, const DatasetOptions& options = {});
  ~Dataset();
  Dataset(Dataset&&) noexcept;
  Dataset& operator=(Dataset&&) noexcept;
  Dataset(const Dataset&) = delete;
  Dataset& operator=(const Dataset&) = delete;

  const std::string& directory() const;
  const std::vector<Camera>& cameras() const;
  const Camera& camera(int camera) const;
  int camera_count() const;
  int frame_count() const;
  // Index of the camera called `name`, or -1.
  int CameraIndex(const std::string& name) const;
  std::optional<double> fps() const;
  const std::string& units() const;  // "" when cameras.json has none
  // cameras.json's bounds, or the derived working volume (EstimateWorkingVolume).
  const Bounds& bounds() const;
  bool bounds_from_file() const;

  bool has_videos() const;  // frames come from videos/<camera>.<ext> instead of images/
  bool has_masks() const;
  bool has_background() const;
  bool has_groundtruth() const;
  // What the layout check found legal but worth saying (pixel formats that differ between
  // cameras or within a camera's frames, 16-bit data); each was also logged as a warning
  // when the dataset was opened.
  const std::vector<std::string>& warnings() const;

  // Raw frame as stored (cv::imread IMREAD_UNCHANGED): CV_8U or CV_16U, 1, 3 (BGR) or 4
  // (BGRA) channels; from a video, what VideoCapture decodes (usually CV_8UC3). Size is
  // camera(c).width() × height(). Throws subflow::Error naming the file when it is
  // unreadable or of another size, or when `camera`/`frame` are out of range.
  cv::Mat Image(int camera, int frame) const;
  // The frame as CV_32FC1 intensities in [0, 1]: 8-bit / 255, 16-bit / 65535; colour
  // converted with OpenCV's BGR→gray weights (0.114 B + 0.587 G + 0.299 R).
  cv::Mat Gray(int camera, int frame) const;
  // CV_8UC1 silhouette: 255 where the mask file is non-zero (any colour channel), else 0.
  // Throws when the dataset has no masks.
  cv::Mat Mask(int camera, int frame) const;
  // Raw background image (as Image) and its gray version (as Gray). Throw when absent.
  cv::Mat Background(int camera) const;
  cv::Mat BackgroundGray(int camera) const;

  // Paths of the files (whether or not they exist, for messages and writers).
  std::string ImagePath(int camera, int frame) const;  // images/<cam>/<frame>.png or the video
  std::string MaskPath(int camera, int frame) const;
  std::string BackgroundPath(int camera) const;
  // groundtruth/mesh/<frame>.ply; read it with geometry::ReadMesh. Throws when absent.
  std::string GroundTruthMeshPath(int frame) const;

  // Drops every cached image (e.g. after moving to another window of frames).
  void ClearCache() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// "000042" for frame 42: the six-digit frame name of the layout.
std::string FrameName(int frame);

}  // namespace subflow::vision
