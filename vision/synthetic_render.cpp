#include "vision/synthetic_render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <random>

#include <Eigen/Geometry>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/vertex_normals.h"
#include "vision/dataset_writer.h"
#include "vision/zbuffer.h"

namespace subflow::vision {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBackgroundRadiance = 0.03;
constexpr double kAmbient = 0.12;

struct Light {
  Eigen::Vector3d direction;  // unit, towards the light
  double strength;
};

Light MakeLight(double azimuth_deg, double elevation_deg, double strength) {
  const double a = azimuth_deg * kPi / 180.0, e = elevation_deg * kPi / 180.0;
  return {Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)), strength};
}

const Light kLights[2] = {MakeLight(-35.0, 50.0, 0.75), MakeLight(140.0, 30.0, 0.25)};

double EncodeSrgb(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b) {
  std::uint64_t h = a * 0x9E3779B97F4A7C15ull + b + 0x632BE59BD9B4E019ull;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  return h;
}

}  // namespace

void SyntheticRenderOptions::Check() const {
  if (supersample < 1 || supersample > 8)
    ThrowError("synth", "supersample", "expected 1..8, got " + std::to_string(supersample));
  if (background != "dark" && background != "texture")
    ThrowError("synth", "background", "expected dark or texture, got \"" + background + "\"");
  if (!std::isfinite(noise_sigma) || noise_sigma < 0.0)
    ThrowError("synth", "noise", "expected a finite σ ≥ 0 (grey levels)");
}

SyntheticRenderer::SyntheticRenderer(const SyntheticRenderOptions& options)
    : options_(options), albedo_(options.albedo) {
  options_.Check();
  textured_background_ = options_.background == "texture";
}

Eigen::Vector3d SyntheticRenderer::BackgroundRadiance(const Camera& camera, double x, double y) const {
  if (!textured_background_) return Eigen::Vector3d::Constant(kBackgroundRadiance);
  const std::uint32_t seed = static_cast<std::uint32_t>(std::hash<std::string>()(camera.name()));
  const double noise = ValueNoise(Eigen::Vector3d(x / 9.0, y / 9.0, 0.5), seed);
  return Eigen::Vector3d::Constant(kBackgroundRadiance * (0.6 + 0.8 * noise));
}

cv::Mat SyntheticRenderer::Encode(const std::vector<Eigen::Vector3d>& radiance, int width,
                                  int height, bool colour, std::uint64_t noise_seed) const {
  cv::Mat image(height, width, colour ? CV_8UC3 : CV_8UC1);
  std::mt19937_64 generator(noise_seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double sigma = options_.noise_sigma;
  auto quantize = [&](double linear) {
    double level = 255.0 * EncodeSrgb(linear);
    if (sigma > 0.0) level += sigma * noise(generator);
    return static_cast<std::uint8_t>(std::clamp(std::lround(level), 0L, 255L));
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3d& L = radiance[static_cast<std::size_t>(y) * width + x];
      if (colour) {
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(quantize(L.z()), quantize(L.y()), quantize(L.x()));
      } else {
        image.at<std::uint8_t>(y, x) = quantize(0.2126 * L.x() + 0.7152 * L.y() + 0.0722 * L.z());
      }
    }
  }
  return image;
}

RenderedView SyntheticRenderer::Render(const Camera& camera, const geometry::Positions& V,
                                       const geometry::Faces& F, const geometry::Positions& normals,
                                       const geometry::Positions& rest, bool colour,
                                       std::uint64_t noise_seed) const {
  SUBFLOW_CHECK(normals.rows() == V.rows() && rest.rows() == V.rows(), "one normal and rest position per vertex");
  const int s = options_.supersample;
  const Camera fine_camera = SupersampledCamera(camera, s);
  ZBufferOptions zbuffer_options;
  zbuffer_options.cull_back_faces = true;  // scenes are closed surfaces seen from outside
  const ZBuffer zbuffer(fine_camera, V, F, zbuffer_options);

  const int width = camera.width(), height = camera.height();
  std::vector<Eigen::Vector3d> radiance(static_cast<std::size_t>(width) * height);
  RenderedView view;
  view.mask = cv::Mat::zeros(height, width, CV_8UC1);
  const double inverse_samples = 1.0 / (s * s);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int covered = 0;
      for (int j = 0; j < s; ++j) {
        for (int i = 0; i < s; ++i) {
          const int fx = s * x + i, fy = s * y + j;
          const int f = zbuffer.Face(fx, fy);
          if (f < 0) {
            sum += BackgroundRadiance(camera, (fx + 0.5) / s - 0.5, (fy + 0.5) / s - 0.5);
            continue;
          }
          ++covered;
          const Eigen::Vector2f uv = zbuffer.Barycentric(fx, fy);
          const double w1 = uv.x(), w2 = uv.y(), w0 = 1.0 - w1 - w2;
          const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
          const Eigen::Vector3d material = (w0 * rest.row(a) + w1 * rest.row(b) + w2 * rest.row(c)).transpose();
          const Eigen::Vector3d normal =
              (w0 * normals.row(a) + w1 * normals.row(b) + w2 * normals.row(c)).transpose().normalized();
          double irradiance = kAmbient;
          for (const Light& light : kLights) irradiance += light.strength * std::max(0.0, normal.dot(light.direction));
          sum += irradiance * albedo_(material);
        }
      }
      radiance[static_cast<std::size_t>(y) * width + x] = sum * inverse_samples;
      if (2 * covered > s * s) view.mask.at<std::uint8_t>(y, x) = 255;
    }
  }
  view.image = Encode(radiance, width, height, colour, noise_seed);
  return view;
}

