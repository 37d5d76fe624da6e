#include "geometry/local_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Geometry>

#include "geometry/error.h"
#include "geometry/point_stencil.h"

namespace subflow::geometry {
namespace {

// Relative size of |t1 × t2| against |t1||t2| below which a frame counts as degenerate.
constexpr double kDegenerateSine = 1e-12;

// The frame of one vertex from its tangents a = t1, b = t2 (raw doubles: this runs once
// per vertex of every level on the synthesis hot path).
inline void FrameFromTangentsRaw(const double* a, const double* b, double* n, double* r,
                                 double* q) {
  const double c0 = a[1] * b[2] - a[2] * b[1];
  const double c1 = a[2] * b[0] - a[0] * b[2];
  const double c2 = a[0] * b[1] - a[1] * b[0];
  const double cross2 = c0 * c0 + c1 * c1 + c2 * c2;
  const double a2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
  const double b2 = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
  if (!(cross2 > kDegenerateSine * kDegenerateSine * a2 * b2)) {  // also catches NaN
    n[0] = 0.0, n[1] = 0.0, n[2] = 1.0;
    r[0] = 1.0, r[1] = 0.0, r[2] = 0.0;
    q[0] = 0.0, q[1] = 1.0, q[2] = 0.0;
    return;
  }
  const double inverse_cross = 1.0 / std::sqrt(cross2);
  const double inverse_a = 1.0 / std::sqrt(a2);
  n[0] = c0 * inverse_cross, n[1] = c1 * inverse_cross, n[2] = c2 * inverse_cross;
  r[0] = a[0] * inverse_a, r[1] = a[1] * inverse_a, r[2] = a[2] * inverse_a;  // t1 ⟂ n
  q[0] = n[1] * r[2] - n[2] * r[1];
  q[1] = n[2] * r[0] - n[0] * r[2];
  q[2] = n[0] * r[1] - n[1] * r[0];
}

// Both tangents of vertex v from the two-channel tangent stencil. Regular vertices
// (pattern key 6, the vast majority on fine levels) use the closed form of the masks
// cos/sin(2πj/6) = (1, ½, −½, −1, −½, ½) / (0, h, h, 0, −h, −h), h = √3/2.
inline void TangentsAt(const PointStencil& stencil, int regular_offset, const double* points,
                       int v, double* a, double* b) {
  const int* offsets = stencil.offsets();
  const int* columns = stencil.columns();
  const int weight_offset = stencil.weight_offsets()[v];
  if (weight_offset == regular_offset) {
    const int* ring = columns + offsets[v];
    const double* p0 = points + 3 * static_cast<Eigen::Index>(ring[0]);
    const double* p1 = points + 3 * static_cast<Eigen::Index>(ring[1]);
    const double* p2 = points + 3 * static_cast<Eigen::Index>(ring[2]);
    const double* p3 = points + 3 * static_cast<Eigen::Index>(ring[3]);
    const double* p4 = points + 3 * static_cast<Eigen::Index>(ring[4]);
    const double* p5 = points + 3 * static_cast<Eigen::Index>(ring[5]);
    const double h = 0.8660254037844386;  // √3/2
    for (int k = 0; k < 3; ++k) {
      a[k] = (p0[k] - p3[k]) + 0.5 * ((p1[k] + p5[k]) - (p2[k] + p4[k]));
      b[k] = h * ((p1[k] + p2[k]) - (p4[k] + p5[k]));
    }
    return;
  }
  const double* w = stencil.weights() + weight_offset;
  a[0] = a[1] = a[2] = b[0] = b[1] = b[2] = 0.0;
  for (int i = offsets[v]; i < offsets[v + 1]; ++i, w += 2) {
    const double* p = points + 3 * static_cast<Eigen::Index>(columns[i]);
    for (int k = 0; k < 3; ++k) {
      a[k] += w[0] * p[k];
      b[k] += w[1] * p[k];
    }
  }
}

// The frame kernel in batches. One vertex at a time, the frame is scalar arithmetic with a
// branch (the degenerate case) around two square roots and two divisions, the slowest
// instructions of the pass. So a block of vertices first gathers its tangents into
// structure-of-arrays buffers, then computes all its frames in branch-free element-wise
// loops that run two vertices per vector instruction (SSE2, the x86-64 baseline; Eigen's
// packets for the square root and division). Every lane does FrameFromTangentsRaw's
// operations in its order, so the frames are identical to it bit for bit (the degenerate
// frame is selected, not branched to).
constexpr int kFrameBlock = 256;  // 17 doubles × 256 = 34 KiB: about L1

struct FrameBlock {
  alignas(64) double a[3][kFrameBlock];
  alignas(64) double b[3][kFrameBlock];
  alignas(64) double n[3][kFrameBlock];
  alignas(64) double r[3][kFrameBlock];
  alignas(64) double q[3][kFrameBlock];
  alignas(64) double length[2][kFrameBlock];  // scratch: |t1 × t2|, |t1| (squared, inverted)
};

// Tangents of vertices begin .. begin + count − 1 into block->a, block->b.
inline void GatherTangents(const PointStencil& stencil, int regular_offset,
                           const double* points, int begin, int count, FrameBlock* block) {
  double a[3], b[3];
  for (int j = 0; j < count; ++j) {
    TangentsAt(stencil, regular_offset, points, begin + j, a, b);
    for (int k = 0; k < 3; ++k) {
      block->a[k][j] = a[k];
      block->b[k][j] = b[k];
    }
  }
}

// Frames of the first `count` tangent pairs of the block (block->n, r, q), in three
// element-wise passes the compiler vectorizes:
//  1. the cross product c = t1 × t2 into n, t1 into r and the squared lengths |c|², |t1|²;
//     a degenerate lane gets c = e_z, t1 = e_x and squared lengths 1 instead (selected
//     values, no branch);
//  2. the reciprocal lengths 1/√· (Eigen's packet square root and division, IEEE-exact
//     like the scalar ones);
//  3. n = c/|c|, r = t1/|t1|, q = n × r. On a degenerate lane the factors are exactly 1,
//     so the frame is exactly (e_z, e_x, e_y), FrameFromTangentsRaw's fallback.
template <typename Block>
inline void FramesOfBlock(int count, Block* block) {
  const double* __restrict a0 = block->a[0];
  const double* __restrict a1 = block->a[1];
  const double* __restrict a2 = block->a[2];
  const double* __restrict b0 = block->b[0];
  const double* __restrict b1 = block->b[1];
  const double* __restrict b2 = block->b[2];
  double* __restrict n0 = block->n[0];
  double* __restrict n1 = block->n[1];
  double* __restrict n2 = block->n[2];
  double* __restrict r0 = block->r[0];
  double* __restrict r1 = block->r[1];
  double* __restrict r2 = block->r[2];
  double* __restrict cross_length = block->length[0];
  double* __restrict a_length = block->length[1];
  for (int j = 0; j < count; ++j) {
    const double x = a1[j] * b2[j] - a2[j] * b1[j];
    const double y = a2[j] * b0[j] - a0[j] * b2[j];
    const double z = a0[j] * b1[j] - a1[j] * b0[j];
    const double cross2 = x * x + y * y + z * z;
    const double a_2 = a0[j] * a0[j] + a1[j] * a1[j] + a2[j] * a2[j];
    const double b_2 = b0[j] * b0[j] + b1[j] * b1[j] + b2[j] * b2[j];
    const bool regular = cross2 > kDegenerateSine * kDegenerateSine * a_2 * b_2;  // false on NaN
    n0[j] = regular ? x : 0.0;
    n1[j] = regular ? y : 0.0;
    n2[j] = regular ? z : 1.0;
    r0[j] = regular ? a0[j] : 1.0;
    r1[j] = regular ? a1[j] : 0.0;
    r2[j] = regular ? a2[j] : 0.0;
    cross_length[j] = regular ? cross2 : 1.0;
    a_length[j] = regular ? a_2 : 1.0;
  }
  for (double* length2 : {cross_length, a_length}) {
    Eigen::Map<Eigen::ArrayXd> values(length2, count);
    values = values.sqrt().inverse();
  }
  double* __restrict q0 = block->q[0];
  double* __restrict q1 = block->q[1];
  double* __restrict q2 = block->q[2];
  for (int j = 0; j < count; ++j) {
    const double n_0 = n0[j] * cross_length[j], n_1 = n1[j] * cross_length[j],
                 n_2 = n2[j] * cross_length[j];
    const double r_0 = r0[j] * a_length[j], r_1 = r1[j] * a_length[j], r_2 = r2[j] * a_length[j];
    n0[j] = n_0, n1[j] = n_1, n2[j] = n_2;
    r0[j] = r_0, r1[j] = r_1, r2[j] = r_2;
    q0[j] = n_1 * r_2 - n_2 * r_1;
    q1[j] = n_2 * r_0 - n_0 * r_2;
    q2[j] = n_0 * r_1 - n_1 * r_0;
  }
}

// The fused step's block: FrameBlock's arrays plus the predicted points, half as long so
// that it stays within L1 as well.
constexpr int kFusedBlock = 128;

struct FusedBlock {
  alignas(64) double a[3][kFusedBlock];
  alignas(64) double b[3][kFusedBlock];
  alignas(64) double n[3][kFusedBlock];
  alignas(64) double r[3][kFusedBlock];
  alignas(64) double q[3][kFusedBlock];
  alignas(64) double length[2][kFusedBlock];
  alignas(64) double p[3][kFusedBlock];
};

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

// out rows = block.p + F d for the block's vertices, d and out starting at `first`.
template <typename Block>
inline void WriteDetailed(const Block& block, int size, const double* __restrict d,
                          double* __restrict out) {
  for (int j = 0; j < size; ++j)
    for (int k = 0; k < 3; ++k)
      out[3 * j + k] = block.p[k][j] + (d[3 * j] * block.n[k][j] + d[3 * j + 1] * block.r[k][j] +
                                        d[3 * j + 2] * block.q[k][j]);
}

}  // namespace

void FrameFromTangents(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                       Eigen::Vector3d* n, Eigen::Vector3d* r, Eigen::Vector3d* q) {
  FrameFromTangentsRaw(t1.data(), t2.data(), n->data(), r->data(), q->data());
}

Positions LocalFrames::ToWorld(const Positions& local) const {
  SUBFLOW_CHECK(local.rows() == normal.rows(), "local vectors do not match the frames");
  Positions world(local.rows(), 3);
  for (Eigen::Index v = 0; v < local.rows(); ++v)
    world.row(v) = local(v, 0) * normal.row(v) + local(v, 1) * r.row(v) + local(v, 2) * q.row(v);
  return world;
}

Positions LocalFrames::ToLocal(const Positions& world) const {
  SUBFLOW_CHECK(world.rows() == normal.rows(), "world vectors do not match the frames");
  Positions local(world.rows(), 3);
  for (Eigen::Index v = 0; v < world.rows(); ++v) {
    local(v, 0) = world.row(v).dot(normal.row(v));
    local(v, 1) = world.row(v).dot(r.row(v));
    local(v, 2) = world.row(v).dot(q.row(v));
  }
  return local;
}

LocalFrames FramesFromTangents(const Positions& t1, const Positions& t2) {
  SUBFLOW_CHECK(t1.rows() == t2.rows(), "tangent counts differ");
  const Eigen::Index count = t1.rows();
  LocalFrames frames;
  frames.normal.resize(count, 3);
  frames.r.resize(count, 3);
  frames.q.resize(count, 3);
  Eigen::Vector3d n, r, q;
  for (Eigen::Index v = 0; v < count; ++v) {
    FrameFromTangents(t1.row(v).transpose(), t2.row(v).transpose(), &n, &r, &q);
    frames.normal.row(v) = n.transpose();
    frames.r.row(v) = r.transpose();
    frames.q.row(v) = q.transpose();
  }
  return frames;
}

LocalFrames ComputeLocalFrames(const LoopHierarchy& hierarchy, int level,
                               const Positions& control_points) {
  SUBFLOW_CHECK(control_points.rows() == hierarchy.VertexCount(level),
                "control points do not match the level's vertex count");
  const PointStencil& stencil = hierarchy.LimitTangentStencil(level);
  const int regular_offset = stencil.PatternWeightOffset(6);
  const int count = static_cast<int>(control_points.rows());
  LocalFrames frames;
  frames.normal.resize(count, 3);
  frames.r.resize(count, 3);
  frames.q.resize(count, 3);
  ForEachRowBlock(count, [&](int begin, int end) {
    FrameBlock block;
    for (int first = begin; first < end; first += kFrameBlock) {
      const int size = std::min(kFrameBlock, end - first);
      GatherTangents(stencil, regular_offset, control_points.data(), first, size, &block);
      FramesOfBlock(size, &block);
      for (int j = 0; j < size; ++j) {
        const Eigen::Index v = first + j;
        for (int k = 0; k < 3; ++k) {
          frames.normal(v, k) = block.n[k][j];
          frames.r(v, k) = block.r[k][j];
          frames.q(v, k) = block.q[k][j];
        }
      }
    }
  });
  return frames;
}

void AddDetailsInLocalFrames(const LoopHierarchy& hierarchy, int level,
                             const Positions& predicted, const Positions& local,
                             Positions* result) {
  SUBFLOW_CHECK(predicted.rows() == hierarchy.VertexCount(level) &&
                    local.rows() == predicted.rows(),
                "points or details do not match the level's vertex count");
  SUBFLOW_CHECK(result != &predicted && result != &local, "output aliases input");
  const PointStencil& stencil = hierarchy.LimitTangentStencil(level);
  const int regular_offset = stencil.PatternWeightOffset(6);
  const int count = static_cast<int>(predicted.rows());
  result->resize(count, 3);
  const double* p = predicted.data();
  const double* d = local.data();
  double* out = result->data();
  ForEachRowBlock(count, [&](int begin, int end) {
    FrameBlock block;
    for (int first = begin; first < end; first += kFrameBlock) {
      const int size = std::min(kFrameBlock, end - first);
      GatherTangents(stencil, regular_offset, p, first, size, &block);
      FramesOfBlock(size, &block);
      const double* __restrict pv = p + 3 * static_cast<Eigen::Index>(first);
      const double* __restrict dv = d + 3 * static_cast<Eigen::Index>(first);
      double* __restrict ov = out + 3 * static_cast<Eigen::Index>(first);
      for (int j = 0; j < size; ++j)
        for (int k = 0; k < 3; ++k)
          ov[3 * j + k] = pv[3 * j + k] + (dv[3 * j] * block.n[k][j] + dv[3 * j + 1] * block.r[k][j] +
                                           dv[3 * j + 2] * block.q[k][j]);
    }
  });
}

void RefineAndAddDetails(const LoopHierarchy& hierarchy, int level, const Positions& coarse,
                         const Positions& local, Positions* result) {
  SUBFLOW_CHECK(level >= 1 && level <= hierarchy.finest_level(), "level out of range");
  SUBFLOW_CHECK(coarse.rows() == hierarchy.VertexCount(level - 1) &&
                    local.rows() == hierarchy.VertexCount(level),
                "points or details do not match the levels' vertex counts");
  SUBFLOW_CHECK(result != &coarse && result != &local, "output aliases input");
  const SynthesisPlan& plan = hierarchy.SynthesisPlanOf(level);
  const PointStencil& refinement = hierarchy.RefinementStencil(level - 1);
  const PointStencil& coarse_tangents = hierarchy.LimitTangentStencil(level - 1);
  const int regular_offset = coarse_tangents.PatternWeightOffset(6);
  const int nc = plan.coarse_vertex_count;
  result->resize(hierarchy.VertexCount(level), 3);
  // The even predicted points p(v) = (C c)(v), v < #V(level − 1): the odd tangents use them.
  Positions even(nc, 3);
  const double* c = coarse.data();
  const double* d = local.data();
  double* out = result->data();
  double* even_points = even.data();
  const int* offsets = refinement.offsets();
  const int* columns = refinement.columns();
  const int* weight_offsets = refinement.weight_offsets();
  const double* weights = refinement.weights();
  const double* rotations = plan.rotations.data();

  // Even vertices: p by the refinement row (Apply's sums, in its order), tangents by level
  // level − 1's stencil at v on the coarse points, rotated.
  ForEachRowBlock(nc, [&](int begin, int end) {
    FusedBlock block;
    for (int first = begin; first < end; first += kFusedBlock) {
      const int size = std::min(kFusedBlock, end - first);
      for (int j = 0; j < size; ++j) {
        const int v = first + j;
        const double* w = weights + weight_offsets[v];
        const int* column = columns + offsets[v];
        const int count = offsets[v + 1] - offsets[v];
        double s[3] = {0.0, 0.0, 0.0};
        for (int i = 0; i < count; ++i) {
          const double* x = c + 3 * static_cast<Eigen::Index>(column[i]);
          s[0] += w[i] * x[0];
          s[1] += w[i] * x[1];
          s[2] += w[i] * x[2];
        }
        double t1[3], t2[3];
        const std::uint8_t rotation = plan.even_rotation[v];
        if (rotation == SynthesisPlan::kGeneral) {
          GeneralTangents(plan, plan.even_general_row[v], c, t1, t2);
        } else {
          double a[3], b[3];
          if (count == 7) {  // interior, valence 6: the ring is the row's columns 1..6
            const double* p0 = c + 3 * static_cast<Eigen::Index>(column[1]);
            const double* p1 = c + 3 * static_cast<Eigen::Index>(column[2]);
            const double* p2 = c + 3 * static_cast<Eigen::Index>(column[3]);
            const double* p3 = c + 3 * static_cast<Eigen::Index>(column[4]);
            const double* p4 = c + 3 * static_cast<Eigen::Index>(column[5]);
            const double* p5 = c + 3 * static_cast<Eigen::Index>(column[6]);
            const double h = 0.8660254037844386;  // √3/2
            for (int k = 0; k < 3; ++k) {
              a[k] = (p0[k] - p3[k]) + 0.5 * ((p1[k] + p5[k]) - (p2[k] + p4[k]));
              b[k] = h * ((p1[k] + p2[k]) - (p4[k] + p5[k]));
            }
          } else {
            TangentsAt(coarse_tangents, regular_offset, c, v, a, b);
          }
          const double cs = rotations[2 * rotation], sn = rotations[2 * rotation + 1];
          for (int k = 0; k < 3; ++k) {
            t1[k] = cs * a[k] - sn * b[k];
            t2[k] = cs * b[k] + sn * a[k];
          }
        }
        for (int k = 0; k < 3; ++k) {
          even_points[3 * static_cast<Eigen::Index>(v) + k] = s[k];
          block.p[k][j] = s[k];
          block.a[k][j] = t1[k];
          block.b[k][j] = t2[k];
        }
      }
      FramesOfBlock(size, &block);
      WriteDetailed(block, size, d + 3 * static_cast<Eigen::Index>(first),
                    out + 3 * static_cast<Eigen::Index>(first));
    }
  });

  // Odd vertices: p = 3/8 (a + b) + 1/8 (P + Q) (Apply's order), tangents by the closed
  // form of synthesis_plan.h on the coarse and even predicted points.
  ForEachRowBlock(plan.odd_vertex_count, [&](int begin, int end) {
    FusedBlock block;
    for (int first = begin; first < end; first += kFusedBlock) {
      const int size = std::min(kFusedBlock, end - first);
      for (int j = 0; j < size; ++j) {
        const int e = first + j;
        const int m = nc + e;
        const int* col = plan.odd_columns.data() + 8 * static_cast<Eigen::Index>(e);
        const std::uint8_t rotation = plan.odd_rotation[e];
        double t1[3], t2[3];
        if (rotation == SynthesisPlan::kGeneral) {
          const double* w = weights + weight_offsets[m];
          double s[3] = {0.0, 0.0, 0.0};
          for (int i = offsets[m]; i < offsets[m + 1]; ++i, ++w) {
            const double* x = c + 3 * static_cast<Eigen::Index>(columns[i]);
            s[0] += *w * x[0];
            s[1] += *w * x[1];
            s[2] += *w * x[2];
          }
          GeneralTangents(plan, col[0], c, t1, t2);
          for (int k = 0; k < 3; ++k) block.p[k][j] = s[k];
        } else {
          const double* pa = c + 3 * static_cast<Eigen::Index>(col[0]);
          const double* pb = c + 3 * static_cast<Eigen::Index>(col[1]);
          const double* pp = c + 3 * static_cast<Eigen::Index>(col[2]);
          const double* pq = c + 3 * static_cast<Eigen::Index>(col[3]);
          const double* x1 = c + 3 * static_cast<Eigen::Index>(col[4]);
          const double* x2 = c + 3 * static_cast<Eigen::Index>(col[5]);
          const double* x3 = c + 3 * static_cast<Eigen::Index>(col[6]);
          const double* x4 = c + 3 * static_cast<Eigen::Index>(col[7]);
          const double* ea = even_points + 3 * static_cast<Eigen::Index>(col[0]);
          const double* eb = even_points + 3 * static_cast<Eigen::Index>(col[1]);
          const double cs = rotations[2 * rotation], sn = rotations[2 * rotation + 1];
          const double h = 0.8660254037844386;  // √3/2
          for (int k = 0; k < 3; ++k) {
            block.p[k][j] = ((0.375 * pa[k] + 0.375 * pb[k]) + 0.125 * pp[k]) + 0.125 * pq[k];
            const double a0 = (ea[k] - eb[k]) + 0.25 * (pa[k] - pb[k]) +
                              0.0625 * ((x1[k] + x4[k]) - (x2[k] + x3[k]));
            const double b0 = h * (0.75 * (pq[k] - pp[k]) + 0.125 * ((x1[k] + x2[k]) - (x3[k] + x4[k])));
            t1[k] = cs * a0 - sn * b0;
            t2[k] = cs * b0 + sn * a0;
          }
        }
        for (int k = 0; k < 3; ++k) {
          block.a[k][j] = t1[k];
          block.b[k][j] = t2[k];
        }
      }
      FramesOfBlock(size, &block);
      WriteDetailed(block, size, d + 3 * static_cast<Eigen::Index>(nc + first),
                    out + 3 * static_cast<Eigen::Index>(nc + first));
    }
  });
}

Positions LimitNormals(const LoopHierarchy& hierarchy, int level,
                       const Positions& control_points) {
  return ComputeLocalFrames(hierarchy, level, control_points).normal;
}

}  // namespace subflow::geometry
