#include "vision/image_sequence.h"

#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "vision/dataset.h"
#include "vision/working_scale.h"
#include "vision/zbuffer.h"

namespace subflow::vision {

void ImageSequence::Check(const std::string& stage) const {
  if (cameras.empty()) ThrowError(stage, "cameras", "needs at least one camera");
  if (frame_count < 1) ThrowError(stage, "frames", "needs at least one frame");
  if (!gray) ThrowError(stage, "gray images", "no image loader given");
}

namespace {

// Silhouettes computed from a background image (a shadow-robust difference: ~20 ms a
// camera at 320×240), kept so that each is computed once per sequence, not once per
// refinement level, round and chain. Kept PNG-compressed (a binary mask of 320×240 takes a
// few KB) up to a byte budget; past it the oldest go first, so a long take costs bounded
// memory and only recomputes.
class SilhouetteMemo {
 public:
  explicit SilhouetteMemo(std::size_t budget_bytes) : budget_(budget_bytes) {}

  cv::Mat Get(int camera, int frame, const std::function<cv::Mat()>& compute) {
    const std::pair<int, int> key(camera, frame);
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      const auto it = png_.find(key);
      if (it != png_.end()) return cv::imdecode(it->second, cv::IMREAD_UNCHANGED);
    }
    cv::Mat mask = compute();  // outside the lock: other cameras' in parallel
    std::vector<uchar> png;
    if (mask.empty() || !cv::imencode(".png", mask, png) || png.size() > budget_) return mask;
    const std::lock_guard<std::mutex> lock(mutex_);
    if (png_.count(key)) return mask;  // computed meanwhile by another thread, the same
    while (bytes_ + png.size() > budget_ && !order_.empty()) {
      bytes_ -= png_[order_.front()].size();
      png_.erase(order_.front());
      order_.pop_front();
    }
    bytes_ += png.size();
    order_.push_back(key);
    png_.emplace(key, std::move(png));
    return mask;
  }

 private:
  std::mutex mutex_;
  std::map<std::pair<int, int>, std::vector<uchar>> png_;
  std::deque<std::pair<int, int>> order_;  // first kept first
  std::size_t bytes_ = 0;
  const std::size_t budget_;
};

constexpr std::size_t kSilhouetteMemoBytes = std::size_t{64} << 20;

}  // namespace

cv::Mat Undistorted(const Camera& camera, const cv::Mat& image, int interpolation) {
  return camera.HasDistortion() ? camera.UndistortImage(image, interpolation) : image;
}

ImageSequence DatasetImages(const Dataset& dataset, int first_frame, int frame_count,
                            EvidenceSource evidence, const std::vector<geometry::TriangleMesh>* hulls,
                            const std::vector<Camera>* working, const std::vector<cv::Mat>* outlines,
                            const SilhouetteOptions* background_outlines) {
  if (first_frame < 0 || frame_count < 1 || first_frame + frame_count > dataset.frame_count())
    ThrowError(dataset.directory(), "frames",
               "window [" + std::to_string(first_frame) + ", " + std::to_string(first_frame + frame_count) +
                   ") is not inside the dataset's " + std::to_string(dataset.frame_count()) + " frames");
  if (hulls && static_cast<int>(hulls->size()) != frame_count)
    ThrowError(dataset.directory(), "hulls",
               std::to_string(hulls->size()) + " visual hulls for " + std::to_string(frame_count) + " frames");
  SUBFLOW_CHECK(!working || static_cast<int>(working->size()) == dataset.camera_count(),
                "one working camera per camera of the dataset");
  if (outlines && outlines->empty()) outlines = nullptr;
  if (outlines && static_cast<int>(outlines->size()) != dataset.camera_count())
    ThrowError(dataset.directory(), "outlines",
               std::to_string(outlines->size()) + " outlines for " + std::to_string(dataset.camera_count()) +
                   " cameras");
  ImageSequence sequence;
  sequence.cameras = working ? *working : dataset.cameras();
  sequence.first_frame = first_frame;
  sequence.frame_count = frame_count;
  const std::vector<Camera> cameras = sequence.cameras;
  sequence.gray = [&dataset, first_frame, cameras](int camera, int frame) {
    const Camera& working_camera = cameras[camera];
    return Undistorted(working_camera, ResizeToCamera(dataset.Gray(camera, first_frame + frame), working_camera),
                       cv::INTER_LINEAR);
  };
  std::vector<bool> masks(dataset.camera_count()), backgrounds(dataset.camera_count());
  sequence.tight_outline.resize(dataset.camera_count());
  for (int k = 0; k < dataset.camera_count(); ++k) {
    const EvidenceSource source = evidence == EvidenceSource::kAuto ? AutomaticSource(dataset, k) : evidence;
    masks[k] = source == EvidenceSource::kMask;
    backgrounds[k] = background_outlines && source == EvidenceSource::kBackground;
    sequence.tight_outline[k] = masks[k] || backgrounds[k] || (outlines && !(*outlines)[k].empty());
  }
  std::optional<SilhouetteOptions> background_options;
  if (background_outlines) background_options = *background_outlines;
  const auto memo = std::make_shared<SilhouetteMemo>(kSilhouetteMemoBytes);
  sequence.silhouette = [&dataset, first_frame, hulls, masks, cameras, outlines, backgrounds, background_options,
                         memo](int camera, int frame) {
    const Camera& working_camera = cameras[camera];
    if (masks[camera])
      return Undistorted(working_camera,
                         ResizeToCamera(dataset.Mask(camera, first_frame + frame), working_camera, true),
                         cv::INTER_NEAREST);
    if (backgrounds[camera])
      return memo->Get(camera, frame, [&] {
        const Silhouette silhouette = BackgroundImageSilhouette(dataset, camera, first_frame + frame, *background_options);
        return Undistorted(working_camera, ResizeToCamera(silhouette.mask, working_camera, true), cv::INTER_NEAREST);
      });
    if (outlines && !(*outlines)[camera].empty())
      return Undistorted(working_camera, ResizeToCamera((*outlines)[camera], working_camera, true),
                         cv::INTER_NEAREST);
    if (!hulls || (*hulls)[frame].F.rows() == 0) return cv::Mat();
    const geometry::TriangleMesh& hull = (*hulls)[frame];
    return ZBuffer(working_camera, hull.V, hull.F).Mask();
  };
  return sequence;
}

}  // namespace subflow::vision
