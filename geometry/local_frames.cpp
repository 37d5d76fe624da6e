#include "geometry/local_frames.h"

#include <cmath>

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
    double a[3], b[3];
    for (int v = begin; v < end; ++v) {
      TangentsAt(stencil, regular_offset, control_points.data(), v, a, b);
      FrameFromTangentsRaw(a, b, frames.normal.row(v).data(), frames.r.row(v).data(),
                           frames.q.row(v).data());
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
    double a[3], b[3], n[3], r[3], q[3];
    for (int v = begin; v < end; ++v) {
      TangentsAt(stencil, regular_offset, p, v, a, b);
      FrameFromTangentsRaw(a, b, n, r, q);
      const double* dv = d + 3 * static_cast<Eigen::Index>(v);
      for (int k = 0; k < 3; ++k)
        out[3 * v + k] = p[3 * v + k] + (dv[0] * n[k] + dv[1] * r[k] + dv[2] * q[k]);
    }
  });
}

Positions LimitNormals(const LoopHierarchy& hierarchy, int level,
                       const Positions& control_points) {
  return ComputeLocalFrames(hierarchy, level, control_points).normal;
}

}  // namespace subflow::geometry
