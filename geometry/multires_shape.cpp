#include "geometry/multires_shape.h"

#include <string>
#include <utility>

#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::geometry {
namespace {

std::string RowsMessage(Eigen::Index rows, int expected) {
  return "has " + std::to_string(rows) + " rows, expected " + std::to_string(expected);
}

}  // namespace

MultiresShape::MultiresShape(const LoopHierarchy& hierarchy, Positions base,
                             int detail_levels)
    : base_(std::move(base)) {
  if (detail_levels < 0) detail_levels = hierarchy.finest_level();
  if (detail_levels > hierarchy.finest_level())
    ThrowError("multires shape", "detail levels",
               std::to_string(detail_levels) + " exceeds the hierarchy's finest level " +
                   std::to_string(hierarchy.finest_level()));
  if (base_.rows() != hierarchy.VertexCount(0))
    ThrowError("multires shape", "base control points",
               RowsMessage(base_.rows(), hierarchy.VertexCount(0)));
  details_.reserve(detail_levels);
  for (int level = 1; level <= detail_levels; ++level)
    details_.push_back(Positions::Zero(hierarchy.VertexCount(level), 3));
}

void MultiresShape::Check(const LoopHierarchy& hierarchy) const {
  if (base_.rows() != hierarchy.VertexCount(0))
    ThrowError("multires shape", "base control points",
               RowsMessage(base_.rows(), hierarchy.VertexCount(0)));
  if (detail_levels() > hierarchy.finest_level())
    ThrowError("multires shape", "details",
               std::to_string(detail_levels()) + " levels, the hierarchy has " +
                   std::to_string(hierarchy.finest_level()));
  for (int level = 1; level <= detail_levels(); ++level)
    if (Detail(level).rows() != hierarchy.VertexCount(level))
      ThrowError("multires shape", "detail level " + std::to_string(level),
                 RowsMessage(Detail(level).rows(), hierarchy.VertexCount(level)));
}

MultiresShape MultiresShape::Analyze(const LoopHierarchy& hierarchy,
                                     const Positions& finest_control_points) {
  const int n = hierarchy.finest_level();
  if (finest_control_points.rows() != hierarchy.VertexCount(n))
    ThrowError("multires analysis", "finest control points",
               RowsMessage(finest_control_points.rows(), hierarchy.VertexCount(n)));
  MultiresShape shape;
  shape.details_.resize(n);
  Positions fine = finest_control_points;
  for (int level = n; level >= 1; --level) {
    Positions coarse = MultiplyPoints(hierarchy.Coarsening(level), fine);
    Positions predicted;  // as synthesis computes it (same stencil, same rounding)
    hierarchy.RefinementStencil(level - 1).Apply(coarse, &predicted);
    const LocalFrames frames = ComputeLocalFrames(hierarchy, level, predicted);
    shape.details_[level - 1] = frames.ToLocal(fine - predicted);
    fine = std::move(coarse);
  }
  shape.base_ = std::move(fine);
  return shape;
}

Positions MultiresShape::Synthesize(const LoopHierarchy& hierarchy, int level,
                                    std::vector<LocalFrames>* frames) const {
  Check(hierarchy);
  SUBFLOW_CHECK(level >= 0 && level <= hierarchy.finest_level(), "level out of range");
  if (frames) {
    frames->clear();
    frames->resize(level);
  }
  Positions c = base_, next;
  for (int i = 1; i <= level; ++i) {
    if (i > detail_levels()) {
      hierarchy.RefinementStencil(i - 1).Apply(c, &next);
    } else if (frames) {
      hierarchy.RefinementStencil(i - 1).Apply(c, &next);
      (*frames)[i - 1] = ComputeLocalFrames(hierarchy, i, next);
      next += (*frames)[i - 1].ToWorld(Detail(i));
    } else {
      RefineAndAddDetails(hierarchy, i, c, Detail(i), &next);
    }
    c.swap(next);
  }
  return c;
}

std::vector<Positions> MultiresShape::SynthesizeLevels(const LoopHierarchy& hierarchy,
                                                       int level) const {
  Check(hierarchy);
  SUBFLOW_CHECK(level >= 0 && level <= hierarchy.finest_level(), "level out of range");
  std::vector<Positions> levels;
  levels.reserve(level + 1);
  levels.push_back(base_);
  for (int i = 1; i <= level; ++i) {
    Positions predicted;
    hierarchy.RefinementStencil(i - 1).Apply(levels.back(), &predicted);
    if (i <= detail_levels()) {
      Positions c;
      AddDetailsInLocalFrames(hierarchy, i, predicted, Detail(i), &c);
      predicted.swap(c);
    }
    levels.push_back(std::move(predicted));
  }
  return levels;
}

Trajectory AnalyzeTrajectory(const LoopHierarchy& hierarchy,
                             const std::vector<Positions>& finest_control_points) {
  Trajectory trajectory(finest_control_points.size());
  tbb::parallel_for(size_t{0}, finest_control_points.size(), [&](size_t frame) {
    trajectory[frame] = MultiresShape::Analyze(hierarchy, finest_control_points[frame]);
  });
  return trajectory;
}

std::vector<Positions> SynthesizeTrajectory(const LoopHierarchy& hierarchy,
                                            const Trajectory& trajectory, int level) {
  std::vector<Positions> control_points(trajectory.size());
  tbb::parallel_for(size_t{0}, trajectory.size(), [&](size_t frame) {
    control_points[frame] = trajectory[frame].Synthesize(hierarchy, level);
  });
  return control_points;
}

}  // namespace subflow::geometry
