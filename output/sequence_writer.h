// The recovered surface of a sequence in the layout of ../shared/OUTPUT.md and beside it:
//   <out>/meshes/<frame>.ply               the limit surface at the finest level's vertices
//                                          (L c(f), one connectivity for every frame) with
//                                          x y z, vx vy vz (motion to the next frame, zero at
//                                          the last), rigid_vx.., nonrigid_vx.. (the flow's
//                                          rigid part v + ω × x at the midpoints, and the
//                                          rest), motion_energy, nonrigid_energy (Σ over the
//                                          sequence of |flow|, |non-rigid flow|)
//   <out>/obj/<frame>.obj                  the same surface as OBJ
//   <out>/control/<frame>/level_<i>.ply    the control meshes of levels 0..n (synthesized
//                                          from the frame's multires shape)
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/rigid/rigid_split.h"

namespace subflow::output {

// `control`: the finest control points of frames first_frame, first_frame + 1, …; `split`
// their rigid split (solver::SplitRigidMotion). Returns the report's "flow" section: mean
// |flow| and |non-rigid flow| per frame step over the output vertices, vertex and face
// counts.
nlohmann::json WriteSequence(const std::string& out, const geometry::LoopHierarchy& hierarchy, int first_frame,
                             const std::vector<geometry::Positions>& control, const solver::RigidSplit& split);

}  // namespace subflow::output
