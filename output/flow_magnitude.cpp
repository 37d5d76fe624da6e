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

void ForEachFrameFlow(const ResultReader& result, const std::vector<FlowKind>& kinds,
                      const std::function<void(const ResultFrame&, const std::vector<Eigen::VectorXf>&)>& visit) {
  std::vector<Eigen::VectorXf> previous;
  for (int i = 0; i < result.frame_count(); ++i) {
    const ResultFrame frame = result.ReadFrame(i);
    std::vector<Eigen::VectorXf> magnitudes;
    for (FlowKind kind : kinds)
      magnitudes.push_back(frame.Vectors(FlowPropertyPrefix(kind), result.MeshPath(i)).rowwise().norm().cast<float>());
    if (i + 1 == result.frame_count() && i > 0) magnitudes = previous;
    visit(frame, magnitudes);
    previous = std::move(magnitudes);
  }
}

void ForEachFrameProperty(const ResultReader& result, const std::string& name,
                          const std::function<void(const ResultFrame&, const Eigen::VectorXf&)>& visit) {
  for (int i = 0; i < result.frame_count(); ++i) {
    const ResultFrame frame = result.ReadFrame(i);
    const auto found = frame.properties.values.find(name);
    if (found == frame.properties.values.end())
      ThrowError(result.MeshPath(i), "vertex property " + name, "missing (asked for by --colour-by)");
    visit(frame, found->second.cast<float>());
  }
}

bool HasFlow(const ResultReader& result, FlowKind kind) {
  const ResultFrame first = result.ReadFrame(0);
  return first.properties.values.count(FlowPropertyPrefix(kind) + "x") > 0;
}

FlowRange SequenceFlowRange(const ResultReader& result, FlowKind kind) {
  double low = std::numeric_limits<double>::infinity(), high = 0.0;
  ForEachFrameFlow(result, {kind}, [&](const ResultFrame&, const std::vector<Eigen::VectorXf>& magnitudes) {
    low = std::min(low, static_cast<double>(magnitudes[0].minCoeff()));
    high = std::max(high, static_cast<double>(magnitudes[0].maxCoeff()));
  });
  return {low, high};
}

}  // namespace subflow::output
