// The Ceres linear solver of the stereo refinement, chosen by measurement on our real
// problem: the blob dataset (10 cameras, 320×240), frames 10–12 refined jointly (one
// window) with the default options (normal-only increments; levels 0–1, 400 and 1,600
// patches, by the automatic finest level), starting from the pipeline's own shape and
// motion initialization (computed once).
// Measured 2026-11-26, quiet machine, one run each: sparse_normal_cholesky 9.70 s,
// sparse_schur 10.9 s, cgnr 11.2 s, iterative_schur 11.9 s (same iterations, mean distance
// to the truth 0.19–0.20 mm): the default is sparse_normal_cholesky.
//
// Per solver: wall time of RefineStereo, time inside ceres::Solve, Ceres iterations,
// mean NCC after refinement and the mean distance of the output surface (limit positions
// of the finest vertices) to the ground truth. Run with
//   refinement_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// Threads: SUBFLOW_BENCH_THREADS (default: all cores).
#include <cstdlib>

#include <benchmark/benchmark.h>

#include "geometry/closest_point.h"
#include "geometry/mesh_io.h"
#include "solver/motion/motion_init.h"
#include "solver/shape/shape_init.h"
#include "solver/stereo/stereo_refinement.h"
#include "vision/dataset.h"
#include "vision/image_sequence.h"

namespace {

using namespace subflow;
using geometry::Positions;

constexpr int kFirstFrame = 10, kFrames = 3;

struct Initialized {
  vision::Dataset dataset{SUBFLOW_SHARED_DIR "/data/blob"};
  solver::ShapeInitResult shape;
  std::vector<geometry::TriangleMesh> hulls;
  vision::ImageSequence images;
  std::vector<Positions> control;
  std::vector<geometry::ClosestPointTree> truth;

  Initialized() {
    solver::ShapeInitOptions options;
    options.first_frame = kFirstFrame;
    options.frame_count = kFrames;
    shape = solver::InitializeShape(dataset, options);
    const int finest = shape.hierarchy->finest_level();
    std::vector<Positions> fitted;
    for (const auto& frame : shape.frames) fitted.push_back(frame.control.at(finest));
    for (const auto& frame : shape.frames) hulls.push_back(frame.hull);
    images = vision::DatasetImages(dataset, kFirstFrame, kFrames, vision::EvidenceSource::kAuto, &hulls);
    control = solver::InitializeMotion(images, *shape.hierarchy, fitted, shape.reference_frame - kFirstFrame, {})
                  .control;
    for (int f = 0; f < kFrames; ++f)
      truth.emplace_back(geometry::ReadMesh(dataset.GroundTruthMeshPath(kFirstFrame + f)), "ground truth");
  }
  double MeanDistanceToTruth(const std::vector<Positions>& result) const {
    const geometry::LoopHierarchy& h = *shape.hierarchy;
    double sum = 0.0;
    Eigen::Index count = 0;
    for (int f = 0; f < kFrames; ++f) {
      const Positions surface = h.LimitPositions(h.finest_level()) * result[f];
      for (Eigen::Index i = 0; i < surface.rows(); ++i, ++count)
        sum += (truth[f].Closest(surface.row(i).transpose()).point - surface.row(i).transpose()).norm();
    }
    return sum / static_cast<double>(count);
  }
};

const Initialized& State() {
  static const Initialized state;
  return state;
}

void BM_Refinement(benchmark::State& bench, const char* solver, bool reduced_blocks) {
  const Initialized& s = State();
  solver::StereoRefinementOptions options;
  if (!ceres::StringToLinearSolverType(solver, &options.solver.linear_solver)) std::abort();
  options.solver.reduced_correlation_blocks = reduced_blocks;
  options.rounds = 1;
  options.window = kFrames;
  if (const char* env = std::getenv("SUBFLOW_BENCH_THREADS")) options.solver.threads = std::atoi(env);
  solver::RefinementResult result;
  for (auto _ : bench) {
    result = solver::RefineStereo(s.images, *s.shape.hierarchy, s.control, s.dataset.bounds(), options);
  }
  double solver_seconds = 0, iterations = 0, ncc = 0;
  for (const auto& level : result.levels) {
    solver_seconds += level.solver_seconds;
    iterations += level.iterations;
  }
  for (const auto& frame : result.frames) ncc += frame.ncc_after / kFrames;
  bench.counters["ceres_s"] = solver_seconds;
  bench.counters["iterations"] = iterations;
  bench.counters["ncc_after"] = ncc;
  bench.counters["mean_dist_mm"] = 1e3 * s.MeanDistanceToTruth(result.control);
}

// The reference: correlation blocks with all their residuals (the implementation before
// the reduced form), then every solver on the reduced blocks (the default).
BENCHMARK_CAPTURE(BM_Refinement, full_blocks_sparse_normal_cholesky, "sparse_normal_cholesky", false)
    ->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_Refinement, sparse_normal_cholesky, "sparse_normal_cholesky", true)
    ->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_Refinement, cgnr, "cgnr", true)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_Refinement, iterative_schur, "iterative_schur", true)
    ->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_Refinement, sparse_schur, "sparse_schur", true)
    ->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
