// Writing a synthetic dataset (vision/synthetic_render.h's WriteSyntheticDataset).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <tbb/parallel_for.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/vertex_normals.h"
#include "vision/dataset_writer.h"
#include "vision/synthetic_render.h"

namespace subflow::vision {
namespace {

std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b) {
  std::uint64_t h = a * 0x9E3779B97F4A7C15ull + b + 0x632BE59BD9B4E019ull;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  return h;
}

}  // namespace

void SynthOptions::Check() const {
  scene.Check();
  rig.Check();
  render.Check();
  for (int c : colour_cameras)
    if (c < 0 || c >= rig.camera_count)
      ThrowError("synth", "color-cameras",
                 "camera index " + std::to_string(c) + " out of range 0.." + std::to_string(rig.camera_count - 1));
  if (colour_every < 0) ThrowError("synth", "color-every", "expected ≥ 0");
  if (!(fps > 0.0) || !std::isfinite(fps)) ThrowError("synth", "fps", "expected > 0");
  if (!(bounds_margin >= 0.0) || !std::isfinite(bounds_margin))
    ThrowError("synth", "bounds_margin", "expected ≥ 0");
  environment.Check();
  if (!distortion.empty() && distortion.size() != 5)
    ThrowError("synth", "distortion", "expected 5 values k1,k2,p1,p2,k3, got " + std::to_string(distortion.size()));
  for (double k : distortion)
    if (!std::isfinite(k) || std::abs(k) > 2.0) ThrowError("synth", "distortion", "expected finite values in [-2, 2]");
  if (!video.empty() && video != "mp4") ThrowError("synth", "video", "expected mp4 (or none), got \"" + video + "\"");
}

bool SynthOptions::IsColourCamera(int camera) const {
  if (colour_every > 0) return camera % colour_every == 0;
  return std::find(colour_cameras.begin(), colour_cameras.end(), camera) != colour_cameras.end();
}

namespace {

// The rig's cameras with the requested lens distortion.
std::vector<Camera> WithDistortion(const std::vector<Camera>& cameras, const std::vector<double>& distortion) {
  if (distortion.empty()) return cameras;
  Eigen::VectorXd k = Eigen::Map<const Eigen::VectorXd>(distortion.data(), static_cast<Eigen::Index>(distortion.size()));
  std::vector<Camera> distorted;
  for (const Camera& c : cameras) distorted.emplace_back(c.name(), c.width(), c.height(), c.K(), c.R(), c.t(), k, "synth");
  return distorted;
}

// videos/<cam>.mp4 written frame by frame under a temporary name, renamed by Finish().
class VideoFiles {
 public:
  VideoFiles(const std::string& directory, const std::vector<Camera>& cameras, double fps) {
    namespace fs = std::filesystem;
    fs::create_directories(fs::path(directory) / "videos");
    for (const Camera& camera : cameras) {
      const fs::path final_path = fs::path(directory) / "videos" / (camera.name() + ".mp4");
      files_.push_back(std::make_unique<AtomicFile>(final_path.string(), AtomicFile::kKeepExtension));
      writers_.emplace_back(files_.back()->temporary(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps,
                            cv::Size(camera.width(), camera.height()), true);
      if (!writers_.back().isOpened())
        ThrowError(final_path.string(), "video", "OpenCV cannot write MP4 (mp4v) here");
    }
  }
  void Write(int camera, const cv::Mat& image) {
    cv::Mat bgr = image;
    if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
    writers_[camera].write(bgr);
  }
  void Finish(const std::string& directory) {
    namespace fs = std::filesystem;
    for (std::size_t c = 0; c < writers_.size(); ++c) {
      writers_[c].release();
      files_[c]->Commit();
    }
    // DatasetWriter made images/<cam>/ for PNG frames: a dataset has one source of frames.
    const fs::path images = fs::path(directory) / "images";
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(images, error)) fs::remove(entry.path(), error);
    fs::remove(images, error);
  }

 private:
  std::vector<std::unique_ptr<AtomicFile>> files_;  // removed unless committed
  std::vector<cv::VideoWriter> writers_;
};

}  // namespace

