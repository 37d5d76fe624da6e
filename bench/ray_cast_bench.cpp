// Ray casts as surface snapping makes them (ClosestPointTree::NearestHitsOnLines: one line
// per vertex, both directions, bounded), against the blob's ground truth (20,480
// triangles): Embree (/0, what the pipeline uses) against CGAL's exact-predicate AABB
// traversal (/1, the reference), in the same process.
#include <random>

#include <benchmark/benchmark.h>

#include "geometry/closest_point.h"
#include "geometry/mesh_io.h"
#include "vision/dataset.h"

namespace {

using namespace subflow;

struct Lines {
  geometry::TriangleMesh target;
  geometry::Positions origins, directions;
  double bound = 0.0;
};

// Lines through the target's vertices moved off the surface by up to ±1 % of its size,
// along the direction from its centroid (the blob is star-shaped about it), with a bound of
// 2 % of its size: the shape of a hull correction step.
const Lines& GetLines() {
  static const Lines lines = [] {
    Lines made;
    const vision::Dataset dataset(SUBFLOW_SHARED_DIR "/data/blob");
    made.target = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
    const Eigen::RowVector3d centroid = made.target.V.colwise().mean();
    const double size = (made.target.V.colwise().maxCoeff() - made.target.V.colwise().minCoeff()).maxCoeff();
    std::mt19937 generator(1);
    std::uniform_real_distribution<double> offset(-0.01 * size, 0.01 * size);
    made.directions = (made.target.V.rowwise() - centroid).rowwise().normalized();
    made.origins = made.target.V;
    for (Eigen::Index v = 0; v < made.origins.rows(); ++v) made.origins.row(v) += offset(generator) * made.directions.row(v);
    made.bound = 0.02 * size;
    return made;
  }();
  return lines;
}

void BM_SnapLines(benchmark::State& state) {
  const Lines& lines = GetLines();
  const geometry::ClosestPointTree tree(lines.target);
  const geometry::RayEngine engine = state.range(0) == 0 ? geometry::RayEngine::kEmbree : geometry::RayEngine::kCgal;
  int hits = 0;
  for (auto _ : state) {
    const std::vector<geometry::RayHit> result = tree.NearestHitsOnLines(lines.origins, lines.directions, lines.bound, engine);
    hits = 0;
    for (const geometry::RayHit& hit : result) hits += hit.hit;
    benchmark::DoNotOptimize(hits);
  }
  state.counters["lines"] = static_cast<double>(lines.origins.rows());
  state.counters["hits"] = hits;
  state.SetLabel(engine == geometry::RayEngine::kEmbree ? "embree" : "cgal (reference)");
}
BENCHMARK(BM_SnapLines)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Building the tree (CGAL's AABB tree and distance accelerator, and the Embree scene): once
// per hull and frame.
void BM_BuildTree(benchmark::State& state) {
  const Lines& lines = GetLines();
  for (auto _ : state) {
    const geometry::ClosestPointTree tree(lines.target);
    benchmark::DoNotOptimize(&tree);
  }
}
BENCHMARK(BM_BuildTree)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
