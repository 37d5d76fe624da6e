// Motion initialization on the blob dataset (10 cameras, 320×240, 24 frames): seconds per
// frame step, with the stages timed alone as references (visibility, constraint
// building), and the scene-flow end-point error against the ground truth for the motion
// estimate, zero motion and per-frame snapping alone.
//
// Shape: a Loop hierarchy on icosphere(2) (162 base vertices, 2 levels → 2562 finest
// control points) whose finest control points are snapped onto the ground-truth mesh of
// the reference frame (an oracle for shape initialization). "Per-frame snapping alone"
// snaps the same template onto every frame's ground truth independently (the best a
// normal-only, hull-like correspondence can do); "hull" runs use those per-frame fits as
// the per-frame surfaces of the normal correction.
// The sequence benchmarks run once (Iterations(1)); set SUBFLOW_BENCH_FRAMES to use fewer
// frames, SUBFLOW_BENCH_LEVELS=3 for a hierarchy of the product's size (10242 finest
// control points, 20480 faces; `subflow reconstruct` fits 3 levels on a ~400-face hull).
#include <cstdio>
#include <cstdlib>
#include <random>

#include <benchmark/benchmark.h>

#include "geometry/closest_point.h"
#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/loop_operators.h"
#include "geometry/mesh_io.h"
#include "solver/motion/conjugate_gradient.h"
#include "solver/motion/level_matrices.h"
#include "solver/motion/motion_init.h"
#include "solver/shape/surface_snapping.h"
#include "vision/dataset.h"
#include "vision/evaluation.h"
#include "vision/image_sequence.h"

namespace {

using namespace subflow;
using geometry::Positions;

int BenchLevels() {
  const char* env = std::getenv("SUBFLOW_BENCH_LEVELS");
  return env ? std::max(1, std::atoi(env)) : 2;
}
const int kLevels = BenchLevels();

struct Blob {
  vision::Dataset dataset{SUBFLOW_SHARED_DIR "/data/blob"};
  geometry::TriangleMesh base = geometry::MakeIcosphere(2, 0.1);
  geometry::LoopHierarchy hierarchy{base.F, base.vertex_count(), kLevels};
  int frames = 0;
  std::vector<geometry::TriangleMesh> truth;
  std::vector<Positions> fits;  // per frame: the template snapped onto the ground truth

