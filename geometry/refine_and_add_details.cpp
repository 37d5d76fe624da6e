// RefineAndAddDetails (local_frames.h): the synthesis step, refinement, frames and details
// in one pass over the vertices of the finer level, in kernels for the x86-64 baseline and
// for AVX2+FMA.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>

#include "core/error.h"
#include "geometry/local_frames.h"
#include "geometry/local_frames_kernels.h"
#include "geometry/loop_weights.h"
#include "geometry/point_stencil.h"
#include "geometry/synthesis_plan.h"

namespace subflow::geometry {
namespace {

using internal::kDegenerateSine;
using internal::TangentsAt;

// Tangents from a general row of T(i)·C(i−1) on the coarse points.
inline void GeneralTangents(const SynthesisPlan& plan, int row, const double* coarse, double* a,
                            double* b) {
  a[0] = a[1] = a[2] = b[0] = b[1] = b[2] = 0.0;
  const double* w = plan.general_weights.data() + 2 * plan.general_offsets[row];
  for (int i = plan.general_offsets[row]; i < plan.general_offsets[row + 1]; ++i, w += 2) {
    const double* x = coarse + 3 * static_cast<Eigen::Index>(plan.general_columns[i]);
    for (int k = 0; k < 3; ++k) {
      a[k] += w[0] * x[k];
      b[k] += w[1] * x[k];
    }
  }
}

// ---- The fused synthesis step (RefineAndAddDetails) ----
//
// Per block of vertices, two phases:
//  1. per vertex, gather its few source points and form the predicted point p and the
//     tangents (t1, t2) of synthesis_plan.h (rotated), stored structure-of-arrays; the AVX2
//     kernels hold the three coordinates of a point in one register (x, y, z, ·), the
//     baseline ones go through the coordinates one at a time;
//  2. element-wise over the block, in loops the compiler vectorizes across vertices: the
//     frame (as FramesOfBlock: degenerate lanes selected, not branched to) and the output
//     row p + d_n n + d_r r + d_q q.
// Both phases exist twice: for the x86-64 baseline (SSE2) and, chosen at run time when the
// CPU has them, for AVX2 with FMA (fused multiply-adds in phase 2 only; this file is
// compiled with -ffp-contract=off, so p, and hence synthesis with zero details, is rounded
// exactly as PointStencil::Apply rounds it in both).
constexpr int kSynthesisBlock = 128;  // 14 doubles × 128 = 14 KiB, within L1

struct SynthesisBlock {
  alignas(64) double p[3][kSynthesisBlock];  // predicted points
  alignas(64) double a[3][kSynthesisBlock];  // tangents t1, t2
  alignas(64) double b[3][kSynthesisBlock];
  alignas(64) double n[3][kSynthesisBlock];       // scratch of phase 2: t1 × t2
  alignas(64) double length[2][kSynthesisBlock];  // |t1 × t2|, |t1|
};

// The inputs and outputs of one step, shared by the block kernels.
struct SynthesisStep {
  const SynthesisPlan* plan;
  const PointStencil* refinement;       // C(level − 1)
  const PointStencil* coarse_tangents;  // tangents of level − 1
  int regular_offset;                   // coarse_tangents' weights of valence-6 vertices
  const double* coarse;                 // c, #V(level − 1)×3
  const double* details;                // d, #V(level)×3
  double* even_points;                  // p of the even vertices (written by the even pass)
                                        // (coarse and even_points: one padding row each)
  double* out;                          // result, #V(level)×3
};

// A point as one vector value (x, y, z, ·) (GCC/Clang vector extension); the fourth lane
// is whatever follows the point in memory, computed with but never stored.
typedef double Point4 __attribute__((vector_size(32)));

#define SUBFLOW_KERNEL inline __attribute__((always_inline))

// Point `index` of a #V×3 array that has (at least) one more double after its last row.
SUBFLOW_KERNEL Point4 LoadPoint(const double* points, int index) {
  Point4 x;
  std::memcpy(&x, points + 3 * static_cast<Eigen::Index>(index), sizeof x);
  return x;
}

SUBFLOW_KERNEL void StoreColumn(double (*soa)[kSynthesisBlock], int j, Point4 value) {
  soa[0][j] = value[0];
  soa[1][j] = value[1];
  soa[2][j] = value[2];
}

// The phase-1 formulas run on a type T of coordinates: Point4 (the three at once, the AVX2
// kernels) or double (one coordinate k at a time, the baseline kernels: with SSE2 a Point4
// is two registers, and ten of them no longer fit in the sixteen).
template <typename T>
constexpr int kCoordinatePasses = std::is_same_v<T, double> ? 3 : 1;

template <typename T>
SUBFLOW_KERNEL T Load(const double* points, int index, int k) {
  if constexpr (std::is_same_v<T, double>)
    return points[3 * static_cast<Eigen::Index>(index) + k];
  else
    return LoadPoint(points, index);
}

template <typename T>
SUBFLOW_KERNEL void Store(double (*soa)[kSynthesisBlock], int j, int k, T value) {
  if constexpr (std::is_same_v<T, double>)
    soa[k][j] = value;
  else
    StoreColumn(soa, j, value);
}

// The tangents t1 = cos φ a − sin φ b, t2 = cos φ b + sin φ a (coordinate k, or all) into
// column j of block->a, block->b.
template <typename T>
SUBFLOW_KERNEL void StoreRotated(double cs, double sn, T a, T b, int j, int k,
                                 SynthesisBlock* block) {
  Store(block->a, j, k, cs * a - sn * b);
  Store(block->b, j, k, cs * b + sn * a);
}

// (cos φ, sin φ) of rotation code `rotation` of the plan's table; (1, 0) for kGeneral.
SUBFLOW_KERNEL void Rotation(const double* rotations, std::uint8_t rotation, double* cs,
                             double* sn) {
  const int index = rotation == SynthesisPlan::kGeneral ? 0 : rotation;
  *cs = rotations[2 * index];
  *sn = rotations[2 * index + 1];
}

// a · b + c, fused (one rounding) in the FMA kernels.
template <bool kFma>
SUBFLOW_KERNEL double MulAdd(double a, double b, double c) {
  if constexpr (kFma) return __builtin_fma(a, b, c);
  return a * b + c;
}

// Phase 2 over the first `size` vertices of the block; d and out start at its first vertex.
// Two element-wise loops, each with some of the slow square roots and divisions beside
// other arithmetic: the cross product c = t1 × t2 with the degenerate lanes selected (as
// FramesOfBlock) and the lengths of the selected c and t1 (exactly 1 on a degenerate lane,
// so no length needs a selection, which would keep the loop from vectorizing); then the
// frame and the output row. The two reciprocal lengths take one division:
// 1/|c| = |t1| e, 1/|t1| = |c| e, e = 1/(|c| |t1|).
template <bool kFma>
SUBFLOW_KERNEL void FinishBlock(SynthesisBlock* block, int size, const double* __restrict d,
                                double* __restrict out) {
  for (int j = 0; j < size; ++j) {
    const double t1[3] = {block->a[0][j], block->a[1][j], block->a[2][j]};
    const double t2[3] = {block->b[0][j], block->b[1][j], block->b[2][j]};
    const double x = MulAdd<kFma>(t1[1], t2[2], -(t1[2] * t2[1]));
    const double y = MulAdd<kFma>(t1[2], t2[0], -(t1[0] * t2[2]));
    const double z = MulAdd<kFma>(t1[0], t2[1], -(t1[1] * t2[0]));
    const double cross2 = MulAdd<kFma>(x, x, MulAdd<kFma>(y, y, z * z));
    const double a_2 = MulAdd<kFma>(t1[0], t1[0], MulAdd<kFma>(t1[1], t1[1], t1[2] * t1[2]));
    const double b_2 = MulAdd<kFma>(t2[0], t2[0], MulAdd<kFma>(t2[1], t2[1], t2[2] * t2[2]));
    const bool regular = cross2 > kDegenerateSine * kDegenerateSine * a_2 * b_2;  // false on NaN
    const double c[3] = {regular ? x : 0.0, regular ? y : 0.0, regular ? z : 1.0};  // or e_z
    const double t[3] = {regular ? t1[0] : 1.0, regular ? t1[1] : 0.0,
                         regular ? t1[2] : 0.0};  // or e_x
    for (int k = 0; k < 3; ++k) {
      block->n[k][j] = c[k];
      block->a[k][j] = t[k];
    }
    // The lengths of the selected vectors: |c| and |t1|, or exactly 1 on a degenerate lane.
    block->length[0][j] = std::sqrt(MulAdd<kFma>(c[0], c[0], MulAdd<kFma>(c[1], c[1], c[2] * c[2])));
    block->length[1][j] = std::sqrt(MulAdd<kFma>(t[0], t[0], MulAdd<kFma>(t[1], t[1], t[2] * t[2])));
  }
  for (int j = 0; j < size; ++j) {
    const double cross_length = block->length[0][j];
    const double a_length = block->length[1][j];
    const double inverse_product = 1.0 / (cross_length * a_length);
    const double inverse_cross = a_length * inverse_product;
    const double inverse_a = cross_length * inverse_product;
    const double n[3] = {block->n[0][j] * inverse_cross, block->n[1][j] * inverse_cross,
                         block->n[2][j] * inverse_cross};
    const double r[3] = {block->a[0][j] * inverse_a, block->a[1][j] * inverse_a,
                         block->a[2][j] * inverse_a};
    const double q[3] = {MulAdd<kFma>(n[1], r[2], -(n[2] * r[1])),
                         MulAdd<kFma>(n[2], r[0], -(n[0] * r[2])),
                         MulAdd<kFma>(n[0], r[1], -(n[1] * r[0]))};
    const double dn = d[3 * j], dr = d[3 * j + 1], dq = d[3 * j + 2];
    for (int k = 0; k < 3; ++k)
      out[3 * j + k] =
          block->p[k][j] + MulAdd<kFma>(dn, n[k], MulAdd<kFma>(dr, r[k], dq * q[k]));
  }
}

// Phase 1 of the even vertices v ∈ [first, first + size): p by the refinement row (Apply's
// sums, in its order; also stored to even_points for the odd pass), tangents by level
// level − 1's stencil at v on the coarse points.
template <typename T>
SUBFLOW_KERNEL void GatherEvenBlock(const SynthesisStep& step, int first, int size,
                                    SynthesisBlock* block) {
  const PointStencil& refinement = *step.refinement;
  const int* offsets = refinement.offsets();
  const int* columns = refinement.columns();
  const int* weight_offsets = refinement.weight_offsets();
  const double* weights = refinement.weights();
  const SynthesisPlan& plan = *step.plan;
  const double* c = step.coarse;
  for (int j = 0; j < size; ++j) {
    const int v = first + j;
    const double* w = weights + weight_offsets[v];
    const int* column = columns + offsets[v];
    const int count = offsets[v + 1] - offsets[v];
    const std::uint8_t rotation = plan.even_rotation[v];
    double cs, sn;
    Rotation(plan.rotations.data(), rotation, &cs, &sn);
    double* even = step.even_points + 3 * static_cast<Eigen::Index>(v);
    if (count == 7 && rotation != SynthesisPlan::kGeneral) {
      // Interior, valence 6: the ring is the row's columns 1..6.
      for (int k = 0; k < kCoordinatePasses<T>; ++k) {
        const T x0 = Load<T>(c, column[0], k), x1 = Load<T>(c, column[1], k),
                x2 = Load<T>(c, column[2], k), x3 = Load<T>(c, column[3], k),
                x4 = Load<T>(c, column[4], k), x5 = Load<T>(c, column[5], k),
                x6 = Load<T>(c, column[6], k);
        T s = w[0] * x0;
        s += w[1] * x1;
        s += w[2] * x2;
        s += w[3] * x3;
        s += w[4] * x4;
        s += w[5] * x5;
        s += w[6] * x6;
        const double h = 0.8660254037844386;  // √3/2
        const T a = (x1 - x4) + 0.5 * ((x2 + x6) - (x3 + x5));
        const T b = h * ((x2 + x3) - (x5 + x6));
        Store(block->p, j, k, s);
        StoreRotated(cs, sn, a, b, j, k, block);
        if constexpr (std::is_same_v<T, double>)
          even[k] = s;
        else
          even[0] = s[0], even[1] = s[1], even[2] = s[2];
      }
    } else {
      Point4 s{0.0, 0.0, 0.0, 0.0};
      for (int i = 0; i < count; ++i) s += w[i] * LoadPoint(c, column[i]);
      double t1[3], t2[3];
      if (rotation == SynthesisPlan::kGeneral)
        GeneralTangents(plan, plan.even_general_row[v], c, t1, t2);
      else
        TangentsAt(*step.coarse_tangents, step.regular_offset, c, v, t1, t2);
      for (int k = 0; k < 3; ++k) {
        even[k] = s[k];
        block->p[k][j] = s[k];
        StoreRotated(cs, sn, t1[k], t2[k], j, k, block);
      }
    }
  }
}

// Phase 1 of the odd vertices nc + e, e ∈ [first, first + size): p = 3/8 (a + b) +
// 1/8 (P + Q) (Apply's order), tangents by the closed form of synthesis_plan.h on the
// coarse and even predicted points; general rows otherwise.
template <typename T>
SUBFLOW_KERNEL void GatherOddBlock(const SynthesisStep& step, int first, int size,
                                   SynthesisBlock* block) {
  const SynthesisPlan& plan = *step.plan;
  const PointStencil& refinement = *step.refinement;
  const double* c = step.coarse;
  const double* even = step.even_points;
  for (int j = 0; j < size; ++j) {
    const int e = first + j;
    const int* col = plan.odd_columns.data() + 8 * static_cast<Eigen::Index>(e);
    const std::uint8_t rotation = plan.odd_rotation[e];
    double cs, sn;
    Rotation(plan.rotations.data(), rotation, &cs, &sn);
    if (rotation == SynthesisPlan::kGeneral) {
      const int m = plan.coarse_vertex_count + e;
      const double* w = refinement.weights() + refinement.weight_offsets()[m];
      Point4 p{0.0, 0.0, 0.0, 0.0};
      for (int i = refinement.offsets()[m]; i < refinement.offsets()[m + 1]; ++i, ++w)
        p += *w * LoadPoint(c, refinement.columns()[i]);
      double t1[3], t2[3];
      GeneralTangents(plan, col[0], c, t1, t2);
      for (int k = 0; k < 3; ++k) {
        block->p[k][j] = p[k];
        StoreRotated(cs, sn, t1[k], t2[k], j, k, block);
      }
      continue;
    }
    for (int k = 0; k < kCoordinatePasses<T>; ++k) {
      const T pa = Load<T>(c, col[0], k), pb = Load<T>(c, col[1], k),
              pp = Load<T>(c, col[2], k), pq = Load<T>(c, col[3], k),
              x1 = Load<T>(c, col[4], k), x2 = Load<T>(c, col[5], k),
              x3 = Load<T>(c, col[6], k), x4 = Load<T>(c, col[7], k),
              ea = Load<T>(even, col[0], k), eb = Load<T>(even, col[1], k);
      const T p = ((kLoopOddEdgeWeight * pa + kLoopOddEdgeWeight * pb) + kLoopOddOppositeWeight * pp) +
                  kLoopOddOppositeWeight * pq;
      const T a = (ea - eb) + 0.25 * (pa - pb) + 0.0625 * ((x1 + x4) - (x2 + x3));
      const double h = 0.8660254037844386;  // √3/2
      const T b = h * (0.75 * (pq - pp) + 0.125 * ((x1 + x2) - (x3 + x4)));
      Store(block->p, j, k, p);
      StoreRotated(cs, sn, a, b, j, k, block);
    }
  }
}

// Even vertices [begin, end) and odd vertices nc + [begin, end) of a step, block by block.
template <bool kFma>
SUBFLOW_KERNEL void EvenVertices(const SynthesisStep& step, int begin, int end) {
  SynthesisBlock block;
  for (int first = begin; first < end; first += kSynthesisBlock) {
    const int size = std::min(kSynthesisBlock, end - first);
    GatherEvenBlock<std::conditional_t<kFma, Point4, double>>(step, first, size, &block);
    FinishBlock<kFma>(&block, size, step.details + 3 * static_cast<Eigen::Index>(first),
                      step.out + 3 * static_cast<Eigen::Index>(first));
  }
}

template <bool kFma>
SUBFLOW_KERNEL void OddVertices(const SynthesisStep& step, int begin, int end) {
  SynthesisBlock block;
  const Eigen::Index nc = step.plan->coarse_vertex_count;
  for (int first = begin; first < end; first += kSynthesisBlock) {
    const int size = std::min(kSynthesisBlock, end - first);
    GatherOddBlock<std::conditional_t<kFma, Point4, double>>(step, first, size, &block);
    FinishBlock<kFma>(&block, size, step.details + 3 * (nc + first),
                      step.out + 3 * (nc + first));
  }
}

void EvenVerticesBaseline(const SynthesisStep& step, int begin, int end) {
  EvenVertices<false>(step, begin, end);
}
void OddVerticesBaseline(const SynthesisStep& step, int begin, int end) {
  OddVertices<false>(step, begin, end);
}

#if defined(__x86_64__) && defined(__GNUC__)
#define SUBFLOW_HAVE_AVX2_KERNELS 1
__attribute__((target("avx2,fma"))) void EvenVerticesAvx2Fma(const SynthesisStep& step,
                                                             int begin, int end) {
  EvenVertices<true>(step, begin, end);
}
__attribute__((target("avx2,fma"))) void OddVerticesAvx2Fma(const SynthesisStep& step,
                                                            int begin, int end) {
  OddVertices<true>(step, begin, end);
}
#endif

bool CpuHasAvx2Fma() {
#ifdef SUBFLOW_HAVE_AVX2_KERNELS
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

}  // namespace

bool SynthesisKernelAvailable(SynthesisKernel kernel) {
  return kernel != SynthesisKernel::kAvx2Fma || CpuHasAvx2Fma();
}

void RefineAndAddDetails(const LoopHierarchy& hierarchy, int level, const Positions& coarse,
                         const Positions& local, Positions* result, SynthesisKernel kernel) {
  SUBFLOW_CHECK(level >= 1 && level <= hierarchy.finest_level(), "level out of range");
  SUBFLOW_CHECK(coarse.rows() == hierarchy.VertexCount(level - 1) &&
                    local.rows() == hierarchy.VertexCount(level),
                "points or details do not match the levels' vertex counts");
  SUBFLOW_CHECK(result != &coarse && result != &local, "output aliases input");
  SUBFLOW_CHECK(SynthesisKernelAvailable(kernel), "the CPU lacks AVX2 or FMA");
  const SynthesisPlan& plan = hierarchy.SynthesisPlanOf(level);
  const PointStencil& coarse_tangents = hierarchy.LimitTangentStencil(level - 1);
  result->resize(hierarchy.VertexCount(level), 3);
  // The coarse points, and the even predicted points p(v) = (C c)(v), v < #V(level − 1)
  // (the odd tangents use them), both with a padding row for LoadPoint.
  const Eigen::Index nc = plan.coarse_vertex_count;
  const std::unique_ptr<double[]> padded_coarse(new double[3 * (nc + 1)]),
      even(new double[3 * (nc + 1)]);  // uninitialized: all but the padding is written
  std::copy(coarse.data(), coarse.data() + 3 * nc, padded_coarse.get());
  std::fill(padded_coarse.get() + 3 * nc, padded_coarse.get() + 3 * (nc + 1), 0.0);
  std::fill(even.get() + 3 * nc, even.get() + 3 * (nc + 1), 0.0);
  const SynthesisStep step{&plan,
                           &hierarchy.RefinementStencil(level - 1),
                           &coarse_tangents,
                           coarse_tangents.PatternWeightOffset(6),
                           padded_coarse.get(),
                           local.data(),
                           even.get(),
                           result->data()};
  auto even_vertices = EvenVerticesBaseline;
  auto odd_vertices = OddVerticesBaseline;
#ifdef SUBFLOW_HAVE_AVX2_KERNELS
  if (kernel == SynthesisKernel::kAvx2Fma || (kernel == SynthesisKernel::kBest && CpuHasAvx2Fma())) {
    even_vertices = EvenVerticesAvx2Fma;
    odd_vertices = OddVerticesAvx2Fma;
  }
#endif
  ForEachRowBlock(plan.coarse_vertex_count,
                  [&](int begin, int end) { even_vertices(step, begin, end); });
  ForEachRowBlock(plan.odd_vertex_count,
                  [&](int begin, int end) { odd_vertices(step, begin, end); });
}
}  // namespace subflow::geometry
