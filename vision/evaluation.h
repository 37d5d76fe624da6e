// Scoring a reconstruction against ground truth (`subflow eval DATASET RESULT`).
//
// Inputs: the true meshes (DATASET/groundtruth/mesh/<frame>.ply, ../shared/DATASET.md)
// and the result's meshes (RESULT/meshes/<frame>.ply, ../shared/OUTPUT.md), both with
// the same vertex count, order and faces at every frame. Distances are in world units.
//
// Surface figures per frame (R = result surface, T = true surface, d(x, S) = distance
// from x to the nearest point of S, samples = SampleSurface, area-weighted):
//   accuracy      the `accuracy_percentile` (90) percentile of d(r, T) over samples r of R
//   completeness  fraction of samples t of T with d(t, R) ≤ threshold
//                 (default threshold: 1 % of the diagonal of T's bounding box at frame 0)
//   chamfer       (mean_r d(r, T) + mean_t d(t, R)) / 2
//   hausdorff     max(max_r d(r, T), max_t d(t, R))   (over the samples)
// Scene flow per frame f < last (for each result vertex x_i at f):
//   (face, u, v) = the closest point c_i of T_f to x_i; the true position of that
//   material point at f + 1 is c'_i = the same (face, u, v) on T_{f+1};
//   true motion m_i = c'_i − c_i; recovered motion r_i = (vx, vy, vz) of vertex i when
//   the result PLY has them, else x_i(f + 1) − x_i(f);
//   EPE_i = |r_i − m_i|; reported: mean, median, mean |m_i|, relative = mean EPE / mean |m_i|.
// Overall: accuracy = percentile of the pooled samples of all frames; completeness,
// chamfer = mean over frames; hausdorff = max; EPE mean / median / relative pooled over
// all vertices of all frames.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "geometry/closest_point.h"
#include "core/progress.h"
#include "geometry/triangle_mesh.h"

namespace subflow::vision {

struct EvaluationOptions {
  double threshold = 0.0;              // completeness distance; 0 = 1 % of the true bbox diagonal
  int samples = 50000;                 // area-weighted samples per surface and frame
  double accuracy_percentile = 90.0;   // in (0, 100]

  void Check() const;  // throws subflow::Error naming the field
};

struct SurfaceScores {
  double accuracy = 0.0, completeness = 0.0, chamfer = 0.0, hausdorff = 0.0;
  double mean_result_to_truth = 0.0, mean_truth_to_result = 0.0;
};

struct FlowScores {
  bool evaluated = false;  // false at the last frame
  double epe_mean = 0.0, epe_median = 0.0, true_motion_mean = 0.0, epe_relative = 0.0;
  // Mean magnitude of the error's component along the true surface normal (the part a
  // shape error makes) and of its component in the tangent plane (sliding along the surface).
  double epe_normal_mean = 0.0, epe_tangential_mean = 0.0;
};

struct FrameScores {
  int frame = -1;  // −1 for the overall figures
  SurfaceScores surface;
  FlowScores flow;
};

struct EvaluationReport {
  std::vector<FrameScores> frames;
  FrameScores overall;
  double threshold = 0.0;
  int samples = 0;
  double accuracy_percentile = 90.0;
  std::string flow_source;  // "vx vy vz" or "vertex differences"

  std::string Table() const;  // one line per frame + overall, fixed-width columns
  std::string Json() const;   // the same figures as a JSON document
};

// `count` points on the surface, area-weighted and deterministic: triangle i gets
// floor(C_i) − floor(C_{i−1}) points (C = cumulative area · count / total area), placed
// by an R2 low-discrepancy sequence folded into the triangle. #count×3.
geometry::Positions SampleSurface(const geometry::TriangleMesh& mesh, int count);

// A frame of a sequence: the mesh and, when present, the recovered motion (#V×3).
struct EvaluationFrame {
  geometry::TriangleMesh mesh;
  std::optional<geometry::Positions> motion;
};

// Core: evaluates `frame_count` frames given loaders of the true mesh and the result at
// a frame (each called about once per frame, a window of two frames is kept). Checks
// that vertex counts and faces do not change between frames (throws subflow::Error
// naming `result_source` / `truth_source` and the frame).
EvaluationReport EvaluateSequence(int frame_count,
                                  const std::function<geometry::TriangleMesh(int)>& load_truth,
                                  const std::function<EvaluationFrame(int)>& load_result,
                                  const EvaluationOptions& options, Progress* progress = nullptr,
                                  const std::string& truth_source = "ground truth",
                                  const std::string& result_source = "result");

// Reads DATASET/groundtruth/mesh/*.ply and RESULT/meshes/*.ply and evaluates them.
// Throws subflow::Error for a missing directory, a gap in the frame numbers, different
// frame counts, or meshes whose vertex count / faces change between frames.
EvaluationReport EvaluateReconstruction(const std::string& dataset_directory,
                                        const std::string& result_directory,
                                        const EvaluationOptions& options,
                                        Progress* progress = nullptr);

// Frame files "<dir>/000000.ply" … of a directory, checked to be contiguous from 0, or,
// when `first_frame` is given, from the first frame present (returned there). Throws
// naming the directory when it is missing or empty, and the first missing frame.
std::vector<std::string> ListFrameMeshes(const std::string& directory, int* first_frame = nullptr);

}  // namespace subflow::vision