  Blob() {
    frames = dataset.frame_count();
    if (const char* env = std::getenv("SUBFLOW_BENCH_FRAMES")) frames = std::min(frames, std::atoi(env));
    Positions sphere = hierarchy.Refine(base.V, 0, kLevels);
    for (Eigen::Index i = 0; i < sphere.rows(); ++i) sphere.row(i) *= 0.1 / sphere.row(i).norm();
    solver::SurfaceSnapOptions snap;
    snap.iterations = 12;
    for (int f = 0; f < frames; ++f) {
      truth.push_back(geometry::ReadMesh(dataset.GroundTruthMeshPath(f)));
      const geometry::ClosestPointTree tree(truth.back(), "ground truth");
      fits.push_back(solver::SnapToSurface(hierarchy, kLevels, sphere, tree, snap));
    }
  }
  std::vector<cv::Mat> Images(int frame) const {
    std::vector<cv::Mat> images;
    for (int k = 0; k < dataset.camera_count(); ++k) images.push_back(dataset.Gray(k, frame));
    return images;
  }
};

const Blob& GetBlob() {
  static const Blob blob;
  return blob;
}

// One motion step of the blob; the argument chooses the CG's preconditioner: 0 block Jacobi
// alone (the reference: as before 2026-12-04), 1 the defaults (the V-cycle on levels of at
// least multigrid_min_vertices control points: none of the blob's), 2 the V-cycle on every
// level above the base.
void BM_MotionStep(benchmark::State& state) {
  const Blob& blob = GetBlob();
  solver::MotionStepOptions options;
  options.solver.multigrid = state.range(0) != 0;
  if (state.range(0) == 2) options.solver.multigrid_min_vertices = 0;
  const solver::MotionStepEstimator estimator(blob.hierarchy, blob.dataset.cameras(), blob.fits[0], options);
  const std::vector<cv::Mat> before = blob.Images(0), after = blob.Images(1);
  solver::MotionStep step;
  for (auto _ : state) step = estimator.Estimate(blob.fits[0], before, after);
  state.counters["samples"] = step.report.samples;
  state.counters["constraints"] = step.report.constraints;
  state.counters["pruned"] = step.report.pruned;
  state.counters["cg_iterations"] = step.report.cg_iterations;
  state.counters["photometric_zero"] = step.report.photometric_rms_zero;
  state.counters["photometric"] = step.report.photometric_rms;
  for (const solver::LevelSolveReport& level : step.solution.levels) {
    state.counters["unknowns_" + std::to_string(level.level)] = level.unknowns;
    state.counters["cg_last_" + std::to_string(level.level)] = level.cg_iterations;
  }
}
BENCHMARK(BM_MotionStep)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->MeasureProcessCPUTime()->UseRealTime()->Iterations(3);

// Reference: the visibility stage alone (tessellation, 10 z-buffers, per-sample tests).
void BM_VisibilityReference(benchmark::State& state) {
  const Blob& blob = GetBlob();
  const solver::MotionStepEstimator estimator(blob.hierarchy, blob.dataset.cameras(), blob.fits[0]);
  const solver::SurfaceSamples& samples = estimator.samples();
  const Positions X = samples.SamplePositions(blob.fits[0]);
  const Positions normals = samples.SampleNormals(blob.fits[0]);
  for (auto _ : state) {
    auto visibility = estimator.visibility().Compute(blob.dataset.cameras(), blob.fits[0], X, normals);
    benchmark::DoNotOptimize(visibility.visible.data());
  }
}
BENCHMARK(BM_VisibilityReference)->Unit(benchmark::kMillisecond)->UseRealTime();

// Reference: one pass of constraint building (smoothing 20 images, bilinear sampling).
void BM_ConstraintsReference(benchmark::State& state) {
  const Blob& blob = GetBlob();
  const solver::MotionStepEstimator estimator(blob.hierarchy, blob.dataset.cameras(), blob.fits[0]);
  const solver::SurfaceSamples& samples = estimator.samples();
  const Positions X = samples.SamplePositions(blob.fits[0]);
  const auto visibility = estimator.visibility().Compute(blob.dataset.cameras(), blob.fits[0], X,
                                                         samples.SampleNormals(blob.fits[0]));
  const std::vector<cv::Mat> before = blob.Images(0), after = blob.Images(1);
  for (auto _ : state) {
    std::vector<solver::SmoothedImage> sb, sa;
    for (std::size_t k = 0; k < before.size(); ++k) {
      sb.push_back(solver::SmoothImage(before[k], 1.0));
      sa.push_back(solver::SmoothImage(after[k], 1.0));
    }
    auto constraints = solver::BuildStepConstraints(blob.dataset.cameras(), sb, sa, X, Positions(), visibility);
    benchmark::DoNotOptimize(constraints.rhs.data());
  }
}
BENCHMARK(BM_ConstraintsReference)->Unit(benchmark::kMillisecond)->UseRealTime();

// The CG matrices of the solver's levels from the block sums of the finest estimated level
// (one IRLS solve's worth), on the blob's sample stencils: the current path
// (level_matrices.h: precomputed coarsening map, values written into a fixed pattern)
// against the previous one kept as the reference (Kron3 sparse triple products per level,
// then A += κ·regularizer as an Eigen sparse sum). Both start from the interleaved
// finest-level matrix / its block sums; max_difference compares their matrices.
using Sparse = Eigen::SparseMatrix<double>;

Sparse Kron3(const geometry::SparseMatrix& A) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (int r = 0; r < A.outerSize(); ++r)
    for (geometry::SparseMatrix::InnerIterator it(A, r); it; ++it)
      for (int a = 0; a < 3; ++a)
        triplets.emplace_back(3 * static_cast<int>(it.row()) + a, 3 * static_cast<int>(it.col()) + a, it.value());
  Sparse result(3 * A.rows(), 3 * A.cols());
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

struct LevelMatricesCase {
  int lo = 0, hi = 0;
  std::vector<solver::SymmetricPattern> pattern;
  std::vector<geometry::SparseMatrix> map;    // level + 1 → level
  std::vector<Sparse> refinement3, regularizer3;
  std::vector<solver::LevelMatrix> level;
  std::vector<double> sums;                   // of level hi
  Sparse finest;                              // interleaved data matrix of level hi

