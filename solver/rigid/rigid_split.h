// The last stage of the method (§5): the rigid / non-rigid split of trajectories on one
// LoopHierarchy. Every frame's finest control points are analyzed into a MultiresShape
// (base c⁰ and details in local frames, geometry::AnalyzeTrajectory), and the rigid motion
// of every frame step is fitted to the base control trajectories (FitRigidMotions: Cayley
// convention, midpoints, see rigid_motion.h). Per-vertex flows of the output surface come
// from AnalyzeFlow on its positions with these rigid motions.
#pragma once

#include <string>
#include <vector>

#include "geometry/loop_hierarchy.h"
#include "geometry/multires_shape.h"
#include "solver/rigid/rigid_motion.h"

namespace subflow::solver {

struct RigidSplit {
  geometry::Trajectory trajectory;  // per frame: multires analysis of the control points
  std::vector<RigidMotion> rigid;   // per frame step f → f + 1 (frames − 1)
  double seconds = 0.0;

  // One line: frame steps, mean rotation per step, mean fit residual.
  std::string BriefReport() const;
};

// `control`: per frame, the finest control points (#V(n)×3). Throws subflow::Error when
// there is no frame or a frame has another vertex count.
RigidSplit SplitRigidMotion(const geometry::LoopHierarchy& hierarchy,
                            const std::vector<geometry::Positions>& control);

}  // namespace subflow::solver
