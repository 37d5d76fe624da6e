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
#include "output/stage_frames.h"
#include "solver/rigid/rigid_split.h"

namespace subflow::output {

// The rigid / non-rigid split (method §5) of `frames` and the files above in `out`, read
// and written frame by frame in two passes (the energies of every frame's mesh are sums
// over the take): the first fits the rigid motion of each frame step on the base control
// points (solver::FitRigidMotions) and sums the energies, the second writes each frame.
// Memory holds two frames at a time; the results equal solver::SplitRigidMotion and
// solver::AnalyzeFlow on the whole take, bit for bit (the same operations in the same
// order). *split gets the rigid motions (its trajectory stays empty) and the first pass's
// time. Returns the report's "flow" section: mean |flow| and |non-rigid flow| per frame
// step over the output vertices, vertex and face counts.
nlohmann::json WriteSequence(const std::string& out, const StageFrames& frames, solver::RigidSplit* split);

}  // namespace subflow::output
