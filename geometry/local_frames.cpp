#include "geometry/local_frames.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"
#include "geometry/local_frames_kernels.h"
#include "geometry/point_stencil.h"

namespace subflow::geometry {
namespace {

using internal::kDegenerateSine;
using internal::TangentsAt;

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

Positions LimitNormals(const LoopHierarchy& hierarchy, int level,
                       const Positions& control_points) {
  return ComputeLocalFrames(hierarchy, level, control_points).normal;
}

}  // namespace subflow::geometry