cv::Mat SyntheticRenderer::RenderBackground(const Camera& camera, bool colour,
                                            std::uint64_t noise_seed) const {
  const int s = options_.supersample, width = camera.width(), height = camera.height();
  std::vector<Eigen::Vector3d> radiance(static_cast<std::size_t>(width) * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i)
          sum += BackgroundRadiance(camera, (s * x + i + 0.5) / s - 0.5, (s * y + j + 0.5) / s - 0.5);
      radiance[static_cast<std::size_t>(y) * width + x] = sum / (s * s);
    }
  }
  return Encode(radiance, width, height, colour, noise_seed);
}

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
}

bool SynthOptions::IsColourCamera(int camera) const {
  if (colour_every > 0) return camera % colour_every == 0;
  return std::find(colour_cameras.begin(), colour_cameras.end(), camera) != colour_cameras.end();
}

SynthSummary WriteSyntheticDataset(const std::string& directory, const SynthOptions& options,
                                   Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  options.Check();
  SyntheticSceneOptions scene_options = options.scene;
  const SyntheticScene scene = MakeSyntheticScene(scene_options);

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

  const std::vector<Camera> cameras = MakeCameraRig(options.rig, 0.5 * (low + high));
  summary.camera_count = static_cast<int>(cameras.size());
  DatasetInfo info;
  info.fps = options.fps;
  info.frame_count = scene.frame_count();
  info.bounds = summary.bounds;
  info.units = "meters";
  const DatasetWriter writer(directory, cameras, info, options.overwrite);

  SyntheticRenderOptions render_options = options.render;
  render_options.albedo.seed = options.seed;
  const SyntheticRenderer renderer(render_options);
  const int camera_count = summary.camera_count, frame_count = summary.frame_count;

  std::vector<geometry::Positions> normals(static_cast<std::size_t>(frame_count));
  tbb::parallel_for(0, frame_count, [&](int f) {
    normals[f] = geometry::VertexNormals(scene.frames[f], scene.F);
    writer.WriteGroundTruthMesh(f, scene.Mesh(f));
  });
  tbb::parallel_for(0, camera_count, [&](int c) {
    writer.WriteBackground(c, renderer.RenderBackground(cameras[c], options.IsColourCamera(c),
                                                        MixSeed(options.seed, 1000003ull * (c + 1))));
  });

  const auto render_start = std::chrono::steady_clock::now();
  const int task_count = camera_count * frame_count;
  ProgressBegin(progress, "synth: rendering " + std::to_string(task_count) + " images",
                static_cast<std::size_t>(task_count));
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  int reported = 0;
  tbb::parallel_for(0, task_count, [&](int task) {
    const int f = task / camera_count, c = task % camera_count;
    const std::uint64_t noise_seed = MixSeed(options.seed, static_cast<std::uint64_t>(task) + 1);
    const RenderedView view = renderer.Render(cameras[c], scene.frames[f], scene.F, normals[f], scene.rest,
                                              options.IsColourCamera(c), noise_seed);
    writer.WriteImage(c, f, view.image);
    writer.WriteMask(c, f, view.mask);
    const int finished = ++done;
    std::lock_guard<std::mutex> lock(progress_mutex);
    reported = std::max(reported, finished);
    ProgressUpdate(progress, static_cast<std::size_t>(reported));
  });
  ProgressEnd(progress);
  const auto end = std::chrono::steady_clock::now();
  summary.render_seconds = std::chrono::duration<double>(end - render_start).count();
  summary.seconds = std::chrono::duration<double>(end - start).count();
  return summary;
}

}  // namespace subflow::vision
