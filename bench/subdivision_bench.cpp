// Re-synthesis is the optimizer's hot path: base control points + details in local
// frames → control points of the finest level. This compares, in one run, on an
// icosphere of 1280 faces (displaced so it is not symmetric) subdivided 4 times
// (327,680 faces, 163,842 vertices):
//   BM_Resynthesis          c(i) = C c(i−1) + F(i) d(i), i = 1..4, frames from the limit
//                           tangents of C c(i−1) (MultiresShape::Synthesize)
//   BM_Refinement           c(4) = C(3) C(2) C(1) C(0) c(0), no details
//   BM_LimitTessellation    s = LimitPositions(4) c(4): the limit surface at every
//                           vertex of the finest level
//   BM_CgalLoopSubdivision  CGAL::Subdivision_method_3::Loop_subdivision, 4 iterations,
//                           on a Surface_mesh of the same base mesh. The subdivision
//                           changes its input, so each iteration starts from a fresh copy
//                           of the base Surface_mesh; the copy is excluded from the
//                           timing (PauseTiming/ResumeTiming).
//   BM_OpenMeshLoop         OpenMesh::Subdivider::Uniform::LoopT (double points), 4
//                           iterations, on a TriMesh of the same base mesh, from a fresh
//                           copy excluded from the timing as for CGAL. Built only when
//                           CMake finds OpenMesh (Debian libopenmesh-dev).
//   BM_HierarchyConstruction  the one-time cost of LoopHierarchy (connectivity and all
//                           operators of levels 0..4), for scale.
//   BM_ResynthesisBaselineKernel  BM_Resynthesis with the synthesis step's x86-64 baseline
//                           (SSE2) kernels, which BM_Resynthesis uses only on CPUs without
//                           AVX2+FMA.
// CGAL and OpenMesh are single-threaded; ours is timed with one TBB thread and with all cores. Run with
//   subdivision_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// How re-synthesis gets its speed (geometry/refine_and_add_details.cpp): one pass per level
// over blocks of 128 vertices; per vertex, its few coarse points are gathered into the
// predicted point and the two tangents (synthesis_plan.h); then the frames and p + F d of
// the whole block in element-wise loops vectorized across vertices (the square roots and
// the one division per vertex spread over both loops). AVX2+FMA kernels are chosen at run
// time, the baseline (SSE2) ones otherwise; the build stays baseline x86-64 (no -march).
//
// Measured 2026-11-26 (2-vCPU AMD EPYC VM with AVX2+FMA, GCC 12, Release; the machine was
// shared with other builds, so CPU time is the steadier figure), medians of 5, 3 runs:
//                                      CPU time (ms)       real time (ms)
//   BM_Resynthesis/threads:1           6.46  6.56  6.95    6.47  9.84  10.4
//   BM_Resynthesis/threads:0           4.89  4.80  4.88    6.55  10.1  10.2
//   BM_ResynthesisBaselineKernel/1     7.38  7.71  8.23    7.43  11.6  12.4
//   BM_Refinement/threads:1            2.19  2.14  2.22
//   BM_CgalLoopSubdivision             37.8  37.0  40.6    42.1  54.3  60.9
//   BM_OpenMeshLoop                    64.7  63.7  67.7    99.4  95.7  101
// Single-thread re-synthesis is 5.6–5.9× faster than CGAL in CPU time (5.5–6.5× real),
// 4.8–5.1× with the baseline kernels, ~10× faster than OpenMesh. Before this method
// (scalar gathers and frames): 11.2–11.4 ms, 3.7× CGAL.
#include <cmath>
#include <memory>
#include <vector>

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#ifdef SUBFLOW_HAVE_OPENMESH
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#endif

#include "geometry/icosphere.h"
#include "geometry/local_frames.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/multires_shape.h"

