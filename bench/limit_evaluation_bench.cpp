// The limit matrix L (s = L c) is built once per connectivity and applied every time the
// control points change, so building may be slow-ish but applying must be fast. On a
// level mesh of 81,920 faces (an icosphere of 1,280 faces with 240 random edge flips —
// valences 3 to 9 — split 1→4 three times, so extraordinary vertices are isolated and
// every face is a box-spline or a Stam patch), this measures, in one run:
//   BM_EvaluatorConstruction      classify faces, gather control indices, Stam patches
//   BM_LimitMatrixBuild/t         L for 1 sample per face (u = v = 1/3), t TBB threads
//   BM_LimitMatrixBuildDerivs/t   L, L_u, L_v
//   BM_LimitMatrixApply           s = L c (sparse × dense #V×3)
//   BM_EvaluateEachSample         reference: Evaluate() per sample, no matrix
//   BM_TessellationBuild/m        TessellateLimitSurface(m) + its L (2 threads)
//   BM_TessellationApply/m        s = L c for that tessellation
// Run: limit_evaluation_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "geometry/icosphere.h"
#include "geometry/limit_evaluation.h"
#include "geometry/limit_tessellation.h"
#include "geometry/mesh_topology.h"

namespace subflow::geometry {
namespace {

// Flips `count` random interior edges (a, b) → (c, d) that keep valences ≥ 4 and create
// no duplicate edge.
Faces RandomFlips(Faces f, int vertex_count, int count, unsigned seed) {
  std::mt19937 random(seed);
  for (int done = 0; done < count;) {
    const MeshTopology topology(f, vertex_count);
    const int h = std::uniform_int_distribution<int>(0, 3 * topology.face_count() - 1)(random);
    const int twin = topology.HalfedgeTwin(h);
    const int a = topology.HalfedgeSource(h), b = topology.HalfedgeTarget(h);
    const int c = topology.HalfedgeOpposite(h), d = topology.HalfedgeOpposite(twin);
    if (topology.Valence(a) <= 4 || topology.Valence(b) <= 4) continue;
    bool adjacent = false;
    for (const int r : topology.Ring(c)) adjacent |= r == d;
    if (adjacent) continue;
    f.row(h / 3) << a, d, c;
    f.row(twin / 3) << d, b, c;
    ++done;
  }
  return f;
}

TriangleMesh MidpointSplit(const TriangleMesh& mesh) {
  const MeshTopology topology(mesh.F, mesh.vertex_count());
  const int n = mesh.vertex_count();
  TriangleMesh split;
  split.V.resize(n + topology.edge_count(), 3);
  split.V.topRows(n) = mesh.V;
  for (int e = 0; e < topology.edge_count(); ++e)
    split.V.row(n + e) = (mesh.V.row(topology.EdgeVertex(e, 0)) + mesh.V.row(topology.EdgeVertex(e, 1))).normalized();
  split.F.resize(4 * mesh.F.rows(), 3);
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int ab = n + topology.FaceEdge(f, 0), bc = n + topology.FaceEdge(f, 1), ca = n + topology.FaceEdge(f, 2);
    split.F.row(4 * f) << a, ab, ca;
    split.F.row(4 * f + 1) << ab, b, bc;
    split.F.row(4 * f + 2) << ca, bc, c;
    split.F.row(4 * f + 3) << ab, bc, ca;
  }
  return split;
}

struct Fixture {
  TriangleMesh mesh;
  MeshTopology topology;
  LoopLimitEvaluator evaluator;
  std::vector<FaceSample> samples;
  SparseMatrix limit;

