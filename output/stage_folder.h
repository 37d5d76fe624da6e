// A stage folder (docs/stages.md, layout version kStageLayoutVersion): what one stage of
// the pipeline (solver/reconstruction.h) hands to the next, on disk.
//   <folder>/base_mesh.ply                  T0, whose faces are the hierarchy's level 0
//   <folder>/hull/<frame>.ply               each frame's visual hull (silhouettes of the
//                                           cameras without masks)
//   <folder>/control/<frame>/level_<i>.ply  the frame's control points: every level for the
//                                           shape stage, the finest level for the others
//   <folder>/meshes/<frame>.ply             (shape stage) the fitted limit surfaces, OUTPUT.md
//   <folder>/outlines/<camera>.png          per camera index, the object's outline when the
//                                           shape stage measured one (StageState::outlines:
//                                           a still set on a plain backdrop); listed in
//                                           report.json's "outlines" 
//   <folder>/report.json                    written last: stage_layout_version, stage,
//                                           frames, reference_frame, levels, evidence, the
//                                           options and figures of every stage so far
// The PLY files a later stage reads hold doubles, so a stage run from the folder sees
// exactly the values the previous stage computed. Every file is written to a temporary
// name and renamed, and report.json comes last: a folder without it is unfinished, and
// reading it says so.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/reconstruction.h"

namespace subflow::output {

inline constexpr int kStageLayoutVersion = 1;

// A stage's state with its report.json.
struct StageRecord {
  solver::StageState state;
  nlohmann::json report;
};

// Writes `record` into `folder` (created; a previous stage's report.json there is removed
// first, its other files replaced), adding the layout fields to the report. `all_levels`
// (the shape stage): per frame, the control points of levels 0..n, also written as
// meshes/ (the fitted limit surfaces); otherwise the finest level only.
void WriteStageFolder(const std::string& folder, const StageRecord& record,
                      const std::vector<std::vector<geometry::Positions>>* all_levels = nullptr);

// A solver::ShapeFrameStore writing a shape stage folder while shape initialization makes
// it (the `shape` command: memory independent of the take's length): hull/<frame>.ply and
// control/<frame>/level_<i>.ply as doubles, the exact values, a hull read back from its
// file when it is needed again. Creating it marks the folder unfinished (removes its
// report.json); FinishShapeStageFolder completes it.
class ShapeStageFolderStore : public solver::ShapeFrameStore {
 public:
  explicit ShapeStageFolderStore(std::string folder);
  void StoreHull(int frame, const geometry::TriangleMesh& hull) override;
  geometry::TriangleMesh LoadHull(int frame) const override;
  void StoreControl(int frame, const geometry::LoopHierarchy& hierarchy,
                    const std::vector<geometry::Positions>& levels) override;
  int frames_fitted() const { return frames_fitted_; }  // frames whose control points were stored

 private:
  std::string folder_;
  int frames_fitted_ = 0;
};

// Completes the shape stage folder a ShapeStageFolderStore wrote the `frame_count` frames
// of: base_mesh.ply, meshes/ (from the finest control points read back two frames at a
// time) and, last, report.json (`record`: the stage's report and its state without frames).
void FinishShapeStageFolder(const std::string& folder, const StageRecord& record, int frame_count);

// True when `folder`/report.json exists: the stage that wrote the folder finished.
bool StageFolderComplete(const std::string& folder);

// Reads a complete stage folder: all its frames, or, with count > 0, only dataset frames
// [first, first + count) (a range of frames or a refinement window run alone; memory
// then grows with the range, not with the folder), the reference frame moved to the frame
// of the range nearest to it. Throws subflow::Error naming the file: no report.json
// ("unfinished"), another layout version, a stage other than `expected_stage` (when not
// empty), a range not inside the folder's frames, a missing frame file, control points
// of the wrong count.
StageRecord ReadStageFolder(const std::string& folder, const std::string& expected_stage = "", int first = 0,
                            int count = -1);

// ReadStageFolder without the frames: the report and the state's hierarchy, base mesh,
// first and reference frame, evidence and image scales, its hulls and control empty;
// *frame_count gets the number of frames (of the range, with count > 0). The files of
// frame f: StageHullPath and ControlFilePath(folder, f, levels).
StageRecord ReadStageFolderHead(const std::string& folder, const std::string& expected_stage, int first, int count,
                                int* frame_count);
// A stage folder's hull/<frame>.ply, read (without the manifold check: the stage that
// wrote it had it). Throws subflow::Error naming a missing file.
geometry::TriangleMesh ReadStageHull(const std::string& folder, int frame);
// A stage folder's finest control points of `frame`, checked against `hierarchy`.
geometry::Positions ReadStageControl(const std::string& folder, int frame, const geometry::LoopHierarchy& hierarchy);

// Seeds `in` (a motion or retrack stage's input) from the stage folder `seed`: the frame
// both hold (the one nearest to seed's reference frame, when several) becomes the
// reference frame, with seed's control points there, so that the stage's trajectories
// continue seed's across the shared frame (chunks of a plan, docs/cluster.md). Records
// {"folder", "frame"} as in->report["seed"]. Throws subflow::Error naming `seed` when the
// folders share no frame or another connectivity.
void SeedStageInput(StageRecord* in, const std::string& seed);

}  // namespace subflow::output