namespace subflow::geometry {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

constexpr int kLevels = 4;

TriangleMesh DisplacedIcosphere() {
  TriangleMesh mesh = MakeIcosphere(3);  // 642 vertices, 1280 faces
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    const Eigen::RowVector3d p = mesh.V.row(v);
    mesh.V.row(v) *= 1.0 + 0.1 * std::sin(3.0 * p.x() + 1.0) * std::cos(2.0 * p.y()) +
                      0.05 * std::sin(5.0 * p.z());
  }
  return mesh;
}

struct Fixture {
  TriangleMesh base = DisplacedIcosphere();
  LoopHierarchy hierarchy{base.F, base.vertex_count(), kLevels};
  MultiresShape shape;
  Positions finest;

  Fixture() {
    // A finest level with genuine details at every level: the refined base plus a
    // high-frequency radial ripple, decomposed by the analysis.
    Positions fine = hierarchy.Refine(base.V, 0, kLevels);
    for (Eigen::Index v = 0; v < fine.rows(); ++v)
      fine.row(v) *= 1.0 + 0.01 * std::sin(40.0 * fine(v, 0)) * std::sin(37.0 * fine(v, 1));
    shape = MultiresShape::Analyze(hierarchy, fine);
    finest = shape.Synthesize(hierarchy, kLevels);
  }
};

const Fixture& GetFixture() {
  static const Fixture fixture;
  return fixture;
}

// Our loops run in parallel (TBB) over blocks of rows on the finer levels. Argument 1
// limits TBB to one thread, so those rows compare single thread against single thread;
// argument 0 lets TBB use every core. Wall-clock time either way (UseRealTime).
std::unique_ptr<tbb::global_control> ThreadLimit(const benchmark::State& state) {
  if (state.range(0) == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<size_t>(state.range(0)));
}

void BM_Resynthesis(benchmark::State& state) {
  const Fixture& f = GetFixture();
  const auto limit = ThreadLimit(state);
  for (auto _ : state) {
    Positions c = f.shape.Synthesize(f.hierarchy, kLevels);
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["faces"] = f.hierarchy.FaceCount(kLevels);
}
BENCHMARK(BM_Resynthesis)->ArgName("threads")->Arg(1)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);

// The same synthesis with the x86-64 baseline (SSE2) kernels of the step, which
// BM_Resynthesis uses only on CPUs without AVX2+FMA.
void BM_ResynthesisBaselineKernel(benchmark::State& state) {
  const Fixture& f = GetFixture();
  const auto limit = ThreadLimit(state);
  for (auto _ : state) {
    Positions c = f.shape.base(), next;
    for (int level = 1; level <= kLevels; ++level) {
      RefineAndAddDetails(f.hierarchy, level, c, f.shape.Detail(level), &next,
                          SynthesisKernel::kBaseline);
      c.swap(next);
    }
    benchmark::DoNotOptimize(c.data());
  }
}
BENCHMARK(BM_ResynthesisBaselineKernel)->ArgName("threads")->Arg(1)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_Refinement(benchmark::State& state) {
  const Fixture& f = GetFixture();
  const auto limit = ThreadLimit(state);
  for (auto _ : state) {
    Positions c = f.hierarchy.Refine(f.shape.base(), 0, kLevels);
    benchmark::DoNotOptimize(c.data());
  }
}
BENCHMARK(BM_Refinement)->ArgName("threads")->Arg(1)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_LimitTessellation(benchmark::State& state) {
  const Fixture& f = GetFixture();
  const auto limit = ThreadLimit(state);
  for (auto _ : state) {
    Positions s = MultiplyPoints(f.hierarchy.LimitPositions(kLevels), f.finest);
    benchmark::DoNotOptimize(s.data());
  }
}
BENCHMARK(BM_LimitTessellation)->ArgName("threads")->Arg(1)->Arg(0)->UseRealTime()->Unit(benchmark::kMillisecond);