  static TriangleMesh Build() {
    TriangleMesh mesh = MakeIcosphere(3);
    mesh.F = RandomFlips(mesh.F, mesh.vertex_count(), 240, 7);
    for (int level = 0; level < 3; ++level) mesh = MidpointSplit(mesh);
    return mesh;
  }
  Fixture() : mesh(Build()), topology(mesh.F, mesh.vertex_count()), evaluator(topology) {
    for (int f = 0; f < topology.face_count(); ++f) samples.push_back({f, 1.0 / 3, 1.0 / 3});
    limit = evaluator.LimitMatrix(samples);
  }
};

Fixture& Shared() {
  static Fixture fixture;
  return fixture;
}

void BM_EvaluatorConstruction(benchmark::State& state) {
  Fixture& fx = Shared();
  for (auto _ : state) {
    LoopLimitEvaluator evaluator(fx.topology);
    benchmark::DoNotOptimize(&evaluator);
  }
  int stam = 0;
  for (int f = 0; f < fx.topology.face_count(); ++f) stam += fx.evaluator.PatchKind(f) == LimitPatchKind::kStam;
  state.counters["faces"] = fx.topology.face_count();
  state.counters["stam_faces"] = stam;
  state.counters["stam_valences"] = fx.evaluator.StamPatchCount();
}
BENCHMARK(BM_EvaluatorConstruction)->Unit(benchmark::kMillisecond);

void BM_LimitMatrixBuild(benchmark::State& state) {
  Fixture& fx = Shared();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(fx.evaluator.LimitMatrix(fx.samples));
  state.counters["rows"] = static_cast<double>(fx.samples.size());
  state.counters["nonzeros"] = static_cast<double>(fx.limit.nonZeros());
}
BENCHMARK(BM_LimitMatrixBuild)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_LimitMatrixBuildDerivs(benchmark::State& state) {
  Fixture& fx = Shared();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(0));
  SparseMatrix l_u, l_v;
  for (auto _ : state) benchmark::DoNotOptimize(fx.evaluator.LimitMatrix(fx.samples, &l_u, &l_v));
}
BENCHMARK(BM_LimitMatrixBuildDerivs)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_LimitMatrixApply(benchmark::State& state) {
  Fixture& fx = Shared();
  Positions s(fx.samples.size(), 3);
  for (auto _ : state) {
    s.noalias() = fx.limit * fx.mesh.V;
    benchmark::DoNotOptimize(s.data());
  }
}
BENCHMARK(BM_LimitMatrixApply)->Unit(benchmark::kMillisecond);

void BM_EvaluateEachSample(benchmark::State& state) {
  Fixture& fx = Shared();
  Positions s(fx.samples.size(), 3);
  for (auto _ : state) {
    for (size_t i = 0; i < fx.samples.size(); ++i)
      s.row(i) = fx.evaluator.Evaluate(fx.samples[i].face, fx.samples[i].u, fx.samples[i].v, fx.mesh.V).position;
    benchmark::DoNotOptimize(s.data());
  }
}
BENCHMARK(BM_EvaluateEachSample)->Unit(benchmark::kMillisecond);

void BM_TessellationBuild(benchmark::State& state) {
  Fixture& fx = Shared();
  size_t rows = 0;
  for (auto _ : state) {
    const LimitTessellation t = TessellateLimitSurface(fx.topology, static_cast<int>(state.range(0)));
    const SparseMatrix l = fx.evaluator.LimitMatrix(t.samples);
    rows = t.samples.size();
    benchmark::DoNotOptimize(l.nonZeros());
  }
  state.counters["vertices"] = static_cast<double>(rows);
}
BENCHMARK(BM_TessellationBuild)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

void BM_TessellationApply(benchmark::State& state) {
  Fixture& fx = Shared();
  const LimitTessellation t = TessellateLimitSurface(fx.topology, static_cast<int>(state.range(0)));
  const SparseMatrix l = fx.evaluator.LimitMatrix(t.samples);
  Positions s(t.samples.size(), 3);
  for (auto _ : state) {
    s.noalias() = l * fx.mesh.V;
    benchmark::DoNotOptimize(s.data());
  }
  state.counters["vertices"] = static_cast<double>(t.samples.size());
}
BENCHMARK(BM_TessellationApply)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace subflow::geometry

BENCHMARK_MAIN();
