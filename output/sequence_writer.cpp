#include "output/sequence_writer.h"

#include <filesystem>
#include <map>

#include "core/stopwatch.h"
#include "output/result_files.h"
#include "output/result_writer.h"
#include "solver/rigid/rigid_motion.h"

namespace subflow::output {
namespace {

using geometry::Positions;

// The output surface of frame index i: the limit positions of the finest level's vertices.
Positions Surface(const StageFrames& frames, int i) {
  const geometry::LoopHierarchy& hierarchy = frames.Hierarchy();
  return hierarchy.LimitPositions(hierarchy.finest_level()) * frames.Control(i);
}

// One frame step's flow, its rigid part (at the midpoints, as solver::AnalyzeFlow) and the rest.
struct StepFlow {
  Positions flow, rigid_flow, non_rigid;
};
StepFlow FlowOfStep(const Positions& from, const Positions& to, const solver::RigidMotion& rigid) {
  StepFlow step;
  step.flow = to - from;
  const Positions midpoints = 0.5 * (from + to);
  step.rigid_flow = rigid.Velocity(midpoints);
  step.non_rigid = step.flow - step.rigid_flow;
  return step;
}

// First pass: the rigid motion of every frame step and the per-vertex energies
// Σ_f |flow_f|, Σ_f |non-rigid flow_f| (summed in frame order, as solver::AnalyzeFlow),
// and the mean |flow|, |non-rigid flow| per step.
struct SplitPass {
  std::vector<solver::RigidMotion> rigid;
  Eigen::VectorXd motion_energy, non_rigid_energy;
  double mean_flow = 0, mean_non_rigid = 0;
};
SplitPass RunSplitPass(const StageFrames& frames) {
  const geometry::LoopHierarchy& hierarchy = frames.Hierarchy();
  const int count = frames.frame_count();
  SplitPass pass;
  Positions previous_c0, previous_surface;
  for (int i = 0; i < count; ++i) {
    const Positions control = frames.Control(i);
    Positions c0 = geometry::MultiresShape::Analyze(hierarchy, control).base();
    Positions surface = hierarchy.LimitPositions(hierarchy.finest_level()) * control;
    if (i == 0) {
      pass.motion_energy = Eigen::VectorXd::Zero(surface.rows());
      pass.non_rigid_energy = Eigen::VectorXd::Zero(surface.rows());
    } else {
      pass.rigid.push_back(solver::FitRigidMotion(0.5 * (previous_c0 + c0), c0 - previous_c0));
      const StepFlow step = FlowOfStep(previous_surface, surface, pass.rigid.back());
      const Eigen::VectorXd flow = solver::FlowMagnitudes(step.flow), non_rigid = solver::FlowMagnitudes(step.non_rigid);
      pass.motion_energy += flow;
      pass.non_rigid_energy += non_rigid;
      pass.mean_flow += flow.mean() / (count - 1);
      pass.mean_non_rigid += non_rigid.mean() / (count - 1);
    }
    previous_c0 = std::move(c0);
    previous_surface = std::move(surface);
  }
  return pass;
}

// The mesh's vertex properties of one frame (rigid and non-rigid flow to the next frame,
// zero at the last; the energies).
std::map<std::string, Eigen::VectorXd> FlowProperties(const StepFlow& step, const SplitPass& pass) {
  std::map<std::string, Eigen::VectorXd> properties;
  const char* axes[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    properties[std::string("rigid_v") + axes[axis]] = step.rigid_flow.col(axis);
    properties[std::string("nonrigid_v") + axes[axis]] = step.non_rigid.col(axis);
  }
  properties["motion_energy"] = pass.motion_energy;
  properties["nonrigid_energy"] = pass.non_rigid_energy;
  return properties;
}

}  // namespace

nlohmann::json WriteSequence(const std::string& out, const StageFrames& frames, solver::RigidSplit* split) {
  const geometry::LoopHierarchy& hierarchy = frames.Hierarchy();
  const int finest = hierarchy.finest_level();
  const geometry::Faces& faces = hierarchy.LevelFaces(finest);
  const int count = frames.frame_count();
  const Stopwatch split_start;
  const SplitPass pass = RunSplitPass(frames);
  split->rigid = pass.rigid;
  split->seconds = split_start.Seconds();

  std::filesystem::create_directories(std::filesystem::path(out) / "meshes");
  Positions surface = Surface(frames, 0);
  const Eigen::Index vertices = surface.rows();
  for (int i = 0; i < count; ++i) {
    const int frame = frames.first_frame() + i;
    Positions next;
    StepFlow step;
    if (i + 1 < count) {
      next = Surface(frames, i + 1);
      step = FlowOfStep(surface, next, pass.rigid[i]);
    } else {
      step = {Positions::Zero(vertices, 3), Positions::Zero(vertices, 3), Positions::Zero(vertices, 3)};
    }
    WriteResultMesh(out, frame, faces, surface, step.flow, FlowProperties(step, pass));
    WriteObjFile(out, frame, faces, surface);
    const geometry::MultiresShape shape = geometry::MultiresShape::Analyze(hierarchy, frames.Control(i));
    WriteFrameControlFiles(out, hierarchy, frame, shape.SynthesizeLevels(hierarchy, finest));
    WriteHullFile(out, frame, frames.Hull(i));
    surface = std::move(next);
  }
  return {{"mean_flow_per_step", pass.mean_flow},
          {"mean_non_rigid_flow_per_step", pass.mean_non_rigid},
          {"output_vertices", vertices},
          {"output_faces", hierarchy.FaceCount(finest)}};
}

}  // namespace subflow::output
