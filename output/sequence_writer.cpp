#include "output/sequence_writer.h"

#include <map>

#include "output/result_files.h"
#include "output/result_writer.h"
#include "solver/rigid/rigid_motion.h"

namespace subflow::output {
namespace {

// Per-frame vertex properties of the flow analysis (rigid and non-rigid flow, energies).
std::map<std::string, std::vector<Eigen::VectorXd>> FlowProperties(const solver::FlowAnalysis& flow) {
  std::map<std::string, std::vector<Eigen::VectorXd>> properties;
  const char* axes[3] = {"x", "y", "z"};
  for (std::size_t f = 0; f < flow.flow.size(); ++f) {
    for (int axis = 0; axis < 3; ++axis) {
      properties[std::string("rigid_v") + axes[axis]].push_back(flow.rigid_flow[f].col(axis));
      properties[std::string("nonrigid_v") + axes[axis]].push_back(flow.non_rigid_flow[f].col(axis));
    }
    properties["motion_energy"].push_back(flow.motion_energy);
    properties["nonrigid_energy"].push_back(flow.non_rigid_energy);
  }
  return properties;
}

}  // namespace

nlohmann::json WriteSequence(const std::string& out, const geometry::LoopHierarchy& hierarchy, int first_frame,
                             const std::vector<geometry::Positions>& control, const solver::RigidSplit& split) {
  const int finest = hierarchy.finest_level();
  const int frames = static_cast<int>(control.size());
  std::vector<geometry::Positions> surfaces;
  std::vector<std::vector<geometry::Positions>> levels;
  for (int i = 0; i < frames; ++i) {
    surfaces.push_back(hierarchy.LimitPositions(finest) * control[i]);
    levels.push_back(split.trajectory.at(i).SynthesizeLevels(hierarchy, finest));
  }
  const solver::FlowAnalysis flow = solver::AnalyzeFlow(surfaces, split.rigid);
  WriteResultMeshes(out, first_frame, hierarchy.LevelFaces(finest), surfaces, FlowProperties(flow));
  WriteObjSequence(out, first_frame, hierarchy.LevelFaces(finest), surfaces);
  WriteControlFiles(out, hierarchy, first_frame, levels);

  double mean_flow = 0, mean_non_rigid = 0;
  for (int i = 0; i + 1 < frames; ++i) {
    mean_flow += solver::FlowMagnitudes(flow.flow[i]).mean() / (frames - 1);
    mean_non_rigid += solver::FlowMagnitudes(flow.non_rigid_flow[i]).mean() / (frames - 1);
  }
  return {{"mean_flow_per_step", mean_flow},
          {"mean_non_rigid_flow_per_step", mean_non_rigid},
          {"output_vertices", surfaces.front().rows()},
          {"output_faces", hierarchy.FaceCount(finest)}};
}

}  // namespace subflow::output
