// Bilinear image samples with their gradients, as the refinement and the motion passes take
// them: the gradients taken at sampling time from one plane (SampleImage, SampleSignedDistance)
// against the reference they replaced, gradient planes computed once per image (filter2D,
// Sobel) and interpolated like the intensity. Both give the same values to the bit
// (tests/solver/normal_flow_test.cpp, ncc_cost_test.cpp); the planes cost two more floats
// per pixel in every frame cache.
//
// The same 2^16 random sample positions on a 1088 × 1920 image (pose2sim's size), in the
// order of a patch's samples (runs of nearby pixels). Run with
//   image_sampling_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <cmath>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "solver/observation/image_derivatives.h"
#include "solver/stereo/ncc_cost.h"

namespace {

using namespace subflow;

struct Images {
  solver::SmoothedImage smoothed;
  solver::SignedDistanceImage distance;
  cv::Mat gx, gy, dx, dy;  // the reference's planes
  std::vector<Eigen::Vector2d> pixels;

  Images() {
    cv::Mat image(1920, 1088, CV_32FC1);
    cv::RNG rng(11);
    rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
    smoothed = solver::SmoothImage(image, 1.0);
    const cv::Mat k = (cv::Mat_<float>(1, 3) << -0.5f, 0.0f, 0.5f);
    cv::filter2D(smoothed.intensity, gx, CV_32F, k, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
    cv::filter2D(smoothed.intensity, gy, CV_32F, k.t(), cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
    cv::Mat mask = cv::Mat::zeros(image.size(), CV_8UC1);
    cv::ellipse(mask, {544, 960}, {300, 700}, 0.0, 0.0, 360.0, cv::Scalar(255), cv::FILLED);
    distance = solver::ComputeSignedDistance(mask);
    cv::Sobel(distance.distance, dx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0, cv::BORDER_REPLICATE);
    cv::Sobel(distance.distance, dy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0, cv::BORDER_REPLICATE);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> x(10.0, 1070.0), y(10.0, 1900.0), step(-4.0, 4.0);
    for (int patch = 0; patch < 4096; ++patch) {  // 16 samples around each patch's centre
      const Eigen::Vector2d centre(x(random), y(random));
      for (int s = 0; s < 16; ++s) pixels.emplace_back(centre + Eigen::Vector2d(step(random), step(random)));
    }
  }
};

const Images& Shared() {
  static const Images images;
  return images;
}

double Bilinear(const cv::Mat& plane, const Eigen::Vector2d& p) {
  const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
  const double fx = p.x() - x0, fy = p.y() - y0;
  const float* r0 = plane.ptr<float>(y0);
  const float* r1 = plane.ptr<float>(y0 + 1);
  return (1.0 - fy) * ((1.0 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1.0 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

void BM_ImageGradientPlanes(benchmark::State& state) {  // the reference
  const Images& images = Shared();
  for (auto _ : state) {
    double sum = 0.0;
    for (const Eigen::Vector2d& p : images.pixels)
      sum += Bilinear(images.smoothed.intensity, p) + Bilinear(images.gx, p) + Bilinear(images.gy, p);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(images.pixels.size()));
}
BENCHMARK(BM_ImageGradientPlanes);

void BM_SampleImage(benchmark::State& state) {
  const Images& images = Shared();
  for (auto _ : state) {
    double sum = 0.0, intensity = 0.0;
    Eigen::Vector2d gradient;
    for (const Eigen::Vector2d& p : images.pixels)
      if (solver::SampleImage(images.smoothed, p, &intensity, &gradient)) sum += intensity + gradient.sum();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(images.pixels.size()));
}
BENCHMARK(BM_SampleImage);

void BM_DistanceGradientPlanes(benchmark::State& state) {  // the reference
  const Images& images = Shared();
  for (auto _ : state) {
    double sum = 0.0;
    for (const Eigen::Vector2d& p : images.pixels)
      sum += Bilinear(images.distance.distance, p) + Bilinear(images.dx, p) + Bilinear(images.dy, p);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(images.pixels.size()));
}
BENCHMARK(BM_DistanceGradientPlanes);

void BM_SampleSignedDistance(benchmark::State& state) {
  const Images& images = Shared();
  for (auto _ : state) {
    double sum = 0.0, value = 0.0;
    Eigen::Vector2d gradient;
    for (const Eigen::Vector2d& p : images.pixels)
      if (solver::SampleSignedDistance(images.distance, p, &value, &gradient)) sum += value + gradient.sum();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(images.pixels.size()));
}
BENCHMARK(BM_SampleSignedDistance);

}  // namespace

BENCHMARK_MAIN();
