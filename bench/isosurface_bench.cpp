// Cost of the base-mesh construction of section 4.1 on n³ occupancy volumes:
//   ExtractIsosurface (CGAL Mesh_3) against its O(n³) preparation alone (pad + blur), and
//   SimplifyMesh (guarded Garland–Heckbert) against plain Garland–Heckbert edge collapse
//   (no shape/valence filter, no flips, no self-intersection check) on the same input.
// Run: subflow/build/bench/isosurface_bench [--benchmark_filter=...]
#include <cmath>

#include <benchmark/benchmark.h>

#include "geometry/isosurface.h"
#include "geometry/simplify.h"

namespace subflow::geometry {
namespace {

// A non-convex blob (three balls and a thick disk) filling most of an n³ grid.
ScalarVolume BlobOccupancy(int n) {
  ScalarVolume volume(Eigen::Vector3d::Zero(), 1.0, n, n, n, 0.0f);
  const double s = n / 64.0;  // the blob is drawn in a 64³ frame and scaled
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d p = Eigen::Vector3d(i, j, k) / s - Eigen::Vector3d::Constant(32);
        const bool inside = (p - Eigen::Vector3d(-8, 0, 0)).norm() < 14 ||
                            (p - Eigen::Vector3d(10, 4, 0)).norm() < 11 ||
                            (p - Eigen::Vector3d(2, -10, 6)).norm() < 9 ||
                            (std::abs(p.z()) < 4 && std::hypot(p.x(), p.y()) < 24);
        volume.at(i, j, k) = inside ? 1.0f : 0.0f;
      }
  return volume;
}

// A ball of radius 0.4 n in the middle of an n³ grid.
ScalarVolume SphereOccupancy(int n) {
  ScalarVolume volume(Eigen::Vector3d::Zero(), 1.0, n, n, n, 0.0f);
  const Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.5 * n - 0.3);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        volume.at(i, j, k) = (Eigen::Vector3d(i, j, k) - centre).norm() < 0.4 * n ? 1.0f : 0.0f;
  return volume;
}

void BM_ExtractIsosurfaceSphere(benchmark::State& state) {
  const ScalarVolume volume = SphereOccupancy(static_cast<int>(state.range(0)));
  IsosurfaceSummary summary;
  for (auto _ : state) benchmark::DoNotOptimize(ExtractIsosurface(volume, {}, &summary));
  state.counters["faces"] = summary.face_count;
}
BENCHMARK(BM_ExtractIsosurfaceSphere)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

void BM_ExtractIsosurfaceBlob(benchmark::State& state) {
  const ScalarVolume volume = BlobOccupancy(static_cast<int>(state.range(0)));
  IsosurfaceSummary summary;
  for (auto _ : state) benchmark::DoNotOptimize(ExtractIsosurface(volume, {}, &summary));
  state.counters["faces"] = summary.face_count;
}
BENCHMARK(BM_ExtractIsosurfaceBlob)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

// Reference: the preparation every extraction does (padding + Gaussian blur).
void BM_PadAndSmoothReference(benchmark::State& state) {
  const ScalarVolume volume = BlobOccupancy(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(PadAndSmoothVolume(volume, 4, 1.0));
}
BENCHMARK(BM_PadAndSmoothReference)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

const TriangleMesh& BlobSurface128() {
  static const TriangleMesh mesh = ExtractIsosurface(BlobOccupancy(128), {});
  return mesh;
}

void BM_SimplifyMeshTo400(benchmark::State& state) {
  const TriangleMesh& input = BlobSurface128();
  SimplifySummary summary;
  for (auto _ : state) benchmark::DoNotOptimize(SimplifyMesh(input, {}, &summary));
  state.counters["input_faces"] = input.face_count();
  state.counters["faces"] = summary.face_count;
}
BENCHMARK(BM_SimplifyMeshTo400)->Unit(benchmark::kMillisecond);

// Reference: plain Garland–Heckbert, every guard switched off.
void BM_PlainGarlandHeckbertReference(benchmark::State& state) {
  const TriangleMesh& input = BlobSurface128();
  SimplifyOptions plain;
  plain.max_normal_change_degrees = 180.0;
  plain.min_triangle_angle_degrees = 0.0;
  plain.max_valence = 1000;
  plain.min_valence = 3;
  plain.flip_rounds = 0;
  plain.check_self_intersections = false;
  for (auto _ : state) benchmark::DoNotOptimize(SimplifyMesh(input, plain));
}
BENCHMARK(BM_PlainGarlandHeckbertReference)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace subflow::geometry

BENCHMARK_MAIN();
