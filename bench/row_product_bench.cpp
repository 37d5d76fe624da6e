// Aᵀ b of the normal-flow solver's data right-hand side (solver/motion/row_product.h), on
// a matrix the size of an HD take's level-hi limit matrix L_hi (300,000 samples × 8,202
// control points, 12 entries a row): TransposeParallelProduct, which forms no Aᵀ, against
// the reference it replaced, RowParallelProduct on a stored transpose (as large as A), and
// Eigen's serial A.transpose() * b.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "solver/motion/row_product.h"

namespace {

using subflow::solver::RowMajorColumns;

struct Operands {
  subflow::geometry::SparseMatrix A, At;
  RowMajorColumns<3> b;
  Operands() {
    constexpr int kRows = 300000, kCols = 8202;
    std::mt19937 random(3);
    std::uniform_int_distribution<int> column(0, kCols - 13);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    std::vector<Eigen::Triplet<double>> entries;
    for (int r = 0; r < kRows; ++r) {
      const int first = column(random);  // a stencil: neighbouring columns, as a 1-ring's
      for (int k = 0; k < 12; ++k) entries.emplace_back(r, first + k, value(random));
    }
    A.resize(kRows, kCols);
    A.setFromTriplets(entries.begin(), entries.end());
    A.makeCompressed();
    At = A.transpose();
    At.makeCompressed();
    b = RowMajorColumns<3>::NullaryExpr(kRows, 3, [&] { return value(random); });
  }
};

const Operands& Data() {
  static const Operands operands;
  return operands;
}

void BM_TransposeParallelProduct(benchmark::State& state) {
  const Operands& o = Data();
  for (auto _ : state) benchmark::DoNotOptimize(subflow::solver::TransposeParallelProduct<3>(o.A, o.b));
}
BENCHMARK(BM_TransposeParallelProduct)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_StoredTransposeRowProduct(benchmark::State& state) {  // the reference: Aᵀ kept
  const Operands& o = Data();
  for (auto _ : state) benchmark::DoNotOptimize(subflow::solver::RowParallelProduct<3>(o.At, o.b));
}
BENCHMARK(BM_StoredTransposeRowProduct)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EigenTransposeProduct(benchmark::State& state) {
  const Operands& o = Data();
  for (auto _ : state) {
    RowMajorColumns<3> result = o.A.transpose() * o.b;
    benchmark::DoNotOptimize(result.data());
  }
}
BENCHMARK(BM_EigenTransposeProduct)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
