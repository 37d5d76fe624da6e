// Per-vertex scene-flow magnitudes of a result, frame by frame. The result stores at
// frame f the motion to frame f + 1 (vx vy vz; nonrigid_vx ... for its non-rigid part),
// zero at the last frame by definition; for pictures and colours the last frame shows
// the motion that led into it (the previous frame's), so a sequence does not end in a
// frame of "no motion". Magnitudes are in world units per frame.
#pragma once

#include <functional>
#include <string>
#include <vector>

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

// Calls visit(frame, magnitudes) for every frame of `result` in order; magnitudes[k] has
// the #V magnitudes of kinds[k] (the last frame's from the previous frame, see above).
// Reads each frame once.
void ForEachFrameFlow(const ResultReader& result, const std::vector<FlowKind>& kinds,
                      const std::function<void(const ResultFrame&, const std::vector<Eigen::VectorXf>&)>& visit);

// Calls visit(frame, values) for every frame of `result` in order with the #V values of
// its scalar vertex property `name` (e.g. motion_energy, or the error of `subflow eval
// --error-maps`); throws subflow::Error naming the file when a frame lacks it.
void ForEachFrameProperty(const ResultReader& result, const std::string& name,
                          const std::function<void(const ResultFrame&, const Eigen::VectorXf&)>& visit);

// Whether the result's frames carry the properties of `kind` (looked up in the first frame).
bool HasFlow(const ResultReader& result, FlowKind kind);

// Smallest and largest magnitude over every vertex and frame.
struct FlowRange {
  double min = 0.0, max = 0.0;
};
FlowRange SequenceFlowRange(const ResultReader& result, FlowKind kind);

}  // namespace subflow::output
