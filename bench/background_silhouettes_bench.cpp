// Background-difference silhouettes (issue 12 item 4): their agreement with the true masks
// and their cost, for the plain colour difference with the histogram (triangle) threshold
// as the reference, the per-camera noise threshold alone, the shadow-robust difference
// alone, and both (the defaults), in one run.
//   SUBFLOW_SILHOUETTES_DATASET  a dataset with background images (default the shared blob)
//   SUBFLOW_SILHOUETTES_TRUTH    a dataset with the true masks of the same images (default:
//                                the same dataset; e.g. critter_ring for critter_nomasks)
//   SUBFLOW_SILHOUETTES_FRAMES   comma-separated frames (default 0)
//   SUBFLOW_SILHOUETTES_DEBUG    a folder: per variant, camera and frame, PNGs of the
//                                measure (×4), the silhouette and the truth
// Counters: iou_mean / iou_min over cameras and frames, missed (true object pixels not in
// the silhouette) and extra (silhouette pixels not in the truth), as fractions of the true
// object's pixels. A per-camera line goes to stderr.
// Run: SUBFLOW_SILHOUETTES_DATASET=… bench/background_silhouettes_bench
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>

#include "vision/dataset.h"
#include "vision/silhouettes.h"

namespace {

using namespace subflow::vision;

std::string Environment(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0' ? value : fallback;
}

const Dataset& Images() {
  static const Dataset dataset(Environment("SUBFLOW_SILHOUETTES_DATASET", SUBFLOW_SHARED_DIR "/data/blob"));
  return dataset;
}
const Dataset& Truth() {
  static const Dataset dataset(Environment("SUBFLOW_SILHOUETTES_TRUTH", Images().directory()));
  return dataset;
}
std::vector<int> Frames() {
  std::vector<int> frames;
  std::stringstream list(Environment("SUBFLOW_SILHOUETTES_FRAMES", "0"));
  for (std::string item; std::getline(list, item, ',');) frames.push_back(std::stoi(item));
  return frames;
}

enum Variant { kPlain, kNoiseThreshold, kShadowTest, kBoth };
const char* const kVariantNames[] = {"plain+triangle", "plain+noise_threshold", "shadow+triangle", "shadow+noise_threshold"};

SilhouetteOptions OptionsOf(Variant variant) {
  SilhouetteOptions options;
  options.source = EvidenceSource::kBackground;
  options.background_shadow_test = variant == kShadowTest || variant == kBoth;
  if (variant == kPlain || variant == kShadowTest) options.min_background_fraction = 1.0;  // never enough
  return options;
}

void WriteDebug(const std::string& folder, Variant variant, int camera, int frame, const Silhouette& silhouette,
                const cv::Mat& truth) {
  std::filesystem::create_directories(folder);
  char name[128];
  std::snprintf(name, sizeof name, "%s/%s_cam%02d_f%03d_", folder.c_str(), kVariantNames[variant], camera, frame);
  cv::Mat measure;
  silhouette.measure.convertTo(measure, CV_8U, 4 * 255.0);
  cv::imwrite(std::string(name) + "measure.png", measure);
  cv::imwrite(std::string(name) + "mask.png", silhouette.mask);
  cv::imwrite(std::string(name) + "truth.png", truth);
}

void BM_BackgroundSilhouettes(benchmark::State& state) {
  const Variant variant = static_cast<Variant>(state.range(0));
  const SilhouetteOptions options = OptionsOf(variant);
  const std::vector<int> frames = Frames();
  std::vector<std::vector<Silhouette>> silhouettes(frames.size());
  for (auto _ : state)
    for (size_t i = 0; i < frames.size(); ++i) silhouettes[i] = ComputeSilhouettes(Images(), frames[i], options);

  const std::string debug = Environment("SUBFLOW_SILHOUETTES_DEBUG", "");
  double iou_sum = 0, iou_min = 1, missed = 0, extra = 0, truth_pixels = 0;
  int count = 0;
  for (int c = 0; c < Images().camera_count(); ++c) {
    double camera_iou = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
      const cv::Mat truth = Truth().Mask(c, frames[i]) != 0;
      const cv::Mat& mask = silhouettes[i][c].mask;
      const double both = cv::countNonZero(mask & truth), either = cv::countNonZero(mask | truth);
      const double iou = either > 0 ? both / either : 1.0;
      camera_iou += iou;
      iou_sum += iou;
      iou_min = std::min(iou_min, iou);
      missed += cv::countNonZero(truth & ~mask);
      extra += cv::countNonZero(mask & ~truth);
      truth_pixels += cv::countNonZero(truth);
      ++count;
      if (!debug.empty()) WriteDebug(debug, variant, c, frames[i], silhouettes[i][c], truth);
    }
    std::fprintf(stderr, "%-24s cam%02d iou %.4f threshold %.4f\n", kVariantNames[variant], c,
                 camera_iou / frames.size(), silhouettes[0][c].threshold);
  }
  state.SetLabel(kVariantNames[variant]);
  state.counters["iou_mean"] = iou_sum / count;
  state.counters["iou_min"] = iou_min;
  state.counters["missed"] = missed / truth_pixels;
  state.counters["extra"] = extra / truth_pixels;
}
BENCHMARK(BM_BackgroundSilhouettes)
    ->Arg(kPlain)
    ->Arg(kNoiseThreshold)
    ->Arg(kShadowTest)
    ->Arg(kBoth)
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
