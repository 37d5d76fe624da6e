#include "geometry/local_frames.h"

#include <cmath>

#include <Eigen/Geometry>

#include "geometry/error.h"

namespace subflow::geometry {
namespace {

// Relative size of |t1 × t2| against |t1||t2| below which a frame counts as degenerate.
constexpr double kDegenerateSine = 1e-12;

}  // namespace

void FrameFromTangents(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                       Eigen::Vector3d* n, Eigen::Vector3d* r, Eigen::Vector3d* q) {
  const Eigen::Vector3d cross = t1.cross(t2);
  const double cross_norm = cross.norm();
  const double t1_norm = t1.norm();
  if (!(cross_norm > kDegenerateSine * t1_norm * t2.norm())) {  // also catches NaN
    *n = Eigen::Vector3d::UnitZ();
    *r = Eigen::Vector3d::UnitX();
    *q = Eigen::Vector3d::UnitY();
    return;
  }
  *n = cross / cross_norm;
  *r = t1 / t1_norm;  // t1 ⟂ n already
  *q = n->cross(*r);
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
  const Positions t1 = MultiplyPoints(hierarchy.LimitTangent(level, 0), control_points);
  const Positions t2 = MultiplyPoints(hierarchy.LimitTangent(level, 1), control_points);
  return FramesFromTangents(t1, t2);
}

void AddDetailsInLocalFrames(const LoopHierarchy& hierarchy, int level, const Positions& local,
                             Positions* points) {
  SUBFLOW_CHECK(points->rows() == hierarchy.VertexCount(level) && local.rows() == points->rows(),
                "points or details do not match the level's vertex count");
  // tangents.row(2v) = t1(v), tangents.row(2v + 1) = t2(v).
  const Positions tangents = MultiplyPoints(hierarchy.LimitTangentPair(level), *points);
  Eigen::Vector3d n, r, q;
  for (Eigen::Index v = 0; v < points->rows(); ++v) {
    FrameFromTangents(tangents.row(2 * v).transpose(), tangents.row(2 * v + 1).transpose(), &n,
                      &r, &q);
    points->row(v) += (local(v, 0) * n + local(v, 1) * r + local(v, 2) * q).transpose();
  }
}

Positions LimitNormals(const LoopHierarchy& hierarchy, int level,
                       const Positions& control_points) {
  return ComputeLocalFrames(hierarchy, level, control_points).normal;
}

}  // namespace subflow::geometry
