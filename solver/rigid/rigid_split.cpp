#include "solver/rigid/rigid_split.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <spdlog/fmt/fmt.h>

#include "core/error.h"
#include "core/stopwatch.h"

namespace subflow::solver {

std::string RigidSplit::BriefReport() const {
  double angle = 0, residual = 0;
  for (const RigidMotion& step : rigid) angle += step.RotationAngle(), residual += step.rms_residual;
  const double steps = std::max<std::size_t>(1, rigid.size());
  return fmt::format("rigid split: {} frame steps, mean rotation {:.3f}° per step, mean fit residual {:.3g}",
                     rigid.size(), angle / steps * 180.0 / M_PI, residual / steps);
}

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
