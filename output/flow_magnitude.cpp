#include "output/flow_magnitude.h"

#include <limits>

#include "core/error.h"

namespace subflow::output {

std::string FlowPropertyPrefix(FlowKind kind) { return kind == FlowKind::kTotal ? "v" : "nonrigid_v"; }

std::string FlowLabel(FlowKind kind) {
  return kind == FlowKind::kTotal ? "scene flow |v|" : "non-rigid flow |v - v_rigid|";
}

FlowKind ParseFlowKind(const std::string& name, const std::string& source) {
  if (name == "flow") return FlowKind::kTotal;
  if (name == "nonrigid") return FlowKind::kNonRigid;
  ThrowError(source, "", "unknown flow \"" + name + "\" (expected flow or nonrigid)");
}

void ForEachFrameFlow(const ResultReader& result, FlowKind kind,
                      const std::function<void(const ResultFrame&, const Eigen::VectorXf&)>& visit) {
  Eigen::VectorXf previous;
  const std::string prefix = FlowPropertyPrefix(kind);
  for (int i = 0; i < result.frame_count(); ++i) {
    const ResultFrame frame = result.ReadFrame(i);
    Eigen::VectorXf magnitudes = frame.Vectors(prefix, result.MeshPath(i)).rowwise().norm().cast<float>();
    if (i + 1 == result.frame_count() && i > 0) magnitudes = previous;
    visit(frame, magnitudes);
    previous = std::move(magnitudes);
  }
}

FlowRange SequenceFlowRange(const ResultReader& result, FlowKind kind) {
  double low = std::numeric_limits<double>::infinity(), high = 0.0;
  ForEachFrameFlow(result, kind, [&](const ResultFrame&, const Eigen::VectorXf& magnitudes) {
    low = std::min(low, static_cast<double>(magnitudes.minCoeff()));
    high = std::max(high, static_cast<double>(magnitudes.maxCoeff()));
  });
  return {low, high};
}

}  // namespace subflow::output
