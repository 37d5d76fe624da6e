// Voxel carving cost (issue 4: "a 128³ volume from 10 cameras at 320×240 in well under a
// second per frame on 2 cores"): the blob dataset's masks at frame 0 → occupancy of a
// 128³ grid (carving, closing, opening, components, cavities), with TBB on all cores
// against the same run on one thread (threads = 1) as the reference; with and without
// the silhouette-IoU figures. The silhouette stage (mask / background / motion) is timed
// separately. Run: bench/voxel_carving_bench --benchmark_repetitions=5
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "vision/dataset.h"
#include "vision/silhouettes.h"
#include "vision/voxel_carving.h"

namespace {

using namespace subflow::vision;

const Dataset& Blob() {
  static const Dataset dataset(SUBFLOW_SHARED_DIR "/data/blob");
  return dataset;
}

const std::vector<Silhouette>& BlobMasks() {
  static const std::vector<Silhouette> silhouettes = [] {
    std::vector<Silhouette> result;
    for (int c = 0; c < Blob().camera_count(); ++c) result.push_back(SilhouetteFromMask(Blob().Mask(c, 0)));
    return result;
  }();
  return silhouettes;
}

// Args: threads (0 = all, 1 = serial), silhouette IoU on/off.
void BM_Carve128FromMasks(benchmark::State& state) {
  VoxelCarvingOptions options;
  options.resolution = 128;
  options.threads = static_cast<int>(state.range(0));
  options.compute_silhouette_iou = state.range(1) != 0;
  const std::vector<Silhouette>& silhouettes = BlobMasks();
  CarvingResult result;
  for (auto _ : state) {
    result = CarveVoxels(Blob().cameras(), silhouettes, Blob().bounds(), options);
    benchmark::DoNotOptimize(result.occupied_voxels);
  }
  state.counters["voxels"] = static_cast<double>(result.occupancy.size());
  state.counters["occupied"] = static_cast<double>(result.occupied_voxels);
  state.counters["cameras"] = static_cast<double>(silhouettes.size());
  if (options.compute_silhouette_iou) state.counters["mean_iou"] = result.mean_silhouette_iou;
}
BENCHMARK(BM_Carve128FromMasks)
    ->ArgNames({"threads", "iou"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The silhouettes of all 10 cameras at frame 0 from each source (decoding included).
void BM_Silhouettes(benchmark::State& state) {
  SilhouetteOptions options;
  options.source = static_cast<EvidenceSource>(state.range(0));
  for (auto _ : state) {
    Blob().ClearCache();
    benchmark::DoNotOptimize(ComputeSilhouettes(Blob(), 0, options));
  }
  state.SetLabel(ToString(options.source));
}
BENCHMARK(BM_Silhouettes)
    ->Arg(static_cast<int>(EvidenceSource::kMask))
    ->Arg(static_cast<int>(EvidenceSource::kBackground))
    ->Arg(static_cast<int>(EvidenceSource::kMotion))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
