#include "solver/rigid/rigid_split.h"

#include <string>

#include "core/error.h"
#include "core/stopwatch.h"

namespace subflow::solver {

RigidSplit SplitRigidMotion(const geometry::LoopHierarchy& hierarchy,
                            const std::vector<geometry::Positions>& control) {
  const Stopwatch start;
  if (control.empty()) ThrowError("rigid split", "control points", "needs at least one frame");
  const Eigen::Index vertices = hierarchy.VertexCount(hierarchy.finest_level());
  for (std::size_t f = 0; f < control.size(); ++f)
    if (control[f].rows() != vertices)
      ThrowError("rigid split", "control points of frame " + std::to_string(f),
                 std::to_string(control[f].rows()) + " rows, expected #V(n) = " + std::to_string(vertices));
  RigidSplit split;
  split.trajectory = geometry::AnalyzeTrajectory(hierarchy, control);
  std::vector<geometry::Positions> bases;
  bases.reserve(split.trajectory.size());
  for (const geometry::MultiresShape& shape : split.trajectory) bases.push_back(shape.base());
  split.rigid = FitRigidMotions(bases);
  split.seconds = start.Seconds();
  return split;
}

}  // namespace subflow::solver