  LevelMatricesCase() {
    const Blob& blob = GetBlob();
    const solver::MotionStepEstimator estimator(blob.hierarchy, blob.dataset.cameras(), blob.fits[0]);
    lo = estimator.solver().coarsest_level();
    hi = estimator.solver().finest_estimated_level();
    geometry::SparseMatrix L = estimator.samples().limit;
    for (int l = kLevels - 1; l >= hi; --l) L = geometry::SparseMatrix(L * blob.hierarchy.Refinement(l));
    L.prune(1.0, 1e-12);
    Sparse ones = L;
    for (int k = 0; k < ones.outerSize(); ++k)
      for (Sparse::InnerIterator it(ones, k); it; ++it) it.valueRef() = 1.0;
    pattern.resize(hi + 1);
    map.resize(hi + 1);
    refinement3.resize(hi + 1);
    regularizer3.resize(hi + 1);
    level.resize(hi + 1);
    pattern[hi] = solver::MakeSymmetricPattern(Sparse(ones.transpose() * ones));
    for (int l = hi - 1; l >= lo; --l) {
      map[l] = solver::CoarseningMap(pattern[l + 1], blob.hierarchy.Refinement(l), &pattern[l]);
      refinement3[l] = Kron3(blob.hierarchy.Refinement(l));
    }
    for (int l = lo; l <= hi; ++l) {
      const geometry::SparseMatrix U = geometry::UmbrellaLaplacian(blob.hierarchy.Topology(l));
      Sparse identity(3 * U.rows(), 3 * U.rows());
      identity.setIdentity();
      regularizer3[l] = Kron3(geometry::SparseMatrix(U.transpose() * U)) + 0.01 * identity;
      level[l] = solver::MakeLevelMatrix(pattern[l], regularizer3[l]);
    }
    sums.assign(6 * static_cast<std::size_t>(pattern[hi].entries()), 0.0);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> value(0.0, 1.0);
    for (double& v : sums) v = value(random);
    const Sparse empty(regularizer3[hi].rows(), regularizer3[hi].cols());
    finest = solver::AssembleLevelMatrix(solver::MakeLevelMatrix(pattern[hi], empty), sums, 0.0);
  }
};

const LevelMatricesCase& GetLevelMatricesCase() {
  static const LevelMatricesCase instance;
  return instance;
}

std::vector<Sparse> LevelMatricesReference(const LevelMatricesCase& c) {
  std::vector<Sparse> data(c.hi + 1);
  data[c.hi] = c.finest;
  for (int l = c.hi - 1; l >= c.lo; --l)
    data[l] = Sparse(c.refinement3[l].transpose() * Sparse(data[l + 1] * c.refinement3[l]));
  for (int l = c.lo; l <= c.hi; ++l) {
    const double stiffness = data[l].diagonal().sum() / data[l].rows();
    data[l] += stiffness * c.regularizer3[l];
    data[l].makeCompressed();
  }
  return data;
}

std::vector<Sparse> LevelMatricesCurrent(const LevelMatricesCase& c) {
  std::vector<std::vector<double>> sums(c.hi + 1);
  sums[c.hi] = c.sums;
  for (int l = c.hi - 1; l >= c.lo; --l) sums[l] = solver::CoarsenBlockSums(c.map[l], sums[l + 1]);
  std::vector<Sparse> matrices(c.hi + 1);
  for (int l = c.lo; l <= c.hi; ++l)
    matrices[l] = solver::AssembleLevelMatrix(c.level[l], sums[l], solver::DataStiffness(c.level[l], sums[l]));
  return matrices;
}

void BM_LevelMatricesReference(benchmark::State& state) {
  const LevelMatricesCase& c = GetLevelMatricesCase();
  for (auto _ : state) benchmark::DoNotOptimize(LevelMatricesReference(c).data());
  state.counters["finest_unknowns"] = static_cast<double>(c.finest.rows());
}
BENCHMARK(BM_LevelMatricesReference)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_LevelMatrices(benchmark::State& state) {
  const LevelMatricesCase& c = GetLevelMatricesCase();
  for (auto _ : state) benchmark::DoNotOptimize(LevelMatricesCurrent(c).data());
  const std::vector<Sparse> reference = LevelMatricesReference(c), current = LevelMatricesCurrent(c);
  double difference = 0.0;
  for (int l = c.lo; l <= c.hi; ++l) difference = std::max(difference, Eigen::MatrixXd(reference[l] - current[l]).cwiseAbs().maxCoeff());
  state.counters["max_difference"] = difference;
}
BENCHMARK(BM_LevelMatrices)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// The CG matrix–vector product on the finest estimated level's assembled matrix: the 3×3
// block form (conjugate_gradient.h) against the scalar column form kept as the reference.
void BM_CgProductReference(benchmark::State& state) {
  const LevelMatricesCase& c = GetLevelMatricesCase();
  const Sparse A = LevelMatricesCurrent(c)[c.hi];
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 1.0);
  Eigen::VectorXd y(A.rows());
  for (auto _ : state) solver::MultiplySymmetric(A, x, &y);
  state.counters["nonzeros"] = static_cast<double>(A.nonZeros());
}
BENCHMARK(BM_CgProductReference)->Unit(benchmark::kMicrosecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_CgProduct(benchmark::State& state) {
  const LevelMatricesCase& c = GetLevelMatricesCase();
  const Sparse A = LevelMatricesCurrent(c)[c.hi];
  const solver::BlockSparseMatrix blocks = solver::MakeBlockSparse(A);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 1.0);
  Eigen::VectorXd y(A.rows()), reference(A.rows());
  for (auto _ : state) solver::MultiplySymmetric(blocks, x, &y);
  solver::MultiplySymmetric(A, x, &reference);
  state.counters["max_difference"] = (y - reference).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_CgProduct)->Unit(benchmark::kMicrosecond)->MeasureProcessCPUTime()->UseRealTime();

