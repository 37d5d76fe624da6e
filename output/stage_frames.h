// The frames of a stage's state one at a time, so that what reads them (the split and the
// result files, output/sequence_writer.h) holds one or two frames, not the take: from a
// StageState in memory (reconstruct) or from a stage folder read frame by frame (`subflow
// split`, whose memory then does not grow with the take's length; docs/cluster.md).
#pragma once

#include <string>

#include "output/stage_folder.h"

namespace subflow::output {

class StageFrames {
 public:
  virtual ~StageFrames() = default;
  virtual int first_frame() const = 0;  // dataset frame of index 0
  virtual int frame_count() const = 0;
  virtual const geometry::LoopHierarchy& Hierarchy() const = 0;
  virtual const geometry::TriangleMesh& BaseMesh() const = 0;
  // Index i's finest control points, #V(n)×3.
  virtual geometry::Positions Control(int i) const = 0;
  // Index i's visual hull.
  virtual geometry::TriangleMesh Hull(int i) const = 0;
};

// The frames of a StageState in memory (which must outlive this).
class StateFrames : public StageFrames {
 public:
  explicit StateFrames(const solver::StageState& state) : state_(state) {}
  int first_frame() const override { return state_.first_frame; }
  int frame_count() const override { return state_.frame_count(); }
  const geometry::LoopHierarchy& Hierarchy() const override { return state_.Hierarchy(); }
  const geometry::TriangleMesh& BaseMesh() const override { return state_.base_mesh; }
  geometry::Positions Control(int i) const override { return state_.control.at(i); }
  geometry::TriangleMesh Hull(int i) const override { return state_.hulls.at(i); }

 private:
  const solver::StageState& state_;
};

// The frames of a complete stage folder, read from its files when asked for (the exact
// doubles the stage wrote, as ReadStageFolder reads them). The constructor reads and
// checks the report and the base mesh (ReadStageFolderHead); Control and Hull throw
// subflow::Error naming a missing or mismatched file.
class StageFolderFrames : public StageFrames {
 public:
  explicit StageFolderFrames(const std::string& folder, const std::string& expected_stage = "");
  const nlohmann::json& report() const { return head_.report; }
  int first_frame() const override { return head_.state.first_frame; }
  int frame_count() const override { return frame_count_; }
  const geometry::LoopHierarchy& Hierarchy() const override { return head_.state.Hierarchy(); }
  const geometry::TriangleMesh& BaseMesh() const override { return head_.state.base_mesh; }
  geometry::Positions Control(int i) const override;
  geometry::TriangleMesh Hull(int i) const override;

 private:
  std::string folder_;
  StageRecord head_;  // the report and the state without frames
  int frame_count_ = 0;
};

}  // namespace subflow::output