SynthSummary WriteSyntheticDataset(const std::string& directory, const SynthOptions& options,
                                   Progress* progress) {
  const Stopwatch stopwatch;
  options.Check();
  const SyntheticScene scene = MakeSyntheticScene(options.scene, progress);

  SynthSummary summary;
  summary.frame_count = scene.frame_count();
  summary.vertex_count = static_cast<int>(scene.rest.rows());
  summary.face_count = static_cast<int>(scene.F.rows());
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const geometry::Positions& V : scene.frames) {
    low = low.cwiseMin(V.colwise().minCoeff().transpose());
    high = high.cwiseMax(V.colwise().maxCoeff().transpose());
  }
  const Eigen::Vector3d margin = options.bounds_margin * (high - low);
  summary.bounds.min = low - margin;
  summary.bounds.max = high + margin;

  const std::vector<Camera> cameras =
      WithDistortion(MakeCameraRig(options.rig, 0.5 * (low + high)), options.distortion);
  summary.camera_count = static_cast<int>(cameras.size());
  DatasetInfo info;
  info.fps = options.fps;
  info.frame_count = scene.frame_count();
  info.bounds = summary.bounds;
  info.units = "meters";
  const DatasetWriter writer(directory, cameras, info, options.overwrite);
  std::optional<VideoFiles> videos;
  if (options.video == "mp4") videos.emplace(directory, cameras, options.fps);

  SyntheticRenderOptions render_options = options.render;
  render_options.albedo.seed = options.seed;
  const SyntheticRenderer renderer(render_options);
  const SyntheticEnvironment environment(options.environment, low, high, cameras, options.rig.distance);
  const int camera_count = summary.camera_count, frame_count = summary.frame_count;

  if (options.write_background) {
    const TexturedMesh& plate = environment.static_geometry();
    const geometry::Positions plate_normals =
        plate.F.rows() > 0 ? geometry::VertexNormals(plate.V, plate.F) : geometry::Positions(0, 3);
    const SceneView plate_view{plate.V, plate.F, plate_normals, plate.rest, 0};
    tbb::parallel_for(0, camera_count, [&](int c) {
      writer.WriteBackground(c, renderer.RenderBackground(cameras[c], options.IsColourCamera(c),
                                                          MixSeed(options.seed, 1000003ull * (c + 1)), &plate_view));
    });
  }

  const Stopwatch render_stopwatch;
  const int task_count = camera_count * frame_count;
  ProgressBegin(progress, "synth: rendering " + std::to_string(task_count) + " images",
                static_cast<std::size_t>(task_count));
  for (int f = 0; f < frame_count; ++f) {
    writer.WriteGroundTruthMesh(f, scene.Mesh(f));
    TexturedMesh composed{scene.frames[f], scene.rest, scene.F};
    AppendMesh(&composed, environment.AtFrame(options.scene.start_frame + f));
    const geometry::Positions normals = geometry::VertexNormals(composed.V, composed.F);
    const SoftShadows shadows(options.environment, KeyLightDirection(), scene.frames[f], scene.F);
    const SceneView view{composed.V, composed.F, normals, composed.rest, static_cast<int>(scene.F.rows()),
                         shadows.enabled() ? &shadows : nullptr};
    std::vector<cv::Mat> images(static_cast<std::size_t>(camera_count));
    tbb::parallel_for(0, camera_count, [&](int c) {
      const int task = f * camera_count + c;
      const RenderedView rendered = renderer.Render(cameras[c], view, options.IsColourCamera(c),
                                                    MixSeed(options.seed, static_cast<std::uint64_t>(task) + 1));
      if (videos) {
        images[c] = rendered.image;
      } else {
        writer.WriteImage(c, f, rendered.image);
      }
      if (options.write_masks) writer.WriteMask(c, f, rendered.mask);
    });
    if (videos)
      for (int c = 0; c < camera_count; ++c) videos->Write(c, images[c]);
    ProgressUpdate(progress, static_cast<std::size_t>((f + 1) * camera_count));
  }
  if (videos) videos->Finish(directory);
  ProgressEnd(progress);
  summary.render_seconds = render_stopwatch.Seconds();
  summary.seconds = stopwatch.Seconds();
  return summary;
}

}  // namespace subflow::vision
