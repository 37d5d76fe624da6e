// Z-buffer speed on the blob ground truth (10242 vertices, 20480 triangles, 320×240),
// against the naive reference: one CGAL AABB-tree ray cast per pixel centre.
#include <benchmark/benchmark.h>

#include "geometry/closest_point.h"
#include "geometry/mesh_io.h"
#include "vision/dataset.h"
#include "vision/zbuffer.h"

namespace {

using namespace subflow;

struct Blob {
  vision::Dataset dataset{SUBFLOW_SHARED_DIR "/data/blob"};
  geometry::TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
};

const Blob& GetBlob() {
  static const Blob blob;
  return blob;
}

void BM_ZBufferOneCamera(benchmark::State& state) {
  const Blob& blob = GetBlob();
  vision::ZBuffer zbuffer;
  for (auto _ : state) {
    zbuffer.Render(blob.dataset.camera(0), blob.mesh.V, blob.mesh.F);
    benchmark::DoNotOptimize(zbuffer.depth().data());
  }
  state.counters["covered_px"] = zbuffer.CoveredPixelCount();
}
BENCHMARK(BM_ZBufferOneCamera)->Unit(benchmark::kMillisecond);

void BM_ZBufferOneCameraCulled(benchmark::State& state) {
  const Blob& blob = GetBlob();
  vision::ZBuffer zbuffer;
  vision::ZBufferOptions options;
  options.cull_back_faces = true;
  for (auto _ : state) {
    zbuffer.Render(blob.dataset.camera(0), blob.mesh.V, blob.mesh.F, options);
    benchmark::DoNotOptimize(zbuffer.depth().data());
  }
}
BENCHMARK(BM_ZBufferOneCameraCulled)->Unit(benchmark::kMillisecond);

void BM_ZBufferAllCamerasParallel(benchmark::State& state) {
  const Blob& blob = GetBlob();
  for (auto _ : state) {
    auto zbuffers = vision::RenderZBuffers(blob.dataset.cameras(), blob.mesh.V, blob.mesh.F);
    benchmark::DoNotOptimize(zbuffers.data());
  }
  state.counters["cameras"] = blob.dataset.camera_count();
}
BENCHMARK(BM_ZBufferAllCamerasParallel)->Unit(benchmark::kMillisecond)->UseRealTime();

// Reference: the same depth map by casting one ray per pixel through an AABB tree
// (tree built once, outside the timing).
void BM_RayCastOneCameraReference(benchmark::State& state) {
  const Blob& blob = GetBlob();
  const geometry::ClosestPointTree tree(blob.mesh);
  const vision::Camera& camera = blob.dataset.camera(0);
  for (auto _ : state) {
    int hits = 0;
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x)
        hits += tree.FirstHit(camera.Center(), camera.BackProjectUndistorted({x, y})).hit;
    benchmark::DoNotOptimize(hits);
  }
}
BENCHMARK(BM_RayCastOneCameraReference)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
