// Per-vertex scene-flow magnitudes of a result, frame by frame. The result stores at
// frame f the motion to frame f + 1 (vx vy vz; nonrigid_vx ... for its non-rigid part),
// zero at the last frame by definition; for pictures and colours the last frame shows
// the motion that led into it (the previous frame's), so a sequence does not end in a
// frame of "no motion". Magnitudes are in world units per frame.
#pragma once

#include <functional>
#include <string>

#include <Eigen/Core>

#include "output/result_reader.h"

namespace subflow::output {

enum class FlowKind {
  kTotal,     // vx vy vz: the scene flow
  kNonRigid,  // nonrigid_vx ...: the flow minus the rigid motion fitted per frame
};

// "v" or "nonrigid_v": the property prefix of the flow (ResultFrame::Vectors).
std::string FlowPropertyPrefix(FlowKind kind);
// "scene flow |v|" or "non-rigid flow |v − v_rigid|".
std::string FlowLabel(FlowKind kind);
// Parses "flow" / "nonrigid"; throws subflow::Error naming `source` otherwise.
FlowKind ParseFlowKind(const std::string& name, const std::string& source);

// Calls visit(frame, magnitudes) for every frame of `result` in order (#V magnitudes,
// the last frame's from the previous frame, see above). Reads each frame once.
void ForEachFrameFlow(const ResultReader& result, FlowKind kind,
                      const std::function<void(const ResultFrame&, const Eigen::VectorXf&)>& visit);

// Smallest and largest magnitude over every vertex and frame.
struct FlowRange {
  double min = 0.0, max = 0.0;
};
FlowRange SequenceFlowRange(const ResultReader& result, FlowKind kind);

}  // namespace subflow::output