// One CG solve of the finest estimated level as the motion solver runs it: the scalar
// matrix assembled, then converted to blocks inside the solve (the reference, as before
// 2026-12-04), against the values written straight into the blocks (AssembleLevelBlocks).
// 136 iterations: the blob's mean per solve (1,222 a step over 3 levels × 3 passes).
constexpr int kLevelSolveIterations = 136;

struct LevelSolveCase {
  const LevelMatricesCase& c = GetLevelMatricesCase();
  const double stiffness = solver::DataStiffness(c.level[c.hi], c.sums);
  const Eigen::VectorXd b =
      Eigen::VectorXd::LinSpaced(static_cast<Eigen::Index>(c.level[c.hi].diagonal_slot.size()), -1.0, 1.0);
};

void BM_LevelSolveReference(benchmark::State& state) {
  const LevelSolveCase s;
  for (auto _ : state) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(s.b.size());
    const Sparse A = solver::AssembleLevelMatrix(s.c.level[s.c.hi], s.c.sums, s.stiffness);
    state.counters["cg_iterations"] = solver::SolveConjugateGradient(A, s.b, 1e-4, kLevelSolveIterations, &x).iterations;
  }
}
BENCHMARK(BM_LevelSolveReference)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_LevelSolve(benchmark::State& state) {
  const LevelSolveCase s;
  Eigen::VectorXd x, reference = Eigen::VectorXd::Zero(s.b.size());
  for (auto _ : state) {
    x = Eigen::VectorXd::Zero(s.b.size());
    const solver::BlockSparseMatrix A = solver::AssembleLevelBlocks(s.c.level[s.c.hi], s.c.sums, s.stiffness);
    state.counters["cg_iterations"] = solver::SolveConjugateGradient(A, s.b, 1e-4, kLevelSolveIterations, &x).iterations;
  }
  solver::SolveConjugateGradient(solver::AssembleLevelMatrix(s.c.level[s.c.hi], s.c.sums, s.stiffness), s.b, 1e-4,
                                 kLevelSolveIterations, &reference);
  state.counters["max_difference"] = (x - reference).cwiseAbs().maxCoeff();
}
BENCHMARK(BM_LevelSolve)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