// Builds `mesh` in a reference library's type: add_vertex(x, y, z) returns a Handle,
// add_face(a, b, c) takes three of them.
template <typename Handle, typename AddVertex, typename AddFace>
void CopyMesh(const TriangleMesh& mesh, AddVertex add_vertex, AddFace add_face) {
  std::vector<Handle> vertices;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
    vertices.push_back(add_vertex(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)));
  for (Eigen::Index t = 0; t < mesh.F.rows(); ++t)
    add_face(vertices[mesh.F(t, 0)], vertices[mesh.F(t, 1)], vertices[mesh.F(t, 2)]);
}

// Times `subdivide(mesh)` (which returns the face count it produced) on a fresh copy of
// `base` per iteration, as the reference libraries subdivide in place. Copying and
// destroying the mesh are excluded from the timing; a wrong face count fails the run.
template <typename Mesh, typename Subdivide>
void TimeOnFreshCopies(benchmark::State& state, const Mesh& base, Subdivide subdivide,
                       int expected_faces) {
  for (auto _ : state) {
    state.PauseTiming();
    Mesh mesh = base;
    state.ResumeTiming();
    const int faces = subdivide(mesh);
    benchmark::DoNotOptimize(faces);
    state.PauseTiming();
    if (faces != expected_faces) state.SkipWithError("the subdivision produced a different face count");
    {
      Mesh discard = std::move(mesh);
    }
    state.ResumeTiming();
  }
}

void BM_CgalLoopSubdivision(benchmark::State& state) {
  const Fixture& f = GetFixture();
  SurfaceMesh base;
  CopyMesh<SurfaceMesh::Vertex_index>(
      f.base, [&](double x, double y, double z) { return base.add_vertex(Kernel::Point_3(x, y, z)); },
      [&](auto a, auto b, auto c) { base.add_face(a, b, c); });
  TimeOnFreshCopies(
      state, base,
      [](SurfaceMesh& mesh) {
        CGAL::Subdivision_method_3::Loop_subdivision(
            mesh, CGAL::parameters::number_of_iterations(kLevels));
        return static_cast<int>(mesh.number_of_faces());
      },
      f.hierarchy.FaceCount(kLevels));
}
BENCHMARK(BM_CgalLoopSubdivision)->UseRealTime()->Unit(benchmark::kMillisecond);

#ifdef SUBFLOW_HAVE_OPENMESH
// Double-precision points, as ours and CGAL's (OpenMesh's default is float).
struct OpenMeshTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
};
using OpenMeshTriMesh = OpenMesh::TriMesh_ArrayKernelT<OpenMeshTraits>;

void BM_OpenMeshLoop(benchmark::State& state) {
  const Fixture& f = GetFixture();
  OpenMeshTriMesh base;
  CopyMesh<OpenMeshTriMesh::VertexHandle>(
      f.base, [&](double x, double y, double z) { return base.add_vertex(OpenMesh::Vec3d(x, y, z)); },
      [&](auto a, auto b, auto c) { base.add_face(a, b, c); });
  OpenMesh::Subdivider::Uniform::LoopT<OpenMeshTriMesh, double> loop;
  TimeOnFreshCopies(
      state, base,
      [&loop](OpenMeshTriMesh& mesh) {
        loop(mesh, kLevels);
        return static_cast<int>(mesh.n_faces());
      },
      f.hierarchy.FaceCount(kLevels));
}
BENCHMARK(BM_OpenMeshLoop)->UseRealTime()->Unit(benchmark::kMillisecond);
#endif

void BM_HierarchyConstruction(benchmark::State& state) {
  const Fixture& f = GetFixture();
  for (auto _ : state) {
    LoopHierarchy hierarchy(f.base.F, f.base.vertex_count(), kLevels);
    benchmark::DoNotOptimize(&hierarchy);
  }
}
BENCHMARK(BM_HierarchyConstruction)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace subflow::geometry

BENCHMARK_MAIN();
