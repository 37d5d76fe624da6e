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
#include "vision/synthetic_canvas.h"
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

}  // namespace

void SyntheticRenderOptions::Check() const {
  if (supersample < 1 || supersample > 8)
    ThrowError("synth", "supersample", "expected 1..8, got " + std::to_string(supersample));
  if (background != "dark" && background != "texture")
    ThrowError("synth", "background", "expected dark or texture, got \"" + background + "\"");
  if (!std::isfinite(noise_sigma) || noise_sigma < 0.0)
    ThrowError("synth", "noise", "expected a finite σ ≥ 0 (grey levels)");
}

ProceduralAlbedoOptions SyntheticRenderOptions::EnvironmentAlbedo() {
  ProceduralAlbedoOptions o;
  o.cell_size = 0.03;
  o.border_width = 0.003;
  o.blotch_size = 0.012;
  o.blotch_contrast = 0.35;
  o.min_brightness = 0.1;
  o.max_brightness = 0.7;
  o.tint = 0.4;
  o.seed = 7;
  return o;
}

SyntheticRenderer::SyntheticRenderer(const SyntheticRenderOptions& options)
    : options_(options), albedo_(options.albedo), environment_albedo_(options.environment_albedo) {
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
  return Render(camera, SceneView{V, F, normals, rest, static_cast<int>(F.rows())}, colour, noise_seed);
}

RenderedView SyntheticRenderer::Render(const Camera& camera, const SceneView& scene, bool colour,
                                       std::uint64_t noise_seed) const {
  const geometry::Positions& V = scene.V;
  const geometry::Faces& F = scene.F;
  SUBFLOW_CHECK(scene.normals.rows() == V.rows() && scene.rest.rows() == V.rows(),
                "one normal and rest position per vertex");
  const int s = options_.supersample;
  SampleCanvas canvas(camera, s);
  ZBufferOptions zbuffer_options;
  zbuffer_options.cull_back_faces = true;  // closed surfaces seen from outside, walls seen from inside
  canvas.Render(V, F, zbuffer_options);

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
          const CanvasHit hit = canvas.Hit(x, y, i, j, V, F);
          if (hit.face < 0) {
            sum += BackgroundRadiance(camera, (s * x + i + 0.5) / s - 0.5, (s * y + j + 0.5) / s - 0.5);
            continue;
          }
          const bool subject = hit.face < scene.subject_face_count;
          covered += subject ? 1 : 0;
          sum += SampleRadiance(scene, hit, subject);
        }
      }
      radiance[static_cast<std::size_t>(y) * width + x] = sum * inverse_samples;
      if (2 * covered > s * s) view.mask.at<std::uint8_t>(y, x) = 255;
    }
  }
  view.image = Encode(radiance, width, height, colour, noise_seed);
  return view;
}

Eigen::Vector3d SyntheticRenderer::SampleRadiance(const SceneView& scene, const CanvasHit& hit, bool subject) const {
  const double w1 = hit.w1, w2 = hit.w2, w0 = 1.0 - w1 - w2;
  const int a = scene.F(hit.face, 0), b = scene.F(hit.face, 1), c = scene.F(hit.face, 2);
  const Eigen::Vector3d material =
      (w0 * scene.rest.row(a) + w1 * scene.rest.row(b) + w2 * scene.rest.row(c)).transpose();
  const Eigen::Vector3d normal =
      (w0 * scene.normals.row(a) + w1 * scene.normals.row(b) + w2 * scene.normals.row(c)).transpose().normalized();
  double key = kLights[0].strength * std::max(0.0, normal.dot(kLights[0].direction));
  if (scene.shadows != nullptr && key > 0.0) {
    const Eigen::Vector3d X = (w0 * scene.V.row(a) + w1 * scene.V.row(b) + w2 * scene.V.row(c)).transpose();
    key *= scene.shadows->LightFraction(X);
  }
  double irradiance = kAmbient + key;
  for (std::size_t l = 1; l < std::size(kLights); ++l)
    irradiance += kLights[l].strength * std::max(0.0, normal.dot(kLights[l].direction));
  return irradiance * (subject ? albedo_(material) : environment_albedo_(material));
}

Eigen::Vector3d KeyLightDirection() { return kLights[0].direction; }

cv::Mat SyntheticRenderer::RenderBackground(const Camera& camera, bool colour, std::uint64_t noise_seed,
                                            const SceneView* environment) const {
  if (environment != nullptr && environment->F.rows() > 0) return Render(camera, *environment, colour, noise_seed).image;
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

}  // namespace subflow::vision