// End-point error of a per-frame sequence of finest control points, on the limit
// tessellation (density 2), motion = vertex differences (or zero).
vision::EvaluationReport Evaluate(const Blob& blob, const std::vector<Positions>& control,
                                  bool zero_motion) {
  const solver::VisibilityTester tessellator(blob.hierarchy, kLevels);
  vision::EvaluationOptions options;
  options.samples = 5000;
  return vision::EvaluateSequence(
      blob.frames, [&](int f) { return blob.truth[f]; },
      [&](int f) {
        vision::EvaluationFrame frame;
        frame.mesh = tessellator.Tessellation(control[f]);
        if (zero_motion) frame.motion = Positions::Zero(frame.mesh.vertex_count(), 3);
        return frame;
      },
      options);
}

void Report(benchmark::State& state, const vision::EvaluationReport& report) {
  state.counters["epe_mean_mm"] = 1e3 * report.overall.flow.epe_mean;
  state.counters["epe_median_mm"] = 1e3 * report.overall.flow.epe_median;
  state.counters["epe_relative"] = report.overall.flow.epe_relative;
  state.counters["true_motion_mm"] = 1e3 * report.overall.flow.true_motion_mean;
  state.counters["chamfer_mm"] = 1e3 * report.overall.surface.chamfer;
}

void BM_BlobZeroMotion(benchmark::State& state) {
  const Blob& blob = GetBlob();
  vision::EvaluationReport report;
  for (auto _ : state) report = Evaluate(blob, blob.fits, true);
  Report(state, report);
}
BENCHMARK(BM_BlobZeroMotion)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_BlobPerFrameSnapping(benchmark::State& state) {
  const Blob& blob = GetBlob();
  vision::EvaluationReport report;
  for (auto _ : state) report = Evaluate(blob, blob.fits, false);
  Report(state, report);
}
BENCHMARK(BM_BlobPerFrameSnapping)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// state.range(0): hull weight in percent (0 = only the reference frame's fit is used).
void BM_BlobMotionInit(benchmark::State& state) {
  const Blob& blob = GetBlob();
  solver::MotionInitOptions options;
  options.hull_weight = state.range(0) / 100.0;
  std::vector<Positions> initial =
      options.hull_weight > 0.0 ? blob.fits : std::vector<Positions>{blob.fits[0]};
  solver::MotionInitResult result;
  const vision::ImageSequence images = vision::DatasetImages(blob.dataset, 0, blob.frames);
  for (auto _ : state) result = solver::InitializeMotion(images, blob.hierarchy, initial, 0, options);
  double step_seconds = 0.0;
  for (int f = 1; f < blob.frames; ++f) step_seconds += result.frames[f].step.seconds;
  state.counters["seconds_per_step"] = step_seconds / std::max(1, blob.frames - 1);
  Report(state, Evaluate(blob, result.control, false));
}
BENCHMARK(BM_BlobMotionInit)->Arg(0)->Arg(50)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
