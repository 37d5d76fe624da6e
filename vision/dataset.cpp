// Dataset: opening and validating the layout of ../shared/DATASET.md, and lazy, cached
// access to its frames. The layout checks live in dataset_layout.cpp.
#include "vision/dataset.h"

#include <cstdio>
#include <filesystem>
#include <list>
#include <map>
#include <mutex>
#include <tuple>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "vision/dataset_layout.h"

namespace subflow::vision {
namespace {

enum class Kind { kImage, kGray, kMask, kBackground, kBackgroundGray };

using Key = std::tuple<int, int, int>;  // kind, camera, frame

// CV_32FC1 in [0, 1] from an 8/16-bit, 1/3/4-channel image.
cv::Mat ToGray(const cv::Mat& raw) {
  const double scale = raw.depth() == CV_16U ? 1.0 / 65535.0 : 1.0 / 255.0;
  cv::Mat as_float;
  raw.convertTo(as_float, CV_MAKETYPE(CV_32F, raw.channels()), scale);
  if (raw.channels() == 1) return as_float;
  cv::Mat gray;
  cv::cvtColor(as_float, gray, raw.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

cv::Mat ToMask(const cv::Mat& raw) {
  std::vector<cv::Mat> channels;
  cv::split(raw, channels);
  cv::Mat any = channels[0] != 0;  // CV_8U 0 / 255
  for (int c = 1; c < std::min(3, raw.channels()); ++c) any |= (channels[c] != 0);
  return any;
}

}  // namespace

struct Dataset::State {
  DatasetLayout layout;
  Bounds bounds;
  DatasetOptions options;

  // LRU cache of decoded images: front = most recently used.
  std::mutex cache_mutex;
  std::list<std::pair<Key, cv::Mat>> lru;
  std::map<Key, std::list<std::pair<Key, cv::Mat>>::iterator> index;

  // Per video, two decoders: a pass that walks the frames backwards (motion
  // initialization's chain before the reference frame) or two passes at once (both chains
  // run side by side) would otherwise seek the one decoder back and forth, and a seek
  // decodes from the previous key frame (real captures may have one key frame per take).
  struct VideoReader {
    struct Decoder {
      cv::VideoCapture capture;
      int next_frame = -1;  // frame the capture will return on the next read(); -1 = not open
      long last_used = 0;
    };
    static constexpr int kDecoders = 2;
    std::mutex mutex;
    Decoder decoders[kDecoders];
    long reads = 0;
  };
  std::vector<std::unique_ptr<VideoReader>> videos;

  std::size_t Capacity() const {
    return static_cast<std::size_t>(options.cache_frames) * layout.cameras.size();
  }

  bool Lookup(const Key& key, cv::Mat* out) {
    std::lock_guard<std::mutex> lock(cache_mutex);
    auto it = index.find(key);
    if (it == index.end()) return false;
    lru.splice(lru.begin(), lru, it->second);
    *out = it->second->second;
    return true;
  }

  void Insert(const Key& key, const cv::Mat& value) {
    if (Capacity() == 0) return;
    std::lock_guard<std::mutex> lock(cache_mutex);
    if (index.count(key)) return;  // another thread decoded it meanwhile
    lru.emplace_front(key, value);
    index[key] = lru.begin();
    while (lru.size() > Capacity()) {
      index.erase(lru.back().first);
      lru.pop_back();
    }
  }

  // Decodes through the cache; `decode` runs outside the lock.
  template <typename Decode>
  cv::Mat Get(Kind kind, int camera, int frame, Decode decode) {
    const Key key(static_cast<int>(kind), camera, frame);
    cv::Mat value;
    if (Lookup(key, &value)) return value;
    value = decode();
    Insert(key, value);
    return value;
  }

  cv::Mat ReadVideoFrame(int camera, int frame) {
    VideoReader& reader = *videos[camera];
    const std::string& path = layout.video_paths[camera];
    std::lock_guard<std::mutex> lock(reader.mutex);
    // Seeking may be slow and inexact for some codecs (it decodes from the previous key
    // frame); a short step forward (a subsampled pass over the video) skips frames
    // without converting them instead. The decoder that reaches `frame` by the shortest
    // such step reads it; if none can, the least recently used one seeks.
    constexpr int kMaxForwardSkip = 64;
    VideoReader::Decoder* chosen = nullptr;
    for (VideoReader::Decoder& decoder : reader.decoders) {
      const bool reaches = decoder.next_frame >= 0 && decoder.next_frame <= frame &&
                           frame - decoder.next_frame <= kMaxForwardSkip;
      if (reaches && (!chosen || decoder.next_frame > chosen->next_frame)) chosen = &decoder;
    }
    if (!chosen) {
      chosen = &reader.decoders[0];
      for (VideoReader::Decoder& decoder : reader.decoders)
        if (decoder.last_used < chosen->last_used) chosen = &decoder;
    }
    VideoReader::Decoder& decoder = *chosen;
    decoder.last_used = ++reader.reads;
    if (decoder.next_frame < 0) {
      if (!decoder.capture.open(path))
        ThrowError(path, "", "cannot open video (expected a file OpenCV's VideoCapture reads)");
      decoder.next_frame = 0;
    }
    while (decoder.next_frame < frame && frame - decoder.next_frame <= kMaxForwardSkip) {
      if (!decoder.capture.grab()) break;
      ++decoder.next_frame;
    }
    if (decoder.next_frame != frame) {
      decoder.capture.set(cv::CAP_PROP_POS_FRAMES, frame);
      decoder.next_frame = frame;
    }
    cv::Mat image;
    if (!decoder.capture.read(image) || image.empty()) {
      decoder.next_frame = -1;
      decoder.capture.release();
      ThrowError(path, "frame " + std::to_string(frame), "could not be decoded");
    }
    decoder.next_frame = frame + 1;
    return image;
  }
};

Dataset::Dataset(const std::string& directory, const DatasetOptions& options)
    : state_(std::make_unique<State>()) {
  options.Check();
  state_->options = options;
  state_->layout = ScanDatasetLayout(directory, options.check_image_headers);
  const DatasetLayout& layout = state_->layout;
  for (const std::string& warning : layout.warnings) spdlog::warn("{}: {}", directory, warning);
  if (layout.info.bounds) {
    state_->bounds = *layout.info.bounds;
  } else {
    state_->bounds = EstimateWorkingVolume(layout.cameras, options.working_volume, layout.cameras_path);
  }
  state_->videos.resize(layout.cameras.size());
  for (auto& reader : state_->videos) reader = std::make_unique<State::VideoReader>();
}

Dataset::~Dataset() = default;
Dataset::Dataset(Dataset&&) noexcept = default;
Dataset& Dataset::operator=(Dataset&&) noexcept = default;

void DatasetOptions::Check() const {
  if (cache_frames < 0)
    ThrowError("DatasetOptions", "cache_frames", "expected ≥ 0, got " + std::to_string(cache_frames));
  working_volume.Check();
}

const std::string& Dataset::directory() const { return state_->layout.directory; }
const std::vector<Camera>& Dataset::cameras() const { return state_->layout.cameras; }
int Dataset::camera_count() const { return static_cast<int>(state_->layout.cameras.size()); }
int Dataset::frame_count() const { return state_->layout.frame_count; }
std::optional<double> Dataset::fps() const { return state_->layout.info.fps; }
const std::string& Dataset::units() const { return state_->layout.info.units; }
const Bounds& Dataset::bounds() const { return state_->bounds; }
bool Dataset::bounds_from_file() const { return state_->layout.info.bounds.has_value(); }
bool Dataset::has_videos() const { return state_->layout.videos; }
bool Dataset::has_masks() const { return state_->layout.masks; }
bool Dataset::has_background() const { return state_->layout.background; }
bool Dataset::has_groundtruth() const { return state_->layout.groundtruth; }
const std::vector<std::string>& Dataset::warnings() const { return state_->layout.warnings; }

const Camera& Dataset::camera(int camera) const {
  state_->layout.CheckIndex(camera, 0);
  return state_->layout.cameras[camera];
}

int Dataset::CameraIndex(const std::string& name) const {
  const auto& cameras = state_->layout.cameras;
  for (std::size_t i = 0; i < cameras.size(); ++i)
    if (cameras[i].name() == name) return static_cast<int>(i);
  return -1;
}

std::string Dataset::ImagePath(int camera, int frame) const {
  state_->layout.CheckIndex(camera, frame);
  return state_->layout.ImagePath(camera, frame);
}

std::string Dataset::MaskPath(int camera, int frame) const {
  state_->layout.CheckIndex(camera, frame);
  return state_->layout.MaskPath(camera, frame);
}

std::string Dataset::BackgroundPath(int camera) const {
  state_->layout.CheckIndex(camera, 0);
  return state_->layout.BackgroundPath(camera);
}

std::string Dataset::GroundTruthMeshPath(int frame) const {
  state_->layout.CheckIndex(0, frame);
  if (!state_->layout.groundtruth)
    ThrowError(state_->layout.directory, "groundtruth/mesh",
               "absent (expected groundtruth/mesh/<frame>.ply for evaluation)");
  return state_->layout.GroundTruthMeshPath(frame);
}

cv::Mat Dataset::Image(int camera, int frame) const {
  const DatasetLayout& layout = state_->layout;
  layout.CheckIndex(camera, frame);
  return state_
      ->Get(Kind::kImage, camera, frame,
            [&] {
              if (!layout.videos) return ReadImageFile(layout.ImagePath(camera, frame), layout.cameras[camera]);
              cv::Mat image = state_->ReadVideoFrame(camera, frame);
              CheckImageSize(image, layout.cameras[camera],
                             layout.video_paths[camera] + ": frame " + std::to_string(frame));
              return image;
            })
      .clone();
}

cv::Mat Dataset::Gray(int camera, int frame) const {
  state_->layout.CheckIndex(camera, frame);
  return state_->Get(Kind::kGray, camera, frame, [&] { return ToGray(Image(camera, frame)); }).clone();
}

cv::Mat Dataset::Mask(int camera, int frame) const {
  const DatasetLayout& layout = state_->layout;
  layout.CheckIndex(camera, frame);
  if (!layout.masks)
    ThrowError(layout.directory, "masks", "absent (expected masks/<camera>/<frame>.png)");
  return state_
      ->Get(Kind::kMask, camera, frame,
            [&] { return ToMask(ReadImageFile(layout.MaskPath(camera, frame), layout.cameras[camera])); })
      .clone();
}

cv::Mat Dataset::Background(int camera) const {
  const DatasetLayout& layout = state_->layout;
  layout.CheckIndex(camera, 0);
  if (!layout.background)
    ThrowError(layout.directory, "background", "absent (expected background/<camera>.png)");
  return state_
      ->Get(Kind::kBackground, camera, -1,
            [&] { return ReadImageFile(layout.BackgroundPath(camera), layout.cameras[camera]); })
      .clone();
}

cv::Mat Dataset::BackgroundGray(int camera) const {
  return state_->Get(Kind::kBackgroundGray, camera, -1, [&] { return ToGray(Background(camera)); }).clone();
}

void Dataset::ClearCache() const {
  std::lock_guard<std::mutex> lock(state_->cache_mutex);
  state_->lru.clear();
  state_->index.clear();
}

std::string FrameName(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d", frame);
  return name;
}

}  // namespace subflow::vision
